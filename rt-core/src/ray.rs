//! Rays with a parameter interval.

use glam::Vec3;

/// A ray `x(t) = origin + t·direction` for `t` in `[t_min, t_max]`.
///
/// The direction need not be unit length; `t` is then measured in units of
/// `|direction|`, and so is every depth the crates report (depth = `t`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Ray {
    /// Start point.
    pub origin: Vec3,
    /// Direction; any non-zero finite vector.
    pub direction: Vec3,
    /// Smallest accepted ray parameter.
    pub t_min: f32,
    /// Largest accepted ray parameter (may be `+∞`).
    pub t_max: f32,
}

impl Ray {
    /// A ray over `[0, +∞)`.
    #[inline]
    #[must_use]
    pub const fn new(origin: Vec3, direction: Vec3) -> Self {
        Self { origin, direction, t_min: 0.0, t_max: f32::INFINITY }
    }

    /// A ray over `[t_min, t_max]`.
    #[inline]
    #[must_use]
    pub const fn with_range(origin: Vec3, direction: Vec3, t_min: f32, t_max: f32) -> Self {
        Self { origin, direction, t_min, t_max }
    }

    /// The point at parameter `t`.
    #[inline]
    #[must_use]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.direction
    }

    /// Whether queries can answer this ray: finite origin and direction, a
    /// non-zero direction, a finite `t_min` and `t_min ≤ t_max` (so `t_max` is
    /// not NaN; it may be `+∞`). Every query returns a miss for other rays.
    #[inline]
    #[must_use]
    pub fn is_valid(&self) -> bool {
        self.origin.is_finite()
            && self.direction.is_finite()
            && self.direction != Vec3::ZERO
            && self.t_min.is_finite()
            && self.t_min <= self.t_max
    }
}
