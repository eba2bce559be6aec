//! The frame's end: ray trace what was recorded and write it into the
//! program's back buffer through the real GL, saving and restoring every
//! piece of state that touches.

use core::ffi::c_void;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::{
    config, gl, log_once, real,
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
    let taken = with_recorder(|r| {
        if r.compiling_only() {
            return None;
        }
        let mut frame = r.end_frame();
        let counters = r.counters;
        let unsupported: Vec<(&'static str, u64)> =
            r.unsupported.iter().map(|(k, v)| (*k, *v)).collect();
        let lighting = frame.lighting.take().unwrap_or_else(|| r.lighting.clone());
        let state = (lighting, r.projection(), r.viewport, r.clear_color);
        Some((frame, state, counters, unsupported))
    })
    .flatten();
    let Some((frame, (lighting, projection, viewport, background), counters, unsupported)) = taken
    else {
        return;
    };
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
    let viewport = if viewport[2] > 0 && viewport[3] > 0 { viewport } else { real_viewport() };
    let [x, y, w, h] = viewport;
    if w <= 0 || h <= 0 {
        return;
    }
    if let (true, Some(dir)) = (cfg.dump_raster, &cfg.dump) {
        let img = read_back(buffer, viewport);
        if let Err(e) = img.write_png(&dir.join(format!("raster-{n:04}.png"))) {
            log_once("dump", &format!("cannot write frame dumps to {}: {e}", dir.display()));
        }
    }
    let mut left_out = 0;
    let rendered = crate::catch(|| {
        let scene = FrameScene::build(frame)?;
        left_out = scene.left_out();
        let render =
            || scene.render(&lighting, projection, w as u32, h as u32, background, &cfg.options);
        match &cfg.pool {
            Some(pool) => pool.install(render),
            None => render(),
        }
    });
    if left_out > 0 {
        log_once(
            "left out",
            &format!(
                "instances whose transform cannot place them (singular or projective, as planar shadows') are left out of the trace ({left_out} in frame {n}; left_out in counters.txt)"
            ),
        );
    }
    if let Some(dir) = &cfg.dump {
        write_counters(dir, &counters, left_out, &unsupported);
    }
    let img = match rendered {
        Some(Ok(img)) => img,
        Some(Err(e)) => {
            // Once per cause.
            log_once(&format!("render: {e}"), &format!("frame {n} left as rasterized: {e}"));
            return;
        }
        None => return,
    };
    // SAFETY: `img` holds w·h RGBA pixels; the state touched is restored.
    unsafe { draw(&img, x, y, buffer) };
    if let Some((dir, Err(e))) =
        cfg.dump.as_ref().map(|d| (d, img.write_png(&d.join(format!("rt-{n:04}.png")))))
    {
        log_once("dump", &format!("cannot write frame dumps to {}: {e}", dir.display()));
    }
    if cfg.stats {
        eprintln!("rt-gl: frame {n}: {:?}", counters);
    }
}

/// `counters.txt` in `dir`: the recorder's counters, the instances left
/// out of the last frame and each unsupported feature's count
/// (`unsupported.NAME=count`).
fn write_counters(
    dir: &std::path::Path,
    c: &crate::record::Counters,
    left_out: usize,
    unsupported: &[(&'static str, u64)],
) {
    let mut line = format!(
        "frames={} list_builds={} list_reuses={} list_inline={} draw_builds={} draw_reuses={} draw_refits={} draw_inline={} instances={} triangles={} ignored={} left_out={left_out}",
        c.frames,
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

/// Writes `img` at window position `(x, y)` with `glDrawPixels`.
///
/// # Safety
/// A current GL context (the program's, at its swap).
unsafe fn draw(img: &Image, x: i32, y: i32, _buffer: u32) {
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
