//! A `no_std` user of the rt crates: loads a BVH from bytes and traces a
//! ray through it (no allocator needed), bends a ray through a linear
//! index, and z-composites two encoded sparse images (on `alloc`, served
//! by a bump allocator over a static arena).
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
/// rt-composite needs only `alloc`.
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
