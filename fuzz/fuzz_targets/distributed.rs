//! What crosses between ranks, from a hostile or broken peer:
//!
//! - occlusion rounds (`resolve_occlusion`) on rank 0 of two, whose peer's
//!   messages are arbitrary bytes: an answer or an `Err`, never a panic
//!   or a hang, and every answer for a ray no region holds is "open";
//! - a photon's state off the network (`PathState::from_words`, any
//!   words): refused, or traced on through a brick of a grid
//!   (`trace_leg`) to a finite answer or an `Err`.
#![no_main]

use std::{cell::RefCell, collections::VecDeque};

use libfuzzer_sys::fuzz_target;
use rt_composite::{CommError, Communicator, resolve_occlusion};
use rt_core::Aabb;
use rt_fuzz::{f64_any, grid, ray, trace_params};
use rt_volume::{BrickField, Bricks, Interp, Leg, PathState, trace_leg};

/// Rank 0 of two: what it sends is dropped; what it receives is scripted.
struct Scripted {
    inbox: RefCell<VecDeque<Vec<u8>>>,
}

impl Communicator for Scripted {
    fn rank(&self) -> usize {
        0
    }
    fn size(&self) -> usize {
        2
    }
    fn send(&self, to: usize, _: u32, _: Vec<u8>) -> Result<(), CommError> {
        if to < 2 { Ok(()) } else { Err(CommError::NoSuchRank(to)) }
    }
    fn recv(&self, from: usize, tag: u32) -> Result<Vec<u8>, CommError> {
        self.inbox.borrow_mut().pop_front().ok_or(CommError::Timeout { from, tag })
    }
}

fuzz_target!(|data: &[u8]| {
    let mut u = arbitrary::Unstructured::new(data);
    let Ok(which) = u.int_in_range(0u8..=1) else { return };
    if which == 0 {
        // Rays and two regions, then the peer's messages.
        let mut rays = Vec::new();
        for _ in 0..u.int_in_range(0usize..=6).unwrap_or(0) {
            let Ok(r) = ray(&mut u) else { return };
            rays.push(r);
        }
        let unit = Aabb::new(rt_core::glam::Vec3::ZERO, rt_core::glam::Vec3::ONE);
        let regions = [unit, Aabb::new(unit.min + 0.5, unit.max + 0.5)];
        let mut inbox = VecDeque::new();
        for _ in 0..u.int_in_range(0usize..=8).unwrap_or(0) {
            let len = u.int_in_range(0usize..=80).unwrap_or(0);
            let Ok(mut msg) = u.bytes(len).map(<[u8]>::to_vec) else { return };
            // Often a valid header, so the payload parser is reached.
            if u.ratio(3u8, 4).unwrap_or(false) && msg.len() >= 2 {
                msg[0] = 0x5a;
                msg[1] &= 1;
            }
            inbox.push_back(msg);
        }
        let comm = Scripted { inbox: RefCell::new(inbox) };
        let blocked_here = |rs: &[rt_core::Ray], out: &mut [bool]| {
            for (r, o) in rs.iter().zip(out.iter_mut()) {
                *o = r.origin.x > 0.25;
            }
        };
        if let Ok((bits, _)) = resolve_occlusion(&comm, &regions, &rays, 2, blocked_here) {
            assert_eq!(bits.len(), rays.len());
            for (r, b) in rays.iter().zip(&bits) {
                let crosses = regions.iter().any(|g| g.intersect_ray(r).is_some());
                assert!(crosses || !b, "a ray outside every region was blocked: {r:?}");
            }
        }
        return;
    }
    // A state off the network, traced through a brick.
    let mut words = [0f64; PathState::WORDS];
    for w in &mut words {
        let Ok(v) = f64_any(&mut u) else { return };
        *w = v;
    }
    let (Ok(Some(g)), Ok(params), Ok(ranks)) =
        (grid(&mut u), trace_params(&mut u), u.int_in_range(1usize..=4))
    else {
        return;
    };
    let Ok(state) = PathState::from_words(&words) else { return };
    let Ok(bricks) = Bricks::for_ranks(g.info(), ranks) else { return };
    let Ok(reach) = rt_volume::step_reach(&params, 2.0, 1.0) else { return };
    let Ok((lo, hi)) = bricks.samples_needed(0, reach, Interp::Trilinear) else { return };
    let Ok(field) = BrickField::from_grid(&g, lo, hi, Interp::Trilinear, 1.0) else { return };
    match trace_leg(&field, state, &params, |x| bricks.owner(x) == 0) {
        Ok(Leg::Finished(r)) => {
            assert!(r.position.is_finite() && r.direction.is_finite(), "{r:?}");
        }
        Ok(Leg::Left(s)) => assert!(s.position().is_finite(), "{s:?}"),
        Err(_) => {}
    }
});
