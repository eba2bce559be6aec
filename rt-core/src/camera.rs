//! Cameras: perspective, orthographic and thin-lens.
//!
//! Pixel `(0, 0)` is the top-left corner of the image; a sample offset in
//! `[0, 1)²` places the ray inside the pixel (`(0.5, 0.5)` is its centre).
//! Camera space is right-handed: `+x` right, `+y` up, looking along `−z`
//! (the `forward` vector). Angles are in radians. Generated directions have
//! unit length, so a hit's `t` is the distance from the ray origin.

use core::fmt;

use glam::{Vec2, Vec3};

use crate::{
    Ray,
    math::{sin_cos_quarter, sqrt, tan},
};

/// How the camera projects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Pinhole perspective with vertical field of view `fov_y` (radians).
    Perspective {
        /// Vertical field of view in radians, in `(0, π)`.
        fov_y: f32,
    },
    /// Parallel projection: all rays share the view direction.
    Orthographic {
        /// Height of the view in world units (width follows the aspect ratio).
        height: f32,
    },
    /// Thin lens: perspective with depth of field.
    ThinLens {
        /// Vertical field of view in radians, in `(0, π)`.
        fov_y: f32,
        /// Lens radius in world units (`0` = pinhole).
        aperture_radius: f32,
        /// Distance along the view direction to the plane in focus.
        focus_distance: f32,
    },
}

/// Why a camera could not be made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraError {
    /// Eye, target or up is not finite, or eye and target coincide.
    BadPose,
    /// `up` is parallel to the view direction.
    UpParallelToView,
    /// A projection parameter is out of its documented range.
    BadProjection,
    /// Width or height is zero.
    EmptyImage,
}

impl fmt::Display for CameraError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::BadPose => "camera eye/target/up must be finite and eye != target",
            Self::UpParallelToView => "camera up vector is parallel to the view direction",
            Self::BadProjection => "projection parameter out of range",
            Self::EmptyImage => "image width and height must be non-zero",
        })
    }
}

impl core::error::Error for CameraError {}

/// A camera with its image size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Position of the eye (centre of projection / lens).
    pub eye: Vec3,
    /// Unit view direction (camera `−z`).
    pub forward: Vec3,
    /// Unit right vector (camera `+x`).
    pub right: Vec3,
    /// Unit up vector (camera `+y`).
    pub up: Vec3,
    /// The projection.
    pub projection: Projection,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl Camera {
    /// A camera at `eye` looking at `target`, with `up` fixing the roll.
    ///
    /// # Errors
    /// [`CameraError`] for non-finite or coincident points, `up` parallel to
    /// the view, out-of-range projection parameters or an empty image.
    pub fn look_at(
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        projection: Projection,
        width: u32,
        height: u32,
    ) -> Result<Self, CameraError> {
        if !(eye.is_finite() && target.is_finite() && up.is_finite()) || eye == target {
            return Err(CameraError::BadPose);
        }
        if width == 0 || height == 0 {
            return Err(CameraError::EmptyImage);
        }
        let in_fov = |f: f32| f > 0.0 && f < core::f32::consts::PI;
        let ok = match projection {
            Projection::Perspective { fov_y } => in_fov(fov_y),
            Projection::Orthographic { height } => height.is_finite() && height > 0.0,
            Projection::ThinLens { fov_y, aperture_radius, focus_distance } => {
                in_fov(fov_y)
                    && aperture_radius.is_finite()
                    && aperture_radius >= 0.0
                    && focus_distance.is_finite()
                    && focus_distance > 0.0
            }
        };
        if !ok {
            return Err(CameraError::BadProjection);
        }
        let forward = (target - eye).normalize_or_zero();
        let right = forward.cross(up).normalize_or_zero();
        if forward == Vec3::ZERO {
            return Err(CameraError::BadPose);
        }
        if right == Vec3::ZERO || !right.is_finite() {
            return Err(CameraError::UpParallelToView);
        }
        let up = right.cross(forward);
        Ok(Self { eye, forward, right, up, projection, width, height })
    }

    /// Width over height.
    #[must_use]
    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// The ray through pixel `(px, py)` at `sample ∈ [0, 1)²` inside it;
    /// `lens ∈ [0, 1)²` picks the point on the lens (thin lens only).
    #[must_use]
    pub fn generate_ray(&self, px: u32, py: u32, sample: Vec2, lens: Vec2) -> Ray {
        // Screen coordinates in [-1, 1], y up.
        let sx = 2.0 * (px as f32 + sample.x) / self.width as f32 - 1.0;
        let sy = 1.0 - 2.0 * (py as f32 + sample.y) / self.height as f32;
        match self.projection {
            Projection::Perspective { fov_y } => {
                Ray::new(self.eye, self.pinhole_dir(fov_y, sx, sy).normalize())
            }
            Projection::Orthographic { height } => {
                let h = 0.5 * height;
                let o = self.eye + (sx * h * self.aspect()) * self.right + (sy * h) * self.up;
                Ray::new(o, self.forward)
            }
            Projection::ThinLens { fov_y, aperture_radius, focus_distance } => {
                let d = self.pinhole_dir(fov_y, sx, sy);
                // `d` has unit component along `forward`, so the focal plane
                // is reached at parameter `focus_distance`.
                let focus = self.eye + focus_distance * d;
                let l = concentric_disk(lens) * aperture_radius;
                let o = self.eye + l.x * self.right + l.y * self.up;
                Ray::new(o, (focus - o).normalize())
            }
        }
    }

    fn pinhole_dir(&self, fov_y: f32, sx: f32, sy: f32) -> Vec3 {
        let t = tan(0.5 * fov_y);
        self.forward + (sx * t * self.aspect()) * self.right + (sy * t) * self.up
    }
}

/// Shirley–Chiu concentric map of `[0, 1)²` onto the unit disk (area
/// preserving, low distortion).
#[must_use]
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o == Vec2::ZERO {
        return Vec2::ZERO;
    }
    // The angle is `π/4·(o.y/o.x)`, or `π/2 − π/4·(o.x/o.y)`, whose sine
    // and cosine are the cosine and sine of `π/4·(o.x/o.y)`: either way a
    // sine and cosine within `±π/4`.
    if o.x.abs() > o.y.abs() {
        let (s, c) = sin_cos_quarter(core::f32::consts::FRAC_PI_4 * (o.y / o.x));
        o.x * Vec2::new(c, s)
    } else {
        let (s, c) = sin_cos_quarter(core::f32::consts::FRAC_PI_4 * (o.x / o.y));
        o.y * Vec2::new(s, c)
    }
}

/// Cosine-weighted direction about `+z` from `u ∈ [0, 1)²` (Malley's method).
#[must_use]
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_disk(u);
    let z = sqrt((1.0 - d.length_squared()).max(0.0));
    Vec3::new(d.x, d.y, z)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam(p: Projection) -> Camera {
        Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, p, 200, 100).unwrap()
    }

    #[test]
    fn centre_ray_looks_at_target_and_corners_span_fov() {
        let c = cam(Projection::Perspective { fov_y: core::f32::consts::FRAC_PI_2 });
        let r = c.generate_ray(100, 50, Vec2::ZERO, Vec2::ZERO);
        assert!((r.direction - Vec3::NEG_Z).length() < 1e-6);
        // Top edge of the image: 45° up.
        let top = c.generate_ray(100, 0, Vec2::ZERO, Vec2::ZERO);
        assert!((top.direction.y - top.direction.z.abs()).abs() < 1e-5);
        // Left edge: tan = aspect (2).
        let left = c.generate_ray(0, 50, Vec2::ZERO, Vec2::ZERO);
        assert!((left.direction.x / left.direction.z - 2.0).abs() < 1e-5);
    }

    #[test]
    fn orthographic_rays_are_parallel() {
        let c = cam(Projection::Orthographic { height: 4.0 });
        let a = c.generate_ray(0, 0, Vec2::ZERO, Vec2::ZERO);
        let b = c.generate_ray(199, 99, Vec2::ONE * 0.999, Vec2::ZERO);
        assert_eq!(a.direction, b.direction);
        assert!((a.origin - Vec3::new(-4.0, 2.0, 5.0)).length() < 1e-5);
    }

    #[test]
    fn thin_lens_rays_converge_on_focal_plane() {
        let p = Projection::ThinLens { fov_y: 1.0, aperture_radius: 0.5, focus_distance: 5.0 };
        let c = cam(p);
        let mut pts = [Vec3::ZERO; 3];
        for (i, l) in
            [Vec2::new(0.1, 0.2), Vec2::new(0.9, 0.5), Vec2::new(0.4, 0.95)].iter().enumerate()
        {
            let r = c.generate_ray(30, 70, Vec2::splat(0.5), *l);
            let t = (0.0 - r.origin.z) / r.direction.z;
            pts[i] = r.at(t);
        }
        assert!((pts[0] - pts[1]).length() < 1e-4 && (pts[1] - pts[2]).length() < 1e-4);
    }

    #[test]
    fn bad_cameras_are_errors() {
        let p = Projection::Perspective { fov_y: 1.0 };
        assert_eq!(
            Camera::look_at(Vec3::ZERO, Vec3::ZERO, Vec3::Y, p, 1, 1),
            Err(CameraError::BadPose)
        );
        assert_eq!(
            Camera::look_at(Vec3::ZERO, Vec3::Y, Vec3::Y, p, 1, 1),
            Err(CameraError::UpParallelToView)
        );
        assert_eq!(
            Camera::look_at(Vec3::ZERO, Vec3::X, Vec3::Y, p, 0, 1),
            Err(CameraError::EmptyImage)
        );
        let bad = Projection::Perspective { fov_y: 4.0 };
        assert_eq!(
            Camera::look_at(Vec3::ZERO, Vec3::X, Vec3::Y, bad, 1, 1),
            Err(CameraError::BadProjection)
        );
    }

    #[test]
    fn disk_and_hemisphere_maps_stay_in_domain() {
        for i in 0..64 {
            let u = Vec2::new((i % 8) as f32 / 8.0, (i / 8) as f32 / 8.0);
            assert!(concentric_disk(u).length() <= 1.0 + 1e-6);
            let w = cosine_hemisphere(u);
            assert!((w.length() - 1.0).abs() < 1e-5 && w.z >= 0.0);
        }
    }
}
