//! Log–log plots of run time against error as PNG, drawn with plotters: a
//! title, labelled axes with tick values, a legend naming each series and
//! the Pareto front ringed.
//!
//! Text is set in DejaVu Sans, embedded from `assets/DejaVuSans.ttf` (its
//! licence is `assets/DejaVuSans-LICENSE`) and rasterised by `ab_glyph`, so
//! no system font library is needed. The PNG is written with `png`.

use std::{fmt, ops::Range, path::Path};

use plotters::{backend::DrawingBackend, drawing::DrawingAreaErrorKind, prelude::*};
use rt_tools::text::{FAMILY, register_font_once, superscript};

use rt_tools::image::{WriteError, write_rgb8};

/// The smallest and largest width or height, in pixels: below the smallest
/// the axis texts do not fit.
pub const SIDE: Range<u32> = 200..8193;

/// Plotters' error for the bitmap backend.
pub type DrawError = DrawingAreaErrorKind<<BitMapBackend<'static> as DrawingBackend>::ErrorType>;

/// Why a plot could not be drawn.
#[derive(Debug)]
pub enum PlotError {
    /// No point with both coordinates finite and positive.
    Empty,
    /// Width or height outside [`SIDE`].
    Size {
        /// The width asked for, in pixels.
        width: u32,
        /// The height asked for, in pixels.
        height: u32,
    },
    /// The embedded font could not be read (a damaged `assets/DejaVuSans.ttf`).
    Font,
    /// Plotters failed to lay out or draw the plot.
    Draw(DrawError),
    /// The PNG could not be written.
    Write(WriteError),
}

impl fmt::Display for PlotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Empty => f.write_str("nothing to plot"),
            Self::Size { width, height } => write!(
                f,
                "plot size {width} × {height}: each side must be {} to {} pixels",
                SIDE.start,
                SIDE.end - 1
            ),
            Self::Font => f.write_str("the plot font (assets/DejaVuSans.ttf) could not be read"),
            Self::Draw(e) => write!(f, "drawing the plot: {e}"),
            Self::Write(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for PlotError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Empty | Self::Size { .. } | Self::Font => None,
            Self::Draw(e) => Some(e),
            Self::Write(e) => Some(e),
        }
    }
}

impl From<DrawError> for PlotError {
    fn from(e: DrawError) -> Self {
        Self::Draw(e)
    }
}

/// For the tools' one-line messages.
impl From<PlotError> for String {
    fn from(e: PlotError) -> Self {
        e.to_string()
    }
}

/// One named polyline: points `(x, y)` joined in the order given; points
/// with a coordinate that is not finite and positive are left out.
#[derive(Clone, Debug, Default)]
pub struct Series {
    /// The legend's name for it.
    pub name: String,
    /// Points in data units.
    pub points: Vec<(f64, f64)>,
}

/// What one plot shows: its texts and its series. Lower is better on both
/// axes (run time on x, error on y): that is what the Pareto front means.
#[derive(Clone, Debug, Default)]
pub struct Plot {
    /// Printed above the plot.
    pub title: String,
    /// The x axis's label, with its unit (`"seconds per ray"`).
    pub x_label: String,
    /// The y axis's label, with its unit.
    pub y_label: String,
    /// Drawn in order; they take [`PALETTE`]'s colours and the markers
    /// circle, square, triangle, diamond in turn.
    pub series: Vec<Series>,
    /// Ring the Pareto front (for run time against error; off where the
    /// axes mean something else, e.g. frame time against scene size).
    pub pareto: bool,
}

/// The series' colours in order (Okabe & Ito 2008, readable with colour
/// blindness): blue, vermillion, bluish green, reddish purple, orange, sky
/// blue.
pub const PALETTE: [RGBColor; 6] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
];

/// Draws `plot` on log–log axes (decades, or 1–2–5 steps on short axes, as
/// labelled ticks) with a legend in the corner with the fewest points;
/// points on the Pareto front of all series (no other point is both faster
/// and more accurate) get a black ring. Writes a `width × height` PNG.
///
/// # Errors
/// [`PlotError`]: nothing to plot, a size outside [`SIDE`], the font,
/// plotters, or the file.
pub fn loglog(plot: &Plot, width: u32, height: u32, path: &Path) -> Result<(), PlotError> {
    if !SIDE.contains(&width) || !SIDE.contains(&height) {
        return Err(PlotError::Size { width, height });
    }
    let series: Vec<Vec<(f64, f64)>> = plot
        .series
        .iter()
        .map(|s| {
            s.points.iter().copied().filter(|&(x, y)| is_plottable(x) && is_plottable(y)).collect()
        })
        .collect();
    let all: Vec<(f64, f64)> = series.iter().flatten().copied().collect();
    if all.is_empty() {
        return Err(PlotError::Empty);
    }
    register()?;
    let x = Axis::covering(all.iter().map(|p| p.0));
    let y = Axis::covering(all.iter().map(|p| p.1));
    let mut rgb = vec![0u8; width as usize * height as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(&plot.title, (FAMILY, 22))
            .margin(14)
            // Room for a tick label centred on the x axis's right end.
            .margin_right(34)
            .x_label_area_size(52)
            .y_label_area_size(78)
            .build_cartesian_2d(
                x.range
                    .clone()
                    .log_scale()
                    .with_key_points(x.bold.clone())
                    .with_light_points(x.light.clone()),
                y.range
                    .clone()
                    .log_scale()
                    .with_key_points(y.bold.clone())
                    .with_light_points(y.light.clone()),
            )?;
        let (x_fmt, y_fmt) = (x.formatter(), y.formatter());
        chart
            .configure_mesh()
            .x_desc(&plot.x_label)
            .y_desc(&plot.y_label)
            .x_label_formatter(&x_fmt)
            .y_label_formatter(&y_fmt)
            .label_style((FAMILY, 16))
            .axis_desc_style((FAMILY, 16))
            .bold_line_style(RGBColor(205, 205, 205))
            .light_line_style(RGBColor(238, 238, 238))
            .draw()?;
        // Lines, then markers on top, one legend entry per series.
        for (i, (s, pts)) in plot.series.iter().zip(&series).enumerate() {
            let color = PALETTE[i % PALETTE.len()];
            let shape = marker(i);
            let key = offset(&shape, 10);
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), color.stroke_width(2)))?
                .label(s.name.as_str())
                .legend(move |p| {
                    EmptyElement::at(p)
                        + PathElement::new([(0, 0), (20, 0)], color.stroke_width(2))
                        + Polygon::new(key.clone(), color.filled())
                });
            chart.draw_series(
                pts.iter()
                    .map(|&p| EmptyElement::at(p) + Polygon::new(shape.clone(), color.filled())),
            )?;
        }
        // The Pareto front: points that no other point beats on both axes.
        if plot.pareto {
            let front: Vec<(f64, f64)> = all
                .iter()
                .copied()
                .filter(|&(px, py)| {
                    !all.iter().any(|&(a, b)| a <= px && b <= py && (a < px || b < py))
                })
                .collect();
            let ring = BLACK.stroke_width(2);
            chart
                .draw_series(
                    front.iter().map(|&p| EmptyElement::at(p) + Circle::new((0, 0), 8, ring)),
                )?
                .label("Pareto front")
                .legend(move |p| EmptyElement::at(p) + Circle::new((10, 0), 7, ring));
        }
        let front_name = plot.pareto.then_some("Pareto front");
        let names = plot.series.iter().map(|s| s.name.as_str()).chain(front_name);
        let corner = legend_corner(&x, &y, &series, names, chart.plotting_area().dim_in_pixel());
        chart
            .configure_series_labels()
            .position(corner)
            .margin(12)
            .legend_area_size(28)
            .label_font((FAMILY, 15))
            .background_style(WHITE.mix(0.9))
            .border_style(RGBColor(150, 150, 150))
            .draw()?;
        root.present()?;
    }
    write_rgb8(&rgb, width, height, path).map_err(PlotError::Write)
}

/// Registers the embedded font with plotters once per process.
fn register() -> Result<(), PlotError> {
    if register_font_once() { Ok(()) } else { Err(PlotError::Font) }
}

#[inline]
fn is_plottable(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

/// A log axis: its range in data units and the values of its labelled
/// ("bold") and unlabelled ("light") grid lines.
#[derive(Debug)]
struct Axis {
    range: Range<f64>,
    bold: Vec<f64>,
    light: Vec<f64>,
}

impl Axis {
    /// At most this many labelled ticks.
    const MAX_LABELS: usize = 8;

    /// An axis over `values` (all finite and > 0, at least one): at least
    /// one decade wide, padded by 4 % each side; ticks at decades where
    /// three or more fit (every second or more past [`Self::MAX_LABELS`],
    /// 2–9 between them as light lines while there is room), else at 1, 2,
    /// 5.
    fn covering(values: impl Iterator<Item = f64>) -> Self {
        let (lo, hi) = values
            .map(f64::log10)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
        let mid = 0.5 * (lo + hi);
        let half = (0.5 * (hi - lo)).max(0.5) * 1.04;
        let (lo, hi) = (mid - half, mid + half);
        let inside = |v: f64| (lo..=hi).contains(&v.log10());
        let decades: Vec<i32> = (lo.ceil() as i32..=hi.floor() as i32).collect();
        let all_mantissas = |mantissas: &[f64]| -> Vec<f64> {
            (lo.floor() as i32..=hi.floor() as i32)
                .flat_map(|k| mantissas.iter().map(move |m| m * 10f64.powi(k)))
                .filter(|&v| inside(v))
                .collect()
        };
        let (bold, light) = if decades.len() >= 3 {
            let step = decades.len().div_ceil(Self::MAX_LABELS) as i32;
            let (bold, rest): (Vec<i32>, Vec<i32>) =
                decades.iter().partition(|k| k.rem_euclid(step) == 0);
            let light = if decades.len() <= 6 {
                all_mantissas(&[2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
            } else {
                rest.iter().map(|&k| 10f64.powi(k)).collect()
            };
            (bold.iter().map(|&k| 10f64.powi(k)).collect(), light)
        } else {
            let light = all_mantissas(&[3.0, 4.0, 6.0, 7.0, 8.0, 9.0]);
            (all_mantissas(&[1.0, 2.0, 5.0]), light)
        };
        Self { range: 10f64.powf(lo)..10f64.powf(hi), bold, light }
    }

    /// Tick labels: plain decimals when every label lies in 0.001 … 10⁴,
    /// else powers of ten (`10⁻⁴`, `2×10⁻⁴`).
    fn formatter(&self) -> impl Fn(&f64) -> String + use<> {
        let plain = self.bold.iter().all(|&v| (0.00099..10001.0).contains(&v));
        move |&v| tick_label(v, plain)
    }
}

/// `v` (a tick: 1, 2 or 5 times a power of ten) as text.
fn tick_label(v: f64, plain: bool) -> String {
    let e = (v.log10() + 1e-9).floor() as i32;
    let m = (v / 10f64.powi(e)).round();
    if plain {
        format!("{:.*}", (-e).max(0) as usize, v)
    } else if m == 1.0 {
        format!("10{}", superscript(e))
    } else {
        format!("{m}×10{}", superscript(e))
    }
}

/// Series `i`'s marker, as pixel offsets around the point: circle,
/// square, triangle, diamond.
fn marker(i: usize) -> Vec<(i32, i32)> {
    match i % 4 {
        0 => (0..12)
            .map(|k| {
                let a = f64::from(k) / 12.0 * std::f64::consts::TAU;
                ((4.5 * a.cos()).round() as i32, (4.5 * a.sin()).round() as i32)
            })
            .collect(),
        1 => vec![(-4, -4), (4, -4), (4, 4), (-4, 4)],
        2 => vec![(0, -5), (5, 4), (-5, 4)],
        _ => vec![(0, -6), (5, 0), (0, 6), (-5, 0)],
    }
}

fn offset(shape: &[(i32, i32)], dx: i32) -> Vec<(i32, i32)> {
    shape.iter().map(|&(x, y)| (x + dx, y)).collect()
}

/// The legend's corner: the one whose box (estimated from the names'
/// lengths) holds the fewest points and line samples; ties go to upper
/// right, lower left, upper left, lower right (error-against-time data
/// usually runs from upper left to lower right).
fn legend_corner<'a>(
    x: &Axis,
    y: &Axis,
    series: &[Vec<(f64, f64)>],
    names: impl Iterator<Item = &'a str>,
    (w, h): (u32, u32),
) -> SeriesLabelPosition {
    let names: Vec<&str> = names.collect();
    let longest = names.iter().map(|n| n.chars().count()).max().unwrap_or(0);
    // Box size as a fraction of the plotting area, with its 12 px margin.
    let bw = (longest as f64 * 8.5 + 60.0) / f64::from(w.max(1));
    let bh = (names.len() as f64 * 20.0 + 36.0) / f64::from(h.max(1));
    let unit =
        |r: &Range<f64>, v: f64| (v.log10() - r.start.log10()) / (r.end.log10() - r.start.log10());
    // Points plus 8 samples along each segment, in [0, 1]² (y up).
    let mut samples = Vec::new();
    for pts in series {
        for (i, &(px, py)) in pts.iter().enumerate() {
            let (u, v) = (unit(&x.range, px), unit(&y.range, py));
            samples.push((u, v));
            if let Some(&(qx, qy)) = pts.get(i + 1) {
                let (u1, v1) = (unit(&x.range, qx), unit(&y.range, qy));
                samples.extend(
                    (1..8)
                        .map(|k| f64::from(k) / 8.0)
                        .map(|t| (u + t * (u1 - u), v + t * (v1 - v))),
                );
            }
        }
    }
    let count = |right: bool, top: bool| {
        samples
            .iter()
            .filter(|&&(u, v)| {
                (if right { u >= 1.0 - bw } else { u <= bw })
                    && (if top { v >= 1.0 - bh } else { v <= bh })
            })
            .count()
    };
    [
        (SeriesLabelPosition::UpperRight, count(true, true)),
        (SeriesLabelPosition::LowerLeft, count(false, false)),
        (SeriesLabelPosition::UpperLeft, count(false, true)),
        (SeriesLabelPosition::LowerRight, count(true, false)),
    ]
    .into_iter()
    .min_by_key(|c| c.1)
    .map_or(SeriesLabelPosition::UpperRight, |c| c.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wide_axes_tick_at_decades_and_short_ones_at_1_2_5() {
        let wide = Axis::covering([1e-7, 3e-3].into_iter());
        assert_eq!(wide.bold.len(), 5, "{wide:?}");
        assert!(wide.bold.iter().all(|v| (v.log10() - v.log10().round()).abs() < 1e-9));
        let many = Axis::covering([1e-16, 1.0].into_iter());
        assert!(many.bold.len() <= Axis::MAX_LABELS, "{many:?}");
        let short = Axis::covering([0.03, 0.05].into_iter());
        assert!(short.bold.len() >= 3, "{short:?}");
        // One point still gets a decade-wide axis with ticks.
        let one = Axis::covering([7.0].into_iter());
        assert!(one.range.start < 7.0 && one.range.end > 7.0 && one.bold.len() >= 3);
    }

    #[test]
    fn tick_labels() {
        assert_eq!(tick_label(0.02, true), "0.02");
        assert_eq!(tick_label(100.0, true), "100");
        assert_eq!(tick_label(1e-4, false), "10⁻⁴");
        assert_eq!(tick_label(5e-12, false), "5×10⁻¹²");
        assert_eq!(tick_label(1e3, false), "10³");
    }

    #[test]
    fn writes_a_png_and_refuses_nothing_to_plot() {
        let dir = std::env::temp_dir().join(format!("rt-benches-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("plot.png");
        let plot = Plot {
            pareto: true,
            title: "test".into(),
            x_label: "seconds".into(),
            y_label: "error".into(),
            series: vec![
                Series { name: "a".into(), points: vec![(1e-3, 1e-2), (1e-2, 1e-5)] },
                Series { name: "b".into(), points: vec![(2e-3, 1e-3), (f64::NAN, 1.0)] },
            ],
        };
        loglog(&plot, 320, 240, &path).unwrap();
        assert!(std::fs::metadata(&path).unwrap().len() > 1000);
        let empty =
            Plot { series: vec![Series { name: "z".into(), points: vec![(0.0, 1.0)] }], ..plot };
        assert!(matches!(loglog(&empty, 320, 240, &path), Err(PlotError::Empty)));
        assert!(matches!(loglog(&empty, 0, 240, &path), Err(PlotError::Size { .. })));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
