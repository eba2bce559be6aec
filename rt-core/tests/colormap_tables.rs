//! The built-in colour maps against their published tables (data files
//! copied from the sources, not from our code): matplotlib's 256 viridis
//! entries and Moreland's 33 cool-to-warm entries. A renderer shades with
//! [`ColorMap::map`] (linear) and encodes to sRGB at output; that path,
//! and [`ColorMap::map_srgb`], must give back every entry within 1/255.

use rt_core::{ColorMap, frame::linear_to_srgb};

/// Rows of `r,g,b` after the comment and header lines, scaled by `scale`.
fn table(csv: &str, scale: f32) -> Vec<[f32; 3]> {
    csv.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with('r'))
        .map(|l| {
            let v: Vec<f32> =
                l.split(',').map(|x| x.trim().parse::<f32>().unwrap() / scale).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

/// Largest difference, in 8-bit steps, between the table and the map at
/// each entry's position, through both output paths.
fn worst(map: &ColorMap<'_>, entries: &[[f32; 3]]) -> (f32, f32) {
    let last = (entries.len() - 1) as f32;
    let (mut shaded, mut direct) = (0.0f32, 0.0f32);
    for (i, want) in entries.iter().enumerate() {
        let x = i as f32 / last;
        let lin = map.map(x);
        let enc = map.map_srgb(x);
        for k in 0..3 {
            shaded = shaded.max((linear_to_srgb(lin[k]) - want[k]).abs() * 255.0);
            direct = direct.max((enc[k] - want[k]).abs() * 255.0);
        }
    }
    (shaded, direct)
}

#[test]
fn viridis_reproduces_matplotlib_table() {
    let entries = table(include_str!("data/viridis.csv"), 1.0);
    assert_eq!(entries.len(), 256);
    let (shaded, direct) = worst(&ColorMap::viridis(), &entries);
    assert!(shaded <= 1.0, "shaded then encoded: {shaded} steps off");
    assert!(direct <= 1.0, "sRGB lookup: {direct} steps off");
    // The published mid entry (index 128), the one a double encoding
    // turned into (100, 198, 196).
    let mid = ColorMap::viridis().map(128.0 / 255.0);
    let px = mid.map(|c| (linear_to_srgb(c) * 255.0 + 0.5) as u8);
    assert_eq!(&px[..3], &[33, 145, 140]);
}

#[test]
fn cool_to_warm_reproduces_moreland_table() {
    let entries = table(include_str!("data/cool_to_warm.csv"), 255.0);
    assert_eq!(entries.len(), 33);
    let (shaded, direct) = worst(&ColorMap::cool_to_warm(), &entries);
    assert!(shaded <= 1.0, "shaded then encoded: {shaded} steps off");
    assert!(direct <= 1.0, "sRGB lookup: {direct} steps off");
}

#[test]
fn between_entries_the_map_interpolates_the_encoded_values() {
    // Halfway between two viridis entries the sRGB value is their mean (as
    // matplotlib's ListedColormap and ParaView's RGB interpolation give).
    let entries = table(include_str!("data/viridis.csv"), 1.0);
    let x = 100.5 / 255.0;
    let got = ColorMap::viridis().map_srgb(x);
    for k in 0..3 {
        let want = 0.5 * (entries[100][k] + entries[101][k]);
        assert!((got[k] - want).abs() < 1e-5, "channel {k}: {} vs {want}", got[k]);
    }
}
