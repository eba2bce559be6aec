//! A `no_std` user of the rt crates: loads a BVH from bytes and traces a
//! ray through it (no allocator needed), renders a frame of it through its
//! own `ShadeScene` with shadows and ambient occlusion, bends a ray through a linear
//! index, renders a tiny knife-edge schlieren image and splats a photon
//! through a cutoff onto a film, and z-composites two encoded sparse
//! images (on `alloc`, served by a bump allocator over a static arena).
#![no_std]

extern crate alloc;

use core::{
    alloc::{GlobalAlloc, Layout},
    cell::UnsafeCell,
    panic::PanicInfo,
    sync::atomic::{AtomicUsize, Ordering},
};

use rt_accel::{BvhRef, TriPacket};
use rt_core::{Ray, glam::Vec3};

#[panic_handler]
fn panic(_: &PanicInfo<'_>) -> ! {
    loop {}
}

/// A bump allocator over 1 MiB that never frees: enough to show that
/// rt-photo and rt-composite need only `alloc`.
struct Bump {
    arena: UnsafeCell<[u8; 1 << 20]>,
    next: AtomicUsize,
}

// SAFETY: the arena is handed out in disjoint pieces by an atomic cursor.
unsafe impl Sync for Bump {}

// SAFETY: every block is inside the arena, aligned, and never handed out
// twice.
unsafe impl GlobalAlloc for Bump {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let base = self.arena.get().cast::<u8>();
        let mut at = self.next.load(Ordering::Relaxed);
        loop {
            let start = (base as usize + at).next_multiple_of(layout.align()) - base as usize;
            let end = start + layout.size();
            if end > 1 << 20 {
                return core::ptr::null_mut();
            }
            match self.next.compare_exchange(at, end, Ordering::Relaxed, Ordering::Relaxed) {
                // SAFETY: `start..end` lies in the arena.
                Ok(_) => return unsafe { base.add(start) },
                Err(now) => at = now,
            }
        }
    }

    unsafe fn dealloc(&self, _: *mut u8, _: Layout) {}
}

#[global_allocator]
static HEAP: Bump = Bump { arena: UnsafeCell::new([0; 1 << 20]), next: AtomicUsize::new(0) };

/// Depth of the nearer of two one-pixel images after encoding, sending
/// (bytes) and z-compositing them; NaN on a decoding error.
#[must_use]
pub fn nearer(a: f32, b: f32) -> f32 {
    use rt_composite::{Fragment, SparseImage};
    use rt_core::Pixel;
    let enc = |d: f32| SparseImage::encode(0, &[Pixel { color: [1.0; 4], depth: d }]).to_bytes();
    let (Ok(x), Ok(y)) =
        (SparseImage::<Pixel>::from_bytes(&enc(a)), SparseImage::<Pixel>::from_bytes(&enc(b)))
    else {
        return f32::NAN;
    };
    let mut out = [Pixel::BACKGROUND];
    if let Some(z) = x.combine(&y, Pixel::z) {
        z.write_into(&mut out);
    }
    out[0].depth
}

/// Distance to the closest triangle of the serialized BVH `bytes` along the
/// ray, `-1` on a miss, `-2` if the bytes are not a valid BVH.
#[must_use]
pub fn trace(bytes: &[u8], origin: [f32; 3], direction: [f32; 3]) -> f32 {
    let Ok(bvh) = BvhRef::<TriPacket>::from_bytes(bytes) else { return -2.0 };
    let ray = Ray::new(Vec3::from(origin), Vec3::from(direction));
    match bvh.closest_hit(&ray) {
        Some(hit) if !bvh.occluded(&Ray { t_max: hit.t * 0.5, ..ray }) => hit.t,
        Some(_) => 0.0,
        None => -1.0,
    }
}

/// A user's scene for the surface renderer: a loaded BVH, one grey matte
/// material, the geometric normal.
struct Shaded<'a>(BvhRef<'a, TriPacket>);

impl rt_core::SceneQuery for Shaded<'_> {
    fn closest_hit(&self, ray: &Ray) -> Option<rt_core::Hit> {
        self.0.closest_hit(ray)
    }
    fn occluded(&self, ray: &Ray) -> bool {
        self.0.occluded(ray)
    }
}

impl rt_surface::ShadeScene for Shaded<'_> {
    fn surface(&self, hit: &rt_core::Hit) -> rt_surface::Surface {
        rt_surface::Surface {
            albedo: [0.8; 3],
            normal: hit.normal,
            material: rt_surface::Material::MATTE,
        }
    }
    fn bounds(&self) -> rt_core::Aabb {
        self.0.bounds()
    }
}

/// Mean red of a 4×4 frame of the serialized BVH `bytes` seen from `eye`
/// (looking at the origin) under an ambient light with 4 AO rays and a
/// shadowing directional light; -1 on an error.
#[must_use]
pub fn shade(bytes: &[u8], eye: [f32; 3]) -> f32 {
    use rt_core::{Camera, Projection};
    use rt_surface::{Light, Renderer, Settings};
    let Ok(bvh) = BvhRef::<TriPacket>::from_bytes(bytes) else { return -1.0 };
    let projection = Projection::Perspective { fov_y: 0.8 };
    let Ok(camera) = Camera::look_at(Vec3::from(eye), Vec3::ZERO, Vec3::Y, projection, 4, 4) else {
        return -1.0;
    };
    let settings = Settings {
        lights: alloc::vec![
            Light::Ambient { color: [0.3; 3] },
            Light::Directional { direction: Vec3::ONE, color: [0.7; 3] },
        ],
        ao_samples: 4,
        ..Settings::default()
    };
    let Ok(mut renderer) = Renderer::new(camera, settings) else { return -1.0 };
    renderer.render_pass(&Shaded(bvh));
    let Ok(frame) = renderer.frame() else { return -1.0 };
    frame.pixels().iter().map(|p| p.color[0]).sum::<f32>() / 16.0
}

/// Height at which a ray launched along +x at the origin leaves the unit
/// box through a linear index `n = 1 + g·y` (a catenary), or NaN on error.
#[must_use]
pub fn bend(g: f64) -> f64 {
    use rt_volume::{Bounds, LinearIndex, TraceParams, glam::DVec3};
    let v = DVec3::new;
    let f = LinearIndex {
        n0: 1.0,
        gradient: v(0.0, g, 0.0),
        bounds: Bounds::new(v(0.0, -1.0, -1.0), v(1.0, 1.0, 1.0)),
    };
    rt_volume::trace(&f, v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), &TraceParams::accurate())
        .map_or(f64::NAN, |r| r.position.y)
}

/// Brightness of the left half of a 4×4 knife-edge schlieren image of a
/// Gaussian bump of strength `delta` (0.5 undisturbed; more for
/// `delta > 0`), plus the weight a photon deflected by `eps` (radians)
/// leaves on a film through the same edge; NaN on an error.
#[must_use]
pub fn schlieren(delta: f64, eps: f64) -> f64 {
    use rt_photo::glam::DVec3;
    use rt_photo::rt_volume::GaussianBump;
    use rt_photo::{
        Cutoff, Film, Filter, Mode, Reconstruction, SchlierenBench, TraceParams, Weighting,
    };
    let edge = Cutoff::KnifeEdge { angle: 0.0, offset: 0.0, f: 1.0, h: 1e-3 };
    if edge.validate().is_err() {
        return f64::NAN;
    }
    let bench = SchlierenBench {
        center: DVec3::new(0.0, 0.0, -6.0),
        direction: DVec3::Z,
        u: DVec3::X,
        width: 6.0,
        height: 6.0,
        image_plane: 6.0,
        film_distance: 0.0,
        mode: Mode::Schlieren(edge.clone()),
        weighting: Weighting::Weight,
        reconstruction: Reconstruction::Photons,
        strata: 1,
        params: TraceParams::accurate(),
    };
    let field = GaussianBump::new(DVec3::ZERO, delta, 1.0, 5.0);
    let Ok(mut film) = Film::new(4, 4, Filter::Tent) else { return f64::NAN };
    if bench.render(&field, &mut film, 0, 1).is_err() {
        return f64::NAN;
    }
    let image = film.normalized_f64();
    let left = image.iter().enumerate().filter(|(i, _)| i % 4 < 2).map(|(_, p)| p[0]).sum::<f64>();
    let Ok(mut one) = Film::new(1, 1, Filter::Box) else { return f64::NAN };
    one.splat(0.5, 0.5, edge.transmit(eps, 0.0), (eps, 0.0));
    left / 8.0 + one.total()[0]
}

/// The automatic knife edge's source height for a blob of `excess`
/// kg/m³ on an 8³ grid of air, from the library's set-up over a medium
/// (survey, choice, one render); NaN on an error.
#[must_use]
pub fn auto_knife(excess: f32) -> f64 {
    use alloc::vec::Vec;
    use rt_photo::glam::DVec3;
    use rt_photo::rt_volume::{Grid, Interp};
    use rt_photo::{Cutoff, Medium, Mode, Samples, SchlierenOptions, SchlierenSetup};
    let data: Vec<f32> = (0..512).map(|i| if i == 292 { 1.2 + excess } else { 1.2 }).collect();
    let Ok(grid) = Grid::new([8; 3], DVec3::ZERO, DVec3::splat(1e-3), data) else {
        return f64::NAN;
    };
    let Ok(medium) = Medium::from_grid(grid, Samples::AIR, false, Interp::Trilinear) else {
        return f64::NAN;
    };
    let options = SchlierenOptions { size: 4, photons: 1, ..SchlierenOptions::default() };
    let Ok(setup) = SchlierenSetup::choose(&medium, &options) else { return f64::NAN };
    if setup.render(&medium, 1, &mut |_, _| {}).is_err() {
        return f64::NAN;
    }
    match setup.bench.mode {
        Mode::Schlieren(Cutoff::KnifeEdge { h, .. }) => h,
        _ => f64::NAN,
    }
}

/// C entry point so the static library exports something.
///
/// # Safety
/// `bytes` must point to `len` readable bytes, `o` and `d` to 3 floats each.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn rt_trace(
    bytes: *const u8,
    len: usize,
    o: *const f32,
    d: *const f32,
) -> f32 {
    // SAFETY: the caller guarantees the pointers and lengths.
    let (b, o, d) = unsafe {
        (core::slice::from_raw_parts(bytes, len), *o.cast::<[f32; 3]>(), *d.cast::<[f32; 3]>())
    };
    trace(b, o, d)
}
