"""rtvis.RayMesh against trimesh's own ray tests (its pure-numpy
intersector, something rt did not write), on its meshes; watertightness,
bad input and bytes."""

import numpy as np
import pytest

import rtvis

trimesh = pytest.importorskip("trimesh")


def random_rays(n, seed, radius=3.0):
    """Rays from a sphere of ``radius`` aimed at points inside the unit
    ball's inner half."""
    rng = np.random.default_rng(seed)
    o = rng.normal(size=(n, 3))
    o *= radius / np.linalg.norm(o, axis=1)[:, None]
    target = rng.uniform(-0.5, 0.5, size=(n, 3))
    d = target - o
    return o, d / np.linalg.norm(d, axis=1)[:, None]


def test_first_hits_and_locations_agree_with_trimesh():
    mesh = trimesh.creation.icosphere(subdivisions=3)
    theirs = trimesh.ray.ray_triangle.RayMeshIntersector(mesh)
    ours = rtvis.RayMesh(mesh.vertices, mesh.faces)
    o, d = random_rays(2000, 1)
    assert np.array_equal(ours.intersects_first(o, d), theirs.intersects_first(o, d))
    assert ours.intersects_any(o, d).all()
    # Every crossing: two per ray, at trimesh's locations.
    loc, ray, tri = ours.intersects_location(o, d)
    loc_t, ray_t, tri_t = theirs.intersects_location(o, d, multiple_hits=True)
    assert np.array_equal(np.bincount(ray, minlength=2000), np.full(2000, 2))
    assert np.array_equal(np.bincount(ray_t, minlength=2000), np.full(2000, 2))
    mine = sorted(zip(ray.tolist(), tri.tolist()))
    their = sorted(zip(ray_t.tolist(), tri_t.tolist()))
    assert mine == their
    for r in range(0, 2000, 97):
        a = loc[ray == r]
        b = loc_t[ray_t == r]
        b = b[np.argsort(np.linalg.norm(b - o[r], axis=1))]
        assert np.allclose(a, b, atol=1e-5), (r, a, b)
    # The first hit's fields hold together.
    hits = ours.first_hit(o, d)
    assert np.allclose(hits.location, o + hits.distance[:, None] * d, atol=1e-5)
    corners = mesh.vertices[mesh.faces[hits.triangle]]
    assert np.allclose(np.einsum("ij,ijk->ik", hits.barycentric, corners), hits.location, atol=1e-5)


def test_rays_aimed_at_every_vertex_of_a_closed_mesh_hit_it():
    # Each ray passes exactly through a vertex (shared by 5 or 6
    # triangles) on its way to the centre: a crack there is a miss.
    mesh = trimesh.creation.icosphere(subdivisions=3)
    v = mesh.vertices.astype(np.float32).astype(np.float64)
    ours = rtvis.RayMesh(v, mesh.faces)
    o = v * 3.0
    d = -v
    assert ours.intersects_any(o, d).all()
    first = ours.first_hit(o, d)
    assert (first.triangle >= 0).all()
    assert np.allclose(first.location, v, atol=1e-6)
    # And through each edge's midpoint.
    edges = mesh.edges_unique
    mid = (v[edges[:, 0]] + v[edges[:, 1]]) / 2
    assert (ours.intersects_first(mid * 3.0, -mid) >= 0).all()
    index, hits = ours.all_hits(mid * 3.0, -mid)
    assert np.array_equal(np.bincount(index, minlength=len(mid)), np.full(len(mid), 2))


def test_bad_rays_hit_nothing_bad_arrays_raise():
    mesh = trimesh.creation.box()
    ours = rtvis.RayMesh(mesh.vertices, mesh.faces)
    o = np.array([[0.0, 0.0, 5.0], [np.nan, 0, 5], [0, 0, np.inf], [0, 0, 5], [0, 0, 1e300]])
    d = np.array([[0.0, 0.0, -1.0], [0, 0, -1], [0, 0, -1], [0, 0, 0], [0, 0, -1]])
    assert ours.intersects_any(o, d).tolist() == [True, False, False, False, False]
    assert ours.intersects_first(o, d).tolist()[1:] == [-1, -1, -1, -1]
    assert ours.intersects_first(np.zeros((0, 3)), np.zeros((0, 3))).shape == (0,)
    with pytest.raises(ValueError, match="shape"):
        ours.intersects_any(np.zeros((4, 2)), np.zeros((4, 2)))
    with pytest.raises(ValueError, match="as many"):
        ours.intersects_any(np.zeros((4, 3)), np.zeros((3, 3)))
    with pytest.raises(TypeError):
        ours.first_hit(["a", "b", "c"], [1, 2, 3])
    with pytest.raises(ValueError, match="faces"):
        rtvis.RayMesh(mesh.vertices, mesh.faces + 100)
    with pytest.raises(ValueError, match="not finite"):
        rtvis.RayMesh(np.full((3, 3), np.nan), [[0, 1, 2]])
    with pytest.raises(ValueError):
        rtvis.RayMesh.from_bytes(b"not a mesh")


def test_a_saved_mesh_answers_alike_in_float32_and_float64():
    mesh = trimesh.creation.icosphere(subdivisions=2)
    ours = rtvis.RayMesh(mesh.vertices, mesh.faces)
    again = rtvis.RayMesh.from_bytes(ours.to_bytes())
    assert len(again) == len(ours) == len(mesh.faces)
    o, d = random_rays(500, 2)
    a, b = ours.first_hit(o, d), again.first_hit(o.astype(np.float32), d.astype(np.float32))
    assert all(np.array_equal(x, y, equal_nan=True) for x, y in zip(a, b))
