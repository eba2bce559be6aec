//! Figures for a paper: an image with what a reader needs to read it —
//! a title (what was imaged, and how), axes in physical units with tick
//! values and a scale bar, and a legend (the colour filter's deflection
//! wheel, or a scalar's colour bar) — drawn with plotters into an 8-bit
//! sRGB PNG on white.
//!
//! Layout, left to right: the y axis's label and ticks, the image (shown
//! 520–1000 px on its longer side: small images are enlarged with sharp
//! pixels, large ones averaged down), the legend; the title and a
//! subtitle above. The image keeps its aspect ratio, so one unit is as
//! long on both axes.
//!
//! Text is DejaVu Sans, embedded from `assets/DejaVuSans.ttf` (licence:
//! `assets/DejaVuSans-LICENSE`) and rasterised by `ab_glyph`: no system
//! font library is needed.

use std::{fmt, ops::Range, path::Path};

use plotters::{
    coord::{
        Shift,
        ranged1d::{DefaultFormatting, KeyPointHint},
    },
    prelude::*,
    style::text_anchor::{HPos, Pos, VPos},
};
use rt_core::{ColorMap, Frame, frame::linear_to_srgb};
use rt_photo::{FilterImage, units::si};

use crate::{
    image::{WriteError, over_background, write_rgb8},
    text::{FAMILY, register_font_once, superscript},
};

/// The image's longer side on the figure, in pixels.
const SHOWN: Range<u32> = 520..1001;

/// Height of the title and subtitle band (at scale 1).
const TITLE_HEIGHT: u32 = 66;

/// Text and layout grow with the image shown, so a large figure printed at
/// a column's width keeps legible text: 1 at a 700-px image, 0.9 to 1.45
/// over [`SHOWN`].
#[derive(Clone, Copy, Debug)]
struct Scale(f64);

impl Scale {
    fn for_image(long_side: u32) -> Self {
        Self((f64::from(long_side) / 700.0).clamp(0.9, 1.45))
    }

    /// A length in pixels.
    fn px(self, v: u32) -> u32 {
        (f64::from(v) * self.0).round() as u32
    }

    /// A signed offset in pixels.
    fn at(self, v: i32) -> i32 {
        (f64::from(v) * self.0).round() as i32
    }

    /// A font size.
    fn pt(self, v: f64) -> f64 {
        (v * self.0).round()
    }
}

/// Plotters' error for the bitmap backend.
type DrawError = DrawingAreaErrorKind<<BitMapBackend<'static> as DrawingBackend>::ErrorType>;

/// A drawing area of the figure, in pixels.
type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// Why a figure could not be made.
#[derive(Debug)]
pub enum FigureError {
    /// The embedded font could not be read (a damaged
    /// `assets/DejaVuSans.ttf`).
    Font,
    /// Plotters failed to lay out or draw the figure.
    Draw(DrawError),
    /// The PNG could not be written.
    Write(WriteError),
}

impl fmt::Display for FigureError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Font => f.write_str("the figure font (assets/DejaVuSans.ttf) could not be read"),
            Self::Draw(e) => write!(f, "drawing the figure: {e}"),
            Self::Write(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for FigureError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Font => None,
            Self::Draw(e) => Some(e),
            Self::Write(e) => Some(e),
        }
    }
}

impl From<DrawError> for FigureError {
    fn from(e: DrawError) -> Self {
        Self::Draw(e)
    }
}

/// 8-bit sRGB RGB pixels, rows top first.
#[derive(Clone, Debug)]
pub struct Image {
    width: u32,
    height: u32,
    rgb: Vec<u8>,
}

impl Image {
    /// `frame` composited over white (a figure is opaque).
    pub fn from_frame(frame: &Frame) -> Self {
        let mut f = frame.clone();
        over_background(&mut f, [1.0; 3], [1.0; 3]);
        let rgb = f.to_srgba8().chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
        Self { width: f.width(), height: f.height(), rgb }
    }

    /// 8-bit sRGB RGB pixels, rows top first (`w·h·3` bytes).
    pub fn from_rgb8(width: u32, height: u32, rgb: Vec<u8>) -> Self {
        debug_assert_eq!(rgb.len(), width as usize * height as usize * 3);
        Self { width, height, rgb }
    }

    /// The size it is shown at: its longer side in [`SHOWN`], same aspect.
    fn shown_size(&self) -> (u32, u32) {
        let long = self.width.max(self.height);
        let s = f64::from(long.clamp(SHOWN.start, SHOWN.end - 1)) / f64::from(long.max(1));
        let side = |n: u32| ((f64::from(n) * s).round() as u32).max(1);
        (side(self.width), side(self.height))
    }

    /// Resampled to `w × h`: nearest pixel when enlarging (pixels stay
    /// sharp), the mean over each target pixel's footprint when shrinking.
    fn resized(&self, w: u32, h: u32) -> Vec<u8> {
        let (sw, sh) = (self.width as usize, self.height as usize);
        let (w, h) = (w as usize, h as usize);
        let span = |i: usize, n: usize, sn: usize| {
            let a = i * sn / n;
            (a, ((i + 1) * sn / n).max(a + 1).min(sn))
        };
        let mut out = Vec::with_capacity(w * h * 3);
        for y in 0..h {
            let (y0, y1) = span(y, h, sh);
            for x in 0..w {
                let (x0, x1) = span(x, w, sw);
                let mut sum = [0u32; 3];
                for sy in y0..y1 {
                    for sx in x0..x1 {
                        let p = 3 * (sy * sw + sx);
                        for (s, &c) in sum.iter_mut().zip(&self.rgb[p..p + 3]) {
                            *s += u32::from(c);
                        }
                    }
                }
                let n = ((y1 - y0) * (x1 - x0)).max(1) as u32;
                out.extend(sum.map(|s| ((s + n / 2) / n) as u8));
            }
        }
        out
    }
}

/// One axis of an image in physical units.
#[derive(Clone, Debug)]
pub struct Axis {
    /// Its name, e.g. `x`.
    pub name: String,
    /// The coordinates at the image's edges in metres: left to right, or
    /// bottom to top.
    pub range: Range<f64>,
}

/// What the figure shows beside the image.
#[derive(Clone, Debug)]
pub enum Legend {
    /// Nothing.
    None,
    /// The colour filter: its transmission over the deflection disc, hue =
    /// direction, saturation = size, the rim at its half range.
    Wheel(FilterImage),
    /// A colour wheel of a displacement field in pixels (BOS): hue =
    /// direction, saturation = size, full at the rim (its half range);
    /// `rim_note` says what the rim is.
    DisplacementWheel {
        /// The wheel.
        filter: FilterImage,
        /// What the rim's value is, e.g. `99th percentile`.
        rim_note: String,
    },
    /// A scalar's colour map over its range; `constant` draws the one
    /// colour a constant scalar was painted in.
    ColorBar {
        /// The map and the range it spans.
        map: ColorMap<'static>,
        /// The scalar's name.
        name: String,
        /// The scalar is constant (drawn in one colour).
        constant: bool,
    },
}

/// A figure: the image, its texts, axes and legend.
#[derive(Clone, Debug)]
pub struct Figure {
    /// The picture.
    pub image: Image,
    /// First line above it.
    pub title: String,
    /// Second, smaller line (the parameters).
    pub subtitle: String,
    /// Horizontal and vertical axes in metres, or none (a perspective
    /// render has no such axes).
    pub axes: Option<(Axis, Axis)>,
    /// Beside the image.
    pub legend: Legend,
}

/// Registers the embedded font with plotters once per process.
fn register() -> Result<(), FigureError> {
    if register_font_once() { Ok(()) } else { Err(FigureError::Font) }
}

/// Margins around the image: left, right, top, bottom (the axes' ticks
/// and labels, or a plain border).
fn margins(axes: bool, k: Scale) -> (u32, u32, u32, u32) {
    let (l, r, t, b) = if axes { (100, 34, 12, 60) } else { (16, 16, 12, 16) };
    (k.px(l), k.px(r), k.px(t), k.px(b))
}

impl Figure {
    /// Draws the figure and writes it as a PNG; creates the folder.
    ///
    /// # Errors
    /// [`FigureError`]: the font, plotters, or the file.
    pub fn write(&self, path: &Path) -> Result<(), FigureError> {
        register()?;
        let (dw, dh) = self.image.shown_size();
        let k = Scale::for_image(dw.max(dh));
        let (left, right, top, bottom) = margins(self.axes.is_some(), k);
        let (legend_w, legend_h) = match self.legend {
            Legend::None => (0, 0),
            Legend::Wheel(_) | Legend::DisplacementWheel { .. } => (k.px(230), k.px(330)),
            Legend::ColorBar { .. } => (k.px(150), k.px(220)),
        };
        let main_w = left + dw + right;
        let width = (main_w + legend_w).max(560);
        let title_h = k.px(TITLE_HEIGHT);
        let height = title_h + (top + dh + bottom).max(legend_h);
        let mut rgb = vec![255u8; width as usize * height as usize * 3];
        {
            let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
            root.fill(&WHITE)?;
            let centre = (width / 2) as i32;
            let title = Pos::new(HPos::Center, VPos::Top);
            text(&root, &self.title, (centre, k.at(10)), k.pt(21.0), width - 24, title)?;
            text(&root, &self.subtitle, (centre, k.at(40)), k.pt(15.0), width - 24, title)?;
            let (_, body) = root.split_vertically(title_h);
            // Any width beyond the image and legend goes to the right.
            let (main, side) = body.split_horizontally(width - legend_w);
            let (main, _) = main.split_vertically(top + dh + bottom);
            let (main, _) = main.split_horizontally(main_w);
            let (picture, (pw, ph)) = match &self.axes {
                Some((u, v)) => draw_axes(&main, u, v, (left, right, top, bottom), k)?,
                None => {
                    let area = main.margin(top, bottom, left, right);
                    let dim = area.dim_in_pixel();
                    (area, dim)
                }
            };
            let shown = self.image.resized(pw, ph);
            if let Some(bitmap) = BitMapElement::with_owned_buffer((0, 0), (pw, ph), shown) {
                picture.draw(&bitmap)?;
            }
            let frame = RGBColor(80, 80, 80).stroke_width(1);
            picture.draw(&Rectangle::new([(0, 0), (pw as i32 - 1, ph as i32 - 1)], frame))?;
            if let Some((u, _)) = &self.axes {
                scale_bar(&picture, u, pw, ph, k)?;
            }
            match &self.legend {
                Legend::None => {}
                Legend::Wheel(filter) => {
                    let name = |a: &Option<(Axis, Axis)>, i: usize| {
                        a.as_ref().map_or(["u", "v"][i].to_string(), |(u, v)| {
                            [&u.name, &v.name][i].clone()
                        })
                    };
                    let names = (name(&self.axes, 0), name(&self.axes, 1));
                    let texts = WheelText {
                        title: "Deflection ε".into(),
                        marks: (format!("+{}", names.0), format!("+{}", names.1)),
                        // A painted filter (square, not a wheel) says so.
                        lines: if filter.round {
                            vec![
                                "hue: direction of ε".into(),
                                "saturation: size |ε|".into(),
                                format!("rim: |ε| = {}", si(filter.half_range, "rad")),
                                "beyond the rim: black (cut)".into(),
                            ]
                        } else {
                            vec![
                                "a painted filter: what it".into(),
                                "transmits at each ε".into(),
                                format!("shown to |ε| = {}", si(filter.half_range, "rad")),
                                "(its square reaches the corners)".into(),
                            ]
                        },
                    };
                    wheel(&side, filter, &texts, top, k)?;
                }
                Legend::DisplacementWheel { filter, rim_note } => {
                    let texts = WheelText {
                        title: "Displacement Δ".into(),
                        marks: ("+x".into(), "−y".into()),
                        lines: vec![
                            "hue: direction of Δ".into(),
                            "saturation: size |Δ|".into(),
                            format!("rim: |Δ| = {} px", significant(filter.half_range)),
                            format!("({rim_note}; beyond: full)"),
                        ],
                    };
                    wheel(&side, filter, &texts, top, k)?;
                }
                Legend::ColorBar { map, name, constant } => {
                    color_bar(&side, map, name, *constant, (top, top + dh), k)?;
                }
            }
            root.present()?;
        }
        write_rgb8(&rgb, width, height, path).map_err(FigureError::Write)
    }
}

/// Draws `s` at `at`, anchored at `pos`, in the largest size up to `size`
/// (down to 9 px) that fits in `max_width` pixels.
fn text(
    area: &Area<'_>,
    s: &str,
    at: (i32, i32),
    size: f64,
    max_width: u32,
    pos: Pos,
) -> Result<(), DrawError> {
    let mut size = size;
    let style = loop {
        let style = TextStyle::from((FAMILY, size).into_font()).color(&BLACK).pos(pos);
        if size <= 9.0 || area.estimate_text_size(s, &style)?.0 <= max_width {
            break style;
        }
        size -= 1.0;
    };
    area.draw(&Text::new(s, at, style))
}

/// Draws axes in metres (or mm, µm, km as the size asks) with tick values
/// and labels around the image's place in `area`; returns that place in
/// pixels and its size.
fn draw_axes<'a>(
    area: &Area<'a>,
    u: &Axis,
    v: &Axis,
    (left, right, top, bottom): (u32, u32, u32, u32),
    k: Scale,
) -> Result<(Area<'a>, (u32, u32)), DrawError> {
    let unit = Unit::for_extent((u.range.end - u.range.start).max(v.range.end - v.range.start));
    let (u_ticks, u_step) = ticks(&u.range, 6);
    let (v_ticks, v_step) = ticks(&v.range, 6);
    let mut chart = ChartBuilder::on(area)
        .margin_top(top)
        .margin_right(right)
        .margin_left(k.px(12))
        .x_label_area_size(bottom)
        .y_label_area_size(left - k.px(12))
        .build_cartesian_2d(Ticked::new(&u.range, u_ticks), Ticked::new(&v.range, v_ticks))?;
    let u_fmt = |x: &f64| unit.format(*x, u_step);
    let v_fmt = |y: &f64| unit.format(*y, v_step);
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(format!("{} [{}]", u.name, unit.name))
        .y_desc(format!("{} [{}]", v.name, unit.name))
        .x_label_formatter(&u_fmt)
        .y_label_formatter(&v_fmt)
        .label_style((FAMILY, k.pt(15.0)))
        .axis_desc_style((FAMILY, k.pt(16.0)))
        .draw()?;
    let picture = chart.plotting_area().strip_coord_spec();
    let dim = picture.dim_in_pixel();
    Ok((picture, dim))
}

/// A bar of a round length (1, 2 or 5 × 10ⁿ, 10–25 % of the width) with
/// its length written above, on a pale box in the image's lower right
/// corner. Left out on images under 160 px wide.
fn scale_bar(picture: &Area<'_>, u: &Axis, pw: u32, ph: u32, k: Scale) -> Result<(), DrawError> {
    let extent = u.range.end - u.range.start;
    if pw < 160 || ph < 60 || !(extent.is_finite() && extent > 0.0) {
        return Ok(());
    }
    let length = round_below(0.25 * extent);
    let bar = (length / extent * f64::from(pw)).round() as i32;
    let unit = Unit::for_extent(length);
    let label = format!("{} {}", unit.format(length, length), unit.name);
    let style = TextStyle::from((FAMILY, k.pt(15.0)).into_font())
        .color(&BLACK)
        .pos(Pos::new(HPos::Center, VPos::Bottom));
    let (tw, th) = picture.estimate_text_size(&label, &style)?;
    let (pad, thick) = (k.at(8), k.at(5));
    let box_w = bar.max(tw as i32) + 2 * pad;
    let box_h = th as i32 + thick + 3 * pad;
    let (x1, y1) = (pw as i32 - k.at(12), ph as i32 - k.at(12));
    let (x0, y0) = (x1 - box_w, y1 - box_h);
    picture.draw(&Rectangle::new([(x0, y0), (x1, y1)], WHITE.mix(0.8).filled()))?;
    let cx = (x0 + x1) / 2;
    let bar_y = y1 - pad - thick;
    picture.draw(&Rectangle::new(
        [(cx - bar / 2, bar_y), (cx - bar / 2 + bar, bar_y + thick)],
        BLACK.filled(),
    ))?;
    picture.draw(&Text::new(label, (cx, bar_y - pad / 2), style))
}

/// The words around a colour wheel: its title, the labels of its right
/// and up marks, and the lines below it.
struct WheelText {
    title: String,
    marks: (String, String),
    lines: Vec<String>,
}

/// The colour filter as a disc: each point's colour is the filter's
/// transmission at that deflection (right = `+u`, up = `+v`, the rim at
/// its half range), with what it means written below.
fn wheel(
    side: &Area<'_>,
    filter: &FilterImage,
    texts: &WheelText,
    top: u32,
    k: Scale,
) -> Result<(), DrawError> {
    let (w, _) = side.dim_in_pixel();
    let cx = (w / 2) as i32 - k.at(6);
    let centre = Pos::new(HPos::Center, VPos::Top);
    text(side, &texts.title, (cx, top as i32), k.pt(16.0), w - 8, centre)?;
    let r = k.at(72);
    let cy = top as i32 + k.at(48) + r;
    // The disc, its edge anti-aliased against the white panel.
    let n = 2 * r + 1;
    let mut px = Vec::with_capacity((n * n * 3) as usize);
    let half = filter.half_range;
    for j in 0..n {
        for i in 0..n {
            let (dx, dy) = (f64::from(i - r), f64::from(j - r));
            let cover = (f64::from(r) + 0.5 - dx.hypot(dy)).clamp(0.0, 1.0) as f32;
            let c = filter.at(dx / f64::from(r) * half, -dy / f64::from(r) * half);
            px.extend(c.map(|c| {
                let s = cover * linear_to_srgb(c) + (1.0 - cover);
                (s * 255.0 + 0.5) as u8
            }));
        }
    }
    if let Some(disc) = BitMapElement::with_owned_buffer((cx - r, cy - r), (n as u32, n as u32), px)
    {
        side.draw(&disc)?;
    }
    let grey = RGBColor(110, 110, 110);
    side.draw(&Circle::new((cx, cy), r, grey.stroke_width(1)))?;
    // Direction marks: +u to the right, +v up.
    let tick = k.at(8);
    side.draw(&PathElement::new([(cx + r, cy), (cx + r + tick, cy)], grey.stroke_width(1)))?;
    side.draw(&PathElement::new([(cx, cy - r), (cx, cy - r - tick)], grey.stroke_width(1)))?;
    let small =
        |h, v| TextStyle::from((FAMILY, k.pt(14.0)).into_font()).color(&BLACK).pos(Pos::new(h, v));
    side.draw(&Text::new(
        texts.marks.0.clone(),
        (cx + r + k.at(11), cy),
        small(HPos::Left, VPos::Center),
    ))?;
    side.draw(&Text::new(
        texts.marks.1.clone(),
        (cx, cy - r - k.at(10)),
        small(HPos::Center, VPos::Bottom),
    ))?;
    for (i, line) in texts.lines.iter().enumerate() {
        let at = (cx + k.at(6), cy + r + k.at(14 + 20 * i as i32));
        text(side, line, at, k.pt(14.0), w - 8, centre)?;
    }
    Ok(())
}

/// A vertical colour bar of `map` between pixel rows `rows` of `side`,
/// ticks and values to its right, the scalar's name above.
fn color_bar(
    side: &Area<'_>,
    map: &ColorMap<'_>,
    name: &str,
    constant: bool,
    rows: (u32, u32),
    k: Scale,
) -> Result<(), DrawError> {
    let (w, h) = side.dim_in_pixel();
    let (lo, hi) = map.range();
    let bar_top = rows.0 + k.px(30);
    let bar_bottom = rows.1.max(bar_top + k.px(120)).min(h.saturating_sub(8));
    // A constant scalar: one value, one colour, a nominal span to draw on.
    let span = if constant || hi <= lo { (lo, lo) } else { (lo, hi) };
    let pad = if span.0 == span.1 { span.0.abs().max(1.0) } else { 0.0 };
    let range = f64::from(span.0) - f64::from(pad)..f64::from(span.1) + f64::from(pad);
    let (key, step, exponent) = if span.0 == span.1 {
        (vec![f64::from(span.0)], f64::from(pad), common_exponent(span.0.into(), span.0.into()))
    } else {
        let (t, s) = ticks(&range, 6);
        (t, s, common_exponent(range.start, range.end))
    };
    let scale = 10f64.powi(exponent);
    let mut label = if constant { format!("{name} (constant)") } else { name.to_string() };
    if exponent != 0 {
        label.push_str(&format!(" ×10{}", superscript(exponent)));
    }
    let left = k.px(36);
    let at = (left as i32, rows.0 as i32);
    text(side, &label, at, k.pt(15.0), w - 10, Pos::new(HPos::Left, VPos::Top))?;
    let area = side.margin(bar_top, h.saturating_sub(bar_bottom), left, 8);
    let mut chart = ChartBuilder::on(&area)
        .set_label_area_size(LabelAreaPosition::Right, k.px(70))
        .build_cartesian_2d(0f64..1.0, Ticked::new(&range, key))?;
    let fmt = |y: &f64| plain(*y / scale, step / scale);
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_label_formatter(&fmt)
        .label_style((FAMILY, k.pt(14.0)))
        .draw()?;
    let bar = chart.plotting_area().strip_coord_spec();
    let (bw, bh) = bar.dim_in_pixel();
    let mut px = Vec::with_capacity((bw * bh * 3) as usize);
    for j in 0..bh {
        let t = (f64::from(j) + 0.5) / f64::from(bh.max(1));
        let s = if span.0 == span.1 {
            span.0
        } else {
            (range.end - t * (range.end - range.start)) as f32
        };
        // The table's own sRGB values: the PNG is sRGB.
        let c = map.map_srgb(s);
        let rgb = [c[0], c[1], c[2]].map(|c| (c.clamp(0.0, 1.0) * 255.0 + 0.5) as u8);
        for _ in 0..bw {
            px.extend(rgb);
        }
    }
    if let Some(bitmap) = BitMapElement::with_owned_buffer((0, 0), (bw, bh), px) {
        bar.draw(&bitmap)?;
    }
    let edge = RGBColor(90, 90, 90).stroke_width(1);
    bar.draw(&Rectangle::new([(0, 0), (bw as i32 - 1, bh as i32 - 1)], edge))
}

/// A linear axis over `range` with its ticks at exactly `ticks` (plotters'
/// own choice of round values cannot be read back to format them).
#[derive(Clone, Debug)]
struct Ticked {
    range: Range<f64>,
    ticks: Vec<f64>,
}

impl Ticked {
    fn new(range: &Range<f64>, ticks: Vec<f64>) -> Self {
        Self { range: range.clone(), ticks }
    }
}

impl Ranged for Ticked {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    /// As plotters maps `f64` ranges.
    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let (a, b) = (self.range.start, self.range.end);
        let length = limit.1 - limit.0;
        let span = b - a;
        if !(span.is_finite() && span > 0.0) || length == 0 {
            return limit.0 + length / 2;
        }
        let t = ((*v - a) / span).clamp(-1.0, 2.0);
        if length > 0 {
            limit.0 + (f64::from(length) * t + 1e-3).floor() as i32
        } else {
            limit.0 + (f64::from(length) * t - 1e-3).ceil() as i32
        }
    }

    fn key_points<Hint: KeyPointHint>(&self, _: Hint) -> Vec<f64> {
        self.ticks.clone()
    }

    fn range(&self) -> Range<f64> {
        self.range.clone()
    }
}

/// Length units for axes and scale bars.
#[derive(Clone, Copy, Debug)]
struct Unit {
    name: &'static str,
    metres: f64,
}

impl Unit {
    /// The unit that writes `extent` metres with few digits: metres from
    /// 0.1 m to 10 km, else km, mm, µm or nm.
    fn for_extent(extent: f64) -> Self {
        let (name, metres) = match extent {
            e if e >= 1e4 => ("km", 1e3),
            e if e >= 0.1 => ("m", 1.0),
            e if e >= 1e-4 => ("mm", 1e-3),
            e if e >= 1e-7 => ("µm", 1e-6),
            _ => ("nm", 1e-9),
        };
        Self { name, metres }
    }

    /// `x` metres in this unit, with the decimals a tick `step` (metres)
    /// needs.
    fn format(self, x: f64, step: f64) -> String {
        plain(x / self.metres, step / self.metres)
    }
}

/// `x` with as many decimals as `step` needs (`-0` written as `0`).
fn plain(x: f64, step: f64) -> String {
    let decimals = if step > 0.0 && step.is_finite() {
        (-(step.log10() + 1e-9).floor()).max(0.0) as usize
    } else {
        3
    };
    let x = if x.abs() < 1e-9 * step.abs() { 0.0 } else { x };
    format!("{x:.decimals$}")
}

/// The largest of 1, 2, 5 × 10ⁿ at or below `x > 0`.
fn round_below(x: f64) -> f64 {
    let p = 10f64.powf((x.log10() + 1e-9).floor());
    [5.0, 2.0, 1.0].into_iter().map(|m| m * p).find(|&v| v <= x * (1.0 + 1e-9)).unwrap_or(p)
}

/// Round tick values inside `range`, about `n` of them, and their step
/// (1, 2 or 5 × 10ⁿ).
fn ticks(range: &Range<f64>, n: usize) -> (Vec<f64>, f64) {
    let (a, b) = (range.start, range.end);
    let raw = (b - a) / n.max(1) as f64;
    if !(raw.is_finite() && raw > 0.0) {
        return (vec![a], 1.0);
    }
    let p = 10f64.powf((raw.log10() + 1e-9).floor());
    let step =
        [1.0, 2.0, 5.0, 10.0].into_iter().map(|m| m * p).find(|&s| s >= raw).unwrap_or(10.0 * p);
    let first = (a / step - 1e-9).ceil() as i64;
    let last = (b / step + 1e-9).floor() as i64;
    ((first..=last).map(|k| k as f64 * step).collect(), step)
}

/// The power of ten to factor out of colour-bar values whose size is
/// outside 10⁻³ … 10⁵ (0 inside).
fn common_exponent(a: f64, b: f64) -> i32 {
    let big = a.abs().max(b.abs());
    if !(big.is_finite() && big > 0.0) || (1e-3..1e5).contains(&big) {
        0
    } else {
        (big.log10() + 1e-9).floor() as i32
    }
}

/// `x` with 4 significant digits: plain from 10⁻³ to 10⁵, else as
/// `m.mmm×10ⁿ`.
pub fn significant(x: f64) -> String {
    if !x.is_finite() || x == 0.0 {
        return format!("{x}");
    }
    let e = (x.abs().log10() + 1e-9).floor() as i32;
    if (-3..5).contains(&e) {
        format!("{x:.*}", (3 - e).max(0) as usize)
    } else {
        format!("{:.3}×10{}", x / 10f64.powi(e), superscript(e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_inside() {
        let (t, step) = ticks(&(0.0..1.0), 6);
        assert_eq!(step, 0.2);
        assert_eq!(t.len(), 6);
        assert!(t.iter().all(|v| (-1e-12..=1.0 + 1e-12).contains(v)));
        let (t, step) = ticks(&(-0.115..0.115), 6);
        assert_eq!(step, 0.05);
        assert_eq!(t.first().copied(), Some(-0.1));
        assert_eq!(round_below(0.23), 0.2);
        assert_eq!(round_below(0.049), 0.02);
        assert_eq!(round_below(1.0), 1.0);
    }

    #[test]
    fn labels_and_units() {
        assert_eq!(plain(0.6000000000000001, 0.2), "0.6");
        assert_eq!(plain(-1e-17, 0.05), "0.00");
        assert_eq!(plain(150.0, 50.0), "150");
        assert_eq!(Unit::for_extent(1.0).name, "m");
        assert_eq!(Unit::for_extent(0.004).name, "mm");
        assert_eq!(Unit::for_extent(0.004).format(0.002, 0.0005), "2.0");
        assert_eq!(Unit::for_extent(3e-6).name, "µm");
        assert_eq!(significant(-0.32526073), "-0.3253");
        assert_eq!(significant(1234.5678), "1235");
        assert_eq!(significant(2.5e-7), "2.500×10⁻⁷");
        assert_eq!(common_exponent(0.0, 2e-5), -5);
        assert_eq!(common_exponent(-3.0, 40.0), 0);
    }

    #[test]
    fn images_shrink_by_averaging_and_grow_sharp() {
        let img = Image { width: 2, height: 1, rgb: vec![0, 0, 0, 255, 255, 255] };
        assert_eq!(img.shown_size(), (520, 260));
        assert_eq!(img.resized(1, 1), vec![128; 3]);
        assert_eq!(img.resized(4, 1), vec![0, 0, 0, 0, 0, 0, 255, 255, 255, 255, 255, 255]);
    }
}
