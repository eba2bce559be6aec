//! Sheet reconstruction: the photons of a pass as a deformed lattice.
//!
//! Abel, Hahn & Kaehler 2012, "Tracing the cold dark matter sheet in phase
//! space" (MNRAS 427, 61–76) estimate density from N-body particles by
//! treating the particles' initial lattice as a sheet: each lattice cell,
//! carried by the flow map, keeps its mass and spreads it uniformly over
//! the cell's image. Here the map is the optical bench's, emission point →
//! landing point on the film, and the mass is the photon weight.
//!
//! Splatting independent photons estimates the irradiance
//! `E(x) = Σ_cells w·[x ∈ map(cell)] / |map(cell)|` by sampling; the sheet
//! evaluates it. For an undisturbed beam each cell maps onto itself and
//! every pixel receives exactly its area: no noise at all. Where the field
//! bends light, the only error is the lattice's approximation of the map
//! (each cell's image is taken as two flat triangles), which falls as the
//! square of the lattice spacing for a smooth map; folds (caustics) and
//! crossings are summed correctly, each layer of the sheet adding its
//! share.
//!
//! This module holds the geometry: the exact area a cell's image shares
//! with each pixel of the film.

use crate::math;

/// A convex polygon of at most 12 vertices: a triangle clipped to a
/// rectangle has at most 7, and each axis-aligned cut of a convex polygon
/// adds at most one to a side, so [`cover`]'s four cuts keep at most 11.
#[derive(Clone, Copy)]
pub(crate) struct Polygon {
    v: [(f64, f64); 12],
    n: usize,
}

impl Polygon {
    const EMPTY: Self = Self { v: [(0.0, 0.0); 12], n: 0 };

    fn new(corners: &[(f64, f64)]) -> Self {
        let mut p = Self::EMPTY;
        p.n = corners.len().min(12);
        p.v[..p.n].copy_from_slice(&corners[..p.n]);
        p
    }

    /// The vertices, in order.
    pub(crate) fn vertices(&self) -> &[(f64, f64)] {
        &self.v[..self.n]
    }

    fn push(&mut self, p: (f64, f64)) {
        if self.n < self.v.len() {
            self.v[self.n] = p;
            self.n += 1;
        }
    }

    /// The parts with `coord ≤ c` and `coord ≥ c`, on axis x (`0`) or y
    /// (`1`): one Sutherland–Hodgman step that keeps both sides.
    fn split(&self, axis: usize, c: f64) -> (Self, Self) {
        let coord = |p: (f64, f64)| if axis == 0 { p.0 } else { p.1 };
        let (mut below, mut above) = (Self::EMPTY, Self::EMPTY);
        for i in 0..self.n {
            let (a, b) = (self.v[i], self.v[(i + 1) % self.n]);
            let (ca, cb) = (coord(a), coord(b));
            if ca <= c {
                below.push(a);
            }
            if ca >= c {
                above.push(a);
            }
            if (ca < c && cb > c) || (ca > c && cb < c) {
                // The edge crosses the line: its point there, exactly on
                // the line along `axis`.
                let t = (c - ca) / (cb - ca);
                let p =
                    if axis == 0 { (c, a.1 + t * (b.1 - a.1)) } else { (a.0 + t * (b.0 - a.0), c) };
                below.push(p);
                above.push(p);
            }
        }
        (below, above)
    }

    /// The part inside the slab `lo ≤ coord ≤ hi`.
    fn slab(&self, axis: usize, lo: f64, hi: f64) -> Self {
        self.split(axis, lo).1.split(axis, hi).0
    }

    /// Area (shoelace, unsigned).
    fn area(&self) -> f64 {
        let mut twice = 0.0;
        for i in 0..self.n {
            let (a, b) = (self.v[i], self.v[(i + 1) % self.n]);
            twice += a.0 * b.1 - b.0 * a.1;
        }
        0.5 * twice.abs()
    }

    /// `(min, max)` of the vertices along `axis`.
    fn range(&self, axis: usize) -> (f64, f64) {
        self.v[..self.n].iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            let c = if axis == 0 { p.0 } else { p.1 };
            (lo.min(c), hi.max(c))
        })
    }
}

/// The part of the emission triangle `from` inside the beam `[0, w] ×
/// [0, h]`, carried by the affine map that takes `from` to `to` (a lattice
/// triangle and where its corners landed), and the area of that part
/// before the map; `None` if no part of `from` is inside.
pub(crate) fn clip_and_map(
    from: [(f64, f64); 3],
    to: [(f64, f64); 3],
    w: f64,
    h: f64,
) -> Option<(Polygon, f64)> {
    let inside = Polygon::new(&from).slab(0, 0.0, w).slab(1, 0.0, h);
    let area = inside.area();
    if inside.n < 3 || area <= 0.0 {
        return None;
    }
    // Barycentric coordinates in `from`, applied to `to`.
    let (a, b, c) = (from[0], from[1], from[2]);
    let det = (b.0 - a.0) * (c.1 - a.1) - (c.0 - a.0) * (b.1 - a.1);
    let mut image = inside;
    for p in &mut image.v[..image.n] {
        let l1 = ((p.0 - a.0) * (c.1 - a.1) - (c.0 - a.0) * (p.1 - a.1)) / det;
        let l2 = ((b.0 - a.0) * (p.1 - a.1) - (p.0 - a.0) * (b.1 - a.1)) / det;
        let l0 = 1.0 - l1 - l2;
        *p = (
            l0 * to[0].0 + l1 * to[1].0 + l2 * to[2].0,
            l0 * to[0].1 + l1 * to[1].1 + l2 * to[2].1,
        );
    }
    Some((image, area))
}

/// Whether the quadrilateral `q` (corners in order) is strictly convex:
/// its four turns have one sign. A cell folded or twisted by the optics
/// is not, and is shared out as two triangles instead.
pub(crate) fn convex(q: [(f64, f64); 4]) -> bool {
    let turn = |i: usize| {
        let (a, b, c) = (q[i], q[(i + 1) % 4], q[(i + 2) % 4]);
        (b.0 - a.0) * (c.1 - b.1) - (b.1 - a.1) * (c.0 - b.0)
    };
    let t = [turn(0), turn(1), turn(2), turn(3)];
    t.iter().all(|&x| x > 0.0) || t.iter().all(|&x| x < 0.0)
}

/// `[x0, x1, y0, y1]` if the quadrilateral `q` is a rectangle with sides
/// along the axes to within 1e-9 pixel and of positive size: how an
/// undisturbed cell lands.
fn rectangle(q: &[(f64, f64)]) -> Option<[f64; 4]> {
    let &[a, b, c, d] = q else { return None };
    let near = |u: f64, v: f64| (u - v).abs() <= 1e-9;
    let (x0, x1, y0, y1) = if near(a.1, b.1) && near(c.1, d.1) && near(a.0, d.0) && near(b.0, c.0) {
        (a.0.min(b.0), a.0.max(b.0), a.1.min(d.1), a.1.max(d.1))
    } else if near(a.0, b.0) && near(c.0, d.0) && near(a.1, d.1) && near(b.1, c.1) {
        (a.0.min(d.0), a.0.max(d.0), a.1.min(b.1), a.1.max(b.1))
    } else {
        return None;
    };
    (x1 - x0 > 1e-9 && y1 - y0 > 1e-9).then_some([x0, x1, y0, y1])
}

/// Polygons whose bounding box spans more pixels than this, on either
/// axis, are spread as points at their corners instead: a cell torn across
/// the film (a photon leaving at a grazing angle) would otherwise cost as
/// much as the rest of the image.
pub(crate) const MAX_SPAN: f64 = 64.0;

/// Calls `add(i, j, share)` for each pixel `(i, j)` of a `width × height`
/// film, with `j` in `rows`, that the convex polygon `corners` (a triangle
/// or quadrilateral, in film coordinates in pixels, pixel `(i, j)`
/// spanning `[i, i+1) × [j, j+1)`) overlaps: `share` the overlap's area
/// over the polygon's. The shares over the whole film sum to the part of
/// the polygon on it. A degenerate polygon (area below 1e-12 pixel², a
/// fold seen edge-on) puts all of itself at its centroid; one wider than
/// [`MAX_SPAN`] an equal part at each corner. Non-finite corners deposit
/// nothing.
pub(crate) fn cover(
    corners: &[(f64, f64)],
    width: usize,
    height: usize,
    rows: (usize, usize),
    mut add: impl FnMut(usize, usize, f64),
) {
    if corners.is_empty() || !corners.iter().all(|p| p.0.is_finite() && p.1.is_finite()) {
        return;
    }
    let (wd, ht) = (width as f64, height as f64);
    let rows = (rows.0, rows.1.min(height));
    let mut point = |x: f64, y: f64, share: f64| {
        if x >= 0.0 && y >= 0.0 && x < wd && y < ht {
            let (i, j) = (x as usize, y as usize);
            if (rows.0..rows.1).contains(&j) {
                add(i, j, share);
            }
        }
    };
    let poly = Polygon::new(corners);
    let ((x0, x1), (y0, y1)) = (poly.range(0), poly.range(1));
    if x1 - x0 > MAX_SPAN || y1 - y0 > MAX_SPAN {
        let share = 1.0 / corners.len() as f64;
        for p in corners {
            point(p.0, p.1, share);
        }
        return;
    }
    // All in one pixel: the common case for a lattice finer than the film.
    if math::floor(x0) == math::floor(x1) && math::floor(y0) == math::floor(y1) {
        point(x0, y0, 1.0);
        return;
    }
    if let Some([x0, x1, y0, y1]) = rectangle(corners) {
        // An undisturbed cell: each pixel's share is the product of the
        // overlaps along the two axes.
        let (wx, wy) = (x1 - x0, y1 - y0);
        let lo = math::floor(y0).max(rows.0 as f64);
        let hi = (math::ceil(y1) - 1.0).min(rows.1 as f64 - 1.0);
        let (i0, i1) = (math::floor(x0).max(0.0), (math::ceil(x1) - 1.0).min(wd - 1.0));
        let mut j = lo;
        while j <= hi {
            let fy = (y1.min(j + 1.0) - y0.max(j)) / wy;
            let mut i = i0;
            while i <= i1 {
                let fx = (x1.min(i + 1.0) - x0.max(i)) / wx;
                if fx * fy > 0.0 {
                    add(i as usize, j as usize, fx * fy);
                }
                i += 1.0;
            }
            j += 1.0;
        }
        return;
    }
    let area = poly.area();
    if area < 1e-12 {
        let k = corners.len() as f64;
        let (sx, sy) = corners.iter().fold((0.0, 0.0), |s, p| (s.0 + p.0, s.1 + p.1));
        point(sx / k, sy / k, 1.0);
        return;
    }
    // Rows of pixels split off one at a time from the top, then the
    // pixels of each row from the left: one cut per grid line crossed.
    let mut rest = poly;
    let mut j = math::floor(y0);
    while rest.n >= 3 && j < rows.1 as f64 {
        let (row, below) =
            if j + 1.0 < y1 { rest.split(1, j + 1.0) } else { (rest, Polygon::EMPTY) };
        rest = below;
        if j >= rows.0 as f64 && row.n >= 3 {
            let (rx0, rx1) = row.range(0);
            let mut cells = row;
            let mut i = math::floor(rx0);
            while cells.n >= 3 && i < wd {
                let (cell, right) =
                    if i + 1.0 < rx1 { cells.split(0, i + 1.0) } else { (cells, Polygon::EMPTY) };
                cells = right;
                if i >= 0.0 {
                    let a = cell.area();
                    if a > 0.0 {
                        add(i as usize, j as usize, a / area);
                    }
                }
                i += 1.0;
            }
        }
        j += 1.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec;

    fn shares<const N: usize>(t: [(f64, f64); N], w: usize, h: usize) -> alloc::vec::Vec<f64> {
        let mut out = vec![0.0; w * h];
        cover(&t, w, h, (0, h), |i, j, k| out[i + w * j] += k);
        out
    }

    #[test]
    fn a_triangle_on_the_film_is_shared_out_whole() {
        // Random-looking triangles spanning several pixels: the shares sum
        // to 1, and each pixel's share is its exact overlap.
        let tris = [
            [(0.3, 0.2), (5.7, 1.1), (2.2, 6.9)],
            [(7.9, 7.9), (0.1, 3.3), (4.4, 0.05)],
            [(1.5, 1.5), (2.5, 1.5), (1.5, 2.5)],
        ];
        for t in tris {
            let s = shares(t, 8, 8);
            let total: f64 = s.iter().sum();
            assert!((total - 1.0).abs() < 1e-12, "{t:?}: {total}");
            assert!(s.iter().all(|&k| (0.0..=1.0).contains(&k)));
        }
        // The right triangle (1.5,1.5),(2.5,1.5),(1.5,2.5) of area 1/2:
        // pixel (1,1) holds the square [1.5,2]² (1/4) → share 1/2; pixels
        // (2,1) and (1,2) a triangle of 1/8 each → 1/4 each.
        let s = shares(tris[2], 8, 8);
        assert!((s[1 + 8] - 0.5).abs() < 1e-12);
        assert!((s[2 + 8] - 0.25).abs() < 1e-12);
        assert!((s[1 + 16] - 0.25).abs() < 1e-12);
        assert!(s[2 + 16].abs() < 1e-12);
    }

    #[test]
    fn a_triangle_half_off_the_film_keeps_only_its_part_on_it() {
        // Straddling the left edge x = 0 symmetrically: half of it is on.
        let s = shares([(-2.0, 1.0), (2.0, 1.0), (0.0, 3.0)], 4, 4);
        let total: f64 = s.iter().sum();
        assert!((total - 0.5).abs() < 1e-12, "{total}");
        // Rows outside `rows` get nothing; the rows inside, their share.
        let mut top = 0.0;
        cover(&[(0.0, 0.0), (4.0, 0.0), (0.0, 4.0)], 4, 4, (0, 2), |_, j, k| {
            assert!(j < 2);
            top += k;
        });
        // Of the triangle (area 8), y ≤ 2 holds 8 − 2 = 6.
        assert!((top - 0.75).abs() < 1e-12, "{top}");
    }

    #[test]
    fn degenerate_wide_and_non_finite_triangles() {
        // Inside one pixel: all of it there.
        assert_eq!(shares([(1.1, 1.1), (1.2, 1.1), (1.1, 1.9)], 4, 4)[5], 1.0);
        // A sliver across pixels (zero area): all at its centroid.
        let s = shares([(0.5, 0.5), (3.5, 0.5), (2.0, 0.5)], 4, 4);
        assert_eq!(s[2], 1.0);
        // Too wide: a third at each corner on the film.
        let s = shares([(0.5, 0.5), (1000.5, 0.5), (0.5, 2.5)], 4, 4);
        assert!((s.iter().sum::<f64>() - 2.0 / 3.0).abs() < 1e-15);
        // Non-finite: nothing.
        assert!(shares([(f64::NAN, 0.5), (1.5, 0.5), (0.5, 2.5)], 4, 4).iter().all(|&k| k == 0.0));
        assert!(
            shares([(f64::INFINITY, 0.5), (1.5, 0.5), (0.5, 2.5)], 4, 4).iter().all(|&k| k == 0.0)
        );
    }

    #[test]
    fn quadrilaterals_and_convexity() {
        // A pixel-sized square centred on a grid corner: a quarter each.
        let s = shares([(0.5, 0.5), (1.5, 0.5), (1.5, 1.5), (0.5, 1.5)], 3, 3);
        for p in [0, 1, 3, 4] {
            assert!((s[p] - 0.25).abs() < 1e-15, "{s:?}");
        }
        // A sheared quadrilateral over many pixels: shares sum to 1 and
        // match its two triangles' shares weighted by their areas.
        let q = [(0.2, 0.7), (4.9, 0.1), (5.6, 3.3), (1.1, 4.8)];
        assert!(convex(q));
        let s = shares(q, 8, 8);
        assert!((s.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let t1 = shares([q[0], q[1], q[2]], 8, 8);
        let t2 = shares([q[0], q[2], q[3]], 8, 8);
        let area = |t: [(f64, f64); 3]| {
            let (a, b, c) = (t[0], t[1], t[2]);
            0.5 * ((b.0 - a.0) * (c.1 - a.1) - (c.0 - a.0) * (b.1 - a.1)).abs()
        };
        let (a1, a2) = (area([q[0], q[1], q[2]]), area([q[0], q[2], q[3]]));
        for p in 0..64 {
            let both = (a1 * t1[p] + a2 * t2[p]) / (a1 + a2);
            assert!((s[p] - both).abs() < 1e-12, "pixel {p}: {} vs {both}", s[p]);
        }
        // An axis-aligned rectangle (the fast path) shares exactly as the
        // same rectangle slightly rotated (the general path) would, in the
        // limit.
        let r = shares([(0.3, 0.6), (2.7, 0.6), (2.7, 1.9), (0.3, 1.9)], 4, 4);
        let e = 1e-7;
        let g = shares([(0.3, 0.6), (2.7, 0.6 + e), (2.7 - e, 1.9), (0.3, 1.9 - e)], 4, 4);
        assert!(rectangle(&[(0.3, 0.6), (2.7, 0.6), (2.7, 1.9), (0.3, 1.9)]).is_some());
        assert!(rectangle(&[(0.3, 0.6), (2.7, 0.6 + e), (2.7 - e, 1.9), (0.3, 1.9 - e)]).is_none());
        for p in 0..16 {
            assert!((r[p] - g[p]).abs() < 1e-6, "pixel {p}: {} vs {}", r[p], g[p]);
        }
        assert!((r[1] - 0.4 / (2.4 * 1.3)).abs() < 1e-12);
        // Folded (a bow tie) and reflex quadrilaterals are not convex;
        // orientation does not matter.
        assert!(!convex([(0.0, 0.0), (1.0, 1.0), (1.0, 0.0), (0.0, 1.0)]));
        assert!(!convex([(0.0, 0.0), (2.0, 0.0), (0.5, 0.5), (0.0, 2.0)]));
        assert!(convex([(0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1.0, 0.0)]));
    }

    #[test]
    fn clipped_to_the_beam_and_carried_by_the_affine_map() {
        // Half of this triangle is inside x ≥ 0 (area 1/2 of 2): the part
        // with x + y ≤ 1, x, y ≥ 0.
        let from = [(-1.0, 0.0), (1.0, 0.0), (-1.0, 2.0)];
        // Identity: the image is the clipped part itself.
        let (p, a) = clip_and_map(from, from, 4.0, 4.0).unwrap();
        assert!((a - 0.5).abs() < 1e-15);
        assert!((p.area() - 0.5).abs() < 1e-15);
        // Doubled and shifted: the image's area is 4×, its vertices moved.
        let to = from.map(|q| (2.0 * q.0 + 10.0, 2.0 * q.1 - 1.0));
        let (p, a) = clip_and_map(from, to, 4.0, 4.0).unwrap();
        assert!((a - 0.5).abs() < 1e-15);
        assert!((p.area() - 2.0).abs() < 1e-12);
        for v in p.vertices() {
            let back = ((v.0 - 10.0) / 2.0, (v.1 + 1.0) / 2.0);
            assert!(
                back.0 >= -1e-12 && back.1 >= -1e-12 && back.0 + back.1 <= 1.0 + 1e-12,
                "{v:?}"
            );
        }
        // Entirely outside: nothing.
        assert!(clip_and_map([(-3.0, 0.5), (-2.0, 0.5), (-3.0, 1.0)], from, 4.0, 4.0).is_none());
    }
}
