"""Unstructured meshes from Python: numpy arrays (meshio's cell names) or
a VTK file, rendered on every optical system like a gridded volume."""

import math

import numpy as np
import pytest

import rtvis
from helpers import bump_deflection, pixel_centres


def lattice(n, lo, hi, f):
    """The hexahedra of an n³-point lattice over [lo, hi]³ and f at its
    points (x fastest, VTK's hexahedron order)."""
    t = np.linspace(lo, hi, n)
    z, y, x = np.meshgrid(t, t, t, indexing="ij")
    points = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    i, j, k = np.meshgrid(np.arange(n - 1), np.arange(n - 1), np.arange(n - 1), indexing="ij")
    i, j, k = i.ravel(), j.ravel(), k.ravel()
    pid = lambda a, b, c: a + n * (b + n * c)  # noqa: E731
    hexes = np.stack([pid(i, j, k), pid(i + 1, j, k), pid(i + 1, j + 1, k), pid(i, j + 1, k),
                      pid(i, j, k + 1), pid(i + 1, j, k + 1), pid(i + 1, j + 1, k + 1),
                      pid(i, j + 1, k + 1)], axis=1)
    return points, hexes, f(points)


def bump_index(sigma=8e-3, delta=1e-4):
    return lambda p: 1.0 + delta * np.exp(-(p ** 2).sum(axis=1) / (2 * sigma ** 2))


def test_mesh_deflection_matches_the_analytic_bump():
    sigma, delta = 8e-3, 1e-4
    points, hexes, index = lattice(33, -0.032, 0.032, bump_index(sigma, delta))
    # Cells of σ/4: pixel means of the exact tracer are within 5 % of the
    # peak, the smooth option's within 8 % (`rt-report unstructured` at
    # N = 32: 3.2e-2 and 5.1e-2; the smooth one wins per ray, not per pixel).
    for trace, tolerance in (("exact", 0.05), ("smooth", 0.08)):
        mesh = rtvis.Mesh(points, {"hexahedron": hexes}, index, quantity="index", trace=trace)
        # 24 tetrahedra per hexahedron, 4 boundary triangles per boundary
        # quadrilateral (split about face and cell centres).
        assert mesh.counts == (33 ** 3, 32 ** 3, 24 * 32 ** 3, 4 * 6 * 32 ** 2)
        _, eps = rtvis.schlieren(mesh, f=1.0, h=4e-4, size=48, deflection=True)
        ex, ey = bump_deflection(*pixel_centres(mesh, eps.shape[:2]), sigma, delta)
        peak = np.abs(ex).max()
        assert np.abs(eps[..., 0] - ex).max() < tolerance * peak, trace
        assert np.abs(eps[..., 1] - ey).max() < tolerance * peak, trace


def test_every_optical_system_takes_a_mesh():
    points, hexes, index = lattice(17, -0.032, 0.032, bump_index())
    mesh = rtvis.Mesh(points, {"hexahedron": hexes, "quad": np.zeros((0, 4))}, index,
                      quantity="index")
    assert rtvis.shadowgraph(mesh, size=32).shape == (32, 32)
    assert rtvis.interferogram(mesh, size=32).shape == (32, 32)
    assert rtvis.color_schlieren(mesh, size=32).shape == (32, 32, 3)
    bos = rtvis.bos(mesh, size=32)
    assert bos[0].shape == (32, 32)
    reference, flow, relative, info = rtvis.focusing(mesh, size=32, samples=2)
    assert relative.shape == (32, 32) and np.isfinite(relative).all()


def test_a_uniform_mesh_is_the_background():
    points, hexes, _ = lattice(5, 0.0, 1.0, lambda p: p[:, 0])
    # Wedges and tetrahedra too: each cube's hexahedron, or its two wedges.
    wedges = np.concatenate([hexes[:, [0, 1, 2, 4, 5, 6]], hexes[:, [0, 2, 3, 4, 6, 7]]])
    for cells in ({"hexahedron": hexes}, {"wedge": wedges}):
        mesh = rtvis.Mesh(points, cells, np.full(len(points), 1.2))
        img = rtvis.schlieren(mesh, size=16)
        assert np.abs(img - 1.0).max() < 1e-6


def test_read_mesh_reads_a_vtu(tmp_path):
    points, hexes, index = lattice(9, -0.032, 0.032, bump_index())
    path = tmp_path / "bump.vtu"
    lines = ['<?xml version="1.0"?>',
             '<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">',
             "<UnstructuredGrid>",
             f'<Piece NumberOfPoints="{len(points)}" NumberOfCells="{len(hexes)}">',
             '<PointData Scalars="n">', '<DataArray type="Float64" Name="n" format="ascii">',
             " ".join(repr(float(v)) for v in index), "</DataArray>", "</PointData>",
             "<Points>", '<DataArray type="Float64" NumberOfComponents="3" format="ascii">',
             " ".join(repr(float(v)) for v in points.ravel()), "</DataArray>", "</Points>",
             "<Cells>", '<DataArray type="Int64" Name="connectivity" format="ascii">',
             " ".join(map(str, hexes.ravel())), "</DataArray>",
             '<DataArray type="Int64" Name="offsets" format="ascii">',
             " ".join(str(8 * (i + 1)) for i in range(len(hexes))), "</DataArray>",
             '<DataArray type="UInt8" Name="types" format="ascii">',
             " ".join(["12"] * len(hexes)), "</DataArray>", "</Cells>", "</Piece>",
             "</UnstructuredGrid>", "</VTKFile>"]
    path.write_text("\n".join(lines))
    from_file = rtvis.read_mesh(path, array="n", quantity="index")
    from_arrays = rtvis.Mesh(points, {"hexahedron": hexes}, index, quantity="index")
    assert from_file.counts == from_arrays.counts
    a = rtvis.schlieren(from_file, size=24)
    b = rtvis.schlieren(from_arrays, size=24)
    assert np.array_equal(a, b)
    with pytest.raises(ValueError, match="no point or cell data array named"):
        rtvis.read_mesh(path, array="rho")
    with pytest.raises(OSError):
        rtvis.read_mesh(tmp_path / "missing.vtu")
    (tmp_path / "bad.vtu").write_text("<VTKFile")
    with pytest.raises(ValueError):
        rtvis.read_mesh(tmp_path / "bad.vtu")


def test_bad_meshes_raise():
    points, hexes, index = lattice(3, 0.0, 1.0, lambda p: 1.0 + 0.0 * p[:, 0])
    bad = points.copy()
    bad[4, 1] = math.nan
    with pytest.raises(ValueError, match="not finite"):
        rtvis.Mesh(bad, {"hexahedron": hexes}, index)
    with pytest.raises(ValueError, match="last of length 8"):
        rtvis.Mesh(points, {"hexahedron": hexes[:, :7]}, index)
    with pytest.raises(ValueError, match="unknown kind"):
        rtvis.Mesh(points, {"tetra10": hexes}, index)
    with pytest.raises(ValueError, match="missing point"):
        rtvis.Mesh(points, {"hexahedron": hexes + 100}, index)
    with pytest.raises(ValueError, match="out of range"):
        rtvis.Mesh(points, {"hexahedron": hexes - 100}, index)
    with pytest.raises(ValueError, match="one per point"):
        rtvis.Mesh(points, {"hexahedron": hexes}, index[:-1])
    with pytest.raises(ValueError, match="inverted|no volume"):
        rtvis.Mesh(points, {"hexahedron": hexes[:, [0, 1, 2, 3, 4, 5, 7, 6]]}, index)
    with pytest.raises(ValueError, match="trace"):
        rtvis.Mesh(points, {"hexahedron": hexes}, index, trace="rk4")
    with pytest.raises(TypeError):
        rtvis.Mesh(points, [hexes], index)
    mesh = rtvis.Mesh(points, {"hexahedron": hexes}, index)
    with pytest.raises(ValueError, match="no grid"):
        mesh._v.shape
