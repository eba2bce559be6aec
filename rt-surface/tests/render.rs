//! The surface renderer against answers computed independently.

use rt_accel::BuildParams;
use rt_core::{
    Aabb, Camera, ColorMap, ColorStop, Frame, Hit, Projection, Ray, SceneQuery,
    frame::linear_to_srgb, glam::Vec3, intersect::Sphere,
};
use rt_surface::{
    Glyphs, Light, Material, MaterialError, Mesh, MeshError, ObjectKind, Paint, Renderer,
    SceneError, Settings, ShadeScene, Surface, SurfaceScene, Tube,
};

fn quad(corners: [Vec3; 4]) -> Mesh {
    Mesh::new(corners.to_vec(), vec![[0, 1, 2], [0, 2, 3]], None).unwrap()
}

/// A floor `y = 0` (±50), front face up.
fn floor() -> Mesh {
    floor_of(50.0)
}

fn floor_of(s: f32) -> Mesh {
    quad([
        Vec3::new(-s, 0.0, -s),
        Vec3::new(-s, 0.0, s),
        Vec3::new(s, 0.0, s),
        Vec3::new(s, 0.0, -s),
    ])
}

fn solid(mesh: Mesh, rgb: [f32; 3], m: Material) -> (Mesh, Paint<'static>, Material) {
    (mesh, Paint::Solid(rgb), m)
}

fn scene(meshes: Vec<(Mesh, Paint<'static>, Material)>) -> SurfaceScene<'static> {
    SurfaceScene::build(meshes, vec![], vec![], &BuildParams::medium()).unwrap()
}

fn settings(lights: Vec<Light>) -> Settings {
    Settings { lights, ao_samples: 0, ..Settings::default() }
}

fn render(scene: &SurfaceScene<'_>, cam: Camera, s: Settings, passes: u32) -> (Frame, Renderer) {
    let mut r = Renderer::new(cam, s).unwrap();
    for _ in 0..passes {
        r.render_pass(scene);
    }
    (r.frame().unwrap(), r)
}

/// Looking straight down at `(x, z)` from `y = 5`, one pixel.
fn down_at(x: f32, z: f32) -> Camera {
    Camera::look_at(
        Vec3::new(x, 5.0, z),
        Vec3::new(x, 0.0, z),
        Vec3::Z,
        Projection::Orthographic { height: 1e-4 },
        1,
        1,
    )
    .unwrap()
}

#[test]
fn a_sphere_under_a_directional_light_is_the_lambert_image() {
    let glyphs = Glyphs {
        spheres: vec![Sphere::new(Vec3::ZERO, 1.0)],
        scalars: None,
        paint: Paint::Solid([1.0, 0.5, 0.25]),
        material: Material::MATTE,
    };
    let s = SurfaceScene::build(vec![], vec![glyphs], vec![], &BuildParams::medium()).unwrap();
    let l = Vec3::new(0.3, 0.4, 1.0).normalize();
    let (w, h) = (64, 48);
    let cam = Camera::look_at(
        Vec3::new(0.0, 0.0, 5.0),
        Vec3::ZERO,
        Vec3::Y,
        Projection::Orthographic { height: 2.4 },
        w,
        h,
    )
    .unwrap();
    let lights = vec![Light::Directional { direction: l * 3.0, color: [2.0; 3] }];
    let (f, r) = render(&s, cam, settings(lights), 1);
    let mut hits = 0;
    for y in 0..h {
        for x in 0..w {
            // The pixel centre's ray, computed here from the projection.
            let sx = (2.0 * (x as f32 + 0.5) / w as f32 - 1.0) * 1.2 * w as f32 / h as f32;
            let sy = (1.0 - 2.0 * (y as f32 + 0.5) / h as f32) * 1.2;
            let px = f.get(x, y).unwrap();
            let r2 = sx * sx + sy * sy;
            if r2 > 1.0 - 1e-3 {
                if r2 > 1.0 + 1e-3 {
                    assert_eq!((px.color, px.depth), ([0.0; 4], f32::INFINITY), "{x} {y}");
                }
                continue;
            }
            hits += 1;
            let n = Vec3::new(sx, sy, (1.0 - r2).sqrt());
            let lambert = 2.0 * n.dot(l).max(0.0);
            let want = [lambert, 0.5 * lambert, 0.25 * lambert, 1.0];
            for k in 0..4 {
                assert!(
                    (px.color[k] - want[k]).abs() < 2e-4,
                    "{x} {y}: {:?} vs {want:?}",
                    px.color
                );
            }
            assert!((px.depth - (5.0 - n.z)).abs() < 1e-4);
        }
    }
    assert!(hits > 1000);
    // One light with shadows: one shadow ray per lit hit at most.
    let c = r.counts();
    assert!(c.shadow > 0 && c.shadow <= hits && c.ao == 0 && c.reflection == 0);
}

#[test]
fn ambient_occlusion_of_an_open_plane_is_exactly_one() {
    let s = scene(vec![solid(floor(), [0.5, 0.6, 0.7], Material::MATTE)]);
    let st = Settings {
        lights: vec![Light::Ambient { color: [1.0; 3] }],
        ao_samples: 64,
        ao_distance: 100.0,
        ..Settings::default()
    };
    for (x, z) in [(0.0, 0.0), (12.0, -45.0), (-0.3, 7.0)] {
        let (f, r) = render(&s, down_at(x, z), st.clone(), 4);
        assert_eq!(f.get(0, 0).unwrap().color, [0.5, 0.6, 0.7, 1.0]);
        assert_eq!(r.counts().ao, 4 * 64);
    }
}

#[test]
fn ambient_occlusion_beside_a_wall_is_the_disk_segment() {
    // Floor y = 0 and a wall x = 0 facing +x. Cosine-weighted directions
    // project uniformly onto the unit disk (Malley), and an AO ray of
    // length D from distance d hits the wall iff its x-component is below
    // −d/D: AO = 1 − (acos a − a√(1−a²))/π with a = d/D.
    // Triangles much larger than the AO rays: the hit distance, from
    // barycentric interpolation of large coordinates, rounds below the
    // flat boxes' near planes; the triangle test must not lose them.
    let s = 1e3;
    let wall = quad([
        Vec3::new(0.0, 0.0, -s),
        Vec3::new(0.0, s, -s),
        Vec3::new(0.0, s, s),
        Vec3::new(0.0, 0.0, s),
    ]);
    let sc = scene(vec![
        solid(floor_of(s), [1.0; 3], Material::MATTE),
        solid(wall, [1.0; 3], Material::MATTE),
    ]);
    // Many rays per pass, and two rays over many passes (each pass's
    // fraction 0, ½ or 1: a miscounted ray shows as a large bias).
    let cases = [(0.25f32, 1.0f32, 4096, 8), (0.5, 4.0, 4096, 8), (0.9, 1.0, 4096, 8)];
    for (d, dist, samples, passes) in cases.into_iter().chain([(0.25, 1.0, 2, 2048)]) {
        let st = Settings {
            lights: vec![Light::Ambient { color: [1.0; 3] }],
            ao_samples: samples,
            ao_distance: dist,
            seed: 3,
            ..Settings::default()
        };
        let (f, _) = render(&sc, down_at(d, 0.0), st, passes);
        let a = f64::from(d / dist);
        let want = 1.0 - (a.acos() - a * (1.0 - a * a).sqrt()) / core::f64::consts::PI;
        let n = f64::from(samples * passes);
        let sigma = (want * (1.0 - want) / n).sqrt();
        let got = f64::from(f.get(0, 0).unwrap().color[0]);
        assert!((got - want).abs() < 4.0 * sigma, "d {d} D {dist}: {got} vs {want} (σ {sigma:e})");
    }
}

#[test]
fn colour_maps_the_interpolated_scalar_not_interpolated_colours() {
    static STOPS: [ColorStop; 3] = [
        ColorStop::rgb(0.0, 1.0, 0.0, 0.0),
        ColorStop::rgb(0.5, 0.0, 1.0, 0.0),
        ColorStop::rgb(1.0, 0.0, 0.0, 1.0),
    ];
    let map = ColorMap::from_stops(&STOPS, 0.0, 1.0).unwrap();
    // Scalar 0 at x = 0, 1 at x = 1, linear in x.
    let mesh = Mesh::new(
        vec![Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 0.0, 0.0)],
        vec![[0, 1, 2]],
        Some(vec![0.0, 0.0, 1.0]),
    )
    .unwrap();
    let s = SurfaceScene::build(
        vec![(mesh, Paint::Mapped(map), Material::MATTE)],
        vec![],
        vec![],
        &BuildParams::medium(),
    )
    .unwrap();
    let st = settings(vec![Light::Ambient { color: [1.0; 3] }]);
    // At scalar 0.5 the map is green; blending the vertex colours would
    // give purple (0.5, 0, 0.5).
    let (f, _) = render(&s, down_at(0.5, 0.25), st.clone(), 1);
    let c = f.get(0, 0).unwrap().color;
    assert!(c[1] > 0.999 && c[0] < 1e-3 && c[2] < 1e-3, "{c:?}");
    // Halfway between red and green stops: (½, ½, 0) on the sRGB curve,
    // which the frame holds decoded to linear.
    let (f, _) = render(&s, down_at(0.25, 0.25), st, 1);
    let c = f.get(0, 0).unwrap().color.map(linear_to_srgb);
    assert!((c[0] - 0.5).abs() < 1e-3 && (c[1] - 0.5).abs() < 1e-3 && c[2] < 1e-3, "{c:?}");
}

#[test]
fn a_ramp_under_ambient_light_shows_the_published_colour_map() {
    // Scalar = x on a unit triangle strip, lit by ambient 1 only: the 8-bit
    // sRGB frame is the colour map itself. Published entries (matplotlib's
    // viridis at 0, 128/255, 1; Moreland's cool-to-warm ends and middle)
    // must come out as published, not encoded a second time.
    let mesh = Mesh::new(
        vec![
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, 1.0),
        ],
        vec![[0, 1, 2], [2, 1, 3]],
        Some(vec![0.0, 0.0, 1.0, 1.0]),
    )
    .unwrap();
    // (scalar, published 8-bit sRGB) per map.
    type Entries = [(f32, [u8; 3]); 3];
    let cases: [(ColorMap<'static>, Entries); 2] = [
        (
            ColorMap::viridis(),
            [(0.0, [68, 1, 84]), (128.0 / 255.0, [33, 145, 140]), (1.0, [253, 231, 37])],
        ),
        (
            ColorMap::cool_to_warm(),
            [(0.0, [59, 76, 192]), (0.5, [221, 221, 221]), (1.0, [180, 4, 38])],
        ),
    ];
    let st = settings(vec![Light::Ambient { color: [1.0; 3] }]);
    for (map, entries) in cases {
        let s = SurfaceScene::build(
            vec![(mesh.clone(), Paint::Mapped(map), Material::MATTE)],
            vec![],
            vec![],
            &BuildParams::medium(),
        )
        .unwrap();
        for (x, want) in entries {
            // Just inside the strip at its ends.
            let x = x.clamp(1e-6, 1.0 - 1e-6);
            let (f, _) = render(&s, down_at(x, 0.0), st.clone(), 1);
            let px = f.to_srgba8();
            for k in 0..3 {
                let d = i32::from(px[k]) - i32::from(want[k]);
                assert!(d.abs() <= 1, "x {x}: {:?} vs published {want:?}", &px[..3]);
            }
        }
    }
}

fn view() -> Camera {
    Camera::look_at(
        Vec3::new(3.0, 2.0, 4.0),
        Vec3::new(0.0, 0.3, 0.0),
        Vec3::Y,
        Projection::Perspective { fov_y: 0.8 },
        40,
        30,
    )
    .unwrap()
}

fn ball_on_floor(ball: Material) -> SurfaceScene<'static> {
    let g = Glyphs {
        spheres: vec![Sphere::new(Vec3::new(0.0, 0.5, 0.0), 0.5)],
        scalars: None,
        paint: Paint::Solid([0.9, 0.2, 0.2]),
        material: ball,
    };
    SurfaceScene::build(
        vec![solid(floor(), [0.8; 3], Material::MATTE)],
        vec![g],
        vec![],
        &BuildParams::medium(),
    )
    .unwrap()
}

#[test]
fn counters_show_what_is_skipped() {
    let sun = Light::Directional { direction: Vec3::new(1.0, 2.0, 0.5), color: [1.0; 3] };
    let amb = Light::Ambient { color: [0.2; 3] };
    let s = ball_on_floor(Material::MATTE);
    let px = 40 * 30;
    // No lights: nothing but camera rays (AO is on, but there is no
    // ambient light for it to darken).
    let st = Settings { lights: vec![], ao_samples: 8, ..Settings::default() };
    let c = render(&s, view(), st, 1).1.counts();
    assert_eq!((c.primary, c.total()), (px, px));
    // A light without shadows, AO off: still only camera rays.
    let st = Settings { lights: vec![sun, amb], shadows: false, ..settings(vec![]) };
    assert_eq!(render(&s, view(), st, 1).1.counts().total(), px);
    // Shadows on: shadow rays, but no AO, reflection or transparency rays.
    let c = render(&s, view(), settings(vec![sun, amb]), 1).1.counts();
    assert!(c.shadow > px / 2 && c.ao == 0 && c.reflection == 0 && c.transparency == 0);
    // AO on: 8 per hit.
    let st = Settings { ao_samples: 8, ..settings(vec![amb]) };
    let c = render(&s, view(), st, 1).1.counts();
    assert!(c.ao > 0 && c.ao.is_multiple_of(8) && c.shadow == 0);
    // A mirror ball casts reflection rays, a glass one transparency rays.
    let mirror = ball_on_floor(Material { mirror: 0.5, ..Material::MATTE });
    let c = render(&mirror, view(), settings(vec![amb]), 1).1.counts();
    assert!(c.reflection > 0 && c.transparency == 0);
    let glass = ball_on_floor(Material { opacity: 0.4, ..Material::MATTE });
    let c = render(&glass, view(), settings(vec![amb]), 1).1.counts();
    assert!(c.transparency > 0 && c.reflection == 0);
    // Looking away from everything: every ray is culled at the bounds.
    let away = Camera::look_at(
        Vec3::new(0.0, 1e5, 0.0),
        Vec3::new(0.0, 2e5, 0.0),
        Vec3::Z,
        Projection::Perspective { fov_y: 0.8 },
        8,
        8,
    )
    .unwrap();
    let c = render(&s, away, settings(vec![sun, amb]), 1).1.counts();
    assert_eq!((c.primary, c.culled, c.shadow), (64, 64, 0));
}

#[test]
fn translucent_layers_composite_over_in_depth_order_and_mirrors_see_the_environment() {
    let near = quad([
        Vec3::new(-1.0, 1.0, -1.0),
        Vec3::new(-1.0, 1.0, 1.0),
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(1.0, 1.0, -1.0),
    ]);
    let glass = Material { opacity: 0.25, ..Material::MATTE };
    let s = scene(vec![
        solid(floor(), [1.0, 0.0, 0.0], Material::MATTE),
        solid(near, [0.0, 0.0, 1.0], glass),
    ]);
    let st = settings(vec![Light::Ambient { color: [1.0; 3] }]);
    let (f, r) = render(&s, down_at(0.1, 0.2), st.clone(), 1);
    let p = f.get(0, 0).unwrap();
    assert_eq!(p.color, [0.75, 0.0, 0.25, 1.0]);
    assert_eq!(p.depth, 4.0, "depth of the first surface");
    assert_eq!(r.counts().transparency, 1);
    // Without the floor: premultiplied, alpha 0.25.
    let near_only = scene(vec![solid(
        quad([
            Vec3::new(-1.0, 1.0, -1.0),
            Vec3::new(-1.0, 1.0, 1.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1.0, 1.0, -1.0),
        ]),
        [0.0, 0.0, 1.0],
        glass,
    )]);
    let p = *render(&near_only, down_at(0.1, 0.2), st.clone(), 1).0.get(0, 0).unwrap();
    assert_eq!(p.color, [0.0, 0.0, 0.25, 0.25]);
    // A perfect mirror floor under an open sky shows the environment.
    let mirror = scene(vec![solid(floor(), [1.0; 3], Material { mirror: 1.0, ..Material::MATTE })]);
    let st = Settings { environment: [0.2, 0.4, 0.6], ..st };
    let p = *render(&mirror, down_at(3.0, -2.0), st, 1).0.get(0, 0).unwrap();
    assert_eq!(p.color, [0.2, 0.4, 0.6, 1.0]);
}

#[test]
fn frames_are_identical_at_any_thread_count() {
    let tube = Tube {
        points: (0..20).map(|i| Vec3::new(-1.0 + 0.1 * i as f32, 0.8, 0.3)).collect(),
        radius: 0.05,
        scalars: Some((0..20).map(|i| i as f32).collect()),
        paint: Paint::Mapped(ColorMap::viridis().with_range(0.0, 19.0).unwrap()),
        material: Material::GLOSSY,
    };
    let g = Glyphs {
        spheres: vec![Sphere::new(Vec3::new(0.0, 0.5, 0.0), 0.5)],
        scalars: Some(vec![0.3]),
        paint: Paint::Mapped(ColorMap::cool_to_warm()),
        material: Material { mirror: 0.3, opacity: 0.7, ..Material::GLOSSY },
    };
    let s = SurfaceScene::build(
        vec![solid(floor(), [0.8; 3], Material::MATTE)],
        vec![g],
        vec![tube],
        &BuildParams::medium(),
    )
    .unwrap();
    let st = Settings {
        lights: vec![
            Light::Ambient { color: [0.3; 3] },
            Light::Point { position: Vec3::new(1.0, 3.0, 1.0), color: [4.0; 3] },
        ],
        ao_samples: 4,
        seed: 9,
        ..Settings::default()
    };
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let (f, r) = render(&s, view(), st.clone(), 3);
            (f, r.counts())
        })
    };
    let same = |a: &Frame, b: &Frame| {
        a.pixels().iter().zip(b.pixels()).all(|(a, b)| {
            a.color.map(f32::to_bits) == b.color.map(f32::to_bits)
                && a.depth.to_bits() == b.depth.to_bits()
        })
    };
    let (one, c1) = run(1);
    for t in [2, 5] {
        let (f, c) = run(t);
        assert_eq!(c, c1);
        assert!(same(&one, &f));
    }
    // Progress reports: each tile once per pass, counting up to the total,
    // and the image is the same.
    let pool = rayon::ThreadPoolBuilder::new().num_threads(5).build().unwrap();
    let mut r = Renderer::new(view(), st.clone()).unwrap();
    let tiles = r.tiles_per_pass();
    assert_eq!(tiles, 3 * 2);
    for _ in 0..3 {
        let seen = std::sync::Mutex::new(Vec::new());
        pool.install(|| {
            r.render_pass_with_progress(&s, |done, total| seen.lock().unwrap().push((done, total)))
        });
        let mut seen = seen.into_inner().unwrap();
        seen.sort_unstable();
        assert_eq!(seen, (1..=tiles).map(|d| (d, tiles)).collect::<Vec<_>>());
    }
    assert!(same(&one, &r.frame().unwrap()));

    // A pass told to stop after two tiles is dropped: the renderer keeps
    // its three passes, and a pass after it is the fourth as if none had
    // been stopped.
    let asked = core::sync::atomic::AtomicUsize::new(0);
    let stop = || asked.fetch_add(1, core::sync::atomic::Ordering::Relaxed) >= 2;
    assert_eq!(pool.install(|| r.render_pass_until(&s, |_, _| {}, &stop)), None);
    assert_eq!(r.passes(), 3);
    assert!(same(&one, &r.frame().unwrap()));
    let (four, _) = render(&s, view(), st.clone(), 4);
    assert!(r.render_pass_until(&s, |_, _| {}, &|| false).is_some());
    assert!(same(&four, &r.frame().unwrap()));

    // Camera rays go through the scene as one batch per tile, and shadow
    // and AO rays as one batch per tile and kind; asked one by one (the trait's
    // defaults), every pixel and count is the same.
    struct OneByOne<'a>(&'a SurfaceScene<'a>);
    impl SceneQuery for OneByOne<'_> {
        fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
            self.0.closest_hit(ray)
        }
        fn occluded(&self, ray: &Ray) -> bool {
            self.0.occluded(ray)
        }
    }
    impl ShadeScene for OneByOne<'_> {
        fn surface(&self, hit: &Hit) -> Surface {
            self.0.surface(hit)
        }
        fn bounds(&self) -> Aabb {
            self.0.bounds()
        }
    }
    let mut single = Renderer::new(view(), st.clone()).unwrap();
    for _ in 0..3 {
        single.render_pass(&OneByOne(&s));
    }
    assert_eq!(single.counts(), c1);
    assert!(same(&one, &single.frame().unwrap()));
}

#[test]
fn bad_geometry_is_named_and_moving_vertices_refits() {
    let good = floor();
    let mut pts = floor().positions().to_vec();
    pts[2].y = f32::NAN;
    // Mesh itself names the vertex...
    assert_eq!(
        Mesh::new(pts.clone(), vec![[0, 1, 2]], None),
        Err(MeshError::Geometry(rt_accel::BuildError::NonFiniteVertex { vertex: 2 }))
    );
    // ...and so does the scene, with the object.
    let g = Glyphs {
        spheres: vec![Sphere::new(Vec3::ZERO, 1.0), Sphere::new(Vec3::NAN, 1.0)],
        scalars: None,
        paint: Paint::Solid([1.0; 3]),
        material: Material::MATTE,
    };
    let e = SurfaceScene::build(vec![], vec![g], vec![], &BuildParams::medium()).unwrap_err();
    assert_eq!(
        e,
        SceneError::Build {
            kind: ObjectKind::Glyphs,
            object: 0,
            error: rt_accel::BuildError::InvalidPrimitive { index: 1 }
        }
    );
    let bad = Material { opacity: 2.0, ..Material::MATTE };
    let e = SurfaceScene::build(
        vec![solid(good, [1.0; 3], bad)],
        vec![],
        vec![],
        &BuildParams::medium(),
    )
    .unwrap_err();
    assert_eq!(
        e,
        SceneError::Material { kind: ObjectKind::Mesh, object: 0, error: MaterialError::Opacity }
    );
    // Moving the floor up by 1 is a refit, and rays see it there.
    let mut s = scene(vec![
        solid(floor(), [1.0; 3], Material::MATTE),
        solid(floor(), [1.0; 3], Material::MATTE),
    ]);
    let up: Vec<Vec3> = floor().positions().iter().map(|p| *p + Vec3::Y).collect();
    s.set_mesh_positions(1, &up).unwrap();
    assert_eq!((s.refits(), s.rebuilds()), (1, 0));
    let st = settings(vec![Light::Ambient { color: [1.0; 3] }]);
    assert_eq!(render(&s, down_at(0.0, 0.0), st.clone(), 1).0.get(0, 0).unwrap().depth, 4.0);
    let mut nan = up.clone();
    nan[3].x = f32::INFINITY;
    assert!(matches!(
        s.set_mesh_positions(1, &nan),
        Err(SceneError::Build {
            kind: ObjectKind::Mesh,
            object: 1,
            error: rt_accel::BuildError::NonFiniteVertex { vertex: 3 }
        })
    ));
    assert_eq!(s.set_mesh_positions(7, &up), Err(SceneError::NoSuchMesh(7)));
    // New topology is a rebuild.
    let tri = Mesh::new(up[..3].to_vec(), vec![[0, 1, 2]], None).unwrap();
    s.replace_mesh(1, tri).unwrap();
    assert_eq!((s.refits(), s.rebuilds(), s.triangle_count()), (1, 1, 3));
}

#[test]
fn shadows_of_many_pixels_fall_where_the_geometry_puts_them() {
    // Spheres above a floor, seen from straight above, lit by a red
    // directional light and a green point light with shadows. Each floor
    // pixel's colour is set by whether each of its two shadow rays meets a
    // sphere, found here ray by ray in f64. The renderer gathers a tile's
    // shadow rays, answers them together and adds each light afterwards:
    // an answer given to the wrong pixel or the wrong light shows here.
    let centres: Vec<Vec3> = (0..12)
        .map(|i| {
            let a = i as f32 * 2.4;
            Vec3::new(0.35 * i as f32 * a.cos(), 0.8 + 0.05 * i as f32, 0.35 * i as f32 * a.sin())
        })
        .collect();
    let radius = 0.45;
    let glyphs = Glyphs {
        spheres: centres.iter().map(|&c| Sphere::new(c, radius)).collect(),
        scalars: None,
        paint: Paint::Solid([1.0; 3]),
        material: Material::MATTE,
    };
    let sc = SurfaceScene::build(
        vec![solid(floor(), [1.0; 3], Material::MATTE)],
        vec![glyphs],
        vec![],
        &BuildParams::medium(),
    )
    .unwrap();
    let l = Vec3::new(0.6, 1.0, -0.3).normalize();
    let lamp = Vec3::new(-1.0, 2.5, 1.5);
    let st = Settings {
        lights: vec![
            Light::Directional { direction: l, color: [1.0, 0.0, 0.0] },
            Light::Point { position: lamp, color: [0.0, 4.0, 0.0] },
        ],
        shadows: true,
        ao_samples: 0,
        ..Settings::default()
    };
    let n = 64;
    let cam = Camera::look_at(
        Vec3::new(0.0, 5.0, 0.0),
        Vec3::ZERO,
        Vec3::Z,
        Projection::Orthographic { height: 8.0 },
        n,
        n,
    )
    .unwrap();
    let (f, _) = render(&sc, cam, st, 1);
    // Distance from the segment `p + s·d`, `s ∈ [0, s_max]`, to the nearest
    // sphere surface (negative: the segment passes through a sphere).
    let clearance = |p: Vec3, d: Vec3, s_max: f64| -> f64 {
        let (p, d) = (p.as_dvec3(), d.as_dvec3().normalize());
        centres
            .iter()
            .map(|c| {
                let c = c.as_dvec3();
                let s = (c - p).dot(d).clamp(0.0, s_max);
                (p + s * d).distance(c) - f64::from(radius)
            })
            .fold(f64::INFINITY, f64::min)
    };
    let (mut checked, mut red_shadowed, mut green_shadowed) = (0, 0, 0);
    for y in 0..n {
        for x in 0..n {
            let ray =
                cam.generate_ray(x, y, rt_core::glam::Vec2::splat(0.5), rt_core::glam::Vec2::ZERO);
            // The floor point under the pixel, if no sphere is in the way.
            let t = -ray.origin.y / ray.direction.y;
            let p = ray.origin + t * ray.direction;
            if clearance(ray.origin, ray.direction, f64::from(t)) < 0.02 {
                continue;
            }
            let to_lamp = lamp - p;
            let (red, green) =
                (clearance(p, l, 1e3), clearance(p, to_lamp, f64::from(to_lamp.length())));
            if red.abs() < 0.02 || green.abs() < 0.02 {
                continue; // too close to a shadow's edge to call
            }
            let want_r = if red < 0.0 { 0.0 } else { l.y };
            let want_g = if green < 0.0 {
                0.0
            } else {
                4.0 * to_lamp.normalize().y / to_lamp.length_squared()
            };
            let c = f.get(x, y).unwrap().color;
            assert!(
                (c[0] - want_r).abs() < 1e-4 && (c[1] - want_g).abs() < 1e-4,
                "pixel ({x}, {y}) at {p}: {c:?}, want red {want_r} green {want_g} ({red} {green})"
            );
            checked += 1;
            red_shadowed += usize::from(red < 0.0);
            green_shadowed += usize::from(green < 0.0);
        }
    }
    // Enough pixels of each kind for a misplaced answer to show.
    assert!(checked > 3000, "{checked}");
    assert!(red_shadowed > 300 && green_shadowed > 300, "{red_shadowed} {green_shadowed}");
}
