//! Progress bars on stderr (hidden when stderr is not a terminal).

use indicatif::{ProgressBar, ProgressState, ProgressStyle};

use rt_photo::units::si;

/// A bar counting `total` units of work named `unit` (e.g. "photons"),
/// with the rate (`169 k photons/s`) and the time left.
pub(crate) fn bar(total: u64, unit: &str) -> ProgressBar {
    let bar = ProgressBar::new(total);
    let template = format!(
        "{{spinner}} [{{bar:32}}] {{human_pos}}/{{human_len}} {unit}  {{rate}}  eta {{eta}}  {{msg}}"
    );
    let per_second = format!("{unit}/s");
    if let Ok(style) = ProgressStyle::with_template(&template) {
        let style =
            style.with_key("rate", move |s: &ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = w.write_str(&si(s.per_sec(), &per_second));
            });
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}
