//! Legacy VTK headers checked before `vtkio` parses them: `vtkio` reserves
//! memory for the counts a header declares, so a file declaring billions
//! of values would abort the process instead of failing to parse.

use alloc::{format, string::String, vec::Vec};

use super::{ReadError, error::malformed};

/// Legacy data type names, as `vtkio` reads them.
const DATA_TYPES: [&str; 11] = [
    "bit",
    "char",
    "unsigned_char",
    "short",
    "unsigned_short",
    "int",
    "unsigned_int",
    "long",
    "unsigned_long",
    "float",
    "double",
];

/// Refuses a legacy VTK file (`bytes`) whose header declares more values
/// than its bytes could hold (every value takes at least a byte, ASCII or
/// binary; bits an eighth), before `vtkio` reserves memory for them. The
/// first two lines (version and free-text title) are not read.
pub(super) fn check_legacy_sizes(bytes: &[u8]) -> Result<(), ReadError> {
    let len = u64::try_from(bytes.len()).unwrap_or(u64::MAX);
    let mut tokens = skip_lines(bytes, 2).split(u8::is_ascii_whitespace).filter(|t| !t.is_empty());
    // The current token and the four after it.
    let mut w: [&[u8]; 5] = [&[]; 5];
    for slot in &mut w[1..] {
        *slot = tokens.next().unwrap_or_default();
    }
    // Elements per attribute: the last POINT_DATA / CELL_DATA count.
    let mut elements = 0u64;
    loop {
        w.rotate_left(1);
        w[4] = tokens.next().unwrap_or_default();
        if w[0].is_empty() {
            return Ok(());
        }
        let Some((count, bits, args)) = declared(&w, &mut elements) else { continue };
        let bytes_needed = if bits { count.div_ceil(8) } else { count };
        if bytes_needed > len {
            let words: Vec<_> = w[..=args].iter().map(|t| String::from_utf8_lossy(t)).collect();
            return Err(malformed(format!(
                "legacy VTK: `{}` declares {count} values, more than the file's {len} bytes hold",
                words.join(" ")
            )));
        }
    }
}

/// The values the keyword `w[0]` declares (with the tokens after it),
/// whether they are bits, and how many tokens after the keyword the
/// declaration takes; `elements` is the attribute length in force.
fn declared(w: &[&[u8]; 5], elements: &mut u64) -> Option<(u64, bool, usize)> {
    let int = |i: usize| -> Option<u64> { core::str::from_utf8(w[i]).ok()?.parse().ok() };
    let is = |i: usize, word: &str| w[i].eq_ignore_ascii_case(word.as_bytes());
    let word = |s: &str| is(0, s);
    let n = *elements;
    if word("POINTS") {
        int(1).map(|p| (p.saturating_mul(3), false, 2))
    } else if ["CELLS", "POLYGONS", "LINES", "VERTICES", "TRIANGLE_STRIPS"].into_iter().any(word) {
        // A cell count and the total size read after it.
        int(1).zip(int(2)).map(|(cells, size)| (cells.max(size), false, 2))
    } else if ["CELL_TYPES", "X_COORDINATES", "Y_COORDINATES", "Z_COORDINATES"]
        .into_iter()
        .any(word)
    {
        int(1).map(|c| (c, false, 1))
    } else if word("POINT_DATA") || word("CELL_DATA") {
        let c = int(1)?;
        *elements = c;
        Some((c, false, 1))
    } else if word("SCALARS") {
        let comps = int(3);
        Some((
            comps.unwrap_or(1).saturating_mul(n),
            is(2, "bit"),
            if comps.is_some() { 3 } else { 2 },
        ))
    } else if word("COLOR_SCALARS") {
        int(2).map(|comps| (comps.saturating_mul(n), false, 2))
    } else if word("VECTORS") || word("NORMALS") {
        Some((n.saturating_mul(3), is(2, "bit"), 2))
    } else if word("TENSORS") {
        Some((n.saturating_mul(9), is(2, "bit"), 2))
    } else if word("TEXTURE_COORDINATES") {
        int(2).map(|dim| (dim.saturating_mul(n), is(3, "bit"), 3))
    } else if word("LOOKUP_TABLE") {
        // `LOOKUP_TABLE name n` (a table), not `LOOKUP_TABLE default`.
        int(2).map(|entries| (entries.saturating_mul(4), false, 2))
    } else if word("FIELD") {
        int(2).map(|arrays| (arrays, false, 2))
    } else if DATA_TYPES.iter().any(|d| is(3, d)) {
        // A field array, `name components tuples type`: `vtkio` multiplies
        // the two as `u32`, so a product past that range is refused too.
        let (comps, tuples) = int(1).zip(int(2))?;
        let count = comps.saturating_mul(tuples);
        Some((if count > u64::from(u32::MAX) { u64::MAX } else { count }, is(3, "bit"), 3))
    } else {
        None
    }
}

/// `bytes` after its first `n` lines.
fn skip_lines(bytes: &[u8], n: usize) -> &[u8] {
    let mut rest = bytes;
    for _ in 0..n {
        match rest.iter().position(|&b| b == b'\n') {
            Some(p) => rest = &rest[p + 1..],
            None => return &[],
        }
    }
    rest
}
