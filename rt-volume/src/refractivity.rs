//! From flow quantities to refractive index.

use glam::DVec3;

use crate::{Bounds, IndexField};

/// Gladstone–Dale constant of air at 589 nm, m³/kg (`n − 1 = K ρ`).
pub const GLADSTONE_DALE_AIR: f64 = 2.26e-4;

/// Gladstone–Dale: `n = 1 + K ρ` (`ρ` in kg/m³, `K` in m³/kg).
#[inline]
#[must_use]
pub fn gladstone_dale(rho: f64, k: f64) -> f64 {
    1.0 + k * rho
}

/// Index of dry air from temperature and pressure by the updated Edlén
/// equation (Birch & Downs 1993, 1994): standard air (15 °C, 101 325 Pa,
/// 0.04 % CO₂) `(n − 1)ₛ·10⁸ = 8342.54 + 2406147/(130 − σ²) + 15998/(38.9 − σ²)`
/// with `σ = 1/λ` in µm⁻¹, then scaled to `p` (Pa) and `t` (°C):
/// `(n − 1)_tp = (n − 1)ₛ · p·[1 + 10⁻⁸(0.601 − 0.00972 t) p] / (96095.43·(1 + 0.003661 t))`.
/// `lambda_um`: vacuum wavelength in micrometres.
#[must_use]
pub fn air_index_edlen(t_celsius: f64, p_pa: f64, lambda_um: f64) -> f64 {
    let s2 = 1.0 / (lambda_um * lambda_um);
    let ns = (8342.54 + 2_406_147.0 / (130.0 - s2) + 15998.0 / (38.9 - s2)) * 1e-8;
    let ntp = ns * p_pa * (1.0 + 1e-8 * (0.601 - 0.00972 * t_celsius) * p_pa)
        / (96095.43 * (1.0 + 0.003661 * t_celsius));
    1.0 + ntp
}

/// Several index fields combined: `n = n_a + Σ (nᵢ − n_a)` (their index
/// excesses add; `n_a` is the first field's ambient index). Bounds: the box
/// around all of them. For multifield data such as density plus a species.
#[derive(Clone, Copy, Debug)]
pub struct Sum<A, B>(pub A, pub B);

impl<A: IndexField, B: IndexField> IndexField for Sum<A, B> {
    fn eval(&self, x: DVec3) -> (f64, DVec3) {
        let (na, ga) = inside_or_ambient(&self.0, x);
        let (nb, gb) = inside_or_ambient(&self.1, x);
        (na + (nb - self.1.ambient()), ga + gb)
    }
    fn bounds(&self) -> Bounds {
        let (a, b) = (self.0.bounds(), self.1.bounds());
        Bounds::new(a.min.min(b.min), a.max.max(b.max))
    }
    fn ambient(&self) -> f64 {
        self.0.ambient()
    }
}

/// `f` at `x` inside its bounds, its ambient index outside.
fn inside_or_ambient<F: IndexField>(f: &F, x: DVec3) -> (f64, DVec3) {
    if f.bounds().contains(x) { f.eval(x) } else { (f.ambient(), DVec3::ZERO) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edlen_reference_values() {
        // Birch & Downs: standard air at 633 nm (HeNe) has n − 1 ≈ 2.7652e-4.
        let n = air_index_edlen(15.0, 101_325.0, 0.6328);
        assert!(((n - 1.0) - 2.7652e-4).abs() < 0.0005e-4, "{}", n - 1.0);
        // Warmer and thinner air bends less.
        assert!(air_index_edlen(40.0, 90_000.0, 0.589) < air_index_edlen(0.0, 101_325.0, 0.589));
        assert_eq!(gladstone_dale(1.0, GLADSTONE_DALE_AIR), 1.000226);
    }

    #[test]
    fn sums_add_index_excesses() {
        use crate::GaussianBump;
        let a = GaussianBump::new(DVec3::ZERO, 1e-3, 1.0, 4.0);
        let b = GaussianBump::new(DVec3::new(3.0, 0.0, 0.0), 2e-3, 0.5, 4.0);
        let s = Sum(a, b);
        let x = DVec3::new(1.5, 0.2, 0.0);
        let (n, g) = s.eval(x);
        assert!((n - (a.eval(x).0 + b.eval(x).0 - 1.0)).abs() < 1e-15);
        assert!((g - (a.eval(x).1 + b.eval(x).1)).length() < 1e-15);
        assert_eq!(s.bounds().max.x, 5.0);
        // Outside one part's bounds only the other contributes.
        let far = DVec3::new(4.5, 0.0, 0.0);
        assert_eq!(s.eval(far), (b.eval(far).0, b.eval(far).1));
    }
}
