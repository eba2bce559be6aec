//! Hand-made data that breaks the rules the recorder keeps — a
//! [`Geometry`] with an index out of range or an array of the wrong
//! length, options out of range, an image whose bytes do not match its
//! size — is refused with a typed `Err` by every public entry point that
//! takes it, never a panic; the well-formed geometry it is made from
//! still renders.

extern crate alloc;

use alloc::sync::Arc;
use std::time::Instant;

use rt_accel::BuildError;
use rt_core::glam::{Mat4, Vec2, Vec3, Vec4};
use rt_gl::{
    record::{
        Command, FrameDraws, Geometry, GeometryError, Instance, Lighting, MaterialState, Primitive,
        Recorded, Recorder, Shading, frustum, translate,
    },
    render::{FrameScene, Illumination, Image, MAX_AO_SAMPLES, MAX_BOUNCES, Options, RenderError},
};

const SIZE: u32 = 32;
const RED: Vec4 = Vec4::new(1.0, 0.0, 0.0, 1.0);
const GREEN: Vec4 = Vec4::new(0.0, 1.0, 0.0, 1.0);
const BLUE: Vec4 = Vec4::new(0.0, 0.0, 1.0, 1.0);

fn projection() -> Mat4 {
    frustum(-1.0, 1.0, -1.0, 1.0, 1.0, 10.0).expect("valid frustum")
}

/// Unlit: the image shows the vertex colours as they are.
fn unlit() -> Shading {
    Shading::default()
}

/// A red triangle at z = −3, a green sphere and a blue tube in front of
/// it: every field used, every rule kept.
fn good() -> Geometry {
    Geometry {
        positions: vec![
            Vec3::new(-1.0, -1.0, -3.0),
            Vec3::new(1.0, -1.0, -3.0),
            Vec3::new(0.0, 1.0, -3.0),
            Vec3::new(-0.6, 0.6, -2.5),
            Vec3::new(0.4, -0.6, -2.5),
            Vec3::new(0.8, -0.6, -2.5),
        ],
        normals: vec![Vec3::Z; 6],
        colors: vec![RED, RED, RED, GREEN, BLUE, BLUE],
        texcoords: vec![Vec2::ZERO; 6],
        triangles: vec![[0, 1, 2]],
        triangle_info: vec![(0, 2)],
        spheres: vec![(3, 0.2, 0)],
        tubes: vec![([4, 5], 0.15, 0)],
        shadings: vec![unlit()],
    }
}

/// The pixel whose centre ray passes nearest the eye-space point `p`.
fn pixel_of(p: Vec3) -> (u32, u32) {
    let ndc = projection().project_point3(p);
    let px = |c: f32| ((c + 1.0) * 0.5 * SIZE as f32) as u32;
    (px(ndc.x), px(ndc.y))
}

fn render(frame: FrameDraws, opts: &Options) -> Result<Image, RenderError> {
    let scene = FrameScene::build(frame)?;
    scene.render(&Lighting::default(), projection(), SIZE, SIZE, Vec4::ZERO, opts)
}

fn immediate(g: Geometry) -> FrameDraws {
    FrameDraws { immediate: g, ..FrameDraws::default() }
}

/// `g` as one recording, placed twice (once moved aside).
fn instanced(g: Geometry) -> FrameDraws {
    let rec = Arc::new(Recorded::new(g));
    FrameDraws {
        immediate: Geometry::default(),
        instances: vec![
            Instance { recorded: Arc::clone(&rec), transform: Mat4::IDENTITY, paint: None },
            Instance {
                recorded: rec,
                transform: translate(Vec3::new(0.0, 0.0, -4.0)),
                paint: None,
            },
        ],
        ..FrameDraws::default()
    }
}

/// A way to break [`good`]: its name, the breakage, and what every entry
/// point must answer.
type Case = (&'static str, fn(&mut Geometry), GeometryError);

fn cases() -> Vec<Case> {
    use GeometryError::*;
    let attrs = |positions, normals, colors| VertexAttributeCount { positions, normals, colors };
    vec![
        (
            "a normal missing",
            |g| {
                g.normals.pop();
            },
            attrs(6, 5, 6),
        ),
        ("a normal too many", |g| g.normals.push(Vec3::Z), attrs(6, 7, 6)),
        ("no colours", |g| g.colors.clear(), attrs(6, 6, 0)),
        (
            "a texture coordinate missing",
            |g| {
                g.texcoords.pop();
            },
            TexcoordCount { positions: 6, texcoords: 5 },
        ),
        (
            "no triangle_info",
            |g| g.triangle_info.clear(),
            TriangleInfoCount { triangles: 1, triangle_info: 0 },
        ),
        (
            "a triangle corner one past the end",
            |g| g.triangles[0][1] = 6,
            VertexOutOfRange { primitive: Primitive::Triangle(0), index: 6 },
        ),
        (
            "a triangle corner at u32::MAX",
            |g| g.triangles[0][2] = u32::MAX,
            VertexOutOfRange { primitive: Primitive::Triangle(0), index: u32::MAX },
        ),
        (
            "a provoking vertex out of range",
            |g| g.triangle_info[0].1 = 99,
            VertexOutOfRange { primitive: Primitive::Triangle(0), index: 99 },
        ),
        (
            "a triangle's shading out of range",
            |g| g.triangle_info[0].0 = 1,
            ShadingOutOfRange { primitive: Primitive::Triangle(0), index: 1 },
        ),
        (
            "a sphere's vertex out of range",
            |g| g.spheres[0].0 = 6,
            VertexOutOfRange { primitive: Primitive::Sphere(0), index: 6 },
        ),
        (
            "a sphere's shading out of range",
            |g| g.spheres[0].2 = 7,
            ShadingOutOfRange { primitive: Primitive::Sphere(0), index: 7 },
        ),
        (
            "a tube's end out of range",
            |g| g.tubes[0].0[1] = 6,
            VertexOutOfRange { primitive: Primitive::Tube(0), index: 6 },
        ),
        (
            "a tube's shading out of range",
            |g| g.tubes[0].2 = u32::MAX,
            ShadingOutOfRange { primitive: Primitive::Tube(0), index: u32::MAX },
        ),
        (
            "no shadings",
            |g| g.shadings.clear(),
            ShadingOutOfRange { primitive: Primitive::Triangle(0), index: 0 },
        ),
        // Well formed, but not buildable: the build's own errors.
        (
            "a NaN vertex",
            |g| g.positions[0].x = f32::NAN,
            Build(BuildError::NonFiniteVertex { vertex: 0 }),
        ),
        (
            "a negative radius",
            |g| g.spheres[0].1 = -1.0,
            Build(BuildError::InvalidPrimitive { index: 0 }),
        ),
    ]
}

/// The well-formed geometry renders the same immediate, instanced and
/// flattened: the triangle, sphere and tube each in their colour.
#[test]
fn well_formed_geometry_renders() {
    let g = good();
    assert_eq!(g.check(), Ok(()));
    let opts = Options::default();
    let img = render(immediate(g.clone()), &opts).expect("well formed");
    for (p, colour) in [
        (Vec3::new(0.0, -0.2, -3.0), [255, 0, 0, 255]),
        (Vec3::new(-0.6, 0.6, -2.5), [0, 255, 0, 255]),
        (Vec3::new(0.6, -0.6, -2.5), [0, 0, 255, 255]),
    ] {
        let (x, y) = pixel_of(p);
        assert_eq!(img.get(x, y), Some(colour), "at {p} (pixel {x}, {y})");
    }
    assert_eq!(render(instanced(g.clone()), &opts), Ok(img.clone()));
    let flat = instanced(g).flatten().expect("well formed");
    assert_eq!(render(immediate(flat), &opts), Ok(img));
}

/// Every malformed geometry is an `Err` from [`Geometry::check`] (the
/// structural rules only), [`Geometry::build`], [`Recorded::scene`] (built
/// and refitted from a good recording), [`FrameScene::build`] (as the
/// frame's immediate geometry or as a recording),
/// [`Geometry::append_transformed`] and [`FrameDraws::flatten`], never a
/// panic.
#[test]
fn malformed_geometry_is_refused_everywhere() {
    let opts = Options::default();
    let good_rec = Arc::new(Recorded::new(good()));
    good_rec.scene().expect("well formed");
    for (name, break_it, expected) in cases() {
        let mut g = good();
        break_it(&mut g);
        let structural = !matches!(expected, GeometryError::Build(_));
        let checked = if structural { Err(expected) } else { Ok(()) };
        assert_eq!(g.check(), checked, "{name}: check");
        assert_eq!(g.build().err(), Some(expected), "{name}: build");
        assert_eq!(Recorded::new(g.clone()).scene().err(), Some(expected), "{name}: scene");
        let moved = Recorded::moved(g.clone(), &good_rec);
        assert_eq!(moved.scene().err(), Some(expected), "{name}: moved scene");
        let want = Err(RenderError::Geometry(expected));
        assert_eq!(render(immediate(g.clone()), &opts), want, "{name}: immediate frame");
        assert_eq!(render(instanced(g.clone()), &opts), want, "{name}: instanced frame");
        // Appended or flattened, before or after a good geometry: refused
        // (offset, a bad index could name the other's vertices).
        let mut into = good();
        let appended = into.append_transformed(&g, &Mat4::IDENTITY);
        assert_eq!(appended, checked, "{name}: appended");
        assert_eq!(into == good(), structural, "{name}: appended anyway");
        let mut onto = g.clone();
        assert_eq!(onto.append_transformed(&good(), &Mat4::IDENTITY), checked, "{name}: onto");
        let mut frame = instanced(g);
        frame.immediate = good();
        match frame.flatten() {
            Err(e) => assert_eq!(Err(e), checked, "{name}: flattened"),
            Ok(flat) => {
                // The build's error, naming the flattened vertex or sphere.
                assert!(!structural, "{name}: flattened");
                let got = render(immediate(flat), &opts);
                assert!(
                    matches!(got, Err(RenderError::Geometry(GeometryError::Build(_)))),
                    "{name}: flattened frame {got:?}"
                );
            }
        }
    }
}

/// Two parallel mirrors facing each other, lit: the ray through the
/// centre of an odd-sized image bounces between them as deep as it is
/// allowed to.
fn hall_of_mirrors() -> Geometry {
    let mirror = Shading {
        lit: true,
        material: MaterialState { specular: Vec4::ONE, ..MaterialState::default() },
        ..Shading::default()
    };
    let mut g = Geometry { shadings: vec![mirror], ..Geometry::default() };
    for (z, n) in [(-3.0, Vec3::Z), (1.0, Vec3::NEG_Z)] {
        let b = g.positions.len() as u32;
        g.positions.extend(
            [(-5.0, -5.0), (5.0, -5.0), (5.0, 5.0), (-5.0, 5.0)].map(|(x, y)| Vec3::new(x, y, z)),
        );
        g.normals.extend([n; 4]);
        g.colors.extend([Vec4::ONE; 4]);
        g.triangles.extend([[b, b + 1, b + 2], [b, b + 2, b + 3]]);
        g.triangle_info.extend([(0, b + 2), (0, b + 3)]);
    }
    g
}

/// Options out of range are refused before any ray is traced: bounces
/// recurse on the stack, and between two mirrors 20 000 of them overflow
/// it (an abort, not even a panic); [`MAX_BOUNCES`] itself renders.
#[test]
fn options_out_of_range_are_refused() {
    let base = Options { mode: Illumination::Rt, ao_samples: 2, mirror: 0.5, ..Options::default() };
    let bad = [
        Options { bounces: MAX_BOUNCES + 1, ..base },
        Options { bounces: u32::MAX, ..base },
        Options { ao_samples: MAX_AO_SAMPLES + 1, ..base },
        Options { ao_distance: f32::NAN, ..base },
        Options { ao_distance: -0.1, ..base },
        Options { mirror: f32::INFINITY, ..base },
        Options { mirror: -1.0, ..base },
    ];
    let scene = FrameScene::build(immediate(hall_of_mirrors())).expect("well formed");
    let trace =
        |opts: &Options| scene.render(&Lighting::default(), projection(), 5, 5, Vec4::ZERO, opts);
    for opts in bad {
        assert!(!opts.is_valid(), "{opts:?}");
        assert_eq!(trace(&opts), Err(RenderError::BadOptions), "{opts:?}");
    }
    assert!(Options::default().is_valid());
    // Each bounce adds to the centre pixel: the limit is reached.
    let centre = |bounces| trace(&Options { bounces, ..base }).expect("valid").get(2, 2);
    assert_ne!(centre(MAX_BOUNCES), centre(0));
}

/// An image whose bytes do not match its size reads as missing pixels and
/// fails to write, without a panic.
#[test]
fn mismatched_images_are_errors() {
    let short = Image { width: 4, height: 4, rgba: vec![7; 4 * 4 * 4 - 1] };
    assert_eq!(short.get(3, 3), None);
    assert_eq!(short.get(2, 3), Some([7; 4]));
    assert_eq!(short.get(4, 0), None);
    let path = std::env::temp_dir().join(format!("rt-gl-malformed-{}.png", std::process::id()));
    assert!(short.write_png(&path).is_err());
    let empty = Image { width: 0, height: 3, rgba: Vec::new() };
    let _ = empty.write_png(&path);
    let _ = std::fs::remove_file(&path);
}

/// `glDeleteLists` over the whole id space deletes the lists in it
/// without walking 2³¹ ids; one at a time still works.
#[test]
fn deleting_a_huge_range_of_lists_is_quick() {
    let mut r = Recorder::new();
    for id in [1, 2, 5] {
        r.new_list(id, rt_gl::gl::COMPILE);
        r.command(Command::Begin(rt_gl::gl::TRIANGLES));
        for v in [Vec3::ZERO, Vec3::X, Vec3::Y] {
            r.command(Command::Vertex(v.extend(1.0)));
        }
        r.command(Command::End);
        r.end_list();
    }
    let triangles = |r: &mut Recorder, id| {
        r.command(Command::CallList(id));
        r.end_frame().flatten().expect("well formed").triangles.len()
    };
    r.delete_lists(5, 1);
    assert_eq!((triangles(&mut r, 1), triangles(&mut r, 5)), (1, 0));
    let start = Instant::now();
    r.delete_lists(2, i32::MAX);
    assert!(start.elapsed().as_secs_f32() < 5.0, "{:?}", start.elapsed());
    assert_eq!((triangles(&mut r, 1), triangles(&mut r, 2)), (1, 0));
    assert_eq!(r.counters.ignored, 0);
}
