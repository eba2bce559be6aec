//! The index-field seam: `n(x)` and `∇n(x)` in one call.

use glam::DVec3;

/// An axis-aligned box in f64 (field bounds).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Lower corner.
    pub min: DVec3,
    /// Upper corner.
    pub max: DVec3,
}

impl Bounds {
    /// A box from its corners.
    #[must_use]
    pub const fn new(min: DVec3, max: DVec3) -> Self {
        Self { min, max }
    }

    /// Whether `p` is inside or on the boundary.
    #[must_use]
    pub fn contains(&self, p: DVec3) -> bool {
        self.min.cmple(p).all() && p.cmple(self.max).all()
    }

    /// The parameter interval `[t0, t1]` (with `t0 ≥ 0`) where the line
    /// `o + t·d` is inside the box, or `None`. Slab planes are chosen by the
    /// sign bit of `d`; NaN distances (a line in a face plane) never narrow
    /// the interval.
    #[must_use]
    pub fn clip(&self, o: DVec3, d: DVec3) -> Option<(f64, f64)> {
        let mut t0 = 0.0f64;
        let mut t1 = f64::INFINITY;
        for a in 0..3 {
            let inv = 1.0 / d[a];
            let (lo, hi) = if d[a].is_sign_negative() {
                (self.max[a], self.min[a])
            } else {
                (self.min[a], self.max[a])
            };
            let near = (lo - o[a]) * inv;
            let far = (hi - o[a]) * inv;
            if near > t0 {
                t0 = near;
            }
            if far < t1 {
                t1 = far;
            }
        }
        (t0 <= t1).then_some((t0, t1))
    }
}

/// A refractive-index field: `n(x)` and its gradient, evaluated together
/// (integrators always need both). Outside [`IndexField::bounds`] the index
/// is the constant [`IndexField::ambient`] and nothing is evaluated there.
pub trait IndexField {
    /// `(n(x), ∇n(x))` for `x` inside the bounds.
    fn eval(&self, x: DVec3) -> (f64, DVec3);
    /// The box outside which `n = ambient` and `∇n = 0`.
    fn bounds(&self) -> Bounds;
    /// The index outside the bounds (1 for vacuum, ≈ 1.000293 for air).
    fn ambient(&self) -> f64 {
        1.0
    }
}

impl<F: IndexField + ?Sized> IndexField for &F {
    fn eval(&self, x: DVec3) -> (f64, DVec3) {
        (**self).eval(x)
    }
    fn bounds(&self) -> Bounds {
        (**self).bounds()
    }
    fn ambient(&self) -> f64 {
        (**self).ambient()
    }
}
