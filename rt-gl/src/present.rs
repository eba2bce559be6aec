//! The frame's end: ray trace what was recorded and write it into the
//! program's back buffer through the real GL, saving and restoring every
//! piece of state that touches.

use core::ffi::c_void;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::{
    composite::{Content, Layer, composite, keeps_raster, needs_raster},
    config, gl, log_once, real,
    record::{Counters, Lighting, Pass},
    render::{FrameScene, Image},
    with_recorder,
};

/// Frames presented (numbers the dumps).
static FRAME: AtomicU64 = AtomicU64::new(0);

/// `glXSwapBuffers`: present the recorded frame, if any.
pub(crate) fn swap_frame() {
    present_frame(gl::BACK_BUFFER);
}

/// `glFlush`/`glFinish`: single-buffered windows show a frame here.
pub(crate) fn single_buffered_frame() {
    let mut double = 1u8;
    // SAFETY: GL_DOUBLEBUFFER is one boolean.
    unsafe { real::glGetBooleanv(0x0C32, &raw mut double) };
    if double == 0 {
        present_frame(0x0404);
    }
}

fn present_frame(buffer: u32) {
    let cfg = config();
    if cfg.off {
        let n = FRAME.fetch_add(1, Ordering::Relaxed);
        if cfg.stats {
            eprintln!("rt-gl: frame {n}: not traced (RT_GL_MODE=off)");
        }
        return;
    }
    let Some(taken) = take(buffer) else {
        return;
    };
    if cfg.stats {
        eprintln!("rt-gl: frame {}: {:?}", taken.n, taken.counters);
    }
    if cfg.asynchronous {
        let n = taken.n;
        let (counters, unsupported) = (taken.counters, taken.unsupported.clone());
        crate::worker::submit(taken);
        match crate::worker::latest() {
            Some(traced) => show(buffer, &traced, n, &counters, &unsupported),
            None => {
                if let Some(dir) = &cfg.dump {
                    write_counters(dir, &counters, &[], &unsupported);
                }
            }
        }
    } else {
        let traced = trace(&taken, 0);
        show(buffer, &traced, taken.n, &taken.counters, &taken.unsupported);
    }
}

/// A frame taken from the recorder at its swap: everything tracing it
/// needs, no GL; traced on the program's thread or, with `RT_GL_ASYNC`,
/// on the worker's.
pub(crate) struct Taken {
    /// The frame's number.
    pub(crate) n: u64,
    /// The window rectangle its passes cover.
    pub(crate) window: [i32; 4],
    /// Each pass with its viewport resolved.
    pub(crate) passes: Vec<([i32; 4], Pass)>,
    /// The lights at the swap, for passes with no lit draw.
    pub(crate) lighting: Lighting,
    /// GL's pixels over `window`, read back at the swap when a pass may
    /// be blended over them (see [`crate::composite::needs_raster`]).
    raster: Option<Image>,
    counters: Counters,
    unsupported: Vec<(&'static str, u64)>,
}

/// A traced frame, ready to draw over GL's.
pub(crate) struct Traced {
    /// The number of the frame it shows.
    pub(crate) n: u64,
    /// Where it goes in the window.
    pub(crate) window: [i32; 4],
    /// The composite (alpha 0: GL's pixel stays).
    pub(crate) image: Image,
    /// Instances left out; passes traced; passes kept as GL drew them.
    pub(crate) left_out: usize,
    pub(crate) traced: usize,
    pub(crate) kept: usize,
    /// Progressive passes averaged into `image`.
    pub(crate) samples: u32,
}

/// Ends the recorder's frame: its passes with their viewports resolved,
/// the unsupported features reported, GL's raster dumped. `None`: nothing
/// to trace.
fn take(buffer: u32) -> Option<Taken> {
    let cfg = config();
    let (frame, lighting, counters, unsupported) = with_recorder(|r| {
        if r.compiling_only() {
            return None;
        }
        let frame = r.end_frame();
        let unsupported: Vec<(&'static str, u64)> =
            r.unsupported.iter().map(|(k, v)| (*k, *v)).collect();
        Some((frame, r.lighting.clone(), r.counters, unsupported))
    })
    .flatten()?;
    for (what, _) in &unsupported {
        log_once(
            &format!("unsupported {what}"),
            &format!(
                "{what} is not traced: the frame shows the geometry without it (counts in counters.txt with RT_GL_DUMP)"
            ),
        );
    }
    let n = FRAME.fetch_add(1, Ordering::Relaxed);
    // A program that never calls glViewport draws in GL's initial one,
    // the drawable's size when the context was first made current.
    let initial = std::sync::OnceLock::new();
    let resolve = |v: [i32; 4]| {
        if v[2] > 0 && v[3] > 0 { v } else { *initial.get_or_init(real_viewport) }
    };
    let passes: Vec<_> = frame
        .passes
        .into_iter()
        .map(|p| (resolve(p.view.viewport), p))
        .filter(|(v, _)| v[2] > 0 && v[3] > 0)
        .collect();
    // Pixel operations draw where the raster position is, in or out of
    // the viewport.
    let rects = passes.iter().flat_map(|(_, p)| p.draws.pixels.iter().map(|(r, _)| *r));
    let window = clip_to_window(passes.iter().map(|(v, _)| *v).chain(rects).reduce(union)?);
    if window[2] <= 0 || window[3] <= 0 {
        return None;
    }
    // Blended draws after a 2-D overlay: GL's pixels may be needed under them.
    let blended_after_overlay =
        passes.iter().skip_while(|(v, p)| !p.view.is_kept(*v)).any(|(_, p)| pass_blends(p));
    let dump_raster = cfg.dump_raster && cfg.dump.is_some();
    let raster = (dump_raster || blended_after_overlay).then(|| read_back(buffer, window));
    if let (true, Some(dir), Some(img)) = (dump_raster, &cfg.dump, &raster)
        && let Err(e) = img.write_png(&dir.join(format!("raster-{n:04}.png")))
    {
        log_once("dump", &format!("cannot write frame dumps to {}: {e}", dir.display()));
    }
    if cfg.stats {
        for (k, (v, p)) in passes.iter().enumerate() {
            let d = &p.draws;
            eprintln!(
                "rt-gl: frame {n} pass {k}: viewport {v:?}, {}, depth test {}, depth cleared {}, {} immediate triangles, {} instances",
                if p.view.is_kept(*v) { "kept as GL drew it" } else { "traced" },
                p.view.depth_test,
                p.depth_cleared,
                d.immediate.triangles.len(),
                d.instances.len(),
            );
        }
    }
    Some(Taken { n, window, passes, lighting, raster, counters, unsupported })
}

/// Traces each pass of `taken` (progressive pass `sample`) and composites
/// them. No GL: any thread.
pub(crate) fn trace(taken: &Taken, sample: u32) -> Traced {
    let cfg = config();
    let n = taken.n;
    let mut left_out = 0;
    let mut traced = 0;
    let layers: Vec<Layer> = taken
        .passes
        .iter()
        .map(|(viewport, pass)| {
            let viewport = *viewport;
            let overlay = pass.view.is_kept(viewport);
            let content = crate::catch(|| {
                let lighting = pass.draws.lighting.as_ref().unwrap_or(&taken.lighting);
                let scene = FrameScene::build(pass.draws.clone())?;
                left_out += scene.left_out();
                let [_, _, w, h] = viewport.map(|v| v as u32);
                let projection = pass.view.projection;
                let work = || {
                    if overlay {
                        scene.coverage(projection, w, h).map(|depth| Content::Raster { depth })
                    } else {
                        scene
                            .render_sample(
                                lighting,
                                projection,
                                w,
                                h,
                                pass.background,
                                &cfg.options,
                                sample,
                            )
                            .map(|(image, depth)| Content::Traced { image, depth })
                    }
                };
                match &cfg.pool {
                    Some(pool) => pool.install(work),
                    None => work(),
                }
            });
            let content = match content {
                Some(Ok(c)) => c,
                Some(Err(e)) => {
                    // Once per cause.
                    log_once(
                        &format!("render: {e}"),
                        &format!("a pass of frame {n} left as rasterized: {e}"),
                    );
                    Content::Untraced
                }
                None => Content::Untraced,
            };
            traced += usize::from(matches!(content, Content::Traced { .. }));
            let (viewport, content) =
                with_pixels(viewport, content, &pass.draws.pixels, taken.window);
            Layer {
                viewport,
                depth_test: pass.view.depth_test,
                depth_cleared: pass.depth_cleared,
                background: pass.background,
                content,
            }
        })
        .collect();
    if left_out > 0 {
        log_once(
            "left out",
            &format!(
                "instances whose transform cannot place them (singular or projective, as planar shadows') are left out of the trace ({left_out} in frame {n}; left_out in counters.txt)"
            ),
        );
    }
    let kept = layers.len() - traced;
    // Nothing traced: an empty composite, the frame stays as GL drew it.
    let image = if traced == 0 {
        Image { width: 0, height: 0, rgba: Vec::new() }
    } else {
        composite(taken.window, &layers, taken.raster.as_ref().filter(|_| needs_raster(&layers)))
    };
    Traced { n, window: taken.window, image, left_out, traced, kept, samples: 1 }
}

/// Draws `traced` over GL's frame `n`, dumps what the window shows, writes
/// the counters.
fn show(
    buffer: u32,
    traced: &Traced,
    n: u64,
    counters: &Counters,
    unsupported: &[(&'static str, u64)],
) {
    let cfg = config();
    if let Some(dir) = &cfg.dump {
        let mut extra = vec![
            ("left_out", traced.left_out as u64),
            ("passes.traced", traced.traced as u64),
            ("passes.kept", traced.kept as u64),
        ];
        if cfg.asynchronous {
            extra.extend([("async.frame", traced.n), ("async.samples", u64::from(traced.samples))]);
        }
        write_counters(dir, counters, &extra, unsupported);
    }
    if traced.traced == 0 {
        return;
    }
    let img = &traced.image;
    let keep = keeps_raster(img);
    // SAFETY: `img` holds w·h RGBA pixels; the state touched is restored.
    unsafe { draw(img, traced.window[0], traced.window[1], keep) };
    if let Some(dir) = &cfg.dump {
        // What the window shows: GL's overlays read back where kept.
        let shown = if keep { &read_back(buffer, traced.window) } else { img };
        if let Err(e) = shown.write_png(&dir.join(format!("rt-{n:04}.png"))) {
            log_once("dump", &format!("cannot write frame dumps to {}: {e}", dir.display()));
        }
    }
}

/// A kept pass's coverage widened to the window rectangle `window` and
/// joined by the rectangles its pixel operations drew, at their raster
/// depths (they draw outside the viewport too).
fn with_pixels(
    viewport: [i32; 4],
    content: Content,
    pixels: &[([i32; 4], f32)],
    window: [i32; 4],
) -> ([i32; 4], Content) {
    let Content::Raster { depth } = content else { return (viewport, content) };
    if pixels.is_empty() {
        return (viewport, Content::Raster { depth });
    }
    let [wx, wy, ww, wh] = window;
    let mut all = vec![f32::INFINITY; ww as usize * wh as usize];
    let mut put = |x: i32, y: i32, z: f32| {
        if x >= wx && y >= wy && x - wx < ww && y - wy < wh {
            let i = (y - wy) as usize * ww as usize + (x - wx) as usize;
            all[i] = all[i].min(z);
        }
    };
    let [vx, vy, vw, _] = viewport;
    for (i, &z) in depth.iter().enumerate() {
        if z.is_finite() {
            let (x, y) = ((i % vw as usize) as i32, (i / vw as usize) as i32);
            put(vx + x, vy + y, z);
        }
    }
    for &([x, y, w, h], z) in pixels {
        // Clipped to the window first: a rectangle may be huge.
        let (x0, y0) = (x.max(wx), y.max(wy));
        let (x1, y1) = (x.saturating_add(w).min(wx + ww), y.saturating_add(h).min(wy + wh));
        for py in y0..y1 {
            for px in x0..x1 {
                put(px, py, z);
            }
        }
    }
    (window, Content::Raster { depth: all })
}

/// Whether any of `p`'s draws is blended.
fn pass_blends(p: &Pass) -> bool {
    let d = &p.draws;
    d.immediate.shadings.iter().any(|s| s.blend)
        || d.instances.iter().any(|i| match &i.paint {
            Some(paint) => paint.shading.blend,
            None => i.recorded.geometry().shadings.iter().any(|s| s.blend),
        })
}

/// The smallest rectangle holding `a` and `b` (`[x, y, width, height]`).
fn union(a: [i32; 4], b: [i32; 4]) -> [i32; 4] {
    let (x0, y0) = (a[0].min(b[0]), a[1].min(b[1]));
    let x1 = (a[0].saturating_add(a[2])).max(b[0].saturating_add(b[2]));
    let y1 = (a[1].saturating_add(a[3])).max(b[1].saturating_add(b[3]));
    [x0, y0, x1.saturating_sub(x0), y1.saturating_sub(y0)]
}

/// `r` without what lies left of or below the window's origin (GL reads
/// and writes no pixel there) and at most 16384 pixels a side.
fn clip_to_window([x, y, w, h]: [i32; 4]) -> [i32; 4] {
    let (x0, y0) = (x.max(0), y.max(0));
    let w = (x.saturating_add(w) - x0).min(16384);
    let h = (y.saturating_add(h) - y0).min(16384);
    [x0, y0, w, h]
}

/// `counters.txt` in `dir`: the recorder's counters, then `extra` (the
/// instances left out of the frame shown, its passes traced and kept as
/// GL drew them, and with `RT_GL_ASYNC` which frame it is and how many
/// progressive passes it averages), then each unsupported feature's
/// count (`unsupported.NAME=count`).
fn write_counters(
    dir: &std::path::Path,
    c: &Counters,
    extra: &[(&str, u64)],
    unsupported: &[(&'static str, u64)],
) {
    let mut line = format!(
        "frames={} passes={} passes_merged={} list_builds={} list_reuses={} list_inline={} draw_builds={} draw_reuses={} draw_refits={} draw_inline={} instances={} triangles={} ignored={}",
        c.frames,
        c.passes,
        c.passes_merged,
        c.list_builds,
        c.list_reuses,
        c.list_inline,
        c.draw_builds,
        c.draw_reuses,
        c.draw_refits,
        c.draw_inline,
        c.instances,
        c.triangles,
        c.ignored
    );
    for (what, count) in extra {
        line += &format!(" {what}={count}");
    }
    for (what, count) in unsupported {
        line += &format!(" unsupported.{what}={count}");
    }
    line.push('\n');
    // Written beside, then renamed over: a program stopped mid-write
    // (glxgears is stopped by a signal) leaves the previous frame's
    // counters, never an empty file.
    let tmp = dir.join("counters.txt.tmp");
    if std::fs::write(&tmp, line).is_ok() {
        let _ = std::fs::rename(&tmp, dir.join("counters.txt"));
    }
}

/// The real GL's current viewport.
fn real_viewport() -> [i32; 4] {
    let mut v = [0i32; 4];
    // SAFETY: GL_VIEWPORT is four integers.
    unsafe { real::glGetIntegerv(0x0BA2, v.as_mut_ptr()) };
    v
}

/// What the real GL rasterized into `buffer` in the viewport.
fn read_back(buffer: u32, [x, y, w, h]: [i32; 4]) -> Image {
    let mut rgba = vec![0u8; 4 * w as usize * h as usize];
    // SAFETY: `rgba` holds w·h RGBA pixels at pack alignment 1, row
    // length 0 (set here, restored by the client-attribute pop).
    unsafe {
        real::glPushClientAttrib(gl::CLIENT_ALL_ATTRIB_BITS);
        real::glPushAttrib(gl::ALL_ATTRIB_BITS);
        real::glPixelStorei(gl::PACK_ALIGNMENT, 1);
        real::glPixelStorei(gl::PACK_ROW_LENGTH, 0);
        real::glReadBuffer(buffer);
        real::glReadPixels(x, y, w, h, gl::RGBA, gl::UNSIGNED_BYTE, rgba.as_mut_ptr().cast());
        real::glPopAttrib();
        real::glPopClientAttrib();
    }
    Image { width: w as u32, height: h as u32, rgba }
}

/// Writes `img` at window position `(x, y)` with `glDrawPixels`; with
/// `keep`, its pixels of alpha 0 leave GL's as they are (alpha test).
///
/// # Safety
/// A current GL context (the program's, at its swap).
unsafe fn draw(img: &Image, x: i32, y: i32, keep: bool) {
    // SAFETY: plain state changes, pushed and popped in pairs; the pixel
    // pointer covers width·height RGBA pixels at unpack alignment 1.
    unsafe {
        real::glPushAttrib(gl::ALL_ATTRIB_BITS);
        real::glPushClientAttrib(gl::CLIENT_ALL_ATTRIB_BITS);
        real::glMatrixMode(gl::PROJECTION);
        real::glPushMatrix();
        real::glLoadIdentity();
        real::glMatrixMode(gl::MODELVIEW);
        real::glPushMatrix();
        real::glLoadIdentity();
        for cap in [
            gl::LIGHTING,
            gl::DEPTH_TEST,
            gl::TEXTURE_2D,
            gl::BLEND,
            gl::FOG,
            gl::ALPHA_TEST,
            gl::STENCIL_TEST,
            gl::CULL_FACE,
        ] {
            real::glDisable(cap);
        }
        if keep {
            real::glEnable(gl::ALPHA_TEST);
            real::glAlphaFunc(gl::GREATER, 0.5);
        }
        real::glPixelStorei(gl::UNPACK_ALIGNMENT, 1);
        real::glPixelStorei(gl::UNPACK_ROW_LENGTH, 0);
        real::glPixelStorei(gl::UNPACK_SKIP_ROWS, 0);
        real::glPixelStorei(gl::UNPACK_SKIP_PIXELS, 0);
        real::glPixelZoom(1.0, 1.0);
        real::glWindowPos2i(x, y);
        real::glDrawPixels(
            img.width as i32,
            img.height as i32,
            gl::RGBA,
            gl::UNSIGNED_BYTE,
            img.rgba.as_ptr().cast::<c_void>(),
        );
        real::glMatrixMode(gl::MODELVIEW);
        real::glPopMatrix();
        real::glMatrixMode(gl::PROJECTION);
        real::glPopMatrix();
        real::glPopClientAttrib();
        real::glPopAttrib();
    }
}
