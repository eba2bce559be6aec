//! The sRGB transfer function (IEC 61966-2-1), both ways: frames encode
//! linear light with it at output, colour maps decode their published
//! stops with it (no allocation, so both `no_std` without `alloc`).

use crate::math::powf;

/// The sRGB transfer function (IEC 61966-2-1) for linear `x ∈ [0, 1]`
/// (clamped; NaN → 0).
#[must_use]
pub fn linear_to_srgb(x: f32) -> f32 {
    let x = if x > 0.0 { x.min(1.0) } else { 0.0 };
    if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * powf(x, 1.0 / 2.4) - 0.055 }
}

/// The inverse of [`linear_to_srgb`]: linear light of an sRGB-encoded
/// `x ∈ [0, 1]` (clamped; NaN → 0).
#[must_use]
pub fn srgb_to_linear(x: f32) -> f32 {
    let x = if x > 0.0 { x.min(1.0) } else { 0.0 };
    if x <= 0.040_45 { x / 12.92 } else { powf((x + 0.055) / 1.055, 2.4) }
}
