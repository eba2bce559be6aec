//! A `no_std`, no-allocator user of rt-core and rt-accel: loads a BVH from
//! bytes and traces a ray through it.
#![no_std]

use core::panic::PanicInfo;

use rt_accel::{BvhRef, TriPacket};
use rt_core::{Ray, glam::Vec3};

#[panic_handler]
fn panic(_: &PanicInfo<'_>) -> ! {
    loop {}
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
