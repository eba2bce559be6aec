//! Ray tracing a recorded frame: one ray per pixel through the program's
//! own projection, shaded with the fixed-function lighting equation
//! (OpenGL 2.1 specification §2.14.1) evaluated per pixel; in
//! [`Illumination::Rt`] with shadow rays toward every light, ambient occlusion on
//! the ambient terms and mirror reflections weighted by the specular
//! colour.
//!
//! Why not rt-surface's shading: GL's material has separate ambient,
//! diffuse, specular and emissive colours, unlit primitives show their
//! colour as is, and positional lights attenuate by GL's
//! `1/(k_c + k_l·d + k_q·d²)`, not `1/d²`. Reproducing the program's
//! own image (the `gl` mode) needs exactly GL's equation; rt-accel's BVH
//! answers the rays.

use std::{collections::HashMap, sync::Arc};

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use rayon::prelude::*;
use rt_accel::{InstanceError, Instances, Object, Scene};
use rt_core::{
    Hit, PrimKind, Ray, SceneQuery, camera::cosine_hemisphere, sampling, spawn_ray, spawn_ray_to,
};

use crate::gl;
use crate::record::{
    Fog, FrameDraws, Geometry, GeometryError, Lighting, Paint, Recorded, Shading, alpha_passes,
    normal_matrix, texture::Texture,
};

/// How frames are lit: GL's fixed-function model, or ray-traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Illumination {
    /// The fixed-function lighting model, per pixel: comparable with the
    /// program's own image.
    Gl,
    /// `Gl` plus shadows and ambient occlusion.
    Rt,
}

/// Deepest reflection [`Options::bounces`] may ask for: reflections
/// recurse on the tracing thread's stack.
pub const MAX_BOUNCES: u32 = 16;
/// Most blended surfaces one primary ray is traced through.
pub const MAX_LAYERS: usize = 16;
/// Most ambient-occlusion rays per pixel [`Options::ao_samples`] may ask
/// for.
pub const MAX_AO_SAMPLES: u32 = 1024;

/// Render settings (from the `RT_GL_*` environment variables).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Shading mode.
    pub mode: Illumination,
    /// Shadow rays toward every enabled light (`Rt` mode).
    pub shadows: bool,
    /// Ambient-occlusion rays per pixel (`Rt` mode; 0: off), at most
    /// [`MAX_AO_SAMPLES`].
    pub ao_samples: u32,
    /// Longest AO ray, as a fraction of the scene's diagonal (finite,
    /// ≥ 0).
    pub ao_distance: f32,
    /// Mirror reflections (`Rt` mode): a surface reflects its specular
    /// colour times this (finite, ≥ 0; 0: off), up to `bounces` deep.
    pub mirror: f32,
    /// Deepest reflection, at most [`MAX_BOUNCES`].
    pub bounces: u32,
}

impl Options {
    /// Whether every setting is in its documented range.
    #[must_use]
    pub fn is_valid(&self) -> bool {
        let non_negative = |x: f32| x.is_finite() && x >= 0.0;
        self.ao_samples <= MAX_AO_SAMPLES
            && self.bounces <= MAX_BOUNCES
            && non_negative(self.ao_distance)
            && non_negative(self.mirror)
    }
}

impl Default for Options {
    fn default() -> Self {
        Self {
            mode: Illumination::Gl,
            shadows: true,
            ao_samples: 8,
            ao_distance: 0.2,
            mirror: 0.5,
            bounces: 2,
        }
    }
}

/// An RGBA8 image, rows bottom to top (GL's order).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `4 · width · height` bytes, bottom row first.
    pub rgba: Vec<u8>,
}

impl Image {
    /// The pixel at `(x, y)`, `y` counted from the bottom.
    #[must_use]
    pub fn get(&self, x: u32, y: u32) -> Option<[u8; 4]> {
        if x >= self.width || y >= self.height {
            return None;
        }
        let i = 4 * (y as usize * self.width as usize + x as usize);
        self.rgba.get(i..i + 4).map(|p| [p[0], p[1], p[2], p[3]])
    }

    /// Writes the image as an opaque PNG (top row first, as PNG stores it).
    ///
    /// # Errors
    /// The file cannot be created or written.
    pub fn write_png(&self, path: &std::path::Path) -> std::io::Result<()> {
        let file = std::io::BufWriter::new(std::fs::File::create(path)?);
        let mut enc = png::Encoder::new(file, self.width, self.height);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().map_err(std::io::Error::other)?;
        let row = 4 * self.width as usize;
        // Opaque: what GL rasterizes into a window without alpha reads
        // back as alpha 1, and a transparent background hides the figure.
        let top_down: Vec<u8> = self
            .rgba
            .chunks(row.max(1))
            .rev()
            .flat_map(|r| r.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2], 255]))
            .collect();
        w.write_image_data(&top_down).map_err(std::io::Error::other)
    }
}

/// Why a frame could not be ray traced (the program's own image stays).
#[derive(Clone, Debug, PartialEq)]
pub enum RenderError {
    /// The frame's immediate geometry or a recording's cannot be traced:
    /// malformed (a hand-made [`Geometry`] with an index out of range or
    /// an array of the wrong length), or its BVH could not be built
    /// (e.g. a vertex overflowed to infinity).
    Geometry(GeometryError),
    /// The projection matrix is singular or not finite.
    BadProjection,
    /// The viewport is empty or larger than 16384 × 16384.
    BadViewport,
    /// A recorded modelview cannot place an instance.
    Instance(InstanceError),
    /// A setting is out of its range ([`Options::is_valid`]).
    BadOptions,
}

impl core::fmt::Display for RenderError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Geometry(e) => write!(f, "the frame's geometry: {e}"),
            Self::BadProjection => write!(f, "projection matrix is singular or not finite"),
            Self::BadViewport => write!(f, "viewport empty or larger than 16384 × 16384"),
            Self::Instance(e) => write!(f, "placing a recorded list: {e}"),
            Self::BadOptions => write!(
                f,
                "render options out of range (bounces ≤ {MAX_BOUNCES}, AO rays ≤ {MAX_AO_SAMPLES}, AO distance and mirror finite and ≥ 0)"
            ),
        }
    }
}

impl core::error::Error for RenderError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            Self::Geometry(e) => Some(e),
            Self::Instance(e) => Some(e),
            _ => None,
        }
    }
}

impl From<GeometryError> for RenderError {
    fn from(e: GeometryError) -> Self {
        Self::Geometry(e)
    }
}

/// A frame behind BVHs: the immediate geometry (eye space, built per
/// frame) and a two-level hierarchy of the recorded lists and buffer
/// draws (each recording's BVHs built once, kept across frames).
pub struct FrameScene {
    immediate: Geometry,
    scene: Scene,
    instances: Instances<Arc<Recorded>>,
    /// Per instance: the normal matrix of its transform.
    normal: Vec<Mat3>,
    /// Per instance: what its call paints it with.
    paint: Vec<Option<Paint>>,
    /// The frame's textures, by name.
    textures: Arc<HashMap<u32, Arc<Texture>>>,
    /// The pass's fog, for its fogged primitives.
    fog: Option<Fog>,
    diagonal: f32,
    left_out: usize,
}

/// Which geometry a hit belongs to.
#[derive(Clone, Copy, Debug)]
enum Source {
    Immediate,
    Instance(u32),
}

impl FrameScene {
    /// Builds the immediate geometry's BVHs and the top level over the
    /// frame's instances (building any recording's BVHs not built yet).
    ///
    /// # Errors
    /// [`RenderError::Geometry`] if a geometry is malformed
    /// ([`Geometry::check`]) or a primitive is not finite. An instance
    /// whose transform cannot place it (singular, projective as a planar
    /// shadow's, not finite) is left out and counted
    /// ([`FrameScene::left_out`]), not the frame.
    pub fn build(frame: FrameDraws) -> Result<Self, RenderError> {
        let scene = frame.immediate.build()?;
        let mut objects: Vec<Arc<Recorded>> = Vec::new();
        let mut placements = Vec::with_capacity(frame.instances.len());
        let placeable = |m: &Mat4| {
            m.is_finite()
                && m.determinant() != 0.0
                && m.inverse().is_finite()
                && m.row(3) == glam::Vec4::W
        };
        let mut left_out = 0;
        let mut paint = Vec::with_capacity(frame.instances.len());
        for inst in &frame.instances {
            let (rec, m) = (&inst.recorded, &inst.transform);
            if !placeable(m) {
                left_out += 1;
                continue;
            }
            let k = match objects.iter().position(|o| Arc::ptr_eq(o, rec)) {
                Some(k) => k,
                None => {
                    rec.scene()?;
                    objects.push(Arc::clone(rec));
                    objects.len() - 1
                }
            };
            placements.push((k as u32, *m));
            paint.push(inst.paint);
        }
        let normal = placements.iter().map(|(_, m)| normal_matrix(m)).collect();
        let instances = Instances::new(objects, &placements).map_err(RenderError::Instance)?;
        let b = Object::bounds(&scene).union(instances.bounds());
        let diagonal = if b.is_empty() { 0.0 } else { (b.max - b.min).length() };
        Ok(Self {
            immediate: frame.immediate,
            scene,
            instances,
            normal,
            paint,
            fog: frame.fog,
            textures: frame.textures,
            diagonal,
            left_out,
        })
    }

    /// Instances left out of the trace: their transforms cannot place them
    /// (singular, projective, not finite).
    #[must_use]
    pub fn left_out(&self) -> usize {
        self.left_out
    }

    /// The closest hit among the immediate geometry and the instances,
    /// past the faces culled (`glCullFace`): up to [`MAX_LAYERS`] of them,
    /// each passed through as the ray's next segment.
    /// `flip`: the projection mirrors (see [`ShadeCtx::flip`]).
    fn closest(&self, ray: &Ray, flip: bool) -> Option<(Source, Hit)> {
        // The distance passed through culled faces, in the ray's units
        // (its direction is kept): hits are measured from its origin.
        let (mut r, mut passed) = (*ray, 0.0);
        for _ in 0..MAX_LAYERS {
            let (src, mut hit) = self.closest_any(&r)?;
            let back = (hit.normal.dot(r.direction) > 0.0) != flip;
            let s = self.surface(src, &hit);
            let culled = hit.kind == PrimKind::Triangle
                && match s.shading.cull {
                    gl::FRONT_AND_BACK => true,
                    gl::BACK => back,
                    gl::FRONT => !back,
                    _ => false,
                };
            // The alpha test discards the fragment: the ray goes on.
            let discarded = s
                .shading
                .alpha_test
                .is_some_and(|test| !alpha_passes(test, self.fragment_alpha(&s)));
            let culled = culled || discarded;
            if !culled {
                hit.t += passed;
                return Some((src, hit));
            }
            passed += hit.t;
            let side = if hit.normal.dot(r.direction) > 0.0 { hit.normal } else { -hit.normal };
            let mut on = spawn_ray(hit.position, hit.position_error, side, r.direction);
            on.t_max = (r.t_max - hit.t).max(0.0);
            r = on;
        }
        None
    }

    /// `c` textured as `sh` says (unchanged when untextured).
    fn texture(&self, sh: &Shading, c: Vec4, uv: Vec2) -> Vec4 {
        match sh.texture.and_then(|t| Some((t, self.textures.get(&t.name)?))) {
            Some((t, tex)) => t.env.apply(c, tex.sample(uv), tex.format),
            None => c,
        }
    }

    /// The fragment's alpha before lighting's effect on it (the material's
    /// diffuse alpha when lit, the colour's unlit), textured: what GL's
    /// alpha test compares.
    fn fragment_alpha(&self, s: &Surface) -> f32 {
        let sh = &s.shading;
        let a = if sh.lit { sh.material_with(s.color).diffuse.w } else { s.color.w };
        self.texture(sh, s.color.truncate().extend(a), s.uv).w
    }

    /// The closest hit, culled or not.
    fn closest_any(&self, ray: &Ray) -> Option<(Source, Hit)> {
        let a = SceneQuery::closest_hit(&self.scene, ray);
        let r = Ray { t_max: a.map_or(ray.t_max, |h| h.t), ..*ray };
        match self.instances.closest_hit_instance(&r) {
            Some((i, h)) if a.is_none_or(|a| h.t < a.t) => Some((Source::Instance(i), h)),
            _ => a.map(|h| (Source::Immediate, h)),
        }
    }

    fn occluded(&self, ray: &Ray) -> bool {
        SceneQuery::occluded(&self.scene, ray) || self.instances.occluded(ray)
    }

    /// Ray traces the frame at `width × height` through `projection`,
    /// `background` where nothing is hit.
    ///
    /// # Errors
    /// [`RenderError::BadProjection`], [`RenderError::BadViewport`] or
    /// [`RenderError::BadOptions`].
    pub fn render(
        &self,
        lighting: &Lighting,
        projection: Mat4,
        width: u32,
        height: u32,
        background: Vec4,
        opts: &Options,
    ) -> Result<Image, RenderError> {
        self.render_with_depth(lighting, projection, width, height, background, opts)
            .map(|(image, _)| image)
    }

    /// [`FrameScene::render`], and each pixel's window depth: GL's depth
    /// of the closest hit in `[0, 1]` (the default depth range),
    /// `f32::INFINITY` where nothing is hit. What passes are composited
    /// by.
    ///
    /// # Errors
    /// As [`FrameScene::render`].
    pub fn render_with_depth(
        &self,
        lighting: &Lighting,
        projection: Mat4,
        width: u32,
        height: u32,
        background: Vec4,
        opts: &Options,
    ) -> Result<(Image, Vec<f32>), RenderError> {
        let (mut image, depth) =
            self.render_sample(lighting, projection, width, height, background, opts, 0)?;
        // Over the background: what blended surfaces and misses let through.
        let bg = background.clamp(Vec4::ZERO, Vec4::ONE) * 255.0;
        for px in image.rgba.chunks_exact_mut(4) {
            let through = 1.0 - f32::from(px[3]) / 255.0;
            for (k, c) in px.iter_mut().enumerate() {
                *c = (f32::from(*c) + through * bg[k]).round().min(255.0) as u8;
            }
        }
        Ok((image, depth))
    }

    /// The frame's own colours, not over a background: premultiplied by
    /// their opacity (alpha: 1 where an opaque surface is hit, less where
    /// only blended ones are, 0 where nothing is), to be put over what
    /// lies behind (an earlier pass); and with the random directions
    /// (ambient occlusion) of pass `sample`: passes 0, 1, 2, … of one
    /// scene average to a less noisy image.
    /// [`FrameScene::render_with_depth`] is pass 0 over the background.
    ///
    /// # Errors
    /// As [`FrameScene::render`].
    #[allow(clippy::too_many_arguments)]
    pub fn render_sample(
        &self,
        lighting: &Lighting,
        projection: Mat4,
        width: u32,
        height: u32,
        background: Vec4,
        opts: &Options,
        sample: u32,
    ) -> Result<(Image, Vec<f32>), RenderError> {
        if !opts.is_valid() {
            return Err(RenderError::BadOptions);
        }
        let shade = Shade { lighting, opts, background, sample };
        let (rgba, depth) = self.trace(projection, width, height, Some(&shade))?;
        Ok((Image { width, height, rgba }, depth))
    }

    /// Each pixel's window depth as [`FrameScene::render_with_depth`]
    /// gives it, without shading: where a 2-D overlay's draws cover the
    /// viewport, and how deep.
    ///
    /// # Errors
    /// [`RenderError::BadProjection`] or [`RenderError::BadViewport`].
    pub fn coverage(
        &self,
        projection: Mat4,
        width: u32,
        height: u32,
    ) -> Result<Vec<f32>, RenderError> {
        self.trace(projection, width, height, None).map(|(_, depth)| depth)
    }

    /// One ray per pixel: colours (when `shade` is given; else empty) and
    /// window depths.
    fn trace(
        &self,
        projection: Mat4,
        width: u32,
        height: u32,
        shade: Option<&Shade<'_>>,
    ) -> Result<(Vec<u8>, Vec<f32>), RenderError> {
        if width == 0 || height == 0 || width > 16384 || height > 16384 {
            return Err(RenderError::BadViewport);
        }
        let inv = projection.inverse();
        if projection.determinant() == 0.0 || !inv.is_finite() {
            return Err(RenderError::BadProjection);
        }
        let (w, n) = (width as usize, width as usize * height as usize);
        let mut rgba = vec![0u8; if shade.is_some() { 4 * n } else { 0 }];
        let mut depth = vec![f32::INFINITY; n];
        let flip = projection.determinant() > 0.0;
        let pixel = |x: usize, y: usize, px: Option<&mut [u8]>, z: &mut f32| {
            let ndc = Vec2::new(
                2.0 * (x as f32 + 0.5) / width as f32 - 1.0,
                2.0 * (y as f32 + 0.5) / height as f32 - 1.0,
            );
            let near = inv.project_point3(ndc.extend(-1.0));
            let far = inv.project_point3(ndc.extend(1.0));
            // Parameter 0..1 spans the near to the far plane: GL's clipping.
            let ray = Ray::with_range(near, far - near, 0.0, 1.0);
            let hit = self.closest(&ray, flip);
            if let Some((_, h)) = &hit {
                let ndc_z = projection.project_point3(h.position).z;
                *z = if ndc_z.is_finite() { (0.5 * ndc_z + 0.5).clamp(0.0, 1.0) } else { 0.0 };
            }
            if let (Some(px), Some(s)) = (px, shade) {
                let c = match hit {
                    Some(first) => {
                        let seed = ((y as u64) << 32 | x as u64)
                            ^ u64::from(s.sample).wrapping_mul(0xd1b5_4a32_d192_ed03);
                        let ctx = ShadeCtx {
                            lighting: s.lighting,
                            opts: s.opts,
                            background: s.background,
                            seed,
                            flip,
                        };
                        to_rgba8(self.shade_through(&ray, first, &ctx))
                    }
                    // Nothing: transparent, for what lies behind to show.
                    None => [0; 4],
                };
                px.copy_from_slice(&c);
            }
        };
        if shade.is_some() {
            rgba.par_chunks_mut(4 * w).zip(depth.par_chunks_mut(w)).enumerate().for_each(
                |(y, (row, zs))| {
                    for (x, (px, z)) in row.chunks_exact_mut(4).zip(zs).enumerate() {
                        pixel(x, y, Some(px), z);
                    }
                },
            );
        } else {
            depth.par_chunks_mut(w).enumerate().for_each(|(y, zs)| {
                for (x, z) in zs.iter_mut().enumerate() {
                    pixel(x, y, None, z);
                }
            });
        }
        Ok((rgba, depth))
    }

    /// The shading, colour, normal (eye space) and normal length (GL's,
    /// interpolated as Gouraud shading interpolates what it lights with)
    /// at a hit.
    fn surface(&self, src: Source, hit: &Hit) -> Surface {
        let (g, nm, paint) = match src {
            Source::Immediate => (&self.immediate, Mat3::IDENTITY, None),
            Source::Instance(i) => {
                // `i` came from this frame's own instances.
                let obj = self.instances.object_of(i).unwrap_or(0);
                let g = self.instances.objects()[obj as usize].geometry();
                (g, self.normal[i as usize], self.paint[i as usize].as_ref())
            }
        };
        Self::surface_in(g, hit, nm, paint)
    }

    /// Indexes freely: every geometry of the frame passed
    /// [`Geometry::check`] when its BVHs were built, and a hit's `prim`
    /// comes from those BVHs.
    /// `nm` takes the geometry's normals to eye space (spheres and tubes
    /// give theirs there already).
    /// `paint`: the instance's call's shading and colour, where they
    /// replace the recording's.
    fn surface_in(g: &Geometry, hit: &Hit, nm: Mat3, paint: Option<&Paint>) -> Surface {
        let p = hit.prim as usize;
        // Texture coordinates: interpolated whatever the shade model.
        let uv = |w: [f32; 3], v: [usize; 3]| {
            if g.texcoords.is_empty() {
                Vec2::ZERO
            } else {
                w[0] * g.texcoords[v[0]] + w[1] * g.texcoords[v[1]] + w[2] * g.texcoords[v[2]]
            }
        };
        let color = |v: usize| match paint {
            Some(p) if v < p.vertices as usize => p.color,
            _ => g.colors[v],
        };
        let shading = |s: u32| paint.map_or(g.shadings[s as usize], |p| p.shading);
        match hit.kind {
            PrimKind::Triangle => {
                let [a, b, c] = g.triangles[p].map(|i| i as usize);
                let (s, pv) = g.triangle_info[p];
                let sh = shading(s);
                let w = Vec3::new(1.0 - hit.uv.x - hit.uv.y, hit.uv.x, hit.uv.y);
                let uv = uv(w.to_array(), [a, b, c]);
                if sh.flat {
                    let n = nm * g.normals[pv as usize];
                    Surface {
                        shading: sh,
                        color: color(pv as usize),
                        normal: n,
                        length: n.length(),
                        uv,
                    }
                } else {
                    let col = w.x * color(a) + w.y * color(b) + w.z * color(c);
                    let [na, nb, nc] = [a, b, c].map(|v| nm * g.normals[v]);
                    let n = w.x * na + w.y * nb + w.z * nc;
                    let len = w.x * na.length() + w.y * nb.length() + w.z * nc.length();
                    Surface { shading: sh, color: col, normal: n, length: len, uv }
                }
            }
            PrimKind::Sphere => {
                let (v, _, s) = g.spheres[p];
                let v = v as usize;
                let uv = uv([1.0, 0.0, 0.0], [v; 3]);
                Surface {
                    shading: shading(s),
                    color: color(v),
                    normal: hit.normal,
                    length: 1.0,
                    uv,
                }
            }
            PrimKind::Capsule => {
                let ([a, b], _, s) = g.tubes[p];
                let (pa, pb) = (g.positions[a as usize], g.positions[b as usize]);
                let d = pb - pa;
                let f = if d == Vec3::ZERO {
                    0.0
                } else {
                    ((hit.position - pa).dot(d) / d.length_squared()).clamp(0.0, 1.0)
                };
                let col = color(a as usize).lerp(color(b as usize), f);
                let uv = uv([1.0 - f, f, 0.0], [a as usize, b as usize, b as usize]);
                Surface { shading: shading(s), color: col, normal: hit.normal, length: 1.0, uv }
            }
        }
    }

    /// GL's lighting equation at `hit`, per pixel.
    /// The colour at `hit`: lit (or the vertex colour, unlit), fogged;
    /// alpha its own where it is blended, 1 where it is opaque.
    fn shade(&self, ray: &Ray, src: Source, hit: &Hit, ctx: &ShadeCtx<'_>, depth: u32) -> Vec4 {
        let surface = self.surface(src, hit);
        let sh = surface.shading;
        let mut c = if sh.lit { self.light(ray, hit, &surface, ctx, depth) } else { surface.color };
        c = self.texture(&sh, c, surface.uv);
        if let (true, Some(fog)) = (sh.fog, &self.fog) {
            // GL's fog coordinate: the eye-space depth's magnitude.
            let f = fog.factor(hit.position.z.abs());
            c = (c.truncate() * f + fog.color.truncate() * (1.0 - f)).extend(c.w);
        }
        if !sh.blend {
            c.w = 1.0;
        }
        c
    }

    /// Front to back through blended surfaces, each over what lies behind
    /// it (at most [`MAX_LAYERS`] of them): the colour premultiplied, and
    /// the opacity (what lies behind shows through `1 −` it).
    /// Sorted by depth whatever order they were drawn in: GL's image of
    /// the same surfaces drawn back to front.
    fn shade_through(&self, ray: &Ray, first: (Source, Hit), ctx: &ShadeCtx<'_>) -> Vec4 {
        let (mut acc, mut through) = (Vec3::ZERO, 1.0f32);
        let (mut r, mut next) = (*ray, Some(first));
        let mut nearest_seen = false;
        for _ in 0..MAX_LAYERS {
            let Some((src, hit)) = next else { break };
            // Past the nearest of the surfaces that show their nearest
            // layer only, the others are passed through unseen.
            let hidden = self.surface(src, &hit).shading.nearest_only && nearest_seen;
            if !hidden {
                let c = self.shade(&r, src, &hit, ctx, 0);
                let a = c.w.clamp(0.0, 1.0);
                acc += through * a * c.truncate();
                through *= 1.0 - a;
                nearest_seen |= c.w < 1.0 && self.surface(src, &hit).shading.nearest_only;
            }
            if through < 1.0 / 1024.0 {
                return acc.extend(1.0);
            }
            // On past the surface, as far as the far plane.
            let side = if r.direction.dot(hit.normal) > 0.0 { hit.normal } else { -hit.normal };
            let mut on = spawn_ray(hit.position, hit.position_error, side, r.direction);
            on.t_max = (r.t_max - hit.t).max(0.0);
            r = on;
            next = self.closest(&r, ctx.flip);
        }
        acc.extend(1.0 - through)
    }

    /// GL's lighting equation at `hit`, per pixel.
    fn light(
        &self,
        ray: &Ray,
        hit: &Hit,
        surface: &Surface,
        ctx: &ShadeCtx<'_>,
        depth: u32,
    ) -> Vec4 {
        let Surface { shading: sh, color, normal, length, .. } = *surface;
        let ShadeCtx { lighting, opts, seed, .. } = *ctx;
        // Spheres and tubes carry their own normal; triangles the one
        // the program gave, whose length GL keeps in the lighting dot
        // products unless GL_NORMALIZE is on (`gain`).
        let mut n = normal.normalize_or_zero();
        let gain =
            if n == Vec3::ZERO || sh.normalize || !length.is_finite() { 1.0 } else { length };
        if n == Vec3::ZERO {
            n = hit.normal;
        }
        // GL decides the side by the window-space winding: the geometric
        // normal against the eye ray.
        let back = (hit.normal.dot(ray.direction) > 0.0) != ctx.flip;
        if back && lighting.two_side {
            n = -n;
        }
        // The side the ray came from, whatever GL calls it.
        let geo_n = if hit.normal.dot(ray.direction) > 0.0 { -hit.normal } else { hit.normal };
        let m = sh.material_with(color);
        let rt = opts.mode == Illumination::Rt;
        let ambient_visibility = if rt && depth == 0 && opts.ao_samples > 0 && self.diagonal > 0.0 {
            self.ambient_visibility(hit, geo_n, opts, seed)
        } else {
            1.0
        };
        let p = hit.position;
        // GL's default infinite viewer for what the camera sees; the
        // incoming ray's direction for what a mirror shows.
        let eye = if depth == 0 { Vec3::Z } else { -ray.direction.normalize_or_zero() };
        let mut c = m.emission + m.ambient * lighting.model_ambient * ambient_visibility;
        for l in lighting.lights.iter().filter(|l| l.enabled) {
            let (to_light, attenuation, target) = if l.position.w == 0.0 {
                (l.position.truncate().normalize_or_zero(), 1.0, None)
            } else {
                let lp = l.position.truncate() / l.position.w;
                let d = lp - p;
                let dist = d.length();
                let k = l.attenuation;
                let att = 1.0 / (k.x + k.y * dist + k.z * dist * dist);
                (d / dist, if att.is_finite() { att } else { 0.0 }, Some(lp))
            };
            let spot = if l.spot_cutoff >= 180.0 {
                1.0
            } else {
                let cos = (-to_light).dot(l.spot_direction.normalize_or_zero());
                if cos < l.spot_cutoff.to_radians().cos() {
                    0.0
                } else {
                    cos.max(0.0).powf(l.spot_exponent)
                }
            };
            let k = attenuation * spot;
            if k == 0.0 || !to_light.is_finite() {
                continue;
            }
            c += k * l.ambient * m.ambient * ambient_visibility;
            let ndl = gain * n.dot(to_light);
            if ndl <= 0.0 {
                continue;
            }
            if rt && opts.shadows && geo_n.dot(to_light) > 0.0 {
                let shadow = match target {
                    None => spawn_ray(p, hit.position_error, geo_n, to_light),
                    Some(lp) => spawn_ray_to(p, hit.position_error, geo_n, lp),
                };
                if self.occluded(&shadow) {
                    continue;
                }
            }
            c += k * ndl * l.diffuse * m.diffuse;
            let h = (to_light + eye).normalize_or_zero();
            let ndh = (gain * n.dot(h)).max(0.0);
            let spec = if m.shininess == 0.0 { 1.0 } else { ndh.powf(m.shininess) };
            c += k * spec * l.specular * m.specular;
        }
        let spec = m.specular.truncate() * opts.mirror;
        if rt && depth < opts.bounces && spec.max_element() > 0.0 {
            let d = ray.direction.normalize_or_zero();
            let r = d - 2.0 * d.dot(n) * n;
            // Leave on the side the reflection goes to.
            let side = if r.dot(geo_n) >= 0.0 { geo_n } else { -geo_n };
            let bounce = spawn_ray(p, hit.position_error, side, r);
            let seen = match self.closest(&bounce, ctx.flip) {
                Some((s2, h2)) => self.shade(&bounce, s2, &h2, ctx, depth + 1),
                None => ctx.background,
            };
            c += (spec * seen.truncate()).extend(0.0);
        }
        c.truncate().extend(m.diffuse.w)
    }

    /// The unoccluded fraction of cosine-distributed rays about `n`,
    /// seeded by the pixel (the same image at any thread count).
    fn ambient_visibility(&self, hit: &Hit, n: Vec3, opts: &Options, seed: u64) -> f32 {
        let mut rng = sampling::rng_from_seed(seed ^ 0x9e37_79b9_7f4a_7c15);
        let (t, b) = n.any_orthonormal_pair();
        let reach = opts.ao_distance * self.diagonal;
        let mut open = 0;
        for _ in 0..opts.ao_samples {
            let l = cosine_hemisphere(sampling::uniform2(&mut rng));
            let mut r = spawn_ray(hit.position, hit.position_error, n, t * l.x + b * l.y + n * l.z);
            r.t_max = reach;
            if !self.occluded(&r) {
                open += 1;
            }
        }
        open as f32 / opts.ao_samples as f32
    }
}

/// What a hit shows before lighting.
#[derive(Clone, Copy, Debug)]
struct Surface {
    shading: Shading,
    /// The (interpolated) vertex colour.
    color: Vec4,
    /// The eye-space normal, interpolated, not made unit.
    normal: Vec3,
    /// GL's normal length there (see [`FrameScene::light`]).
    length: f32,
    /// Texture coordinates.
    uv: Vec2,
}

/// What shading a trace needs besides the scene.
struct Shade<'a> {
    lighting: &'a Lighting,
    opts: &'a Options,
    background: Vec4,
    /// The progressive pass (seeds the random directions).
    sample: u32,
}

/// What every shading call of one frame shares.
#[derive(Clone, Copy)]
struct ShadeCtx<'a> {
    lighting: &'a Lighting,
    opts: &'a Options,
    background: Vec4,
    /// The pixel's seed (AO directions).
    seed: u64,
    /// The projection keeps eye space's handedness (its determinant is
    /// positive, as the identity's; glOrtho's and glFrustum's are
    /// negative): GL tells front from back by the window-space winding,
    /// so a triangle facing the eye ray is then a back face.
    flip: bool,
}

pub(crate) fn to_rgba8(c: Vec4) -> [u8; 4] {
    c.to_array().map(|x| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8)
}
