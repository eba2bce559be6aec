//! Every hit along a ray from Embree (3 or 4): an intersection filter
//! that records each hit the traversal finds and rejects it, so the
//! traversal goes on to the next one (Embree's own way to gather all
//! hits). The filter's arguments have one layout in both versions
//! (`RTCFilterFunctionNArguments`), and so do the ray and hit packets it
//! points to (structures of arrays, `N` lanes).

use core::{cell::RefCell, ffi::c_void};

/// `RTCFilterFunctionNArguments`.
#[repr(C)]
pub(crate) struct FilterArgs {
    valid: *mut i32,
    geometry_user_ptr: *mut c_void,
    context: *const c_void,
    ray: *mut f32,
    hit: *mut u32,
    n: u32,
}

/// Field indices in the packets: `tfar` of `RTCRayN`, `primID` of
/// `RTCHitN` (after the normal and `u, v`).
const TFAR: usize = 8;
const PRIM_ID: usize = 5;

std::thread_local! {
    /// The hits of the query running on this thread.
    static HITS: RefCell<Vec<(f32, u32)>> = const { RefCell::new(Vec::new()) };
}

/// The filter to register on a geometry: records `(t, primID)` of every
/// valid lane and rejects it. Never unwinds (an FFI boundary).
pub(crate) unsafe extern "C" fn record_and_reject(args: *const FilterArgs) {
    // SAFETY: Embree passes arguments whose pointers cover `n` lanes of
    // the valid mask, the ray packet and the hit packet.
    unsafe {
        let a = &*args;
        let n = a.n as usize;
        for i in 0..n {
            if *a.valid.add(i) == 0 {
                continue;
            }
            let hit = (*a.ray.add(TFAR * n + i), *a.hit.add(PRIM_ID * n + i));
            HITS.with(|h| {
                if let Ok(mut h) = h.try_borrow_mut() {
                    h.push(hit);
                }
            });
            *a.valid.add(i) = 0;
        }
    }
}

/// The hits `query` (one Embree query on this thread, through a scene
/// whose geometry has [`record_and_reject`]) found, in the order found.
pub(crate) fn collect(query: impl FnOnce()) -> Vec<(f32, u32)> {
    HITS.with(|h| h.borrow_mut().clear());
    query();
    HITS.with(|h| core::mem::take(&mut *h.borrow_mut()))
}
