//! Looking through a medium along a coordinate axis.

use glam::DVec3;
use rt_volume::{Bounds, TraceParams};

use crate::{Mode, Reconstruction, SchlierenBench, Weighting};

/// The coordinate axis a beam or camera looks along.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Axis {
    /// Along +x (image axes y, z).
    X,
    /// Along +y (image axes z, x).
    Y,
    /// Along +z (image axes x, y).
    #[default]
    Z,
}

impl Axis {
    /// The beam direction and the image's u axis (its v axis is their
    /// cross product: right-handed).
    #[must_use]
    pub fn frame(self) -> (DVec3, DVec3) {
        match self {
            Self::X => (DVec3::X, DVec3::Y),
            Self::Y => (DVec3::Y, DVec3::Z),
            Self::Z => (DVec3::Z, DVec3::X),
        }
    }

    /// The image's size in pixels for a box `b` seen along this axis,
    /// `width` pixels across: the height keeps the box's aspect.
    #[must_use]
    pub fn image_size(self, b: Bounds, width: usize) -> (usize, usize) {
        let (direction, u) = self.frame();
        let ext = b.max - b.min;
        let h = crate::math::round(width as f64 * ext.dot(direction.cross(u)) / ext.dot(u));
        (width, (h as usize).max(1))
    }
}

impl SchlierenBench {
    /// A bench looking through the box `b` along `axis`: the beam covers
    /// the box's cross-section and starts upstream of it; the optics image
    /// the box's mid-plane, the film sits `film_distance` behind it
    /// (negative: in front); one photon per lattice cell, by sheet.
    #[must_use]
    pub fn through(
        b: Bounds,
        axis: Axis,
        mode: Mode,
        film_distance: f64,
        params: TraceParams,
    ) -> Self {
        let (direction, u) = axis.frame();
        let v = direction.cross(u);
        let ext = b.max - b.min;
        let upstream = 0.5 * ext.dot(direction) + 0.1 * ext.length();
        Self {
            center: 0.5 * (b.min + b.max) - upstream * direction,
            image_plane: upstream,
            direction,
            u,
            width: ext.dot(u),
            height: ext.dot(v),
            film_distance,
            mode,
            weighting: Weighting::Weight,
            reconstruction: Reconstruction::Sheet,
            strata: 1,
            params,
        }
    }
}
