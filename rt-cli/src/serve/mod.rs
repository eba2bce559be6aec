//! `rt serve FILE`: the schlieren bench in the browser. A local HTTP
//! server (bound to 127.0.0.1 on a free port by default) serves one page
//! and a small API; the page posts its settings, and polls for the
//! newest image while the worker (`engine.rs`) refines it pass by pass.
//!
//! The API, all on the page's own origin (any request whose `Host` is not
//! the server's, or whose `Origin` is another site's, is refused with 403;
//! a request that changes state must carry the page's `Origin`):
//!
//! - `GET /`: the page;
//! - `POST /api/settings`: a JSON object of `rt schlieren` options (see
//!   `settings`), answered at once (the render restarts); 400 and the
//!   message for an unknown name;
//! - `GET /api/frame?after=N`: waits (up to 2 s) for an image newer than
//!   serial `N`, then its JSON description (serial, passes, photons,
//!   seconds, the optics chosen, the equivalent command line, or the
//!   message refusing the settings);
//! - `GET /api/image.png`: the newest image;
//! - `GET /api/deflections.bin`: painting: per pixel, rows top first,
//!   three little-endian f32 (light, `εu`, `εv`; NaN where no photon
//!   landed) of the picking pass;
//! - `POST /api/filter`: the painted filter as a square PNG (sRGB) over
//!   the focal plane's `±half_range`;
//! - `POST /api/save`: writes the figure `rt schlieren --figure` writes
//!   (and the painted filter beside it) into `--out`;
//! - `POST /api/close`: the page is closing; the work stops.

mod engine;
mod settings;

use std::{io::Read, net::SocketAddr, path::PathBuf, sync::Arc, time::Duration};

use anyhow::Context;
use rt_photo::FilterImage;
use tiny_http::{Header, Method, Request, Response, Server};

use crate::{
    optics::{DeviceArg, MeshOptions, Samples},
    schlieren,
};
use engine::Engine;
use settings::{FileOptions, Settings};

/// The page, with its script and style (no other files are served).
const PAGE: &str = include_str!("page.html");

/// The largest request body read (a painted filter's PNG).
const MAX_BODY: usize = 8 << 20;

/// `rt serve FILE`: options.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The volume (as `rt schlieren` reads it).
    pub file: PathBuf,
    /// What the samples are.
    #[command(flatten)]
    pub samples: Samples,
    /// Accept densities ≤ 0 (or indices below 1) instead of refusing them.
    #[arg(long)]
    pub allow_nonphysical: bool,
    /// How an unstructured mesh is read and traced.
    #[command(flatten)]
    pub mesh: MeshOptions,
    /// Address to listen on: loopback by default, so only this machine
    /// reaches the page.
    #[arg(long, default_value = "127.0.0.1")]
    pub host: std::net::IpAddr,
    /// Port to listen on [default: 0, a free port, printed].
    #[arg(long, default_value_t = 0)]
    pub port: u16,
    /// Where the photons are traced: `auto` (the default: the GPU where it
    /// traces the volume, `--interp linear` grids; else the CPU), `cpu`,
    /// `gpu`.
    #[arg(long, value_enum, default_value_t = DeviceArg::Auto)]
    pub device: DeviceArg,
    /// Folder that "save figure" writes into.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
}

/// Runs `rt serve` until interrupted.
///
/// # Errors
/// An unreadable volume, an address that cannot be bound.
pub fn run(a: &Args) -> anyhow::Result<()> {
    let file_options = FileOptions {
        samples: a.samples,
        allow_nonphysical: a.allow_nonphysical,
        mesh: a.mesh.clone(),
    };
    // Read once now: a bad file fails here, not on the page.
    crate::optics::open(
        &a.file,
        a.samples,
        a.allow_nonphysical,
        crate::optics::Interpolation::Cubic,
        &a.mesh,
    )?;
    let server = Server::http(SocketAddr::new(a.host, a.port))
        .map_err(|e| anyhow::anyhow!("{e}"))
        .with_context(|| format!("cannot listen on {}:{}", a.host, a.port))?;
    let addr = server.server_addr().to_ip().context("not an IP address")?;
    let engine = Engine::new(a.file.clone(), file_options, a.device, a.out.clone());
    let worker = engine.clone();
    std::thread::Builder::new().name("bench".into()).spawn(move || worker.run())?;
    println!("rt serve: http://{addr}/  ({}; Ctrl-C to stop)", a.file.display());
    let server = Arc::new(server);
    let site = Arc::new(Site { engine, addr });
    let handlers: Vec<_> = (0..4)
        .map(|_| {
            let (server, site) = (server.clone(), site.clone());
            std::thread::spawn(move || {
                while let Ok(request) = server.recv() {
                    site.answer(request);
                }
            })
        })
        .collect();
    for h in handlers {
        h.join().ok();
    }
    Ok(())
}

/// What the requests share.
struct Site {
    engine: Arc<Engine>,
    addr: SocketAddr,
}

/// A response: status, content type, body.
type Answer = (u16, &'static str, Vec<u8>);

fn json(status: u16, v: &serde_json::Value) -> Answer {
    (status, "application/json", v.to_string().into_bytes())
}

fn message(status: u16, text: &str) -> Answer {
    json(status, &serde_json::json!({ "message": text }))
}

impl Site {
    fn answer(&self, mut request: Request) {
        let (status, kind, body) = match self.allowed(&request) {
            Err(why) => message(403, why),
            Ok(()) => {
                let answer = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    self.route(&mut request)
                }));
                answer.unwrap_or_else(|_| message(500, "internal error (please report it)"))
            }
        };
        let header = |k: &str, v: &str| Header::from_bytes(k.as_bytes(), v.as_bytes()).ok();
        let mut response = Response::from_data(body).with_status_code(status);
        for h in [header("Content-Type", kind), header("Cache-Control", "no-store")]
            .into_iter()
            .flatten()
        {
            response.add_header(h);
        }
        // The peer may have gone; nothing to do about it.
        let _ = request.respond(response);
    }

    /// Only the page's own origin: the `Host` must be the server's (a
    /// site that rebinds a name to 127.0.0.1 sends its own name), a
    /// cross-site `Origin` is refused, and a change must name the origin.
    fn allowed(&self, r: &Request) -> Result<(), &'static str> {
        let get = |name: &'static str| {
            r.headers().iter().find(|h| h.field.equiv(name)).map(|h| h.value.as_str().to_string())
        };
        let port = self.addr.port();
        let hosts = [format!("{}:{port}", self.addr.ip()), format!("localhost:{port}")];
        match get("Host") {
            Some(h) if hosts.contains(&h) => {}
            _ => return Err("this server answers its own address only"),
        }
        let origin = get("Origin");
        if let Some(o) = &origin
            && !hosts.iter().any(|h| *o == format!("http://{h}"))
        {
            return Err("requests from other sites are refused");
        }
        if *r.method() == Method::Post && origin.is_none() {
            return Err("a change must come from the page (no Origin)");
        }
        Ok(())
    }

    fn route(&self, r: &mut Request) -> Answer {
        let url = r.url().to_string();
        let (path, query) = url.split_once('?').unwrap_or((&url, ""));
        match (r.method().clone(), path) {
            (Method::Get, "/") => (200, "text/html; charset=utf-8", PAGE.as_bytes().to_vec()),
            (Method::Post, "/api/settings") => match body(r).and_then(|b| Settings::parse(&b)) {
                Ok(s) => {
                    let generation = self.engine.set(s);
                    json(202, &serde_json::json!({ "generation": generation }))
                }
                Err(e) => message(400, &e),
            },
            (Method::Get, "/api/frame") => {
                let after = query
                    .split('&')
                    .find_map(|kv| kv.strip_prefix("after="))
                    .and_then(|v| v.parse().ok())
                    .unwrap_or(0);
                let s = self.engine.frame(after, Duration::from_secs(2));
                json(200, &describe(&s))
            }
            (Method::Get, "/api/image.png") => {
                let s = self.engine.shown();
                if s.png.is_empty() {
                    message(404, "no image yet")
                } else {
                    (200, "image/png", s.png.as_ref().clone())
                }
            }
            (Method::Get, "/api/deflections.bin") => match self.engine.shown().picking {
                Some(film) => (200, "application/octet-stream", deflections(&film)),
                None => message(404, "no picking pass: turn painting on"),
            },
            (Method::Post, "/api/filter") => {
                let Some(h) = self.engine.shown().half_range else {
                    return message(409, "no focal plane yet: turn painting on");
                };
                match body(r).and_then(|b| read_filter(&b, h).map(|f| (f, b))) {
                    Ok((f, png)) => {
                        self.engine.paint(f, png);
                        json(202, &serde_json::json!({}))
                    }
                    Err(e) => message(400, &e),
                }
            }
            (Method::Post, "/api/save") => match self.save(r) {
                Ok(v) => json(200, &v),
                Err(e) => message(400, &crate::one_line(&e)),
            },
            (Method::Post, "/api/close") => {
                self.engine.leave();
                json(202, &serde_json::json!({}))
            }
            _ => message(404, "not found"),
        }
    }

    /// "Save figure": what `rt schlieren` with the page's settings writes
    /// (the painted filter as `filter.png` beside it when painting).
    fn save(&self, r: &mut Request) -> anyhow::Result<serde_json::Value> {
        let settings =
            Settings::parse(&body(r).map_err(anyhow::Error::msg)?).map_err(anyhow::Error::msg)?;
        let engine = &self.engine;
        std::fs::create_dir_all(&engine.out).with_context(|| engine.out.display().to_string())?;
        let filter = engine.out.join("filter.png");
        let argv = match engine.shown().half_range {
            Some(h) if settings.paint => {
                let png = engine.filter_png().context("paint a filter first")?;
                std::fs::write(&filter, png).with_context(|| filter.display().to_string())?;
                settings.figure(&filter, h)
            }
            _ => settings.traced(),
        };
        let mut a = settings::args(&engine.file, &engine.file_options, &argv)
            .map_err(anyhow::Error::msg)?;
        let stem = if settings.paint { "painted" } else { "schlieren" };
        a.out = engine.out.join(format!("{stem}.png"));
        a.figure = true;
        a.no_figure = false;
        let medium = crate::optics::open(
            &engine.file,
            engine.file_options.samples,
            engine.file_options.allow_nonphysical,
            a.interp,
            &engine.file_options.mesh,
        )?;
        schlieren::render(&medium, &a)?;
        let mut words = argv.clone();
        words.extend(["--out".into(), a.out.display().to_string()]);
        Ok(serde_json::json!({
            "written": [a.out.display().to_string(), crate::image::beside(&a.out, "figure").display().to_string()],
            "command": settings::command_line(&engine.file, &engine.file_options, &words),
        }))
    }
}

/// The request's body, at most [`MAX_BODY`] bytes.
fn body(r: &mut Request) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    r.as_reader()
        .take(MAX_BODY as u64 + 1)
        .read_to_end(&mut out)
        .map_err(|e| format!("reading the request: {e}"))?;
    if out.len() > MAX_BODY {
        return Err(format!("the request is larger than {MAX_BODY} bytes"));
    }
    Ok(out)
}

/// A painted filter from PNG bytes over `±half_range`.
fn read_filter(png: &[u8], half_range: f64) -> Result<FilterImage, String> {
    FilterImage::from_png(png, half_range).map_err(|e| e.to_string())
}

/// The picking pass's light and mean deflection per pixel (f32 LE).
fn deflections(film: &rt_photo::Film) -> Vec<u8> {
    let mut out = Vec::with_capacity(film.width() * film.height() * 12);
    for (light, eps) in film.normalized_iter().zip(film.deflection_iter()) {
        let (u, v) = eps.unwrap_or((f64::NAN, f64::NAN));
        for x in [light[0], u, v] {
            out.extend_from_slice(&(x as f32).to_le_bytes());
        }
    }
    out
}

/// The JSON the page reads of an image.
fn describe(s: &engine::Shown) -> serde_json::Value {
    serde_json::json!({
        "serial": s.serial,
        "generation": s.generation,
        "pass": s.pass,
        "passes": s.passes,
        "photons": s.photons,
        "seconds": s.seconds,
        "width": s.width,
        "height": s.height,
        "message": s.message,
        "optics": s.optics,
        "device": s.device,
        "command": s.command,
        "half_range": s.half_range,
        "scatter": s.picking.as_ref().map(|f| scatter(f, s.half_range.unwrap_or(1.0))),
    })
}

/// Up to 4096 pixels' mean deflections, as fractions of `half_range`
/// (the paint canvas's coordinates) to 1/1024 (a quarter of its pixel),
/// for the page's scatter; the undeflected ones left out.
fn scatter(film: &rt_photo::Film, half_range: f64) -> Vec<[f64; 2]> {
    let n = film.width() * film.height();
    let step = n.div_ceil(4096).max(1);
    let q = |x: f64| (x / half_range * 1024.0).round() / 1024.0;
    film.deflection_iter()
        .step_by(step)
        .flatten()
        .map(|(u, v)| [q(u), q(v)])
        .filter(|p| *p != [0.0, 0.0])
        .collect()
}
