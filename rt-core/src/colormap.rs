//! Colour maps: scalar → RGBA through piecewise-linear control points.
//!
//! Built-ins borrow static tables and user maps borrow the caller's stops,
//! so lookups never allocate. Scientific convention: the *scalar* is
//! interpolated across a primitive first and then looked up here; colours
//! are never interpolated between vertices.

use core::fmt;

/// One control point: a position in `[0, 1]` and a straight (not
/// premultiplied) linear-RGB colour with alpha.
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct ColorStop {
    /// Position along the map, `0` at the low end of the range.
    pub pos: f32,
    /// Colour `[r, g, b, a]`, each in `[0, 1]`.
    pub rgba: [f32; 4],
}

impl ColorStop {
    /// An opaque stop.
    #[must_use]
    pub const fn rgb(pos: f32, r: f32, g: f32, b: f32) -> Self {
        Self { pos, rgba: [r, g, b, 1.0] }
    }
}

/// Why a colour map could not be made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorMapError {
    /// Fewer than two control points.
    TooFewStops,
    /// A stop position or colour is not finite.
    NonFinite {
        /// Index of the offending stop.
        index: usize,
    },
    /// Stop positions are not non-decreasing, or not within `[0, 1]`.
    Unordered {
        /// Index of the offending stop.
        index: usize,
    },
    /// The scalar range is not finite or has `lo > hi`.
    BadRange,
}

impl fmt::Display for ColorMapError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TooFewStops => write!(f, "a colour map needs at least two control points"),
            Self::NonFinite { index } => write!(f, "control point {index} is not finite"),
            Self::Unordered { index } => {
                write!(f, "control point {index} is out of order or outside [0, 1]")
            }
            Self::BadRange => write!(f, "the scalar range must be finite with lo <= hi"),
        }
    }
}

impl core::error::Error for ColorMapError {}

/// A colour map with the scalar range it spans.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColorMap<'a> {
    stops: &'a [ColorStop],
    lo: f32,
    hi: f32,
    /// Colour returned for NaN scalars (ParaView's default, yellow).
    pub nan_color: [f32; 4],
}

impl<'a> ColorMap<'a> {
    /// A map from user control points over the scalar range `[lo, hi]`.
    ///
    /// # Errors
    /// [`ColorMapError`] if there are fewer than two stops, a value is not
    /// finite, positions decrease or leave `[0, 1]`, or the range is bad.
    pub fn from_stops(stops: &'a [ColorStop], lo: f32, hi: f32) -> Result<Self, ColorMapError> {
        if stops.len() < 2 {
            return Err(ColorMapError::TooFewStops);
        }
        let mut prev = 0.0;
        for (index, s) in stops.iter().enumerate() {
            if !s.pos.is_finite() || !s.rgba.iter().all(|c| c.is_finite()) {
                return Err(ColorMapError::NonFinite { index });
            }
            if s.pos < prev || s.pos > 1.0 {
                return Err(ColorMapError::Unordered { index });
            }
            prev = s.pos;
        }
        let mut map = Self { stops, lo: 0.0, hi: 1.0, nan_color: [1.0, 1.0, 0.0, 1.0] };
        map.set_range(lo, hi)?;
        Ok(map)
    }

    /// Sets the scalar range mapped onto `[0, 1]`.
    ///
    /// # Errors
    /// [`ColorMapError::BadRange`] for non-finite bounds or `lo > hi`.
    pub fn set_range(&mut self, lo: f32, hi: f32) -> Result<(), ColorMapError> {
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            return Err(ColorMapError::BadRange);
        }
        self.lo = lo;
        self.hi = hi;
        Ok(())
    }

    /// The scalar range `(lo, hi)`.
    #[must_use]
    pub fn range(&self) -> (f32, f32) {
        (self.lo, self.hi)
    }

    /// Black → white.
    #[must_use]
    pub fn grayscale() -> ColorMap<'static> {
        ColorMap { stops: &GRAYSCALE, lo: 0.0, hi: 1.0, nan_color: [1.0, 0.0, 0.0, 1.0] }
    }

    /// Matplotlib's viridis (van der Walt & Smith), perceptually uniform;
    /// 33 stops sampled from its 256-entry table.
    #[must_use]
    pub fn viridis() -> ColorMap<'static> {
        ColorMap { stops: &VIRIDIS, lo: 0.0, hi: 1.0, nan_color: [1.0, 0.0, 0.0, 1.0] }
    }

    /// Moreland's cool-to-warm diverging map (ParaView's default), his
    /// 33-entry table ("Diverging Color Maps for Scientific Visualization", 2009).
    #[must_use]
    pub fn cool_to_warm() -> ColorMap<'static> {
        ColorMap { stops: &COOL_TO_WARM, lo: 0.0, hi: 1.0, nan_color: [1.0, 1.0, 0.0, 1.0] }
    }

    /// The same map over another range (see [`ColorMap::set_range`]).
    ///
    /// # Errors
    /// [`ColorMapError::BadRange`] for non-finite bounds or `lo > hi`.
    pub fn with_range(mut self, lo: f32, hi: f32) -> Result<Self, ColorMapError> {
        self.set_range(lo, hi)?;
        Ok(self)
    }

    /// The straight-alpha linear RGBA colour of scalar `s`; values outside
    /// the range clamp to the end colours, NaN gives `nan_color`.
    #[must_use]
    pub fn map(&self, s: f32) -> [f32; 4] {
        if s.is_nan() {
            return self.nan_color;
        }
        let span = self.hi - self.lo;
        let x = if span > 0.0 { ((s - self.lo) / span).clamp(0.0, 1.0) } else { 0.5 };
        // First stop at or beyond x (stops are sorted).
        let i = self.stops.partition_point(|st| st.pos < x);
        if i == 0 {
            return self.stops[0].rgba;
        }
        if i == self.stops.len() {
            return self.stops[i - 1].rgba;
        }
        let (a, b) = (&self.stops[i - 1], &self.stops[i]);
        let w = if b.pos > a.pos { (x - a.pos) / (b.pos - a.pos) } else { 1.0 };
        core::array::from_fn(|k| a.rgba[k] + w * (b.rgba[k] - a.rgba[k]))
    }

    /// The control points.
    #[must_use]
    pub fn stops(&self) -> &'a [ColorStop] {
        self.stops
    }
}

static GRAYSCALE: [ColorStop; 2] =
    [ColorStop::rgb(0.0, 0.0, 0.0, 0.0), ColorStop::rgb(1.0, 1.0, 1.0, 1.0)];

static VIRIDIS: [ColorStop; 33] = [
    ColorStop::rgb(0.000000, 0.267004, 0.004874, 0.329415),
    ColorStop::rgb(0.031373, 0.277018, 0.050344, 0.375715),
    ColorStop::rgb(0.062745, 0.282327, 0.094955, 0.417331),
    ColorStop::rgb(0.094118, 0.282884, 0.135920, 0.453427),
    ColorStop::rgb(0.125490, 0.278826, 0.175490, 0.483397),
    ColorStop::rgb(0.156863, 0.270595, 0.214069, 0.507052),
    ColorStop::rgb(0.188235, 0.258965, 0.251537, 0.524736),
    ColorStop::rgb(0.219608, 0.244972, 0.287675, 0.537260),
    ColorStop::rgb(0.250980, 0.229739, 0.322361, 0.545706),
    ColorStop::rgb(0.282353, 0.214298, 0.355619, 0.551184),
    ColorStop::rgb(0.313725, 0.199430, 0.387607, 0.554642),
    ColorStop::rgb(0.345098, 0.185556, 0.418570, 0.556753),
    ColorStop::rgb(0.376471, 0.172719, 0.448791, 0.557885),
    ColorStop::rgb(0.407843, 0.160665, 0.478540, 0.558115),
    ColorStop::rgb(0.439216, 0.149039, 0.508051, 0.557250),
    ColorStop::rgb(0.470588, 0.137770, 0.537492, 0.554906),
    ColorStop::rgb(0.501961, 0.127568, 0.566949, 0.550556),
    ColorStop::rgb(0.529412, 0.121148, 0.592739, 0.544641),
    ColorStop::rgb(0.560784, 0.120081, 0.622161, 0.534946),
    ColorStop::rgb(0.592157, 0.130067, 0.651384, 0.521608),
    ColorStop::rgb(0.623529, 0.153894, 0.680203, 0.504172),
    ColorStop::rgb(0.654902, 0.191090, 0.708366, 0.482284),
    ColorStop::rgb(0.686275, 0.239374, 0.735588, 0.455688),
    ColorStop::rgb(0.717647, 0.296479, 0.761561, 0.424223),
    ColorStop::rgb(0.749020, 0.360741, 0.785964, 0.387814),
    ColorStop::rgb(0.780392, 0.430983, 0.808473, 0.346476),
    ColorStop::rgb(0.811765, 0.506271, 0.828786, 0.300362),
    ColorStop::rgb(0.843137, 0.585678, 0.846661, 0.249897),
    ColorStop::rgb(0.874510, 0.668054, 0.861999, 0.196293),
    ColorStop::rgb(0.905882, 0.751884, 0.874951, 0.143228),
    ColorStop::rgb(0.937255, 0.835270, 0.886029, 0.102646),
    ColorStop::rgb(0.968627, 0.916242, 0.896091, 0.100717),
    ColorStop::rgb(1.000000, 0.993248, 0.906157, 0.143936),
];

static COOL_TO_WARM: [ColorStop; 33] = [
    ColorStop::rgb(0.000000, 0.231373, 0.298039, 0.752941),
    ColorStop::rgb(0.031250, 0.266667, 0.352941, 0.800000),
    ColorStop::rgb(0.062500, 0.301961, 0.407843, 0.843137),
    ColorStop::rgb(0.093750, 0.341176, 0.458824, 0.882353),
    ColorStop::rgb(0.125000, 0.384314, 0.509804, 0.917647),
    ColorStop::rgb(0.156250, 0.423529, 0.556863, 0.945098),
    ColorStop::rgb(0.187500, 0.466667, 0.603922, 0.968627),
    ColorStop::rgb(0.218750, 0.509804, 0.647059, 0.984314),
    ColorStop::rgb(0.250000, 0.552941, 0.690196, 0.996078),
    ColorStop::rgb(0.281250, 0.596078, 0.725490, 1.000000),
    ColorStop::rgb(0.312500, 0.639216, 0.760784, 1.000000),
    ColorStop::rgb(0.343750, 0.682353, 0.788235, 0.992157),
    ColorStop::rgb(0.375000, 0.721569, 0.815686, 0.976471),
    ColorStop::rgb(0.406250, 0.760784, 0.835294, 0.956863),
    ColorStop::rgb(0.437500, 0.800000, 0.850980, 0.933333),
    ColorStop::rgb(0.468750, 0.835294, 0.858824, 0.901961),
    ColorStop::rgb(0.500000, 0.866667, 0.866667, 0.866667),
    ColorStop::rgb(0.531250, 0.898039, 0.847059, 0.819608),
    ColorStop::rgb(0.562500, 0.925490, 0.827451, 0.772549),
    ColorStop::rgb(0.593750, 0.945098, 0.800000, 0.725490),
    ColorStop::rgb(0.625000, 0.960784, 0.768627, 0.678431),
    ColorStop::rgb(0.656250, 0.968627, 0.733333, 0.627451),
    ColorStop::rgb(0.687500, 0.968627, 0.694118, 0.580392),
    ColorStop::rgb(0.718750, 0.968627, 0.650980, 0.529412),
    ColorStop::rgb(0.750000, 0.956863, 0.603922, 0.482353),
    ColorStop::rgb(0.781250, 0.945098, 0.552941, 0.435294),
    ColorStop::rgb(0.812500, 0.925490, 0.498039, 0.388235),
    ColorStop::rgb(0.843750, 0.898039, 0.439216, 0.345098),
    ColorStop::rgb(0.875000, 0.870588, 0.376471, 0.301961),
    ColorStop::rgb(0.906250, 0.835294, 0.313725, 0.258824),
    ColorStop::rgb(0.937500, 0.796078, 0.243137, 0.219608),
    ColorStop::rgb(0.968750, 0.752941, 0.156863, 0.184314),
    ColorStop::rgb(1.000000, 0.705882, 0.015686, 0.149020),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn endpoints_midpoints_and_clamping() {
        let g = ColorMap::grayscale().with_range(10.0, 20.0).unwrap();
        assert_eq!(g.map(10.0), [0.0, 0.0, 0.0, 1.0]);
        assert_eq!(g.map(20.0), [1.0, 1.0, 1.0, 1.0]);
        assert_eq!(g.map(15.0), [0.5, 0.5, 0.5, 1.0]);
        assert_eq!(g.map(-1e30), [0.0, 0.0, 0.0, 1.0]);
        assert_eq!(g.map(f32::INFINITY), [1.0, 1.0, 1.0, 1.0]);
        assert_eq!(g.map(f32::NAN), g.nan_color);
    }

    #[test]
    fn builtin_tables_match_their_sources() {
        let v = ColorMap::viridis();
        assert_eq!(v.map(0.0)[..3], [0.267004, 0.004874, 0.329415]);
        assert_eq!(v.map(1.0)[..3], [0.993248, 0.906157, 0.143936]);
        let c = ColorMap::cool_to_warm();
        let mid = c.map(0.5);
        assert!((mid[0] - 221.0 / 255.0).abs() < 1e-6 && mid[0] == mid[1] && mid[1] == mid[2]);
        assert!(c.map(0.0)[2] > c.map(0.0)[0], "low end is blue");
        assert!(c.map(1.0)[0] > c.map(1.0)[2], "high end is red");
    }

    #[test]
    fn user_stops_are_validated() {
        let ok = [ColorStop::rgb(0.0, 1.0, 0.0, 0.0), ColorStop::rgb(1.0, 0.0, 0.0, 1.0)];
        let m = ColorMap::from_stops(&ok, -1.0, 1.0).unwrap();
        assert_eq!(m.map(0.0), [0.5, 0.0, 0.5, 1.0]);
        assert_eq!(ColorMap::from_stops(&ok[..1], 0.0, 1.0), Err(ColorMapError::TooFewStops));
        let bad = [ok[1], ok[0]];
        assert_eq!(
            ColorMap::from_stops(&bad, 0.0, 1.0),
            Err(ColorMapError::Unordered { index: 1 })
        );
        let nan = [ok[0], ColorStop::rgb(1.0, f32::NAN, 0.0, 0.0)];
        assert_eq!(
            ColorMap::from_stops(&nan, 0.0, 1.0),
            Err(ColorMapError::NonFinite { index: 1 })
        );
        assert_eq!(ColorMap::from_stops(&ok, 1.0, 0.0), Err(ColorMapError::BadRange));
    }
}
