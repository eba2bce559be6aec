//! # rt-gl
//!
//! Ray tracing an unmodified OpenGL program. Built as a shared library and
//! loaded with `LD_PRELOAD`, rt-gl stands between the program and the
//! system's GL: it records the fixed-function geometry the program sends
//! (immediate mode, display lists, matrices, lights, materials), forwards
//! every call to the real GL, and at each `glXSwapBuffers` or
//! `eglSwapBuffers` replaces the frame with a ray-traced one, written into
//! the back buffer just before the real swap.
//!
//! ```sh
//! cargo build --release -p rt-gl
//! LD_PRELOAD=$PWD/target/release/librt_gl.so glxgears
//! ```
//!
//! - [`record`]: the recorder, a mirror of GL's fixed-function state that
//!   turns draws into geometry; display lists and buffer draws are
//!   recorded once and instanced on every call, and a buffer draw whose
//!   vertices change but whose triangles do not has its BVHs refitted,
//!   not rebuilt ([`record::Recorded::moved`]).
//! - [`render`]: a pass ray traced per pixel with GL's lighting
//!   equation (`gl` mode) or with shadows, ambient occlusion and mirror
//!   reflections too (`rt`).
//! - [`composite`]: a frame's passes put together as GL's depth buffer
//!   orders draws, 2-D overlays kept as GL drew them.
//! - The interposer itself (exported `gl*`/`glX*` symbols) is in the
//!   `cdylib`; it never lets a panic reach the program, and any error
//!   leaves that frame as the real GL drew it, logged once to stderr.
//!
//! Settings (environment variables, read once): `RT_GL_MODE=gl|rt`,
//! `RT_GL_SHADOWS=0|1`, `RT_GL_AO=<rays per pixel>`, `RT_GL_MIRROR=<0..1>`
//! (reflections of the specular colour in `rt` mode), `RT_GL_THREADS=<n>`,
//! `RT_GL_DUMP=<dir>` (each frame as `rt-NNNN.png`, counters in
//! `counters.txt`), `RT_GL_DUMP_RASTER=1` (also what the real GL drew, as
//! `raster-NNNN.png`), `RT_GL_STATS=1` (counters per frame on stderr:
//! [`record::Counters`] — builds, refits and reuses of lists and buffer
//! draws, instances, triangles, ignored calls — and each pass),
//! `RT_GL_ASYNC=1` (frames traced on a worker thread while the program
//! swaps at its own rate; each swap shows the newest traced frame).

// A std-only library loaded into programs: the no_std import lints of the
// workspace do not apply.
#![allow(clippy::std_instead_of_core, clippy::std_instead_of_alloc, clippy::alloc_instead_of_core)]

use std::{
    collections::HashSet,
    panic::{AssertUnwindSafe, catch_unwind},
    path::PathBuf,
    sync::{Mutex, OnceLock},
};

pub mod composite;
mod ffi;
pub mod gl;
mod present;
mod real;
pub mod record;
pub mod render;
mod worker;

use record::Recorder;
use render::{Illumination, Options};

/// The settings read from the environment.
#[derive(Debug)]
pub struct Config {
    /// Render options.
    pub options: Options,
    /// `RT_GL_DUMP`.
    pub dump: Option<PathBuf>,
    /// `RT_GL_DUMP_RASTER`.
    pub dump_raster: bool,
    /// `RT_GL_STATS`.
    pub stats: bool,
    /// `RT_GL_ASYNC`: the program swaps at its own rate; frames are traced
    /// on a thread of their own and each swap shows the newest traced.
    pub asynchronous: bool,
    /// `RT_GL_MODE=off`: calls are forwarded, nothing is recorded or
    /// traced; swaps are only counted (`RT_GL_STATS`): the program's own
    /// frame rate through the interposer.
    pub off: bool,
    /// `RT_GL_THREADS` (`None`: rayon's global pool, all cores).
    pub pool: Option<rayon::ThreadPool>,
}

impl Config {
    /// The settings from `var` (the environment, in the interposer).
    /// Unreadable values are reported once and replaced by the default.
    pub fn from_vars(var: impl Fn(&str) -> Option<String>) -> Self {
        let mut options = Options::default();
        let flag = |name: &str, default: bool| match var(name).as_deref() {
            None => default,
            Some("1" | "true" | "on" | "yes") => true,
            Some("0" | "false" | "off" | "no") => false,
            Some(v) => {
                log_once(
                    name,
                    &format!("{name}={v}: expected 0 or 1; using {}", u8::from(default)),
                );
                default
            }
        };
        let mut off = false;
        match var("RT_GL_MODE").as_deref() {
            None | Some("gl") => options.mode = Illumination::Gl,
            Some("rt") => options.mode = Illumination::Rt,
            Some("off") => off = true,
            Some(v) => {
                log_once("RT_GL_MODE", &format!("RT_GL_MODE={v}: expected gl, rt or off; using gl"))
            }
        }
        options.shadows = flag("RT_GL_SHADOWS", true);
        if let Some(v) = var("RT_GL_AO") {
            match v.parse::<u32>() {
                Ok(n) if n <= render::MAX_AO_SAMPLES => options.ao_samples = n,
                _ => log_once(
                    "RT_GL_AO",
                    &format!("RT_GL_AO={v}: expected 0..={} rays; using 8", render::MAX_AO_SAMPLES),
                ),
            }
        }
        if let Some(v) = var("RT_GL_MIRROR") {
            match v.parse::<f32>() {
                Ok(k) if (0.0..=1.0).contains(&k) => options.mirror = k,
                _ => log_once(
                    "RT_GL_MIRROR",
                    &format!("RT_GL_MIRROR={v}: expected 0..=1; using 0.5"),
                ),
            }
        }
        let pool = var("RT_GL_THREADS").and_then(|v| match v.parse::<usize>() {
            Ok(n) if n > 0 => rayon::ThreadPoolBuilder::new().num_threads(n).build().ok(),
            _ => {
                log_once(
                    "RT_GL_THREADS",
                    &format!("RT_GL_THREADS={v}: expected a count > 0; using all cores"),
                );
                None
            }
        });
        let dump = var("RT_GL_DUMP").filter(|d| !d.is_empty()).map(PathBuf::from);
        if let Some(Err(e)) = dump.as_ref().map(std::fs::create_dir_all) {
            log_once("dump", &format!("cannot create the dump directory: {e}"));
        }
        Self {
            options,
            dump,
            dump_raster: flag("RT_GL_DUMP_RASTER", false),
            stats: flag("RT_GL_STATS", false),
            asynchronous: flag("RT_GL_ASYNC", false),
            off,
            pool,
        }
    }
}

/// The settings, read from the environment on first use.
pub(crate) fn config() -> &'static Config {
    static CONFIG: OnceLock<Config> = OnceLock::new();
    CONFIG.get_or_init(|| Config::from_vars(|k| std::env::var(k).ok()))
}

/// Logs `message` to stderr the first time `key` is seen.
pub(crate) fn log_once(key: &str, message: &str) {
    static SEEN: Mutex<Option<HashSet<String>>> = Mutex::new(None);
    let mut seen = SEEN.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    if seen.get_or_insert_with(HashSet::new).insert(key.to_owned()) {
        eprintln!("rt-gl: {message}");
    }
}

/// Runs `f`, catching a panic (logged once): `None` if it panicked.
pub(crate) fn catch<R>(f: impl FnOnce() -> R) -> Option<R> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => Some(r),
        Err(e) => {
            let what = e
                .downcast_ref::<&str>()
                .map(|s| (*s).to_owned())
                .or_else(|| e.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            log_once("panic", &format!("internal error, recording continues: {what}"));
            None
        }
    }
}

/// Runs `f` on the process's recorder (`None` if it panicked, or with
/// `RT_GL_MODE=off`, where nothing is recorded).
pub(crate) fn with_recorder<R>(f: impl FnOnce(&mut Recorder) -> R) -> Option<R> {
    static RECORDER: Mutex<Option<Recorder>> = Mutex::new(None);
    if config().off {
        return None;
    }
    catch(|| {
        let mut r = RECORDER.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        f(r.get_or_insert_with(Recorder::new))
    })
}
