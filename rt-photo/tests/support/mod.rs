//! The bench fixture the integration tests share.
#![allow(dead_code, reason = "each test binary uses only part of it")]

use rt_photo::glam::DVec3;
use rt_photo::{Cutoff, Mode, Reconstruction, SchlierenBench, TraceParams, Weighting};

/// A beam along +z over `[-3, 3]²`, emitted at z = −6, imaging the plane
/// z = 0 (`L = 0`), `strata²` photons per pixel, weighted.
pub(crate) fn bench(mode: Mode, strata: u32) -> SchlierenBench {
    SchlierenBench {
        center: DVec3::new(0.0, 0.0, -6.0),
        direction: DVec3::Z,
        u: DVec3::X,
        width: 6.0,
        height: 6.0,
        image_plane: 6.0,
        film_distance: 0.0,
        mode,
        weighting: Weighting::Weight,
        reconstruction: Reconstruction::Photons,
        strata,
        params: TraceParams::accurate(),
    }
}

/// A half-cut knife edge across the u axis, sensitivity `f/h = f_over_h`.
pub(crate) fn knife(f_over_h: f64) -> Mode {
    Mode::Schlieren(Cutoff::KnifeEdge { angle: 0.0, offset: 0.0, f: f_over_h * 1e-3, h: 1e-3 })
}
