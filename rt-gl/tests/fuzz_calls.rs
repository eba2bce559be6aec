//! Arbitrary call sequences — as a broken or hostile program might send
//! them — never panic the recorder or the renderer: whatever was
//! recorded is built and traced, or refused with an `Err`.

use proptest::prelude::*;
use rt_core::glam::{Mat4, Vec3, Vec4};
use rt_gl::{
    composite::{Content, Layer, composite},
    gl,
    record::{Command, GeometryError, Recorder, arrays},
    render::{FrameScene, Illumination, Options, RenderError},
};

/// Floats including the awkward ones.
fn float() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => -4.0f32..4.0,
        1 => Just(0.0f32),
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => Just(-1e30f32),
        1 => Just(1e30f32),
    ]
}

fn vec4() -> impl Strategy<Value = Vec4> {
    (float(), float(), float(), float()).prop_map(|(x, y, z, w)| Vec4::new(x, y, z, w))
}

fn mat4() -> impl Strategy<Value = Mat4> {
    prop::array::uniform16(float()).prop_map(|m| Mat4::from_cols_array(&m))
}

/// An enum value GL knows, or any other.
fn glenum() -> impl Strategy<Value = u32> {
    prop_oneof![
        0u32..12,
        Just(gl::LIGHTING),
        Just(gl::LIGHT0),
        Just(gl::LIGHT0 + 7),
        Just(gl::COLOR_MATERIAL),
        Just(gl::MODELVIEW),
        Just(gl::PROJECTION),
        Just(gl::AMBIENT_AND_DIFFUSE),
        Just(gl::POSITION),
        Just(gl::SPOT_CUTOFF),
        Just(gl::FLAT),
        Just(gl::TEXTURE_2D),
        Just(gl::FOG),
        Just(gl::BLEND),
        Just(gl::ALPHA_TEST),
        Just(gl::CULL_FACE),
        Just(gl::DEPTH_TEST),
        Just(gl::SCISSOR_TEST),
        Just(0x0C60u32),
        Just(gl::SPHERE_MAP),
        Just(gl::OBJECT_PLANE),
        Just(gl::LINE),
        any::<u32>(),
    ]
}

fn command() -> impl Strategy<Value = Command> {
    prop_oneof![
        glenum().prop_map(Command::Begin),
        Just(Command::End),
        vec4().prop_map(|v| Command::Vertex(v.with_w(1.0))),
        vec4().prop_map(Command::Vertex),
        vec4().prop_map(|v| Command::Normal(v.truncate())),
        vec4().prop_map(Command::Color),
        glenum().prop_map(Command::MatrixMode),
        Just(Command::LoadIdentity),
        mat4().prop_map(Command::LoadMatrix),
        mat4().prop_map(Command::MultMatrix),
        Just(Command::PushMatrix),
        Just(Command::PopMatrix),
        glenum().prop_map(Command::Enable),
        glenum().prop_map(Command::Disable),
        (glenum(), glenum(), vec4()).prop_map(|(l, p, v)| Command::Light(l, p, v)),
        (glenum(), vec4()).prop_map(|(p, v)| Command::LightModel(p, v)),
        (glenum(), glenum(), vec4()).prop_map(|(f, p, v)| Command::Material(f, p, v)),
        glenum().prop_map(Command::ShadeModel),
        float().prop_map(Command::PointSize),
        float().prop_map(Command::LineWidth),
        (0u32..4).prop_map(Command::CallList),
        (glenum(), glenum()).prop_map(|(f, m)| Command::PolygonMode(f, m)),
        (glenum(), vec4()).prop_map(|(p, v)| Command::Fog(p, v)),
        (glenum(), glenum()).prop_map(|(s, d)| Command::BlendFunc(s, d)),
        glenum().prop_map(Command::CullFace),
        any::<bool>().prop_map(Command::ColorMask),
        vec4().prop_map(Command::TexCoord),
        (glenum(), 0u32..3).prop_map(|(t, n)| Command::BindTexture(t, n)),
        (glenum(), vec4()).prop_map(|(p, v)| Command::TexEnv(p, v)),
        (glenum(), float()).prop_map(|(f, r)| Command::AlphaFunc(f, r)),
        glenum().prop_map(Command::DepthFunc),
        (0x2000u32..0x2005, glenum(), vec4()).prop_map(|(c, p, v)| Command::TexGen(c, p, v)),
        vec4().prop_map(Command::RasterPos),
        vec4().prop_map(|v| Command::WindowPos(v.truncate())),
        (-4i32..70000, -4i32..70000, vec4()).prop_map(|(w, h, v)| Command::Bitmap {
            size: [w, h],
            origin: v.truncate().truncate(),
            advance: v.truncate().truncate() * 3.0,
        }),
        (-4i32..70000, -4i32..70000).prop_map(|(w, h)| Command::DrawPixels([w, h])),
    ]
}

/// One step of a program: a command, list management or an array draw.
#[derive(Clone, Debug)]
enum Step {
    Call(Command),
    NewList(u32, u32),
    EndList,
    DeleteLists(u32, i32),
    Buffer(Vec<f32>),
    Draw(u32, i32, i32),
    /// `glTexImage2D` of the bound texture: size, format, type, bytes.
    TexImage(i32, i32, u32, u32, Vec<u8>),
    Clear(u32),
    EndFrame,
}

fn step() -> impl Strategy<Value = Step> {
    prop_oneof![
        12 => command().prop_map(Step::Call),
        1 => (0u32..4, prop_oneof![Just(gl::COMPILE), Just(gl::COMPILE_AND_EXECUTE), any::<u32>()])
            .prop_map(|(i, m)| Step::NewList(i, m)),
        1 => Just(Step::EndList),
        1 => (0u32..4, -2i32..4).prop_map(|(f, r)| Step::DeleteLists(f, r)),
        1 => prop::collection::vec(float(), 0..30).prop_map(Step::Buffer),
        2 => (glenum(), -2i32..12, -2i32..40).prop_map(|(m, f, c)| Step::Draw(m, f, c)),
        1 => (-2i32..20, -2i32..20, prop_oneof![Just(gl::RGB), Just(gl::RGBA), Just(0x1909u32), any::<u32>()],
              prop_oneof![Just(gl::UNSIGNED_BYTE), Just(gl::FLOAT), any::<u32>()],
              prop::collection::vec(any::<u8>(), 0..2000))
            .prop_map(|(w, h, f, t, d)| Step::TexImage(w, h, f, t, d)),
        1 => prop_oneof![Just(0x4100u32), Just(0x100u32), Just(0x4000u32), any::<u32>()].prop_map(Step::Clear),
        1 => Just(Step::EndFrame),
    ]
}

fn trace(r: &Recorder, mode: Illumination) {
    // Each pass under its own view, composited as the interposer does.
    let mut layers = Vec::new();
    for p in &r.frame().passes {
        let Ok(scene) = FrameScene::build(p.draws.clone()) else { continue };
        let v = p.view.viewport.map(|x| x.clamp(0, 16));
        let (w, h) = (v[2].max(1) as u32, v[3].max(1) as u32);
        let opts = Options { mode, ao_samples: 2, ..Options::default() };
        let content = if p.view.is_kept(v) {
            scene.coverage(p.view.projection, w, h).map(|depth| Content::Raster { depth })
        } else {
            scene
                .render_sample(&r.lighting, p.view.projection, w, h, p.background, &opts, 1)
                .map(|(image, depth)| Content::Traced { image, depth })
        };
        let content = content.unwrap_or(Content::Untraced);
        let viewport = [v[0], v[1], w as i32, h as i32];
        layers.push(Layer {
            viewport,
            depth_test: p.view.depth_test,
            depth_cleared: p.depth_cleared,
            background: p.background,
            content,
        });
    }
    let _ = composite([0, 0, 20, 20], &layers, None);
    let frame = r.frame().clone().draws();
    // What the recorder makes is always well formed.
    assert_eq!(frame.immediate.check(), Ok(()));
    for inst in &frame.instances {
        assert_eq!(inst.recorded.geometry().check(), Ok(()));
    }
    // Building may refuse non-finite geometry; rendering may refuse the
    // view: both are errors, not panics.
    match FrameScene::build(frame) {
        Ok(scene) => {
            let opts = Options { mode, ao_samples: 2, ..Options::default() };
            let _ = scene.render(&r.lighting, r.projection(), 12, 9, Vec4::ZERO, &opts);
        }
        Err(e) => {
            assert!(
                matches!(
                    e,
                    RenderError::Geometry(GeometryError::Build(_)) | RenderError::Instance(_)
                ),
                "{e}"
            );
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, rng_seed: proptest::test_runner::RngSeed::Fixed(17), failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_call_sequences_never_panic(steps in prop::collection::vec(step(), 0..80), rt in any::<bool>()) {
        let mut r = Recorder::new();
        // Lists that call each other twice over are exponential: a small
        // budget keeps each case short (the default bounds them too).
        r.set_list_budget(20_000);
        r.viewport = [0, 0, 12, 9];
        let mode = if rt { Illumination::Rt } else { Illumination::Gl };
        for s in steps {
            match s {
                Step::Call(c) => r.command(c),
                Step::NewList(id, m) => r.new_list(id, m),
                Step::EndList => r.end_list(),
                Step::DeleteLists(f, n) => r.delete_lists(f, n),
                Step::Buffer(v) => {
                    let bytes: Vec<u8> = v.iter().flat_map(|x| x.to_ne_bytes()).collect();
                    r.bind_buffer(arrays::ARRAY_BUFFER, 1);
                    r.buffer_data(arrays::ARRAY_BUFFER, bytes.len(), Some(&bytes));
                    r.pointer(arrays::VERTEX_ARRAY, 3, gl::FLOAT, 0, 0);
                    r.client_state(arrays::VERTEX_ARRAY, true);
                }
                // SAFETY: the only array enabled lives in buffer 1, read
                // with bounds checks.
                Step::Draw(m, f, c) => unsafe { r.draw_arrays(m, f, c) },
                Step::TexImage(w, h, f, t, d) => {
                    let data = (!d.is_empty()).then_some(d.as_slice());
                    r.tex_image_2d(gl::TEXTURE_2D, 0, f, [w, h], f, t, data);
                    if let Some(d) = data {
                        r.tex_sub_image_2d(gl::TEXTURE_2D, 0, [1, 1], [w / 2, h / 2], f, t, Some(d));
                    }
                }
                Step::Clear(mask) => r.clear(mask),
                Step::EndFrame => {
                    trace(&r, mode);
                    let _ = r.end_frame();
                }
            }
        }
        trace(&r, mode);
        // The state stays usable: once any open list and primitive are
        // closed, a plain triangle records.
        r.end_list();
        r.command(Command::End);
        let _ = r.end_frame();
        // What a program would set back: colour written, polygons filled.
        r.command(Command::ColorMask(true));
        r.command(Command::PolygonMode(gl::FRONT_AND_BACK, gl::FILL));
        r.command(Command::MatrixMode(gl::MODELVIEW));
        r.command(Command::LoadIdentity);
        r.command(Command::Begin(gl::TRIANGLES));
        for v in [Vec3::ZERO, Vec3::X, Vec3::Y] {
            r.command(Command::Vertex(v.extend(1.0)));
        }
        r.command(Command::End);
        prop_assert_eq!(r.frame().clone().draws().immediate.triangles.len(), 1);
    }
}
