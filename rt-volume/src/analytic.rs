//! Analytic index fields: the closed-form cases of `docs/oracles.md` and any
//! user closure pair.

use glam::DVec3;

use crate::{
    Bounds, IndexField,
    math::{exp, sqrt},
};

/// `n = n₀` everywhere in the bounds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Constant {
    /// The index.
    pub n: f64,
    /// Where the field is defined.
    pub bounds: Bounds,
}

impl IndexField for Constant {
    fn eval(&self, _x: DVec3) -> (f64, DVec3) {
        (self.n, DVec3::ZERO)
    }
    fn bounds(&self) -> Bounds {
        self.bounds
    }
    fn ambient(&self) -> f64 {
        self.n
    }
}

/// Linear index `n = n₀ + g·x` (rays are catenaries, docs/oracles.md §1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearIndex {
    /// Index at the origin.
    pub n0: f64,
    /// Constant gradient.
    pub gradient: DVec3,
    /// Where the field is defined.
    pub bounds: Bounds,
}

impl IndexField for LinearIndex {
    fn eval(&self, x: DVec3) -> (f64, DVec3) {
        (self.n0 + self.gradient.dot(x), self.gradient)
    }
    fn bounds(&self) -> Bounds {
        self.bounds
    }
}

/// Linear `n² = n₀² + a·x` (rays are parabolas, docs/oracles.md §2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearSquared {
    /// Index at the origin.
    pub n0: f64,
    /// Gradient of `n²`.
    pub a: DVec3,
    /// Where the field is defined.
    pub bounds: Bounds,
}

impl IndexField for LinearSquared {
    fn eval(&self, x: DVec3) -> (f64, DVec3) {
        let n = sqrt(self.n0 * self.n0 + self.a.dot(x));
        (n, self.a / (2.0 * n))
    }
    fn bounds(&self) -> Bounds {
        self.bounds
    }
}

/// Parabolic GRIN rod about the z axis: `n² = n₀²(1 − α² r²)`, `r² = x² + y²`
/// (docs/oracles.md §3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GrinRod {
    /// Index on the axis.
    pub n0: f64,
    /// Gradient constant `α` (1/length).
    pub alpha: f64,
    /// Where the field is defined.
    pub bounds: Bounds,
}

impl IndexField for GrinRod {
    fn eval(&self, x: DVec3) -> (f64, DVec3) {
        let r2 = x.x * x.x + x.y * x.y;
        let n2 = self.n0 * self.n0 * (1.0 - self.alpha * self.alpha * r2);
        let n = sqrt(n2);
        let k = -self.n0 * self.n0 * self.alpha * self.alpha / n;
        (n, DVec3::new(k * x.x, k * x.y, 0.0))
    }
    fn bounds(&self) -> Bounds {
        self.bounds
    }
}

/// Luneburg lens of radius `R` at `center`: `n = √(2 − r²/R²)` inside,
/// `1` outside (docs/oracles.md §4). Bounds: the cube around the sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Luneburg {
    /// Centre.
    pub center: DVec3,
    /// Radius.
    pub radius: f64,
}

impl IndexField for Luneburg {
    fn eval(&self, x: DVec3) -> (f64, DVec3) {
        let d = x - self.center;
        let r2 = d.length_squared() / (self.radius * self.radius);
        if r2 >= 1.0 {
            return (1.0, DVec3::ZERO);
        }
        let n = sqrt(2.0 - r2);
        (n, -d / (self.radius * self.radius * n))
    }
    fn bounds(&self) -> Bounds {
        let r = DVec3::splat(self.radius);
        Bounds::new(self.center - r, self.center + r)
    }
}

/// Gaussian bump `n = n_a + δ·exp(−ρ²/(2σ²))`, `ρ = |x − c|` (docs/oracles.md §5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussianBump {
    /// Centre.
    pub center: DVec3,
    /// Peak index excess `δ`.
    pub delta: f64,
    /// Width `σ`.
    pub sigma: f64,
    /// Ambient index `n_a`.
    pub ambient: f64,
    /// Where the field is evaluated (outside: `n_a`); a few `σ` around `c`.
    pub bounds: Bounds,
}

impl GaussianBump {
    /// A bump on ambient index 1, evaluated within `k·σ` of the centre.
    #[must_use]
    pub fn new(center: DVec3, delta: f64, sigma: f64, k: f64) -> Self {
        let r = DVec3::splat(k * sigma);
        Self { center, delta, sigma, ambient: 1.0, bounds: Bounds::new(center - r, center + r) }
    }
}

impl IndexField for GaussianBump {
    fn eval(&self, x: DVec3) -> (f64, DVec3) {
        let d = x - self.center;
        let g = exp(-d.length_squared() / (2.0 * self.sigma * self.sigma));
        (self.ambient + self.delta * g, -self.delta * g / (self.sigma * self.sigma) * d)
    }
    fn bounds(&self) -> Bounds {
        self.bounds
    }
    fn ambient(&self) -> f64 {
        self.ambient
    }
}

/// Any field from a closure returning `(n, ∇n)`.
#[derive(Clone, Copy, Debug)]
pub struct FnField<F> {
    /// `x ↦ (n(x), ∇n(x))`.
    pub f: F,
    /// Where the field is defined.
    pub bounds: Bounds,
    /// Index outside the bounds.
    pub ambient: f64,
}

impl<F: Fn(DVec3) -> (f64, DVec3)> IndexField for FnField<F> {
    fn eval(&self, x: DVec3) -> (f64, DVec3) {
        (self.f)(x)
    }
    fn bounds(&self) -> Bounds {
        self.bounds
    }
    fn ambient(&self) -> f64 {
        self.ambient
    }
}

/// Any field from a closure returning `n` alone; the gradient by central
/// differences, `∂ₐn ≈ (n(x + h·eₐ) − n(x − h·eₐ)) / 2h` (six calls per
/// evaluation, at points up to `h` outside the bounds near a face).
///
/// The error is truncation `h²/6 · |∂³n|` plus rounding `≈ ε·n/h`
/// (`ε = 2⁻⁵²`), smallest for `h ≈ ∛ε · L ≈ 6·10⁻⁶ L`, with `L` the length
/// over which `n` changes: then both terms are about `10⁻¹¹ · n/L`, far below
/// what the integrators resolve. [`FnIndex::new`] takes `L` as the bounds'
/// longest side; set [`FnIndex::step`] for fields with finer structure
/// (e.g. `∛ε` times the smallest feature size). Prefer [`FnField`] when
/// the gradient is known in closed form: it is exact and 6× cheaper.
#[derive(Clone, Copy, Debug)]
pub struct FnIndex<N> {
    /// `x ↦ n(x)`.
    pub n: N,
    /// Where the field is defined.
    pub bounds: Bounds,
    /// Index outside the bounds.
    pub ambient: f64,
    /// The difference step `h` (same units as `x`, finite and > 0).
    pub step: f64,
}

impl<N: Fn(DVec3) -> f64> FnIndex<N> {
    /// `∛ε`, the relative step that balances truncation and rounding.
    pub const RELATIVE_STEP: f64 = 6.055_454_452_393_343e-6;

    /// The field `n` in `bounds`, with the step `RELATIVE_STEP ×` the
    /// bounds' longest side (`RELATIVE_STEP` itself for empty or
    /// non-finite bounds).
    #[must_use]
    pub fn new(n: N, bounds: Bounds, ambient: f64) -> Self {
        let side = (bounds.max - bounds.min).max_element();
        let side = if side.is_finite() && side > 0.0 { side } else { 1.0 };
        Self { n, bounds, ambient, step: Self::RELATIVE_STEP * side }
    }
}

impl<N: Fn(DVec3) -> f64> IndexField for FnIndex<N> {
    fn eval(&self, x: DVec3) -> (f64, DVec3) {
        let h = self.step;
        let d = |e: DVec3| ((self.n)(x + h * e) - (self.n)(x - h * e)) / (2.0 * h);
        ((self.n)(x), DVec3::new(d(DVec3::X), d(DVec3::Y), d(DVec3::Z)))
    }
    fn bounds(&self) -> Bounds {
        self.bounds
    }
    fn ambient(&self) -> f64 {
        self.ambient
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{TraceParams, trace};

    /// Central differences of a Gaussian bump match its analytic gradient
    /// within the documented bound at the default step (rounding
    /// `ε·n/h ≈ 2·10⁻¹¹` dominates; 1e-10 allowed), and rays through both
    /// agree to 1e-9.
    #[test]
    fn central_differences_match_the_analytic_gradient() {
        let bump = GaussianBump::new(DVec3::ZERO, 3e-3, 0.2, 4.0);
        let fd = FnIndex::new(|x| bump.eval(x).0, bump.bounds, bump.ambient);
        assert_eq!(fd.step, FnIndex::<fn(DVec3) -> f64>::RELATIVE_STEP * 1.6);
        for i in 0..200 {
            let t = f64::from(i);
            let x = 0.3 * DVec3::new((0.7 * t).sin(), (1.3 * t).cos(), (0.37 * t).sin());
            let (n, g) = bump.eval(x);
            let (n_fd, g_fd) = fd.eval(x);
            assert_eq!(n, n_fd);
            assert!((g - g_fd).length() < 1e-10, "{g} vs {g_fd} at {x}");
        }
        let p = TraceParams::accurate();
        for y in [-0.15, -0.05, 0.0, 0.1] {
            let o = DVec3::new(-1.0, y, 0.02);
            let a = trace(&bump, o, DVec3::X, &p).unwrap();
            let b = trace(&fd, o, DVec3::X, &p).unwrap();
            assert!((a.position - b.position).length() < 1e-9, "{y}");
            assert!((a.direction - b.direction).length() < 1e-9, "{y}");
            // And the ray did bend: the test is not trivially met.
            assert!(a.direction.y.abs() > 1e-4 || y == 0.0, "{y}: {}", a.direction);
        }
    }
}
