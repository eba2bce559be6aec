//! Synthetic schlieren, shadowgraph and interferometry of the built-in
//! blast wave.

use std::{path::Path, time::Instant};

use glam::DVec3;
use rt_benches::image::write_png;
use rt_core::{Frame, Pixel};
use rt_photo::{Bench, Cutoff, Film, Filter, FilterImage, Mode, Weighting};
use rt_volume::{GLADSTONE_DALE_AIR, GridField, Interp, Method, TraceParams, gladstone_dale, io};

const RAW: &[u8] = include_bytes!("../../../data/blast_sedov_64.raw");
const JSON: &str = include_str!("../../../data/blast_sedov_64.json");
const SIZE: usize = 400;

fn field() -> Result<GridField, String> {
    let header: serde_json::Value = serde_json::from_str(JSON).map_err(|e| e.to_string())?;
    let rho = io::parse_raw_json(&header, RAW).map_err(|e| e.to_string())?;
    let n = rho
        .map(|r| gladstone_dale(f64::from(r), GLADSTONE_DALE_AIR) as f32)
        .map_err(|e| e.to_string())?;
    // C¹ Catmull–Rom: trilinear gradients jump at cell faces, which the
    // shadowgraph (second derivative) shows as a grid.
    GridField::new(n, Interp::CatmullRom, 1.0).map_err(|e| e.to_string())
}

fn write(film: &Film, scale: f32, path: &Path) -> Result<(), String> {
    let mut frame = Frame::new(SIZE as u32, SIZE as u32).map_err(|e| e.to_string())?;
    for (p, v) in frame.pixels_mut().iter_mut().zip(film.normalized()) {
        *p = Pixel { color: [v[0] * scale, v[1] * scale, v[2] * scale, 1.0], depth: 0.0 };
    }
    Ok(write_png(&frame, path)?)
}

pub(crate) fn render_all(out: &Path) -> Result<(), String> {
    let f = field()?;
    let h = f.grid().spacing().x;
    let base = Bench {
        center: DVec3::new(0.0, 0.0, -0.6),
        direction: DVec3::Z,
        u: DVec3::X,
        width: 1.0,
        height: 1.0,
        film_distance: 0.0,
        mode: Mode::Schlieren(Cutoff::None),
        weighting: Weighting::Weight,
        strata: 2,
        params: TraceParams::fixed(Method::Rk4, h),
    };
    let jobs: [(&str, Bench, f32); 4] = [
        (
            "schlieren-knife.png",
            Bench {
                mode: Mode::Schlieren(Cutoff::KnifeEdge {
                    angle: 0.0,
                    offset: 0.0,
                    f: 1.0,
                    h: 2e-3,
                }),
                ..base.clone()
            },
            1.0,
        ),
        ("shadowgraph.png", Bench { film_distance: 2.0, ..base.clone() }, 0.5),
        (
            "interferogram.png",
            Bench {
                // A CO₂ laser (10.6 µm): the blast's optical path excess of
                // ~1e-4 m then spans a few dozen fringes instead of hundreds
                // below the pixel size at visible wavelengths.
                mode: Mode::Interferometry {
                    lambda: 10.6e-6,
                    n_ref: 1.000226,
                    fringe_spacing: Some(0.04),
                },
                ..base.clone()
            },
            1.0,
        ),
        (
            "schlieren-color.png",
            Bench {
                mode: Mode::Schlieren(Cutoff::Color(FilterImage::hue_wheel(256, 2e-3))),
                ..base
            },
            1.0,
        ),
    ];
    for (name, bench, scale) in jobs {
        let t = Instant::now();
        let mut film = Film::new(SIZE, SIZE, Filter::Tent).map_err(|e| e.to_string())?;
        bench.render(&f, &mut film, 0, 2026).map_err(|e| e.to_string())?;
        let path = out.join(name);
        write(&film, scale, &path)?;
        println!(
            "wrote {} ({SIZE}×{SIZE}, {} photons, {:.1} s)",
            path.display(),
            film.emitted,
            t.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
