//! Input checks shared by building and refitting.

use glam::Vec3;

use crate::BuildError;

/// The vertices of each triangle, checked.
pub(crate) fn triangle_vertices<'a>(
    positions: &'a [Vec3],
    indices: &'a [[u32; 3]],
) -> Result<impl Iterator<Item = Result<[Vec3; 3], BuildError>> + 'a, BuildError> {
    if let Some(bad) = indices
        .iter()
        .flatten()
        .map(|&i| i as usize)
        .find(|&i| i < positions.len() && !positions[i].is_finite())
    {
        return Err(BuildError::NonFiniteVertex { vertex: bad });
    }
    Ok(indices.iter().enumerate().map(|(t, idx)| {
        let mut v = [Vec3::ZERO; 3];
        for k in 0..3 {
            v[k] = *positions
                .get(idx[k] as usize)
                .ok_or(BuildError::IndexOutOfRange { triangle: t, index: idx[k] })?;
        }
        Ok(v)
    }))
}
