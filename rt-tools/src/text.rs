//! Text on figures: the embedded font and number formatting shared by the
//! tool's figures and the report's plots (rt-benches).

use std::sync::OnceLock;

use plotters::style::{FontStyle, register_font};

/// DejaVu Sans 2.37 (Debian's `fonts-dejavu-core`; licence in `assets/`).
static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// The family the font is registered under (plotters' default).
pub const FAMILY: &str = "sans-serif";

/// Registers the embedded font with plotters, once per process; `false`
/// if the font data is unusable.
pub fn register_font_once() -> bool {
    static OK: OnceLock<bool> = OnceLock::new();
    *OK.get_or_init(|| register_font(FAMILY, FontStyle::Normal, FONT).is_ok())
}

/// `e` in superscript digits (`-4` → `⁻⁴`), for `m×10ⁿ` labels.
#[must_use]
pub fn superscript(e: i32) -> String {
    e.to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            '0' => '⁰',
            '1' => '¹',
            '2' => '²',
            '3' => '³',
            '4' => '⁴',
            '5' => '⁵',
            '6' => '⁶',
            '7' => '⁷',
            '8' => '⁸',
            _ => '⁹',
        })
        .collect()
}
