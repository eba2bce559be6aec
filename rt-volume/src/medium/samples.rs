//! What a file's samples are, and the one place they become index.

use alloc::{string::ToString, vec::Vec};

use super::MediumError;
use crate::{GLADSTONE_DALE_AIR, Grid, gladstone_dale};

/// What a volume's or mesh's values are.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Samples {
    /// Gas density in kg/m³, mapped to index by Gladstone–Dale
    /// `n = 1 + K·ρ` (`gladstone_dale`: K in m³/kg).
    Density {
        /// The Gladstone–Dale constant K, m³/kg.
        gladstone_dale: f64,
    },
    /// The refractive index itself.
    Index,
}

impl Default for Samples {
    /// Density of air ([`Samples::AIR`]).
    fn default() -> Self {
        Self::AIR
    }
}

impl Samples {
    /// Density of air at 589 nm ([`GLADSTONE_DALE_AIR`]).
    pub const AIR: Self = Self::Density { gladstone_dale: GLADSTONE_DALE_AIR };

    /// `Err` if `lowest` is non-physical for these samples (and not
    /// allowed), or the constant is bad.
    fn check(
        self,
        lowest: f64,
        allow_nonphysical: bool,
        array: Option<&str>,
    ) -> Result<(), MediumError> {
        let (bad, what) = match self {
            Self::Density { .. } => (lowest <= 0.0, "a density ≤ 0 kg/m³"),
            Self::Index => (lowest < 1.0, "an index below 1"),
        };
        if bad && !allow_nonphysical {
            return Err(MediumError::NonPhysical {
                what,
                lowest,
                array: array.map(ToString::to_string),
            });
        }
        match self {
            Self::Density { gladstone_dale: k } if !(k.is_finite() && k > 0.0) => {
                Err(MediumError::GladstoneDale(k))
            }
            _ => Ok(()),
        }
    }

    /// `grid`'s samples as index.
    ///
    /// # Errors
    /// [`MediumError::NonPhysical`] for a density ≤ 0 or an index below 1
    /// unless `allow_nonphysical`; [`MediumError::GladstoneDale`] for a
    /// constant that is not finite and positive; [`MediumError::Grid`] if
    /// the mapping overflows.
    pub fn grid_to_index(self, grid: Grid, allow_nonphysical: bool) -> Result<Grid, MediumError> {
        let lowest = grid.data().iter().copied().fold(f32::INFINITY, f32::min);
        self.check(f64::from(lowest), allow_nonphysical, None)?;
        Ok(match self {
            Self::Density { gladstone_dale: k } => {
                grid.map(|rho| gladstone_dale(f64::from(rho), k) as f32)?
            }
            Self::Index => grid,
        })
    }

    /// A mesh's `values` (of array `array`) as index.
    ///
    /// # Errors
    /// As [`Samples::grid_to_index`] (non-finite results are the mesh's
    /// to refuse).
    pub fn values_to_index(
        self,
        values: Vec<f64>,
        allow_nonphysical: bool,
        array: &str,
    ) -> Result<Vec<f64>, MediumError> {
        let lowest = values.iter().copied().fold(f64::INFINITY, f64::min);
        self.check(lowest, allow_nonphysical, Some(array))?;
        Ok(match self {
            Self::Density { gladstone_dale: k } => {
                values.iter().map(|&rho| gladstone_dale(rho, k)).collect()
            }
            Self::Index => values,
        })
    }
}

#[cfg(test)]
mod tests {
    use alloc::vec;

    use glam::DVec3;

    use super::*;

    fn grid(values: &[f32]) -> Grid {
        Grid::new([values.len(), 1, 1], DVec3::ZERO, DVec3::ONE, values.to_vec()).unwrap()
    }

    /// Gladstone–Dale with air's constant: 1.2 kg/m³ is n − 1 = 2.712e-4
    /// (air at sea level, 589 nm, reads 2.77e-4 in Edlén's tables; the
    /// constant is rounded for 1.225 kg/m³).
    #[test]
    fn density_becomes_index_by_gladstone_dale() {
        let g = Samples::AIR.grid_to_index(grid(&[1.2, 0.6]), false).unwrap();
        assert_eq!(g.data(), &[(1.0 + 2.26e-4 * 1.2f64) as f32, (1.0 + 2.26e-4 * 0.6f64) as f32]);
        let v = Samples::AIR.values_to_index(vec![1.2], false, "rho").unwrap();
        assert!((v[0] - 1.000_271_2).abs() < 1e-12);
    }

    /// Density read as index (or the reverse) is caught, named, and
    /// allowed on request; a bad constant is caught even then.
    #[test]
    fn non_physical_samples_are_refused_unless_allowed() {
        let e = Samples::Index.grid_to_index(grid(&[1.2, 0.6]), false).unwrap_err();
        assert_eq!(e.to_string(), "the volume holds an index below 1 (lowest sample 0.6)");
        let e = Samples::AIR.values_to_index(vec![1.0, -2.0], false, "rho").unwrap_err();
        assert!(e.to_string().contains("density ≤ 0") && e.to_string().contains("\"rho\""));
        assert!(Samples::Index.grid_to_index(grid(&[0.6]), true).is_ok());
        let nan = Samples::Density { gladstone_dale: f64::NAN };
        assert!(matches!(
            nan.grid_to_index(grid(&[1.0]), true),
            Err(MediumError::GladstoneDale(_))
        ));
    }
}
