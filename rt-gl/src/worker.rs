//! Asynchronous presentation (`RT_GL_ASYNC=1`): the program swaps at its
//! own rate while one worker thread traces the newest frame taken and
//! publishes each traced frame; every swap draws the newest published
//! one. While the frames taken show the same scene (same draws, views,
//! lights), the worker goes on with further progressive passes (other
//! ambient-occlusion directions) and publishes their running average, so
//! a still scene in `rt` mode grows less noisy (up to
//! [`MAX_SAMPLES`] passes); in `gl` mode a frame is exact after one.
//!
//! Which traced frame a swap shows depends on timing: unlike synchronous
//! frames, asynchronous ones are not reproducible frame by frame.

use std::{
    collections::hash_map::DefaultHasher,
    hash::{Hash, Hasher},
    sync::{Arc, Condvar, Mutex, OnceLock, PoisonError},
};

use crate::{
    config,
    present::{Taken, Traced, trace},
    record::{Geometry, Pass},
    render::{Illumination, Image},
};

/// Most progressive passes averaged for a still scene.
pub(crate) const MAX_SAMPLES: u32 = 64;

#[derive(Default)]
struct State {
    /// The newest frame taken, not yet picked up.
    pending: Option<Taken>,
    /// The newest frame traced.
    latest: Option<Arc<Traced>>,
}

struct Worker {
    state: Mutex<State>,
    wake: Condvar,
}

fn worker() -> &'static Worker {
    static WORKER: OnceLock<&'static Worker> = OnceLock::new();
    WORKER.get_or_init(|| {
        let w: &'static Worker =
            Box::leak(Box::new(Worker { state: Mutex::default(), wake: Condvar::new() }));
        let spawned = std::thread::Builder::new().name("rt-gl trace".into()).spawn(move || run(w));
        if let Err(e) = spawned {
            crate::log_once("worker", &format!("cannot start the tracing thread: {e}"));
        }
        w
    })
}

/// Hands the worker the newest frame (a frame it has not picked up yet is
/// dropped: only the newest matters).
pub(crate) fn submit(taken: Taken) {
    let w = worker();
    w.state.lock().unwrap_or_else(PoisonError::into_inner).pending = Some(taken);
    w.wake.notify_one();
}

/// The newest traced frame, if any yet.
pub(crate) fn latest() -> Option<Arc<Traced>> {
    worker().state.lock().unwrap_or_else(PoisonError::into_inner).latest.clone()
}

/// The worker's loop: trace the newest frame; while no newer one comes
/// and the scene is still, trace it again with new directions and
/// publish the average.
fn run(w: &'static Worker) {
    let noisy = {
        let o = &config().options;
        o.mode == Illumination::Rt && o.ao_samples > 0
    };
    // Passes worth averaging for one scene.
    let cap = if noisy { MAX_SAMPLES } else { 1 };
    let mut current: Option<(Taken, u64)> = None;
    let mut sum: Vec<u32> = Vec::new();
    let mut samples = 0u32;
    loop {
        let newer = {
            let mut s = w.state.lock().unwrap_or_else(PoisonError::into_inner);
            let more = current.is_some() && samples < cap;
            while s.pending.is_none() && !more {
                s = w.wake.wait(s).unwrap_or_else(PoisonError::into_inner);
            }
            s.pending.take()
        };
        if let Some(t) = newer {
            let sig = signature(&t);
            if current.as_ref().is_none_or(|(_, old)| *old != sig) {
                (sum, samples) = (Vec::new(), 0);
            }
            current = Some((t, sig));
        }
        if samples >= cap {
            // The same scene, as converged as it gets.
            continue;
        }
        let Some((taken, _)) = &current else { continue };
        let Some(mut traced) = crate::catch(|| trace(taken, samples)) else {
            // A panic while tracing: drop this scene, wait for the next.
            current = None;
            continue;
        };
        if traced.image.rgba.len() != sum.len() {
            (sum, samples) = (vec![0; traced.image.rgba.len()], 0);
        }
        samples += 1;
        for (acc, &v) in sum.iter_mut().zip(&traced.image.rgba) {
            *acc += u32::from(v);
        }
        traced.image = average(&traced.image, &sum, samples);
        traced.samples = samples;
        w.state.lock().unwrap_or_else(PoisonError::into_inner).latest = Some(Arc::new(traced));
    }
}

/// `sum` over `samples` passes, rounded; alpha as the newest pass has it
/// (every pass covers the same pixels).
fn average(newest: &Image, sum: &[u32], samples: u32) -> Image {
    let rgba = sum
        .chunks_exact(4)
        .zip(newest.rgba.chunks_exact(4))
        .flat_map(|(s, n)| {
            let avg = |k: usize| ((s[k] + samples / 2) / samples) as u8;
            [avg(0), avg(1), avg(2), n[3]]
        })
        .collect();
    Image { width: newest.width, height: newest.height, rgba }
}

/// A hash of everything a frame's image depends on: two frames with the
/// same signature show the same scene.
fn signature(t: &Taken) -> u64 {
    let mut h = DefaultHasher::new();
    t.window.hash(&mut h);
    format!("{:?}", t.lighting).hash(&mut h);
    for (viewport, pass) in &t.passes {
        viewport.hash(&mut h);
        hash_pass(pass, &mut h);
    }
    h.finish()
}

fn hash_pass(p: &Pass, h: &mut DefaultHasher) {
    // Views, lights, fog and paints are small: their Debug text is exact.
    format!("{:?} {} {:?}", p.view, p.depth_cleared, p.background).hash(h);
    format!("{:?} {:?}", p.draws.lighting, p.draws.fog).hash(h);
    hash_geometry(&p.draws.immediate, h);
    for i in &p.draws.instances {
        // A recording never changes: its address stands for it.
        (Arc::as_ptr(&i.recorded) as usize).hash(h);
        i.transform.to_cols_array().map(f32::to_bits).hash(h);
        format!("{:?}", i.paint).hash(h);
    }
}

fn hash_geometry(g: &Geometry, h: &mut DefaultHasher) {
    let bits = |v: &[f32], h: &mut DefaultHasher| v.iter().for_each(|x| x.to_bits().hash(h));
    g.positions.iter().for_each(|p| bits(&p.to_array(), h));
    g.normals.iter().for_each(|n| bits(&n.to_array(), h));
    g.colors.iter().for_each(|c| bits(&c.to_array(), h));
    g.triangles.hash(h);
    g.triangle_info.hash(h);
    g.spheres.iter().for_each(|&(v, r, s)| (v, r.to_bits(), s).hash(h));
    g.tubes.iter().for_each(|&(e, r, s)| (e, r.to_bits(), s).hash(h));
    format!("{:?}", g.shadings).hash(h);
}
