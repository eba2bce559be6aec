//! `rt serve` as a client other than its page meets it, over plain TCP:
//! only its own origin is answered, bad settings are a message (the
//! server goes on), and the image it serves is the one `rt schlieren`
//! writes with the command line it shows. (The page itself, in a real
//! browser: `tests/serve_browser.py`, run by CI.)

use core::time::Duration;
use std::{
    io::{BufRead, BufReader, Read, Write},
    net::TcpStream,
    path::{Path, PathBuf},
    process::{Child, Command, Stdio},
    time::Instant,
};

fn blast_wave() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../rt-tools/data/blast_sedov_64.nhdr")
}

/// The server, killed when dropped.
struct Server {
    child: Child,
    addr: String,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn serve(out: &Path) -> Server {
    let mut child = Command::new(env!("CARGO_BIN_EXE_rt"))
        .args(["serve", blast_wave().to_str().unwrap(), "--device", "cpu", "--out"])
        .arg(out)
        .stdout(Stdio::piped())
        .spawn()
        .expect("run rt serve");
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap()).read_line(&mut line).unwrap();
    let addr = line
        .strip_prefix("rt serve: http://")
        .and_then(|r| r.split('/').next())
        .unwrap_or_else(|| panic!("no address in {line:?}"))
        .to_string();
    assert!(addr.starts_with("127.0.0.1:"), "{addr}");
    Server { child, addr }
}

/// One request; `(status, body)`.
fn request(
    addr: &str,
    method: &str,
    path: &str,
    headers: &[(&str, &str)],
    body: &[u8],
) -> (u16, Vec<u8>) {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
    // HTTP/1.0: the whole body, never chunked.
    let mut head = format!("{method} {path} HTTP/1.0\r\n");
    if !headers.iter().any(|(k, _)| *k == "Host") {
        head.push_str(&format!("Host: {addr}\r\n"));
    }
    for (k, v) in headers {
        head.push_str(&format!("{k}: {v}\r\n"));
    }
    head.push_str(&format!("Content-Length: {}\r\n\r\n", body.len()));
    s.write_all(head.as_bytes()).unwrap();
    s.write_all(body).unwrap();
    let mut all = Vec::new();
    s.read_to_end(&mut all).unwrap();
    let split = all.windows(4).position(|w| w == b"\r\n\r\n").expect("a response head");
    let status = String::from_utf8_lossy(&all[..split])
        .split_whitespace()
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap();
    (status, all[split + 4..].to_vec())
}

fn json(body: &[u8]) -> serde_json::Value {
    serde_json::from_slice(body)
        .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(body)))
}

/// Waits for an image of `generation` with all its passes done, or a
/// message about it.
fn settled(addr: &str, generation: u64) -> serde_json::Value {
    let t = Instant::now();
    let mut after = 0;
    while t.elapsed() < Duration::from_secs(120) {
        let (status, body) = request(addr, "GET", &format!("/api/frame?after={after}"), &[], b"");
        assert_eq!(status, 200);
        let f = json(&body);
        after = f["serial"].as_u64().unwrap();
        let done = f["pass"].as_u64() == f["passes"].as_u64() && f["pass"].as_u64() > Some(0);
        if f["generation"].as_u64() == Some(generation) && (done || !f["message"].is_null()) {
            return f;
        }
    }
    panic!("generation {generation} did not settle");
}

fn decode(png_bytes: &[u8]) -> (u32, u32, Vec<u8>) {
    let mut reader = png::Decoder::new(png_bytes).read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

#[test]
fn the_server_answers_its_own_page_only_and_serves_rt_schlierens_image() {
    let out = std::env::temp_dir().join(format!("rt-serve-test-{}", std::process::id()));
    let server = serve(&out);
    let addr = server.addr.as_str();
    let origin = format!("http://{addr}");
    let own = [("Origin", origin.as_str())];

    let (status, page) = request(addr, "GET", "/", &[], b"");
    assert_eq!(status, 200);
    assert!(String::from_utf8_lossy(&page).contains("<title>rt serve"));
    // Another name for 127.0.0.1 (DNS rebinding), another site's page, a
    // change with no origin, a path outside the API: refused.
    let evil_host = [("Host", "rebound.example:80")];
    assert_eq!(request(addr, "GET", "/", &evil_host, b"").0, 403);
    let evil = [("Origin", "http://evil.example")];
    assert_eq!(request(addr, "POST", "/api/settings", &evil, b"{}").0, 403);
    assert_eq!(request(addr, "GET", "/api/image.png", &evil, b"").0, 403);
    assert_eq!(request(addr, "POST", "/api/settings", &[], b"{}").0, 403);
    assert_eq!(request(addr, "GET", "/../Cargo.toml", &[], b"").0, 404);
    assert_eq!(request(addr, "GET", "/api/deflections.bin", &[], b"").0, 404);

    // Bad settings: refused by name, or shown as the page's message.
    let (status, body) = request(addr, "POST", "/api/settings", &own, br#"{"knive":1}"#);
    assert_eq!(status, 400);
    assert!(json(&body)["message"].as_str().unwrap().contains("`knive`"));
    assert_eq!(request(addr, "POST", "/api/settings", &own, b"not json").0, 400);
    let (_, body) = request(addr, "POST", "/api/settings", &own, br#"{"size":0}"#);
    let f = settled(addr, json(&body)["generation"].as_u64().unwrap());
    assert!(f["message"].as_str().unwrap().contains("--size"), "{f}");

    // A knife at 90°: the image is `rt schlieren`'s with the shown command.
    let settings = br#"{"cutoff":"knife","angle":90,"size":40,"photons":4}"#;
    let (status, body) = request(addr, "POST", "/api/settings", &own, settings);
    assert_eq!(status, 202);
    let f = settled(addr, json(&body)["generation"].as_u64().unwrap());
    assert!(f["message"].is_null(), "{f}");
    let command = f["command"].as_str().unwrap();
    let words: Vec<&str> = command.split(' ').collect();
    assert_eq!(&words[..2], ["rt", "schlieren"]);
    assert!(command.ends_with("--cutoff knife --angle 90 --size 40 --photons 4"), "{command}");
    let (status, served) = request(addr, "GET", "/api/image.png", &[], b"");
    assert_eq!(status, 200);
    let cli = out.join("cli.png");
    let o = Command::new(env!("CARGO_BIN_EXE_rt"))
        .args(&words[1..])
        .args(["--no-figure", "--out"])
        .arg(&cli)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (w, h, pixels) = decode(&served);
    assert_eq!((w, h), (40, 40));
    assert!(pixels == decode(&std::fs::read(&cli).unwrap()).2, "not rt schlieren's image");

    // Painting: the picking pass's deflections, and a filter to apply.
    let (_, body) =
        request(addr, "POST", "/api/settings", &own, br#"{"size":40,"photons":4,"paint":true}"#);
    let f = settled(addr, json(&body)["generation"].as_u64().unwrap());
    assert!(f["half_range"].as_f64().unwrap() > 0.0, "{f}");
    assert!(f["command"].as_str().unwrap().contains("--cutoff color --filter"), "{f}");
    let (status, defl) = request(addr, "GET", "/api/deflections.bin", &[], b"");
    assert_eq!((status, defl.len()), (200, 40 * 40 * 12));
    let (status, _) = request(addr, "POST", "/api/filter", &own, b"not a png");
    assert_eq!(status, 400);
    drop(server);
    std::fs::remove_dir_all(&out).ok();
}
