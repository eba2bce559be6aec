//! The matrices GL's matrix calls multiply by (`glTranslate`, `glRotate`,
//! `glScale`, `glFrustum`, `glOrtho`) and the normal matrix.

use glam::{Mat3, Mat4, Vec3};

/// The matrix that carries normals along with `m`: the inverse transpose
/// of its upper 3 × 3 (the identity where that is singular).
#[must_use]
pub fn normal_matrix(m: &Mat4) -> Mat3 {
    let a = Mat3::from_mat4(*m);
    if a.determinant() == 0.0 { Mat3::IDENTITY } else { a.inverse().transpose() }
}

/// `glTranslate(x, y, z)`.
#[must_use]
pub fn translate(v: Vec3) -> Mat4 {
    Mat4::from_translation(v)
}

/// `glRotate(angle_degrees, x, y, z)` (the identity for a zero axis).
#[must_use]
pub fn rotate(degrees: f32, axis: Vec3) -> Mat4 {
    let a = axis.normalize_or_zero();
    if a == Vec3::ZERO { Mat4::IDENTITY } else { Mat4::from_axis_angle(a, degrees.to_radians()) }
}

/// `glScale(x, y, z)`.
#[must_use]
pub fn scale(v: Vec3) -> Mat4 {
    Mat4::from_scale(v)
}

/// `glFrustum(l, r, b, t, n, f)` as the OpenGL specification writes it
/// (`None` where GL raises `GL_INVALID_VALUE`).
#[must_use]
pub fn frustum(l: f64, r: f64, b: f64, t: f64, n: f64, f: f64) -> Option<Mat4> {
    if n <= 0.0 || f <= 0.0 || l == r || b == t || n == f {
        return None;
    }
    let m = [
        [2.0 * n / (r - l), 0.0, 0.0, 0.0],
        [0.0, 2.0 * n / (t - b), 0.0, 0.0],
        [(r + l) / (r - l), (t + b) / (t - b), -(f + n) / (f - n), -1.0],
        [0.0, 0.0, -2.0 * f * n / (f - n), 0.0],
    ];
    Some(Mat4::from_cols_array_2d(&m.map(|c| c.map(|x| x as f32))))
}

/// `glOrtho(l, r, b, t, n, f)` (`None` where GL raises `GL_INVALID_VALUE`).
#[must_use]
pub fn ortho(l: f64, r: f64, b: f64, t: f64, n: f64, f: f64) -> Option<Mat4> {
    if l == r || b == t || n == f {
        return None;
    }
    let m = [
        [2.0 / (r - l), 0.0, 0.0, 0.0],
        [0.0, 2.0 / (t - b), 0.0, 0.0],
        [0.0, 0.0, -2.0 / (f - n), 0.0],
        [-(r + l) / (r - l), -(t + b) / (t - b), -(f + n) / (f - n), 1.0],
    ];
    Some(Mat4::from_cols_array_2d(&m.map(|c| c.map(|x| x as f32))))
}
