//! The recorder and the renderer without any GL: calls fed directly, as
//! the interposer feeds them.

use rt_core::glam::{Mat4, Vec3, Vec4};
use rt_gl::{
    gl,
    record::{Command, Recorder, arrays, frustum, ortho, rotate, translate},
    render::{FrameScene, Illumination, Options, RenderError},
};

fn draw(r: &mut Recorder, mode: u32, verts: &[Vec3]) {
    r.command(Command::Begin(mode));
    for v in verts {
        r.command(Command::Vertex(v.extend(1.0)));
    }
    r.command(Command::End);
}

/// A counter-clockwise ring of `n` points in the plane z = 0.
fn ring(n: usize) -> Vec<Vec3> {
    (0..n)
        .map(|i| {
            let a = core::f32::consts::TAU * i as f32 / n as f32;
            Vec3::new(a.cos(), a.sin(), 0.0)
        })
        .collect()
}

/// `glFrustum` and `glOrtho` take the corners of their view volume to the
/// corners of the NDC cube, as the GL specification defines them.
#[test]
fn projections_map_the_view_volume_to_the_ndc_cube() {
    let (l, r, b, t, n, f) = (-0.7, 0.4, -0.3, 0.6, 1.5, 30.0);
    let p = frustum(l, r, b, t, n, f).expect("valid");
    let near = p.project_point3(Vec3::new(l as f32, b as f32, -n as f32));
    assert!((near - Vec3::new(-1.0, -1.0, -1.0)).abs().max_element() < 1e-5, "{near}");
    // The far plane's top-right corner: (r, t)·f/n.
    let k = (f / n) as f32;
    let far = p.project_point3(Vec3::new(r as f32 * k, t as f32 * k, -f as f32));
    assert!((far - Vec3::ONE).abs().max_element() < 1e-4, "{far}");
    let o = ortho(l, r, b, t, n, f).expect("valid");
    let a = o.project_point3(Vec3::new(l as f32, b as f32, -n as f32));
    let c = o.project_point3(Vec3::new(r as f32, t as f32, -f as f32));
    assert!(
        (a + Vec3::ONE).abs().max_element() < 1e-5 && (c - Vec3::ONE).abs().max_element() < 1e-5
    );
    // GL_INVALID_VALUE cases are refused.
    assert!(frustum(l, r, b, t, 0.0, f).is_none() && frustum(l, l, b, t, n, f).is_none());
    assert!(ortho(l, r, b, t, n, n).is_none());
}

/// Every polygonal primitive type gives GL's number of triangles, all
/// facing the way the vertices turn (strips alternate their order to keep
/// it), and the vertices land in eye space through the modelview.
#[test]
fn primitives_assemble_into_consistently_oriented_triangles() {
    let strip: Vec<Vec3> = (0..7)
        .map(|i| Vec3::new((i / 2) as f32, if i % 2 == 0 { 0.0 } else { 1.0 }, 0.0))
        .collect();
    // A quad strip's vertices in pairs: bottom, top.
    let qstrip: Vec<Vec3> = (0..8)
        .map(|i| Vec3::new((i / 2) as f32, if i % 2 == 0 { 0.0 } else { 1.0 }, 0.0))
        .collect();
    let quads = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let cases: [(u32, Vec<Vec3>, usize); 6] = [
        (gl::TRIANGLES, ring(7), 2),
        (gl::TRIANGLE_STRIP, strip, 5),
        (gl::TRIANGLE_FAN, ring(6), 4),
        (gl::QUADS, quads.repeat(2), 4),
        (gl::QUAD_STRIP, qstrip, 6),
        (gl::POLYGON, ring(5), 3),
    ];
    for (mode, verts, expected) in cases {
        let mut r = Recorder::new();
        r.command(Command::MultMatrix(translate(Vec3::new(0.0, 0.0, -5.0))));
        draw(&mut r, mode, &verts);
        let g = r.end_frame().draws().immediate;
        assert_eq!(g.triangles.len(), expected, "mode {mode:#x}");
        for t in &g.triangles {
            let [a, b, c] = t.map(|i| g.positions[i as usize]);
            assert_eq!(a.z, -5.0);
            let n = (b - a).cross(c - a);
            // Strips with the second vertex on top run clockwise.
            let sign =
                if mode == gl::TRIANGLE_STRIP || mode == gl::QUAD_STRIP { -1.0 } else { 1.0 };
            assert!(sign * n.z > 0.0, "mode {mode:#x}: triangle {t:?} faces {n}");
        }
    }
}

/// Points become spheres and lines tubes whose radius is half the size
/// in pixels at the primitive's depth: twice as deep, twice as wide.
/// Lines are as wide across as GL draws them.
#[test]
fn points_and_lines_get_their_pixel_size_at_their_depth() {
    let mut r = Recorder::new();
    r.viewport = [0, 0, 200, 200];
    r.command(Command::MatrixMode(gl::PROJECTION));
    r.command(Command::MultMatrix(frustum(-1.0, 1.0, -1.0, 1.0, 1.0, 100.0).unwrap()));
    r.command(Command::MatrixMode(gl::MODELVIEW));
    r.command(Command::PointSize(10.0));
    draw(&mut r, gl::POINTS, &[Vec3::new(0.0, 0.0, -2.0), Vec3::new(0.0, 0.0, -4.0)]);
    r.command(Command::LineWidth(4.0));
    draw(&mut r, gl::LINE_LOOP, &ring(3).iter().map(|v| *v - 3.0 * Vec3::Z).collect::<Vec<_>>());
    let g = r.end_frame().draws().immediate;
    // At depth 2 the 200-pixel view is 4 units tall: 10 px = 0.2 units.
    assert!((g.spheres[0].1 - 0.1).abs() < 1e-6, "{:?}", g.spheres);
    assert!((g.spheres[1].1 - 0.2).abs() < 1e-6);
    // A loop of three vertices is three tubes: 4 px = 0.12 units at depth
    // 3, GL's width along the window's minor axis, so narrower across a
    // slanted line by max(|dx|, |dy|)/|d| (GL 2.1 §3.4.2).
    assert_eq!(g.tubes.len(), 3);
    let d = ring(3)[1] - ring(3)[0];
    let across = 0.06 * d.x.abs().max(d.y.abs()) / d.length();
    assert!((g.tubes[0].1 - across).abs() < 1e-6, "{:?}", g.tubes[0]);
}

fn gear_like_list(r: &mut Recorder, id: u32, color: Vec4) {
    r.new_list(id, gl::COMPILE);
    r.command(Command::Material(gl::FRONT, gl::AMBIENT_AND_DIFFUSE, color));
    r.command(Command::ShadeModel(gl::FLAT));
    r.command(Command::Normal(Vec3::Z));
    draw(r, gl::QUADS, &[Vec3::ZERO, Vec3::X, Vec3::ONE.with_z(0.0), Vec3::Y]);
    r.command(Command::Normal(Vec3::X));
    draw(r, gl::TRIANGLES, &[Vec3::ZERO, Vec3::Y, Vec3::Z]);
    r.end_list();
}

/// A display list is recorded once and instanced on every call, under
/// any transform, frame after frame, even when each call inherits the
/// state the previous one left (glxgears' pattern); its instances put the
/// same geometry where executing the list would. Redefining the list
/// records it again.
#[test]
fn lists_are_recorded_once_and_instanced() {
    let mut r = Recorder::new();
    r.command(Command::Enable(gl::LIGHTING));
    gear_like_list(&mut r, 1, Vec4::new(0.8, 0.1, 0.0, 1.0));
    gear_like_list(&mut r, 2, Vec4::new(0.0, 0.8, 0.2, 1.0));
    // GL_COMPILE does not draw.
    assert!(r.frame().is_empty());
    let transforms = [
        translate(Vec3::new(1.0, 2.0, -9.0)) * rotate(30.0, Vec3::new(1.0, 1.0, 0.0)),
        translate(Vec3::new(-3.0, 0.5, -7.0)) * Mat4::from_scale(Vec3::splat(2.0)),
    ];
    for frame in 0..3 {
        for (k, m) in transforms.iter().enumerate() {
            r.command(Command::PushMatrix);
            r.command(Command::MultMatrix(*m));
            r.command(Command::CallList(1 + k as u32));
            r.command(Command::PopMatrix);
        }
        let f = r.end_frame().draws();
        assert_eq!(f.instances.len(), 2, "frame {frame}");
        assert!(f.immediate.is_empty());
        if frame == 0 {
            // The same calls executed in immediate mode.
            let mut direct = Recorder::new();
            for (k, m) in transforms.iter().enumerate() {
                direct.command(Command::LoadMatrix(*m));
                let c = if k == 0 {
                    Vec4::new(0.8, 0.1, 0.0, 1.0)
                } else {
                    Vec4::new(0.0, 0.8, 0.2, 1.0)
                };
                direct.command(Command::Material(gl::FRONT, gl::AMBIENT_AND_DIFFUSE, c));
                direct.command(Command::Normal(Vec3::Z));
                draw(
                    &mut direct,
                    gl::QUADS,
                    &[Vec3::ZERO, Vec3::X, Vec3::ONE.with_z(0.0), Vec3::Y],
                );
                direct.command(Command::Normal(Vec3::X));
                draw(&mut direct, gl::TRIANGLES, &[Vec3::ZERO, Vec3::Y, Vec3::Z]);
            }
            let want = direct.end_frame().draws().immediate;
            let got = f.flatten().expect("recorded geometry is well formed");
            assert_eq!(got.triangles, want.triangles);
            for (a, b) in got.positions.iter().zip(&want.positions) {
                assert!((*a - *b).length() < 1e-5, "{a} vs {b}");
            }
            for (a, b) in got.normals.iter().zip(&want.normals) {
                assert!((a.normalize() - b.normalize()).length() < 1e-5, "{a} vs {b}");
            }
            assert_eq!(got.shadings[0].material.diffuse, Vec4::new(0.8, 0.1, 0.0, 1.0));
        }
    }
    assert_eq!((r.counters.list_builds, r.counters.list_reuses), (2, 4));
    gear_like_list(&mut r, 1, Vec4::ONE);
    r.command(Command::CallList(1));
    assert_eq!(r.counters.list_builds, 3);
    // Lit, without colour material, the current colour is never seen:
    // a call with another one reuses the recording.
    r.command(Command::Color(Vec4::new(0.3, 0.3, 0.3, 1.0)));
    r.command(Command::CallList(1));
    assert_eq!(r.counters.list_builds, 3);
}

/// A list that sets no shading state of its own, called many times a
/// frame after a different colour (colour material) or material each
/// time, is recorded once; each instance is painted with its call's
/// colour and material, and the frame traces exactly as the same calls
/// executed in immediate mode do. Vertices after the list's own
/// `glColor` keep that colour.
#[test]
fn a_list_called_with_many_colours_is_recorded_once() {
    let tri = [Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
    let own = Vec4::new(0.1, 0.9, 0.2, 1.0);
    // The list's body: a triangle in the caller's colour, then one in
    // its own, both facing the eye.
    let body = |r: &mut Recorder, dx: f32| {
        r.command(Command::Normal(Vec3::Z));
        draw(r, gl::TRIANGLES, &tri.map(|v| v * 0.2 + Vec3::X * dx));
        r.command(Command::Color(own));
        draw(r, gl::TRIANGLES, &tri.map(|v| v * 0.1 + Vec3::new(dx, 0.4, 0.0)));
    };
    // Calls: (colour-material colour) or (material diffuse), each placed
    // apart along x.
    let calls: Vec<(bool, Vec4)> = (0..24)
        .map(|i| {
            let t = i as f32 / 24.0;
            (i % 2 == 0, Vec4::new(t, 1.0 - t, 0.5 * t, 1.0))
        })
        .collect();
    let run = |r: &mut Recorder, listed: bool| {
        r.command(Command::MatrixMode(gl::PROJECTION));
        r.command(Command::LoadMatrix(ortho(-1.0, 1.0, -1.0, 1.0, -1.0, 1.0).unwrap()));
        r.command(Command::MatrixMode(gl::MODELVIEW));
        r.command(Command::Enable(gl::LIGHTING));
        r.command(Command::Enable(gl::LIGHT0));
        for (k, (color_material, c)) in calls.iter().enumerate() {
            let dx = -0.9 + 1.8 * k as f32 / calls.len() as f32;
            if *color_material {
                r.command(Command::Enable(gl::COLOR_MATERIAL));
                r.command(Command::Color(*c));
            } else {
                r.command(Command::Disable(gl::COLOR_MATERIAL));
                r.command(Command::Material(gl::FRONT, gl::DIFFUSE, *c));
                r.command(Command::Color(Vec4::new(0.5, 0.5, 0.5, 1.0)));
            }
            if listed {
                r.command(Command::LoadMatrix(translate(Vec3::X * dx)));
                r.command(Command::CallList(7));
            } else {
                r.command(Command::LoadIdentity);
                body(r, dx);
            }
        }
    };
    let mut listed = Recorder::new();
    listed.new_list(7, gl::COMPILE);
    body(&mut listed, 0.0);
    listed.end_list();
    run(&mut listed, true);
    assert_eq!(
        (listed.counters.list_builds, listed.counters.list_reuses),
        (1, calls.len() as u64 - 1)
    );
    let mut direct = Recorder::new();
    run(&mut direct, false);
    let image = |r: &mut Recorder| {
        let (lighting, projection) = (r.lighting.clone(), r.projection());
        let scene = FrameScene::build(r.end_frame().draws()).expect("finite");
        scene.render(&lighting, projection, 96, 32, Vec4::ZERO, &Options::default()).unwrap()
    };
    let (a, b) = (image(&mut listed), image(&mut direct));
    let worst = a.rgba.iter().zip(&b.rgba).map(|(x, y)| x.abs_diff(*y)).max();
    assert!(worst <= Some(1), "painted instances differ from immediate mode by {worst:?}/255");
    // Both colours of every call are there.
    assert!(a.rgba.chunks_exact(4).any(|p| p[1] > 200 && p[0] < 60), "the list's own colour");
}

/// A draw from buffer objects is recorded once and reused while the
/// buffers keep their contents; `glBufferSubData` records it again.
#[test]
fn buffer_draws_are_cached_until_the_buffer_changes() {
    let mut r = Recorder::new();
    let verts: Vec<f32> = [0.0f32, 0.0, -3.0, 1.0, 0.0, -3.0, 0.0, 1.0, -3.0].to_vec();
    let bytes: Vec<u8> = verts.iter().flat_map(|v| v.to_ne_bytes()).collect();
    r.bind_buffer(arrays::ARRAY_BUFFER, 7);
    r.buffer_data(arrays::ARRAY_BUFFER, bytes.len(), Some(&bytes));
    r.pointer(arrays::VERTEX_ARRAY, 3, gl::FLOAT, 0, 0);
    r.client_state(arrays::VERTEX_ARRAY, true);
    // SAFETY: the vertex array lives in buffer 7, which holds 3 vertices.
    unsafe {
        r.draw_arrays(gl::TRIANGLES, 0, 3);
        r.draw_arrays(gl::TRIANGLES, 0, 3);
    }
    assert_eq!((r.counters.draw_builds, r.counters.draw_reuses), (1, 1));
    let f = r.end_frame().draws();
    assert_eq!(f.instances.len(), 2);
    assert_eq!(
        f.flatten().expect("recorded geometry is well formed").positions[2],
        Vec3::new(0.0, 1.0, -3.0)
    );
    r.buffer_sub_data(arrays::ARRAY_BUFFER, 28, &2.0f32.to_ne_bytes());
    // SAFETY: as above.
    unsafe { r.draw_arrays(gl::TRIANGLES, 0, 3) };
    assert_eq!(r.counters.draw_builds, 2);
    assert_eq!(
        r.end_frame().flatten().expect("recorded geometry is well formed").positions[2],
        Vec3::new(0.0, 2.0, -3.0)
    );
    // Indices past the buffer, a negative count and an absurd one are
    // ignored, not read.
    let before = r.counters.ignored;
    // SAFETY: only buffer data is read, bounds-checked.
    unsafe {
        r.draw_arrays(gl::TRIANGLES, 2, 3);
        r.draw_arrays(gl::TRIANGLES, 0, -1);
        r.draw_arrays(gl::TRIANGLES, 0, i32::MAX);
    }
    assert_eq!(r.counters.ignored, before + 3);
}

/// A lit triangle facing a white directional light: the pixel is GL's
/// lighting equation (ambient·global + diffuse·(n·l) + emission), an
/// unlit one its colour, the background the clear colour.
#[test]
fn pixels_follow_the_fixed_function_lighting_equation() {
    let mut r = Recorder::new();
    r.viewport = [0, 0, 32, 32];
    r.command(Command::MatrixMode(gl::PROJECTION));
    r.command(Command::MultMatrix(frustum(-1.0, 1.0, -1.0, 1.0, 1.0, 10.0).unwrap()));
    r.command(Command::MatrixMode(gl::MODELVIEW));
    r.command(Command::Enable(gl::LIGHTING));
    r.command(Command::Enable(gl::LIGHT0));
    // Light along (0, 0.6, 0.8): n·l = 0.8 for the triangle facing +z.
    r.command(Command::Light(gl::LIGHT0, gl::POSITION, Vec4::new(0.0, 3.0, 4.0, 0.0)));
    let mat = Vec4::new(0.5, 0.25, 1.0, 1.0);
    r.command(Command::Material(gl::FRONT, gl::AMBIENT_AND_DIFFUSE, mat));
    r.command(Command::Material(gl::FRONT, gl::EMISSION, Vec4::new(0.1, 0.0, 0.0, 1.0)));
    r.command(Command::Normal(Vec3::Z));
    draw(
        &mut r,
        gl::TRIANGLES,
        &[Vec3::new(-4.0, -4.0, -3.0), Vec3::new(4.0, -4.0, -3.0), Vec3::new(0.0, 4.0, -3.0)],
    );
    let frame = r.end_frame();
    let scene = FrameScene::build(frame.draws()).expect("finite");
    let img = scene
        .render(
            &r.lighting,
            r.projection(),
            32,
            32,
            Vec4::new(0.0, 0.0, 1.0, 1.0),
            &Options::default(),
        )
        .expect("valid view");
    let want = |k: usize| 0.1 * f32::from(k == 0) + mat[k] * 0.2 + mat[k] * 0.8;
    let px = img.get(16, 16).expect("inside");
    for (k, &p) in px.iter().enumerate().take(3) {
        let w = (want(k).min(1.0) * 255.0).round();
        assert!((f32::from(p) - w).abs() <= 1.0, "channel {k}: {p} vs {w}");
    }
    // The top corners miss the triangle: the clear colour.
    assert_eq!(img.get(0, 31), Some([0, 0, 255, 255]));
    // Unlit: the vertex colour itself.
    r.command(Command::Disable(gl::LIGHTING));
    r.command(Command::Color(Vec4::new(0.2, 0.4, 0.6, 1.0)));
    draw(
        &mut r,
        gl::TRIANGLES,
        &[Vec3::new(-4.0, -4.0, -3.0), Vec3::new(4.0, -4.0, -3.0), Vec3::new(0.0, 4.0, -3.0)],
    );
    let scene = FrameScene::build(r.end_frame().draws()).unwrap();
    let img =
        scene.render(&r.lighting, r.projection(), 32, 32, Vec4::ZERO, &Options::default()).unwrap();
    assert_eq!(img.get(16, 16), Some([51, 102, 153, 255]));
}

/// In `rt` mode a blocker between the light and a floor casts a shadow
/// the `gl` mode does not have; the same image at 1 and 3 threads.
#[test]
fn rt_mode_adds_shadows_deterministically() {
    let mut r = Recorder::new();
    r.viewport = [0, 0, 48, 48];
    r.command(Command::MatrixMode(gl::PROJECTION));
    r.command(Command::MultMatrix(ortho(-2.0, 2.0, -2.0, 2.0, -10.0, 10.0).unwrap()));
    r.command(Command::MatrixMode(gl::MODELVIEW));
    r.command(Command::Enable(gl::LIGHTING));
    r.command(Command::Enable(gl::LIGHT0));
    r.command(Command::Light(gl::LIGHT0, gl::POSITION, Vec4::new(0.0, 0.0, 1.0, 0.0)));
    r.command(Command::Normal(Vec3::Z));
    // Floor at z = −1 and a small card at z = 1 above its centre.
    let square = |s: f32, z: f32| {
        [Vec3::new(-s, -s, z), Vec3::new(s, -s, z), Vec3::new(s, s, z), Vec3::new(-s, s, z)]
    };
    draw(&mut r, gl::QUADS, &square(2.0, -1.0));
    draw(&mut r, gl::QUADS, &square(0.3, 1.0));
    let scene = FrameScene::build(r.end_frame().draws()).unwrap();
    let render = |mode, threads: usize| {
        let opts = Options { mode, ao_samples: 4, ..Options::default() };
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            scene.render(&r.lighting, r.projection(), 48, 48, Vec4::ZERO, &opts).unwrap()
        })
    };
    let gl_img = render(Illumination::Gl, 1);
    let rt1 = render(Illumination::Rt, 1);
    assert_eq!(rt1, render(Illumination::Rt, 3));
    // Light straight down the view: the card's shadow hides behind the
    // card, so both modes show the same card.
    assert_eq!(rt1.get(24, 24), gl_img.get(24, 24));
    // Tilt the light: the shadow moves out from under the card.
    let mut tilted = r.lighting.clone();
    tilted.lights[0].position = Vec4::new(1.0, 0.0, 1.0, 0.0);
    let opts = Options { mode: Illumination::Rt, ao_samples: 0, ..Options::default() };
    let shadowed = scene.render(&tilted, r.projection(), 48, 48, Vec4::ZERO, &opts).unwrap();
    let plain =
        scene.render(&tilted, r.projection(), 48, 48, Vec4::ZERO, &Options::default()).unwrap();
    // Light toward (1, 0, 1): the card 2 units above the floor shades it
    // over x ∈ [−2.3, −1.7]; pixel 1 is at x ≈ −1.88, pixel 12 at −1.
    let (s, p) = (shadowed.get(1, 24).unwrap(), plain.get(1, 24).unwrap());
    assert!(s[0] < p[0], "shadowed {s:?} vs lit {p:?}");
    assert_eq!(shadowed.get(12, 24), plain.get(12, 24));
}

/// Bad views are errors, not panics; non-finite vertices are dropped.
#[test]
fn bad_views_and_vertices_are_refused() {
    let mut r = Recorder::new();
    r.command(Command::Begin(gl::TRIANGLES));
    r.command(Command::Vertex(Vec4::new(f32::NAN, 0.0, 0.0, 1.0)));
    r.command(Command::Vertex(Vec4::new(f32::INFINITY, 0.0, 0.0, 1.0)));
    r.command(Command::Vertex(Vec4::new(0.0, 0.0, 0.0, 0.0)));
    r.command(Command::End);
    let f = r.end_frame();
    assert!(f.is_empty());
    let scene = FrameScene::build(f.draws()).unwrap();
    let l = r.lighting.clone();
    let o = Options::default();
    assert_eq!(scene.render(&l, Mat4::ZERO, 8, 8, Vec4::ZERO, &o), Err(RenderError::BadProjection));
    assert_eq!(
        scene.render(&l, Mat4::IDENTITY, 0, 8, Vec4::ZERO, &o),
        Err(RenderError::BadViewport)
    );
    // Stack underflow, unknown modes and stray ends are counted, not fatal.
    r.command(Command::PopMatrix);
    r.command(Command::Begin(0x7777));
    r.command(Command::End);
    r.delete_lists(1, -1);
    assert_eq!(r.counters.ignored, 4);
}

/// Settings from the environment: good values are taken, unreadable ones
/// fall back to the defaults (reported once on stderr, not fatal).
#[test]
fn settings_fall_back_on_unreadable_values() {
    let cfg = |pairs: &'static [(&'static str, &'static str)]| {
        rt_gl::Config::from_vars(move |k| {
            pairs.iter().find(|(n, _)| *n == k).map(|(_, v)| (*v).to_owned())
        })
    };
    let good = cfg(&[
        ("RT_GL_MODE", "rt"),
        ("RT_GL_AO", "32"),
        ("RT_GL_SHADOWS", "0"),
        ("RT_GL_THREADS", "2"),
    ]);
    assert_eq!(good.options.mode, Illumination::Rt);
    assert_eq!((good.options.ao_samples, good.options.shadows), (32, false));
    assert_eq!(good.pool.as_ref().map(rayon::ThreadPool::current_num_threads), Some(2));
    let bad = cfg(&[
        ("RT_GL_MODE", "fancy"),
        ("RT_GL_AO", "-3"),
        ("RT_GL_SHADOWS", "maybe"),
        ("RT_GL_THREADS", "0"),
    ]);
    assert_eq!(bad.options, Options::default());
    assert!(bad.pool.is_none() && bad.dump.is_none() && !bad.stats);
}

/// In `rt` mode a specular surface mirrors what it faces, weighted by its
/// specular colour and `mirror`: a floor facing the empty sky gains
/// half the (blue) background in blue only; `gl` mode has no reflection.
#[test]
fn rt_mode_mirrors_specular_surfaces() {
    let mut r = Recorder::new();
    r.command(Command::MatrixMode(gl::PROJECTION));
    r.command(Command::MultMatrix(ortho(-2.0, 2.0, -2.0, 2.0, -10.0, 10.0).unwrap()));
    r.command(Command::MatrixMode(gl::MODELVIEW));
    r.command(Command::Enable(gl::LIGHTING));
    r.command(Command::Enable(gl::LIGHT0));
    r.command(Command::Light(gl::LIGHT0, gl::SPECULAR, Vec4::new(0.0, 0.0, 0.0, 1.0)));
    r.command(Command::Material(gl::FRONT, gl::AMBIENT_AND_DIFFUSE, Vec4::new(0.2, 0.2, 0.2, 1.0)));
    r.command(Command::Material(gl::FRONT, gl::SPECULAR, Vec4::ONE));
    r.command(Command::Normal(Vec3::Z));
    let floor = [
        Vec3::new(-3.0, -3.0, -1.0),
        Vec3::new(3.0, -3.0, -1.0),
        Vec3::new(3.0, 3.0, -1.0),
        Vec3::new(-3.0, 3.0, -1.0),
    ];
    draw(&mut r, gl::QUADS, &floor);
    let scene = FrameScene::build(r.end_frame().draws()).unwrap();
    let sky = Vec4::new(0.0, 0.0, 1.0, 1.0);
    let render = |mode| {
        let opts = Options { mode, ao_samples: 0, shadows: false, ..Options::default() };
        scene.render(&r.lighting, r.projection(), 16, 16, sky, &opts).unwrap()
    };
    // 0.2·0.2 ambient + 0.2·1 diffuse = 0.24 → 61; plus 0.5 · 1 · sky.
    assert_eq!(render(Illumination::Gl).get(8, 8), Some([61, 61, 61, 255]));
    assert_eq!(render(Illumination::Rt).get(8, 8), Some([61, 61, 189, 255]));
}

/// Lists that call each other twice over ask for 2⁶⁴ commands within
/// GL's nesting limit: the call stops at the budget instead of hanging,
/// and the recorder keeps working.
#[test]
fn mutually_recursive_lists_stop_at_the_budget() {
    let mut r = Recorder::new();
    for (id, other) in [(1, 2), (2, 1)] {
        r.new_list(id, gl::COMPILE);
        draw(&mut r, gl::TRIANGLES, &[Vec3::ZERO, Vec3::X, Vec3::Y]);
        r.command(Command::CallList(other));
        r.command(Command::CallList(other));
        r.end_list();
    }
    r.set_list_budget(10_000);
    r.command(Command::CallList(1));
    assert!(r.counters.ignored > 0);
    let tris = r.end_frame().flatten().expect("recorded geometry is well formed").triangles.len();
    assert!(tris > 100 && tris < 10_000, "{tris} triangles");
    // The next call gets a fresh budget.
    r.command(Command::CallList(2));
    assert!(!r.end_frame().is_empty());
}

/// `glTexImage2D` reads client images as the unpack state lays them out
/// (GL 2.1 §3.6.1): rows padded to `GL_UNPACK_ALIGNMENT`, a longer row
/// length, skipped rows and pixels; luminance is spread over RGB and
/// alpha is 1 where the format has none.
#[test]
fn texture_images_are_unpacked_as_gl_reads_them() {
    use rt_gl::record::texture::Texture;
    let mut r = Recorder::new();
    r.command(Command::BindTexture(gl::TEXTURE_2D, 5));
    // 3 × 2 RGB bytes at the default alignment 4: rows of 9 bytes padded
    // to 12; the pad bytes (99) must never be read.
    let rgb: Vec<u8> =
        [[1, 2, 3, 4, 5, 6, 7, 8, 9, 99, 99, 99], [10, 11, 12, 13, 14, 15, 16, 17, 18, 99, 99, 99]]
            .concat();
    r.tex_image_2d(gl::TEXTURE_2D, 0, gl::RGB, [3, 2], gl::RGB, gl::UNSIGNED_BYTE, Some(&rgb));
    let t: &Texture = &r.textures()[&5];
    assert_eq!(t.texels[2], [7, 8, 9, 255]);
    assert_eq!(t.texels[3], [10, 11, 12, 255]);
    // Row length 4 (pixels), skip one row and one pixel, alignment 1:
    // a 2 × 1 luminance image out of a 4 × 2 buffer.
    r.pixel_store(0x0CF5, 1);
    r.pixel_store(0x0CF2, 4);
    r.pixel_store(0x0CF3, 1);
    r.pixel_store(0x0CF4, 1);
    let lum = [0u8, 1, 2, 3, 40, 50, 60, 70];
    r.tex_image_2d(gl::TEXTURE_2D, 0, 0x1909, [2, 1], 0x1909, gl::UNSIGNED_BYTE, Some(&lum));
    let t = &r.textures()[&5];
    assert_eq!(t.texels, vec![[50, 50, 50, 255], [60, 60, 60, 255]]);
    // An image shorter than its layout is not read: the texture is not
    // known, and the draws textured with it are left to GL.
    r.tex_image_2d(gl::TEXTURE_2D, 0, gl::RGB, [3, 2], gl::RGB, gl::UNSIGNED_BYTE, Some(&rgb[..5]));
    assert!(!r.textures()[&5].readable);
    assert_eq!(r.unsupported.get("glTexImage2D.unread_format"), Some(&1));
}
