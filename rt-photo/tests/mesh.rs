//! Unstructured meshes on the optical bench: the same field as a regular
//! grid and as the tetrahedral split of that grid gives the same image,
//! within the difference of their interpolants.
#![cfg(feature = "mesh")]

mod support;

use rt_core::frame::linear_to_srgb;
use rt_photo::Medium;
use rt_photo::glam::DVec3;
use rt_photo::rt_volume::{Grid, GridField, IndexField, Interp};
use rt_photo::{Cell, Film, Filter, UnstructuredField};
use support::{bench, knife};

/// The hexahedral mesh of `n` points a side over `[lo, hi]³`, `f` at the
/// points.
fn mesh(n: usize, lo: f64, hi: f64, f: &impl Fn(DVec3) -> f64) -> UnstructuredField {
    let h = (hi - lo) / (n - 1) as f64;
    let mut points = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                points.push(DVec3::new(i as f64, j as f64, k as f64) * h + lo);
            }
        }
    }
    let cells = Cell::lattice_hexahedra([n; 3]);
    let values = points.iter().map(|&p| f(p)).collect();
    UnstructuredField::new(points, &cells, values, 1.0).unwrap()
}

/// The trilinear grid of `n` samples a side, centred on `[-3, 3]³`.
fn grid(n: usize, f: &impl Fn(DVec3) -> f64) -> GridField {
    let h = 6.0 / (n - 1) as f64;
    let mut data = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                data.push(f(DVec3::new(i as f64, j as f64, k as f64) * h - 3.0) as f32);
            }
        }
    }
    let grid = Grid::new([n; 3], DVec3::splat(-3.0), DVec3::splat(h), data).unwrap();
    GridField::new(grid, Interp::Trilinear, 1.0).unwrap()
}

fn knife_image(render: impl Fn(&mut Film)) -> Vec<f32> {
    let mut film = Film::new(24, 24, Filter::Box).unwrap();
    render(&mut film);
    film.normalized().iter().map(|p| p[0]).collect()
}

fn max_diff(a: &[f32], b: &[f32]) -> f64 {
    a.iter().zip(b).map(|(x, y)| f64::from((x - y).abs())).fold(0.0, f64::max)
}

/// A Gaussian bump (docs/oracles.md §5) sampled on grids of 7, 13 and 25 points a
/// side: the knife-edge images from the trilinear grid and from the mesh's
/// tetrahedra differ by what the two interpolants do, at second order in
/// the spacing while that difference is above the grid's `f32` samples'
/// noise. Measured: 0.024, 0.0078, 0.0061 (0.0035 at 49 points; with 64
/// photons a pixel on the sheet 0.0021, 0.0014, 0.0011 at 13, 25, 49: the
/// floor). The split of 6 tetrahedra per hexahedron gave 0.033 and 0.0077
/// at 13 and 25.
#[test]
fn grid_and_its_tetrahedra_give_the_same_image() {
    let bump = |p: DVec3| 1.0 + 1e-4 * (-p.length_squared() / 2.0).exp();
    let b = bench(knife(2000.0), 3);
    let mut diffs = Vec::new();
    for n in [7, 13, 25] {
        let (grid, mesh) = (grid(n, &bump), mesh(n, -3.0, 3.0, &bump));
        let params = rt_photo::TraceParams::for_grid(&grid);
        let gb = rt_photo::SchlierenBench { params, ..b.clone() };
        let g = knife_image(|film| gb.render(&grid, film, 0, 1).unwrap());
        let mesh = Medium::ExactMesh(mesh);
        let m = knife_image(|film| b.render_medium(&mesh, film, 0, 1).unwrap());
        let contrast = g.iter().fold(0.0f32, |a, &v| a.max((v - 1.0).abs()));
        assert!(contrast > 0.2, "the bump shows: contrast {contrast}");
        diffs.push(max_diff(&g, &m));
    }
    assert!(diffs[1] < 0.012 && diffs[2] < 0.01, "{diffs:?}");
    assert!(diffs[0] / diffs[1] > 2.5, "second order: {diffs:?}");
}

/// A field linear in space is reproduced exactly by both interpolants
/// (the grid's up to its f32 samples): over the same box, the images agree
/// to the grid tracer's integration error.
#[test]
fn linear_field_gives_the_same_image() {
    let lin = |p: DVec3| 1.0 + 1e-3 * (p.x + 0.5 * p.y);
    let g = grid(7, &lin);
    // The grid reaches half a cell past its outer samples.
    let (lo, hi) = (g.bounds().min.x, g.bounds().max.x);
    let m = mesh(5, lo, hi, &lin);
    let b = bench(knife(20.0), 2);
    let gi = knife_image(|film| b.render(&g, film, 0, 3).unwrap());
    let m = Medium::ExactMesh(m);
    let mi = knife_image(|film| b.render_medium(&m, film, 0, 3).unwrap());
    // The uniform deflection cuts the knife edge to a level far from 0.5.
    assert!((gi[0] - 1.0).abs() > 0.1, "{}", gi[0]);
    // Pixels away from the outer half cell, where the trilinear grid
    // holds its outer samples' values rather than continuing the gradient.
    let inner = |img: &[f32]| -> Vec<f32> {
        (0..24 * 24)
            .filter(|k| (2..22).contains(&(k % 24)) && (2..22).contains(&(k / 24)))
            .map(|k| img[k])
            .collect()
    };
    let (gi, mi) = (inner(&gi), inner(&mi));
    let d = max_diff(&gi, &mi);
    assert!(d < 1e-4, "{d}");
}

/// Multifield on a mesh: photons carry the colour of a second field
/// averaged where they leave each cell; with a scalar equal to x and a
/// uniform index, each image column shows the colour map at that x.
#[test]
fn mesh_photons_carry_the_colour_of_a_second_field() {
    let m = mesh(7, -3.0, 3.0, &|_| 1.0);
    let map = rt_photo::ColorMap::viridis().with_range(-3.0, 3.0).unwrap();
    let mut film = Film::new(24, 8, Filter::Box).unwrap();
    let b = bench(rt_photo::Mode::Schlieren(rt_photo::Cutoff::None), 2);
    b.render_mesh_colored(&m, &|x: DVec3| x.x, &map, &mut film, 0, 4).unwrap();
    let img = film.normalized();
    for j in 0..8 {
        for i in 0..24 {
            let x = (i as f64 + 0.5) / 24.0 * 6.0 - 3.0;
            let want = map.map(x as f32);
            let got = img[i + 24 * j];
            for c in 0..3 {
                // Compared as shown (sRGB), where the map is even.
                let (g, w) = (linear_to_srgb(got[c]), linear_to_srgb(want[c]));
                assert!((g - w).abs() < 0.03, "pixel {i},{j}: {got:?} vs {want:?}");
            }
        }
    }
}
