//! PLY output, so the demo's meshes can be opened elsewhere (and fed to
//! the `view` example).

use std::{
    fs::File,
    io::{BufWriter, Write},
    path::Path,
};

use rt_accel::TriangleMesh;

/// Writes `mesh` as binary little-endian PLY: `x y z`, its scalars (if any)
/// as property `scalar_name`, and triangles as `vertex_indices` lists.
///
/// # Errors
/// I/O errors, as text naming the file.
pub fn write_ply(mesh: &TriangleMesh, scalar_name: &str, path: &Path) -> Result<(), String> {
    let err = |e: std::io::Error| format!("{}: {e}", path.display());
    let mut w = BufWriter::new(File::create(path).map_err(err)?);
    let scalars = mesh.scalars();
    let mut header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment written by rt-benches\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n",
        mesh.positions().len()
    );
    if scalars.is_some() {
        header += &format!("property float {scalar_name}\n");
    }
    header += &format!(
        "element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        mesh.indices().len()
    );
    w.write_all(header.as_bytes()).map_err(err)?;
    for (i, p) in mesh.positions().iter().enumerate() {
        for v in p.to_array().into_iter().chain(scalars.map(|s| s[i])) {
            w.write_all(&v.to_le_bytes()).map_err(err)?;
        }
    }
    for t in mesh.indices() {
        w.write_all(&[3]).map_err(err)?;
        for i in t {
            w.write_all(&i.to_le_bytes()).map_err(err)?;
        }
    }
    w.flush().map_err(err)
}
