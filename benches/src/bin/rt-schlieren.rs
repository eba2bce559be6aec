//! Renders a synthetic schlieren / shadowgraph / interferogram of a user's
//! gridded file (raw + JSON, NRRD, VTK image data).
//!
//! ```text
//! cargo run --release -p rt-benches --bin rt-schlieren -- FILE [options]
//!   --quantity density|index   samples are density (Gladstone–Dale) or index (default density)
//!   --k K                      Gladstone–Dale constant, m³/kg (default 2.26e-4)
//!   --cutoff knife|graded|pinhole|darkfield|color|none|interferometry   (default knife)
//!   --angle DEG                knife edge / graded filter direction (default 0: edge ⟂ x)
//!   --f F --h H                focal length and source image height (default 1, 2e-3)
//!   --radius R                 pinhole / dark-field radius in the focal plane (default 2e-4)
//!   --lambda M --fringes M     interferometry wavelength and fringe spacing (default 10.6e-6, none)
//!   --film-distance L          shadowgraph distance behind the volume (default 0)
//!   --axis x|y|z               beam direction (default z)
//!   --size N                   image N×N (default 512)
//!   --passes P                 progressive passes of 1 photon per pixel each (default 4)
//!   --out PATH                 PNG to write (default out/schlieren.png)
//! ```
// A std-only tool crate: the no_std import lints guard the libraries.
#![allow(clippy::std_instead_of_core, clippy::std_instead_of_alloc, clippy::alloc_instead_of_core)]

use std::{io::Write as _, path::PathBuf, process::ExitCode};

use glam::DVec3;
use rt_benches::image::write_png;
use rt_core::{Frame, Pixel};
use rt_photo::{Bench, Cutoff, Film, Filter, FilterImage, Mode, Weighting};
use rt_volume::{GLADSTONE_DALE_AIR, GridField, Interp, Method, TraceParams, gladstone_dale, io};

struct Args {
    file: PathBuf,
    opts: Vec<(String, String)>,
}

impl Args {
    fn parse() -> Result<Self, String> {
        let mut it = std::env::args().skip(1);
        let file = it.next().ok_or("usage: rt-schlieren FILE [--option value]...")?;
        let mut opts = Vec::new();
        while let Some(k) = it.next() {
            let key =
                k.strip_prefix("--").ok_or_else(|| format!("expected --option, got `{k}`"))?;
            let v = it.next().ok_or_else(|| format!("--{key} needs a value"))?;
            opts.push((key.to_string(), v));
        }
        Ok(Self { file: file.into(), opts })
    }

    fn get(&self, key: &str) -> Option<&str> {
        self.opts.iter().rev().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }

    fn num(&self, key: &str, default: f64) -> Result<f64, String> {
        self.get(key).map_or(Ok(default), |v| {
            v.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("--{key}: `{v}` is not a finite number"))
        })
    }
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("rt-schlieren: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), String> {
    let a = Args::parse()?;
    let grid = io::read_grid(&a.file).map_err(|e| e.to_string())?;
    let k = a.num("k", GLADSTONE_DALE_AIR)?;
    let grid = match a.get("quantity").unwrap_or("density") {
        "density" => {
            grid.map(|r| gladstone_dale(f64::from(r), k) as f32).map_err(|e| e.to_string())?
        }
        "index" => grid,
        q => return Err(format!("--quantity: `{q}` (density or index)")),
    };
    let field = GridField::new(grid, Interp::CatmullRom, 1.0).map_err(|e| e.to_string())?;
    let b = field.grid().bounds();
    let (dir, u) = match a.get("axis").unwrap_or("z") {
        "x" => (DVec3::X, DVec3::Y),
        "y" => (DVec3::Y, DVec3::Z),
        "z" => (DVec3::Z, DVec3::X),
        s => return Err(format!("--axis: `{s}` (x, y or z)")),
    };
    let v = dir.cross(u);
    let ext = b.max - b.min;
    let (f, h) = (a.num("f", 1.0)?, a.num("h", 2e-3)?);
    let angle = a.num("angle", 0.0)?.to_radians();
    let mode = match a.get("cutoff").unwrap_or("knife") {
        "knife" => Mode::Schlieren(Cutoff::KnifeEdge { angle, offset: 0.0, f, h }),
        "graded" => Mode::Schlieren(Cutoff::Graded { angle, f, width: h }),
        "pinhole" | "darkfield" => Mode::Schlieren(Cutoff::Pinhole {
            f,
            radius: a.num("radius", 2e-4)?,
            dark_field: a.get("cutoff") == Some("darkfield"),
        }),
        "color" => Mode::Schlieren(Cutoff::Color(FilterImage::hue_wheel(256, h / f))),
        "none" => Mode::Schlieren(Cutoff::None),
        "interferometry" => Mode::Interferometry {
            lambda: a.num("lambda", 10.6e-6)?,
            n_ref: field.grid().data().first().map_or(1.0, |&x| f64::from(x)),
            fringe_spacing: a
                .get("fringes")
                .map(|s| s.parse().map_err(|_| format!("--fringes: `{s}`")))
                .transpose()?,
        },
        c => return Err(format!("--cutoff: `{c}`")),
    };
    let size = a.num("size", 512.0)? as usize;
    let passes = a.num("passes", 4.0)? as u64;
    let bench = Bench {
        center: 0.5 * (b.min + b.max) - (0.5 * ext.dot(dir) + 0.1 * ext.length()) * dir,
        direction: dir,
        u,
        width: ext.dot(u),
        height: ext.dot(v),
        film_distance: a.num("film-distance", 0.0)?,
        mode,
        weighting: Weighting::Weight,
        strata: 1,
        params: TraceParams::fixed(Method::Rk4, field.grid().spacing().min_element()),
    };
    let height = ((size as f64) * bench.height / bench.width).round().max(1.0) as usize;
    let mut film = Film::new(size, height, Filter::Tent).map_err(|e| e.to_string())?;
    for pass in 0..passes.max(1) {
        bench.render(&field, &mut film, pass, 1).map_err(|e| e.to_string())?;
        let done = (pass + 1) as usize * 30 / passes.max(1) as usize;
        eprint!(
            "\r[{}{}] pass {}/{} ",
            "#".repeat(done),
            " ".repeat(30 - done),
            pass + 1,
            passes.max(1)
        );
        std::io::stderr().flush().ok();
    }
    eprintln!();
    let out = a.get("out").map_or_else(|| PathBuf::from("out/schlieren.png"), PathBuf::from);
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    let scale = if matches!(bench.mode, Mode::Schlieren(Cutoff::None)) { 0.5 } else { 1.0 };
    let mut frame = Frame::new(size as u32, height as u32).map_err(|e| e.to_string())?;
    for (p, c) in frame.pixels_mut().iter_mut().zip(film.normalized()) {
        *p = Pixel { color: [c[0] * scale, c[1] * scale, c[2] * scale, 1.0], depth: 0.0 };
    }
    write_png(&frame, &out)?;
    println!(
        "wrote {} ({size}×{height}, {} photons, {} left the film)",
        out.display(),
        film.emitted,
        film.lost
    );
    Ok(())
}
