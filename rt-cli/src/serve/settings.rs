//! The page's settings: the JSON object the page posts, as the
//! `rt schlieren` arguments it stands for (clap checks them, so the page
//! and the command line accept and refuse the same values), and the
//! equivalent command line to show.

use std::path::Path;

use serde_json::{Map, Value};

use crate::{
    optics::{Interpolation, MeshTrace, Quantity},
    parse, schlieren,
};

/// The settings the page may send, each the `rt schlieren` option of the
/// same name (`null` or absent: the option's default, automatic where it
/// is). `paint` is the page's own: render the picking pass and apply the
/// painted filter.
const OPTIONS: [&str; 15] = [
    "cutoff",
    "angle",
    "f",
    "h",
    "radius",
    "half-range",
    "lambda",
    "fringes",
    "film-distance",
    "axis",
    "size",
    "photons",
    "estimator",
    "interp",
    "seed",
];

/// One state of the page.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Settings {
    /// `--name value` pairs, in [`OPTIONS`]' order.
    pub(crate) args: Vec<(String, String)>,
    /// The painted filter replaces the cutoff (a colour filter's set-up:
    /// its rim is the focal plane painted on).
    pub(crate) paint: bool,
}

impl Settings {
    /// The settings in `json` (an object of [`OPTIONS`] and `paint`).
    ///
    /// # Errors
    /// Not an object, an unknown name, a value that is neither a number
    /// nor a string.
    pub(crate) fn parse(json: &[u8]) -> Result<Self, String> {
        let value: Value =
            serde_json::from_slice(json).map_err(|e| format!("settings are not JSON: {e}"))?;
        let Value::Object(map) = value else { return Err("settings must be a JSON object".into()) };
        Self::from_map(&map)
    }

    fn from_map(map: &Map<String, Value>) -> Result<Self, String> {
        if let Some(unknown) = map.keys().find(|k| *k != "paint" && !OPTIONS.contains(&k.as_str()))
        {
            return Err(format!("unknown setting `{unknown}`"));
        }
        let paint = match map.get("paint") {
            None | Some(Value::Null) => false,
            Some(Value::Bool(b)) => *b,
            Some(v) => return Err(format!("`paint` must be true or false, not {v}")),
        };
        let mut args = Vec::new();
        for name in OPTIONS {
            let text = match map.get(name) {
                None | Some(Value::Null) => continue,
                Some(Value::Number(n)) => n.to_string(),
                Some(Value::String(s)) if s.trim().is_empty() => continue,
                Some(Value::String(s)) => s.trim().to_string(),
                Some(v) => return Err(format!("`{name}` must be a number or text, not {v}")),
            };
            args.push((name.to_string(), text));
        }
        Ok(Self { args, paint })
    }

    /// The value of `--name`, if set.
    pub(crate) fn get(&self, name: &str) -> Option<&str> {
        self.args.iter().find(|(n, _)| n == name).map(|(_, v)| v.as_str())
    }

    /// The interpolant asked for (`cubic` unless `interp` says `linear`).
    pub(crate) fn interp(&self) -> Interpolation {
        if self.get("interp") == Some("linear") {
            Interpolation::Linear
        } else {
            Interpolation::Cubic
        }
    }

    /// The arguments of what is traced: these settings, or with `paint`
    /// the colour filter's set-up (the picking pass replaces its wheel by
    /// a clear filter; the other cutoffs' options left out).
    pub(crate) fn traced(&self) -> Vec<String> {
        if !self.paint {
            return self.argv_without(&[]);
        }
        let mut argv = self.argv_without(&PAINTED);
        argv.extend(["--cutoff", "color"].map(String::from));
        argv
    }

    /// The arguments of the figure: these settings, or with `paint` a
    /// colour filter read from `filter` spanning `half_range` radians.
    pub(crate) fn figure(&self, filter: &Path, half_range: f64) -> Vec<String> {
        if !self.paint {
            return self.traced();
        }
        let mut argv = self.argv_without(&[&PAINTED[..], &["half-range"]].concat());
        argv.extend([
            "--cutoff".into(),
            "color".into(),
            "--filter".into(),
            filter.display().to_string(),
            "--half-range".into(),
            format!("{half_range:.3e}"),
        ]);
        argv
    }

    /// `--name value` for each setting not in `skip`.
    fn argv_without(&self, skip: &[&str]) -> Vec<String> {
        self.args
            .iter()
            .filter(|(n, _)| !skip.contains(&n.as_str()))
            .flat_map(|(n, v)| [format!("--{n}"), v.clone()])
            .collect()
    }
}

/// The options a painted filter replaces (the other cutoffs').
const PAINTED: [&str; 6] = ["cutoff", "angle", "h", "radius", "lambda", "fringes"];

/// How the served file is read, as `rt schlieren` options to repeat on
/// its command line (only those that differ from the defaults).
#[derive(Clone, Debug)]
pub(crate) struct FileOptions {
    pub(crate) samples: crate::optics::Samples,
    pub(crate) allow_nonphysical: bool,
    pub(crate) mesh: crate::optics::MeshOptions,
}

impl FileOptions {
    fn argv(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.samples.quantity == Quantity::Index {
            out.extend(["--quantity".into(), "index".into()]);
        }
        if self.samples.k != rt_volume::GLADSTONE_DALE_AIR {
            out.extend(["--k".into(), format!("{:e}", self.samples.k)]);
        }
        if self.allow_nonphysical {
            out.push("--allow-nonphysical".into());
        }
        if self.mesh.mesh == MeshTrace::Exact {
            out.extend(["--mesh".into(), "exact".into()]);
        }
        if let Some(a) = &self.mesh.array {
            out.extend(["--array".into(), a.clone()]);
        }
        out
    }
}

/// `rt schlieren`'s options for `argv` (and the file's own), as its
/// command line would parse them.
///
/// # Errors
/// clap's message for a bad value, first line only.
pub(crate) fn args(
    file: &Path,
    fo: &FileOptions,
    argv: &[String],
) -> Result<schlieren::Args, String> {
    let all: Vec<String> = argv.iter().cloned().chain(fo.argv()).collect();
    parse::subcommand("schlieren", file, &all).map_err(|e| {
        let text = e.to_string();
        let line = text.lines().next().unwrap_or_default();
        line.strip_prefix("error: ").unwrap_or(line).to_string()
    })
}

/// The command line of `argv` on `file`, quoted for a POSIX shell.
pub(crate) fn command_line(file: &Path, fo: &FileOptions, argv: &[String]) -> String {
    let words = ["rt".to_string(), "schlieren".into(), file.display().to_string()]
        .into_iter()
        .chain(argv.iter().cloned())
        .chain(fo.argv());
    words.map(|w| quote(&w)).collect::<Vec<_>>().join(" ")
}

/// `w` as one word for a POSIX shell.
fn quote(w: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "-_./=:+,%@".contains(c);
    if !w.is_empty() && w.chars().all(plain) {
        w.to_string()
    } else {
        format!("'{}'", w.replace('\'', r"'\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fo() -> FileOptions {
        FileOptions {
            samples: crate::optics::Samples {
                quantity: Quantity::Density,
                k: rt_volume::GLADSTONE_DALE_AIR,
            },
            allow_nonphysical: false,
            mesh: crate::optics::MeshOptions { array: None, mesh: MeshTrace::Smooth },
        }
    }

    #[test]
    fn settings_become_the_command_line_that_parses_to_them() {
        let s =
            Settings::parse(br#"{"cutoff":"knife","angle":90,"h":null,"size":128,"paint":false}"#)
                .unwrap();
        let argv = s.traced();
        assert_eq!(argv, ["--cutoff", "knife", "--angle", "90", "--size", "128"]);
        let file = Path::new("my data/blast.nhdr");
        assert_eq!(
            command_line(file, &fo(), &argv),
            "rt schlieren 'my data/blast.nhdr' --cutoff knife --angle 90 --size 128"
        );
        let a = args(file, &fo(), &argv).unwrap();
        assert_eq!((a.angle, a.size), (90.0, 128));
    }

    #[test]
    fn painting_traces_the_picking_pass_and_saves_a_colour_filter() {
        let s =
            Settings::parse(br#"{"cutoff":"knife","angle":30,"size":64,"paint":true}"#).unwrap();
        let traced = s.traced();
        assert_eq!(traced, ["--size", "64", "--cutoff", "color"]);
        let a = args(Path::new("f.nhdr"), &fo(), &traced).unwrap();
        assert_eq!(a.cutoff, crate::schlieren::CutoffKind::Color);
        let fig = s.figure(Path::new("out/filter.png"), 2e-3);
        assert_eq!(
            fig,
            [
                "--size",
                "64",
                "--cutoff",
                "color",
                "--filter",
                "out/filter.png",
                "--half-range",
                "2.000e-3"
            ]
        );
    }

    #[test]
    fn bad_settings_are_refused_with_a_message() {
        assert!(Settings::parse(b"[1]").unwrap_err().contains("object"));
        assert!(
            Settings::parse(br#"{"knife":1}"#).unwrap_err().contains("unknown setting `knife`")
        );
        assert!(Settings::parse(br#"{"angle":[1]}"#).unwrap_err().contains("`angle`"));
        let s = Settings::parse(br#"{"size":0}"#).unwrap();
        let e = args(Path::new("f.nhdr"), &fo(), &s.traced()).unwrap_err();
        assert!(e.contains("--size"), "{e}");
        let s = Settings::parse(br#"{"angle":"NaN"}"#).unwrap();
        assert!(args(Path::new("f.nhdr"), &fo(), &s.traced()).is_err());
    }
}
