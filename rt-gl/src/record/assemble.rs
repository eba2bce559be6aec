//! Primitive assembly: the vertices between `glBegin` and `glEnd` turned
//! into triangles, spheres (points) or tubes (lines).

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};

use super::{Recorder, normal_matrix};
use crate::gl;

/// A vertex between `glBegin` and `glEnd`: eye-space position, normal,
/// colour and texture coordinates (through the texture matrix).
pub(super) type Vert = (Vec3, Vec3, Vec4, Vec2);

impl Recorder {
    pub(super) fn vertex(&mut self, v: Vec4) {
        let mv = self.modelview();
        let e = mv * v;
        let n = normal_matrix(&mv) * self.normal;
        let t = self.texture_matrix() * self.generated_texcoord(v, e, n);
        let Some((_, verts)) = &mut self.begin else {
            self.counters.ignored += 1;
            return;
        };
        if e.w == 0.0 || !e.is_finite() {
            return;
        }
        let uv = if t.w == 0.0 { Vec2::ZERO } else { Vec2::new(t.x, t.y) / t.w };
        verts.push((e.truncate() / e.w, n, self.color, uv));
    }

    /// The size of one pixel at eye-space depth `z` (negative in front).
    fn pixel_size_at(&self, z: f32) -> f32 {
        let p = self.projection();
        let h = self.viewport[3].max(1) as f32;
        // Perspective: w = −z; orthographic: w = 1.
        let w = if p.w_axis.w == 0.0 { -z } else { 1.0 };
        (2.0 * w.abs() / (p.y_axis.y.abs() * h)).max(f32::MIN_POSITIVE)
    }

    /// How much thinner than its width, across itself, GL draws a line
    /// from eye-space `a` to `b` under projection `p` in viewport `v`: a
    /// non-antialiased line of width `w` covers `w` pixels along the
    /// window's minor axis (x for a steep line, y for a flat one), so
    /// `w·max(|dx|, |dy|)/|d|` across it.
    fn line_slant(p: Mat4, v: [i32; 4], a: Vec3, b: Vec3) -> f32 {
        let [_, _, w, h] = v;
        let (w, h) = (w.max(1) as f32, h.max(1) as f32);
        let window = |e: Vec3| {
            let c = p * e.extend(1.0);
            glam::Vec2::new(c.x / c.w * w, c.y / c.w * h) * 0.5
        };
        let d = window(b) - window(a);
        let f = d.abs().max_element() / d.length();
        if f.is_finite() { f.clamp(core::f32::consts::FRAC_1_SQRT_2, 1.0) } else { 1.0 }
    }

    /// Turns one `glBegin`/`glEnd` into triangles, spheres or tubes.
    pub(super) fn assemble(&mut self, mode: u32, verts: &[Vert]) {
        if !self.color_write {
            // A depth-only pass: nothing of it is seen.
            return;
        }
        // `glPolygonMode`: polygons drawn as their edges or corners (the
        // front faces' mode; back faces are taken the same).
        let polygon = (gl::TRIANGLES..=gl::POLYGON).contains(&mode);
        let mode = match self.polygon_mode[0] {
            gl::LINE if polygon => return self.assemble_outlines(mode, verts),
            gl::POINT if polygon => gl::POINTS,
            _ => mode,
        };
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
        let view = (self.projection(), self.viewport);
        let (g, to_local, n_to_local) = if let Some(c) = &mut self.capture {
            (&mut c.geometry, c.to_local, c.normal_to_local)
        } else {
            (&mut self.draws(shading.lit, shading.fog).immediate, Mat4::IDENTITY, Mat3::IDENTITY)
        };
        let base = g.positions.len() as u32;
        let textured = shading.texture.is_some() || !g.texcoords.is_empty();
        if textured {
            g.texcoords.resize(base as usize, Vec2::ZERO);
        }
        for &(p, n, c, uv) in verts {
            g.positions.push(to_local.transform_point3(p));
            g.normals.push(n_to_local * n);
            g.colors.push(c);
            if textured {
                g.texcoords.push(uv);
            }
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
                    let (pa, pb) = (verts[a as usize].0, verts[b as usize].0);
                    let r = 0.5
                        * (radius[a as usize] + radius[b as usize])
                        * Self::line_slant(view.0, view.1, pa, pb);
                    g.tubes.push(([v(a), v(b)], r, s));
                }
            }
        }
    }

    /// `glPolygonMode(GL_LINE)`: each polygon's edges as lines (a quad's
    /// four sides, not its diagonal), each edge once.
    fn assemble_outlines(&mut self, mode: u32, verts: &[Vert]) {
        let n = verts.len();
        let mut polygons: Vec<Vec<usize>> = Vec::new();
        match mode {
            gl::TRIANGLES => {
                (0..n / 3).for_each(|i| polygons.push(vec![3 * i, 3 * i + 1, 3 * i + 2]))
            }
            gl::TRIANGLE_STRIP => {
                (0..n.saturating_sub(2)).for_each(|i| polygons.push(vec![i, i + 1, i + 2]));
            }
            gl::TRIANGLE_FAN => {
                (1..n.saturating_sub(1)).for_each(|i| polygons.push(vec![0, i, i + 1]));
            }
            gl::QUADS => (0..n / 4).for_each(|q| polygons.push((4 * q..4 * q + 4).collect())),
            gl::QUAD_STRIP => (0..n.saturating_sub(2) / 2)
                .for_each(|q| polygons.push(vec![2 * q, 2 * q + 1, 2 * q + 3, 2 * q + 2])),
            _ if n >= 3 => polygons.push((0..n).collect()),
            _ => {}
        }
        let mut seen = std::collections::HashSet::new();
        let mut segments: Vec<Vert> = Vec::new();
        for p in &polygons {
            for (k, &a) in p.iter().enumerate() {
                let b = p[(k + 1) % p.len()];
                if seen.insert((a.min(b), a.max(b))) {
                    segments.extend([verts[a], verts[b]]);
                }
            }
        }
        self.assemble(gl::LINES, &segments);
    }
}
