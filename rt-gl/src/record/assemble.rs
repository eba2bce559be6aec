//! Primitive assembly: the vertices between `glBegin` and `glEnd` turned
//! into triangles, spheres (points) or tubes (lines).

use glam::{Mat3, Mat4, Vec3, Vec4};

use super::{Recorder, normal_matrix};
use crate::gl;

/// A vertex between `glBegin` and `glEnd`: eye-space position, normal and
/// colour.
pub(super) type Vert = (Vec3, Vec3, Vec4);

impl Recorder {
    pub(super) fn vertex(&mut self, v: Vec4) {
        let mv = self.modelview();
        let Some((_, verts)) = &mut self.begin else {
            self.counters.ignored += 1;
            return;
        };
        let e = mv * v;
        if e.w == 0.0 || !e.is_finite() {
            return;
        }
        let n = normal_matrix(&mv) * self.normal;
        verts.push((e.truncate() / e.w, n, self.color));
    }

    /// The size of one pixel at eye-space depth `z` (negative in front).
    fn pixel_size_at(&self, z: f32) -> f32 {
        let p = self.projection();
        let h = self.viewport[3].max(1) as f32;
        // Perspective: w = −z; orthographic: w = 1.
        let w = if p.w_axis.w == 0.0 { -z } else { 1.0 };
        (2.0 * w.abs() / (p.y_axis.y.abs() * h)).max(f32::MIN_POSITIVE)
    }

    /// Turns one `glBegin`/`glEnd` into triangles, spheres or tubes.
    pub(super) fn assemble(&mut self, mode: u32, verts: &[Vert]) {
        let shading = self.shading();
        let point_r = self.point_size * 0.5;
        let line_r = self.line_width * 0.5;
        let radius: Vec<f32> = match mode {
            gl::POINTS => verts.iter().map(|v| point_r * self.pixel_size_at(v.0.z)).collect(),
            gl::LINES | gl::LINE_LOOP | gl::LINE_STRIP => {
                verts.iter().map(|v| line_r * self.pixel_size_at(v.0.z)).collect()
            }
            _ => Vec::new(),
        };
        // Clockwise front faces: each triangle reversed, so its geometric
        // normal points where GL's front does.
        let cw = self.front_cw;
        let (g, to_local, n_to_local) = if let Some(c) = &mut self.capture {
            (&mut c.geometry, c.to_local, c.normal_to_local)
        } else {
            (&mut self.draws(shading.lit).immediate, Mat4::IDENTITY, Mat3::IDENTITY)
        };
        let base = g.positions.len() as u32;
        for &(p, n, c) in verts {
            g.positions.push(to_local.transform_point3(p));
            g.normals.push(n_to_local * n);
            g.colors.push(c);
        }
        let s = g.shading_index(shading);
        let n = verts.len() as u32;
        let v = |i: u32| base + i;
        let mut tri = |a: u32, b: u32, c: u32, provoking: u32| {
            g.triangles.push(if cw { [v(a), v(c), v(b)] } else { [v(a), v(b), v(c)] });
            g.triangle_info.push((s, v(provoking)));
        };
        match mode {
            gl::TRIANGLES => (0..n / 3).for_each(|i| tri(3 * i, 3 * i + 1, 3 * i + 2, 3 * i + 2)),
            gl::TRIANGLE_STRIP => (0..n.saturating_sub(2)).for_each(|i| {
                // Every other triangle swaps its first two vertices to
                // keep the strip's orientation.
                if i % 2 == 0 { tri(i, i + 1, i + 2, i + 2) } else { tri(i + 1, i, i + 2, i + 2) }
            }),
            gl::TRIANGLE_FAN => (1..n.saturating_sub(1)).for_each(|i| tri(0, i, i + 1, i + 1)),
            // Quads split along the diagonal from their second vertex to
            // their last, as Mesa does (it decides how colours interpolate).
            gl::QUADS => (0..n / 4).for_each(|q| {
                let a = 4 * q;
                tri(a, a + 1, a + 3, a + 3);
                tri(a + 1, a + 2, a + 3, a + 3);
            }),
            gl::QUAD_STRIP => (0..n.saturating_sub(2) / 2).for_each(|q| {
                let a = 2 * q;
                tri(a, a + 1, a + 2, a + 3);
                tri(a + 1, a + 3, a + 2, a + 3);
            }),
            gl::POLYGON => (1..n.saturating_sub(1)).for_each(|i| tri(0, i, i + 1, 0)),
            gl::POINTS => (0..n).for_each(|i| g.spheres.push((v(i), radius[i as usize], s))),
            _ => {
                let seg: Vec<[u32; 2]> = match mode {
                    gl::LINES => (0..n / 2).map(|i| [2 * i, 2 * i + 1]).collect(),
                    gl::LINE_STRIP => (1..n).map(|i| [i - 1, i]).collect(),
                    // LINE_LOOP: the strip and the closing segment.
                    _ if n >= 2 => (1..=n).map(|i| [i - 1, i % n]).collect(),
                    _ => Vec::new(),
                };
                for [a, b] in seg {
                    let r = 0.5 * (radius[a as usize] + radius[b as usize]);
                    g.tubes.push(([v(a), v(b)], r, s));
                }
            }
        }
    }
}
