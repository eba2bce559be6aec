//! rtvis's ray API against embreex (Embree 4 from Python, what trimesh
//! uses when it is installed): `rt-python/benches/rays.py` run by the
//! Python in `RT_PYTHON` (default: CI's virtualenv,
//! `target/venv-rtvis/bin/python`), which must have rtvis, trimesh and
//! embreex installed. Its table is the section; its CSV is `rays.csv`.

use std::{path::Path, process::Command};

use crate::Section;

pub(crate) fn run(dir: &Path, quick: bool) -> Result<Section, String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let python = std::env::var_os("RT_PYTHON")
        .map_or_else(|| root.join("target/venv-rtvis/bin/python"), Into::into);
    if !python.exists() {
        return Err(format!(
            "{}: no Python; set RT_PYTHON to one with rtvis, trimesh and embreex installed",
            python.display()
        ));
    }
    let csv = dir.join("rays.csv");
    let mut cmd = Command::new(&python);
    cmd.arg(root.join("rt-python/benches/rays.py")).arg("--csv").arg(&csv);
    if quick {
        cmd.arg("--quick");
    }
    let out = cmd.output().map_err(|e| format!("{}: {e}", python.display()))?;
    if !out.status.success() {
        return Err(format!("rays.py failed: {}", String::from_utf8_lossy(&out.stderr)));
    }
    let table = String::from_utf8_lossy(&out.stdout).into_owned();
    let ours_misses = std::fs::read_to_string(&csv)
        .map_err(|e| e.to_string())?
        .lines()
        .find_map(|l| l.strip_prefix("watertight,first+any,rtvis-misses,").map(str::to_owned))
        .unwrap_or_default();
    Ok(Section {
        title: "rays from Python: rtvis.RayMesh against embreex".into(),
        body: format!(
            "`rt-python/benches/rays.py` (Mrays/s, best of 5; rtvis on one thread and on all cores, embreex on the calling thread).\n\n{table}\nwrote {}",
            csv.display()
        ),
        verdicts: vec![format!(
            "rtvis misses {ours_misses} of the rays aimed at vertices and edge midpoints (target 0: {})",
            if ours_misses == "0" { "met" } else { "NOT met" }
        )],
        plots: vec![],
    })
}
