//! Value parsers for options clap does not know: sizes, vectors, ranges.

use rt_core::glam::Vec3;

/// The options `rt NAME FILE ARGS…` would parse to for a subcommand whose
/// options are `A` (defaults included): how the demo drives a command
/// exactly as a user's command line would.
///
/// # Errors
/// What clap reports for bad arguments.
pub(crate) fn subcommand<A, I, T>(
    name: &'static str,
    file: &std::path::Path,
    args: I,
) -> Result<A, clap::Error>
where
    A: clap::Args + clap::FromArgMatches,
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let command = A::augment_args(clap::Command::new(name));
    let argv = [std::ffi::OsString::from(name), file.as_os_str().to_owned()]
        .into_iter()
        .chain(args.into_iter().map(Into::into));
    let matches = command.try_get_matches_from(argv)?;
    A::from_arg_matches(&matches)
}

/// The largest image edge the tools accept, in pixels.
pub(crate) use rt_photo::MAX_EDGE;

/// `WxH` in pixels, each in `1..=MAX_EDGE`.
pub(crate) fn size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("`{s}` is not WxH"))?;
    let edge = |t: &str| -> Result<u32, String> {
        let v: u32 = t.trim().parse().map_err(|_| format!("`{t}` is not a pixel count"))?;
        if (1..=MAX_EDGE).contains(&v) {
            Ok(v)
        } else {
            Err(format!("{v} pixels: each side must be 1 to {MAX_EDGE}"))
        }
    };
    Ok((edge(w)?, edge(h)?))
}

/// `N` finite numbers separated by commas.
fn numbers<const N: usize>(s: &str) -> Result<[f32; N], String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|t| t.trim().parse::<f32>().map_err(|_| format!("`{t}` is not a number")))
        .collect::<Result<_, _>>()?;
    let arr: [f32; N] = v.try_into().map_err(|_| format!("`{s}`: {N} numbers wanted"))?;
    if arr.iter().all(|x| x.is_finite()) {
        Ok(arr)
    } else {
        Err(format!("`{s}`: numbers must be finite"))
    }
}

/// `X,Y,Z`.
pub(crate) fn vec3(s: &str) -> Result<Vec3, String> {
    numbers::<3>(s).map(Vec3::from)
}

/// `R,G,B` in `[0, 1]`.
pub(crate) fn rgb(s: &str) -> Result<[f32; 3], String> {
    let c = numbers::<3>(s)?;
    if c.iter().all(|v| (0.0..=1.0).contains(v)) {
        Ok(c)
    } else {
        Err(format!("`{s}`: each component in [0, 1]"))
    }
}

/// `LO,HI` with `LO < HI`.
pub(crate) fn range(s: &str) -> Result<(f32, f32), String> {
    let [lo, hi] = numbers::<2>(s)?;
    if lo < hi { Ok((lo, hi)) } else { Err(format!("`{s}`: LO must be below HI")) }
}

/// A finite number.
pub(crate) fn finite(s: &str) -> Result<f64, String> {
    s.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| format!("`{s}` is not a finite number"))
}

/// A finite number `> 0`.
pub(crate) fn positive(s: &str) -> Result<f64, String> {
    let v = finite(s)?;
    if v > 0.0 { Ok(v) } else { Err(format!("{v}: must be > 0")) }
}

/// A finite number `≥ 0`.
pub(crate) fn non_negative(s: &str) -> Result<f64, String> {
    let v = finite(s)?;
    if v >= 0.0 { Ok(v) } else { Err(format!("{v}: must be ≥ 0")) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parsers_accept_good_and_name_bad_values() {
        assert_eq!(size("640x480"), Ok((640, 480)));
        assert!(size("0x0").unwrap_err().contains("1 to 16384"));
        assert!(size("99999x10").is_err());
        assert!(size("640").is_err());
        assert_eq!(vec3("1,2,3"), Ok(Vec3::new(1.0, 2.0, 3.0)));
        assert!(vec3("1,2").is_err());
        assert!(vec3("1,nan,3").is_err());
        assert_eq!(range("-1,2"), Ok((-1.0, 2.0)));
        assert!(range("2,1").is_err());
        assert!(rgb("1,0.5,2").is_err());
        assert!(finite("1e400").is_err());
        assert!(positive("-3").is_err());
        assert!(positive("0").is_err());
        assert_eq!(positive("2e-3"), Ok(2e-3));
    }
}
