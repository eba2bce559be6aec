//! Minimal log–log line plots as PNG (no text: the report's tables carry
//! the numbers; colours are listed next to each plot).

use std::{fmt, path::Path};

use rt_core::{Frame, FrameError, Pixel};

use crate::image::{WriteError, write_png};

/// Why a plot could not be drawn.
#[derive(Debug)]
pub enum PlotError {
    /// No point with both coordinates finite and positive.
    Empty,
    /// The image could not be made (zero or huge size).
    Frame(FrameError),
    /// The PNG could not be written.
    Write(WriteError),
}

impl fmt::Display for PlotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Empty => f.write_str("nothing to plot"),
            Self::Frame(e) => write!(f, "plot image: {e}"),
            Self::Write(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for PlotError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Empty => None,
            Self::Frame(e) => Some(e),
            Self::Write(e) => Some(e),
        }
    }
}

/// For the tools' one-line messages.
impl From<PlotError> for String {
    fn from(e: PlotError) -> Self {
        e.to_string()
    }
}

/// One polyline: points `(x, y)` (both > 0) and an RGB colour.
#[derive(Clone, Debug)]
pub struct Series {
    /// Points in data units.
    pub points: Vec<(f64, f64)>,
    /// Linear RGB in `[0, 1]`.
    pub color: [f32; 3],
}

/// The colours given to series in order (name them in the caption).
pub const PALETTE: [([f32; 3], &str); 6] = [
    ([0.85, 0.20, 0.15], "red"),
    ([0.10, 0.45, 0.85], "blue"),
    ([0.15, 0.65, 0.25], "green"),
    ([0.60, 0.25, 0.75], "purple"),
    ([0.95, 0.60, 0.05], "orange"),
    ([0.25, 0.25, 0.25], "grey"),
];

/// Draws `series` on log–log axes with decade grid lines; points on the
/// Pareto front of all series (no other point is both faster and more
/// accurate) get a black ring. Writes a `width × height` PNG.
///
/// # Errors
/// [`PlotError`]: nothing to plot, a bad size, or the file.
pub fn loglog(series: &[Series], width: u32, height: u32, path: &Path) -> Result<(), PlotError> {
    let pts: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .filter(|&(x, y)| x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite())
        .collect();
    if pts.is_empty() {
        return Err(PlotError::Empty);
    }
    let lx: Vec<f64> = pts.iter().map(|p| p.0.log10()).collect();
    let ly: Vec<f64> = pts.iter().map(|p| p.1.log10()).collect();
    let (x0, x1) = (
        lx.iter().copied().fold(f64::MAX, f64::min).floor(),
        lx.iter().copied().fold(f64::MIN, f64::max).ceil(),
    );
    let (y0, y1) = (
        ly.iter().copied().fold(f64::MAX, f64::min).floor(),
        ly.iter().copied().fold(f64::MIN, f64::max).ceil(),
    );
    let (x1, y1) = (x1.max(x0 + 1.0), y1.max(y0 + 1.0));
    let mut frame = Frame::new(width, height).map_err(PlotError::Frame)?;
    for p in frame.pixels_mut() {
        *p = Pixel { color: [1.0; 4], depth: 0.0 };
    }
    let m = 20.0;
    let to_px = |x: f64, y: f64| {
        let u = (x.log10() - x0) / (x1 - x0);
        let v = (y.log10() - y0) / (y1 - y0);
        (
            m + u * (f64::from(width) - 2.0 * m),
            f64::from(height) - m - v * (f64::from(height) - 2.0 * m),
        )
    };
    let put = |f: &mut Frame, x: f64, y: f64, c: [f32; 3]| {
        if let Some(p) = f.get_mut(x.round() as u32, y.round() as u32) {
            p.color = [c[0], c[1], c[2], 1.0];
        }
    };
    // Decade grid.
    let grey = [0.85, 0.85, 0.85];
    for d in x0 as i32..=x1 as i32 {
        let (px, _) = to_px(10f64.powi(d), 10f64.powf(y0));
        for y in 0..height {
            put(&mut frame, px, f64::from(y), grey);
        }
    }
    for d in y0 as i32..=y1 as i32 {
        let (_, py) = to_px(10f64.powf(x0), 10f64.powi(d));
        for x in 0..width {
            put(&mut frame, f64::from(x), py, grey);
        }
    }
    // Lines and dots.
    for s in series {
        let pts: Vec<(f64, f64)> =
            s.points.iter().copied().filter(|&(x, y)| x > 0.0 && y > 0.0).collect();
        for w in pts.windows(2) {
            let (a, b) = (to_px(w[0].0, w[0].1), to_px(w[1].0, w[1].1));
            let n = ((b.0 - a.0).abs().max((b.1 - a.1).abs()) as usize).max(1);
            for i in 0..=n {
                let t = i as f64 / n as f64;
                put(&mut frame, a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1), s.color);
            }
        }
        for &(x, y) in &pts {
            let (px, py) = to_px(x, y);
            for dy in -2..=2 {
                for dx in -2..=2 {
                    put(&mut frame, px + f64::from(dx), py + f64::from(dy), s.color);
                }
            }
        }
    }
    // Pareto front: rings around points no other point dominates.
    for &(x, y) in &pts {
        if pts.iter().any(|&(a, b)| a <= x && b <= y && (a < x || b < y)) {
            continue;
        }
        let (px, py) = to_px(x, y);
        for k in 0..32 {
            let a = f64::from(k) / 32.0 * std::f64::consts::TAU;
            put(&mut frame, px + 5.0 * a.cos(), py + 5.0 * a.sin(), [0.0; 3]);
        }
    }
    write_png(&frame, path).map_err(PlotError::Write)
}
