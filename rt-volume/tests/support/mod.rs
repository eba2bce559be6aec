//! A seeded generator, and meshes of a box for the unstructured tests
//! (feature `mesh`).

#![allow(dead_code)]

#[cfg(feature = "mesh")]
use glam::DVec3;
#[cfg(feature = "mesh")]
use rt_volume::Cell;

/// SplitMix64: a small seeded generator for test meshes.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    pub(crate) fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in `[0, 1)`.
    pub(crate) fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in `[a, b)`.
    pub(crate) fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.unit()
    }
}

/// How the cells of a box mesh are made.
#[cfg(feature = "mesh")]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    /// One hexahedron per grid cell.
    Hex,
    /// Two wedges per grid cell.
    Wedge,
    /// Six pyramids per grid cell, around an added centre point.
    Pyramid,
    /// Six tetrahedra per grid cell around its main diagonal (Kuhn).
    Tet,
    /// Hexahedra and pyramids, chosen per cell (both cut a grid face about
    /// its centre, so they fit together; wedges and Kuhn tetrahedra cut
    /// them along diagonals).
    Mixed,
}

/// A box `[lo, hi]` cut into `dims` grid cells, each made into cells of
/// `kind`. Interior points move by up to `jitter` of a spacing (boundary
/// points only along their faces), and the point numbering is shuffled
/// when `shuffle` (so quadrilaterals are cut along every kind of diagonal).
#[cfg(feature = "mesh")]
pub(crate) fn box_mesh(
    lo: DVec3,
    hi: DVec3,
    dims: [usize; 3],
    kind: Kind,
    jitter: f64,
    shuffle: bool,
    rng: &mut Rng,
) -> (Vec<DVec3>, Vec<Cell>) {
    let [nx, ny, nz] = dims;
    let h = (hi - lo) / DVec3::new(nx as f64, ny as f64, nz as f64);
    let id = |i: usize, j: usize, k: usize| (i + (nx + 1) * (j + (ny + 1) * k)) as u32;
    let mut points = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                let mut p = lo + h * DVec3::new(i as f64, j as f64, k as f64);
                let inner = [i > 0 && i < nx, j > 0 && j < ny, k > 0 && k < nz];
                for a in 0..3 {
                    if inner[a] {
                        p[a] += jitter * h[a] * rng.range(-1.0, 1.0);
                    }
                }
                points.push(p);
            }
        }
    }
    let mut cells = Vec::new();
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let v = [
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ];
                let kind = if kind == Kind::Mixed {
                    [Kind::Hex, Kind::Pyramid][(rng.next() % 2) as usize]
                } else {
                    kind
                };
                match kind {
                    Kind::Hex => cells.push(Cell::Hexahedron(v)),
                    Kind::Wedge => {
                        cells.push(Cell::Wedge([v[0], v[1], v[2], v[4], v[5], v[6]]));
                        cells.push(Cell::Wedge([v[0], v[2], v[3], v[4], v[6], v[7]]));
                    }
                    Kind::Pyramid => {
                        let c = points.len() as u32;
                        let centre = v.iter().map(|&p| points[p as usize]).sum::<DVec3>() / 8.0;
                        points.push(centre);
                        for q in [
                            [v[0], v[3], v[2], v[1]],
                            [v[4], v[5], v[6], v[7]],
                            [v[0], v[1], v[5], v[4]],
                            [v[1], v[2], v[6], v[5]],
                            [v[2], v[3], v[7], v[6]],
                            [v[3], v[0], v[4], v[7]],
                        ] {
                            cells.push(Cell::Pyramid([q[0], q[1], q[2], q[3], c]));
                        }
                    }
                    Kind::Tet | Kind::Mixed => {
                        // Kuhn: the six paths from corner 0 to corner 6.
                        for path in [[1, 2], [1, 5], [3, 2], [3, 7], [4, 5], [4, 7]] {
                            cells.push(Cell::Tetra([v[0], v[path[0]], v[path[1]], v[6]]));
                        }
                    }
                }
            }
        }
    }
    if shuffle {
        let n = points.len();
        let mut perm: Vec<u32> = (0..n as u32).collect();
        for i in (1..n).rev() {
            perm.swap(i, (rng.next() % (i as u64 + 1)) as usize);
        }
        let mut moved = vec![DVec3::ZERO; n];
        for (old, &new) in perm.iter().enumerate() {
            moved[new as usize] = points[old];
        }
        points = moved;
        for c in &mut cells {
            match c {
                Cell::Tetra(p) => p.iter_mut().for_each(|x| *x = perm[*x as usize]),
                Cell::Pyramid(p) => p.iter_mut().for_each(|x| *x = perm[*x as usize]),
                Cell::Wedge(p) => p.iter_mut().for_each(|x| *x = perm[*x as usize]),
                Cell::Hexahedron(p) => p.iter_mut().for_each(|x| *x = perm[*x as usize]),
            }
        }
    }
    (points, cells)
}

/// Boundary triangles of a box mesh of `dims` grid cells of `kind`: four
/// per grid face on the box's surface where the cells have a
/// quadrilateral there (cut about its centre), two where they have two
/// triangles (Kuhn tetrahedra everywhere, wedges across z).
#[cfg(feature = "mesh")]
pub(crate) fn box_boundary_triangles(dims: [usize; 3], kind: Kind) -> usize {
    let [x, y, z] = dims;
    let (across_z, sides) = (2 * x * y, 2 * (y * z + z * x));
    match kind {
        Kind::Tet => 2 * (across_z + sides),
        Kind::Wedge => 2 * across_z + 4 * sides,
        Kind::Hex | Kind::Pyramid | Kind::Mixed => 4 * (across_z + sides),
    }
}
