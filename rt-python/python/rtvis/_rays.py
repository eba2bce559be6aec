"""Rays cast at triangle meshes: :class:`RayMesh`, numpy in and out, with
the queries (and names) trimesh's ``mesh.ray`` and PyVista's
``multi_ray_trace`` users know, over rt's watertight traversal: a ray
aimed at a shared edge or vertex of a closed mesh hits it."""

from __future__ import annotations

from typing import Any, NamedTuple, Tuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _rtvis
from ._checks import _array, _integer


class RayHits(NamedTuple):
    """First hits of a batch of rays (row ``i`` is ray ``i``'s)."""

    distance: NDArray[np.float32]
    """Ray parameter of the hit (distance along a unit direction); ``inf``
    for a miss."""
    triangle: NDArray[np.int64]
    """Index of the triangle hit; -1 for a miss."""
    barycentric: NDArray[np.float32]
    """``(n, 3)``: the hit's weights of the triangle's three vertices; NaN
    for a miss."""
    location: NDArray[np.float32]
    """``(n, 3)``: the hit point (from the triangle, not ``origin + t d``);
    NaN for a miss."""


def _rays(origins: ArrayLike, directions: ArrayLike) -> Tuple[NDArray[np.float32], NDArray[np.float32]]:
    """``(n, 3)`` float32 origins and directions, as many of each. NaN or
    infinite rays are kept: they hit nothing."""
    out = []
    for name, value in (("origins", origins), ("directions", directions)):
        a = np.asarray(value)
        if a.dtype.kind not in "fiu":
            raise TypeError(f"{name}: expected float32 or float64 numbers, got dtype {a.dtype}")
        if a.ndim == 1 and a.shape == (3,):
            a = a[None, :]
        if a.ndim != 2 or a.shape[1] != 3:
            raise ValueError(f"{name}: expected shape (n, 3); got {a.shape}")
        with np.errstate(over="ignore"):  # beyond float32: infinite, so no hit
            out.append(np.ascontiguousarray(a, dtype=np.float32))
    if len(out[0]) != len(out[1]):
        raise ValueError(f"origins and directions: expected as many of each; got {len(out[0])} and {len(out[1])}")
    return out[0], out[1]


def _hits(t: NDArray[np.float32], tri: NDArray[np.int64], uv: NDArray[np.float32],
          at: NDArray[np.float32]) -> RayHits:
    w = np.column_stack([1.0 - uv[:, 0] - uv[:, 1], uv[:, 0], uv[:, 1]]).astype(np.float32)
    return RayHits(t, tri, w.reshape(len(t), 3), at)


class RayMesh:
    """A triangle mesh built once for rays: first hits, any hits, every
    crossing, for batches of rays (numpy ``(n, 3)`` origins and
    directions, float32 or float64; float64 is rounded to float32, rt's
    precision). Traced on all cores with the GIL released; the answers are
    the same at any thread count. A ray with a NaN or infinite
    coordinate, or a zero direction, hits nothing (the rest of the batch is
    answered). Rays run over ``[0, inf)``; a direction need not be unit
    length (distances are then in its units).

    ``vertices``: ``(n, 3)`` numbers; ``faces``: ``(m, 3)`` indices into
    them. Zero-area faces are kept in the numbering and never hit.

    With trimesh, ``rtvis.RayMesh(mesh.vertices, mesh.faces)`` answers
    ``intersects_first``, ``intersects_any``, ``intersects_location`` and
    ``intersects_id`` as ``mesh.ray`` does.
    """

    def __init__(self, vertices: ArrayLike, faces: ArrayLike) -> None:
        v = _array("vertices", vertices, 2, np.float32, last=3)
        f = _array("faces", faces, 2, np.int64, last=3, integer=True)
        if f.min() < 0 or f.max() >= len(v):
            bad = int(np.argwhere((f < 0) | (f >= len(v)))[0][0])
            raise ValueError(f"faces[{bad}] = {f[bad].tolist()}: indices must lie in 0..{len(v) - 1}")
        self._m = _rtvis._RayMesh(v, f)

    @classmethod
    def from_bytes(cls, data: bytes) -> "RayMesh":
        """The mesh saved by :meth:`to_bytes` (its BVH and triangles; no
        rebuild). ``ValueError`` for bytes that are not one."""
        if not isinstance(data, (bytes, bytearray, memoryview)):
            raise TypeError(f"data: expected bytes, got {type(data).__name__}")
        out = cls.__new__(cls)
        out._m = _rtvis._RayMesh.from_bytes(bytes(data))
        return out

    def to_bytes(self) -> bytes:
        """The built mesh as bytes, for :meth:`from_bytes`."""
        data: bytes = self._m.to_bytes()
        return data

    def __len__(self) -> int:
        return int(self._m.triangle_count())

    def first_hit(self, origins: ArrayLike, directions: ArrayLike) -> RayHits:
        """Each ray's nearest hit: :class:`RayHits` (distance, triangle,
        barycentric weights, location)."""
        o, d = _rays(origins, directions)
        return _hits(*self._m.first(o, d))

    def intersects_first(self, ray_origins: ArrayLike, ray_directions: ArrayLike) -> NDArray[np.int64]:
        """The triangle each ray hits first; -1 where it misses."""
        o, d = _rays(ray_origins, ray_directions)
        tri: NDArray[np.int64] = self._m.first_triangle(o, d)
        return tri

    def intersects_any(self, ray_origins: ArrayLike, ray_directions: ArrayLike) -> NDArray[np.bool_]:
        """Whether each ray hits the mesh (its any-hit query: faster than
        a first hit)."""
        o, d = _rays(ray_origins, ray_directions)
        hit: NDArray[np.bool_] = self._m.any(o, d)
        return hit

    def all_hits(self, origins: ArrayLike, directions: ArrayLike,
                 max_hits: int = 64) -> Tuple[NDArray[np.int64], RayHits]:
        """Every surface crossing along each ray, nearest first, at most
        ``max_hits`` a ray: ``(index_ray, hits)``, in the rays' order. A
        ray crossing at a shared edge or vertex crosses once there, so a
        ray through a closed mesh crosses it an even number of times."""
        o, d = _rays(origins, directions)
        index, columns = self._m.all(o, d, _integer("max_hits", max_hits, 1, 1 << 20))
        return index, _hits(*columns)

    def intersects_location(self, ray_origins: ArrayLike, ray_directions: ArrayLike,
                            multiple_hits: bool = True) -> Tuple[NDArray[np.float32], NDArray[np.int64],
                                                                 NDArray[np.int64]]:
        """``(locations, index_ray, index_tri)`` of every crossing (or
        only the first of each ray without ``multiple_hits``)."""
        index_tri, index_ray, locations = self.intersects_id(ray_origins, ray_directions, multiple_hits,
                                                             return_locations=True)
        return locations, index_ray, index_tri

    def intersects_id(self, ray_origins: ArrayLike, ray_directions: ArrayLike, multiple_hits: bool = True,
                      max_hits: int = 64, return_locations: bool = False) -> Any:
        """``(index_tri, index_ray)`` of every crossing (or the first of
        each ray without ``multiple_hits``), and their ``locations`` with
        ``return_locations``."""
        if multiple_hits:
            index_ray, hits = self.all_hits(ray_origins, ray_directions, max_hits)
        else:
            first = self.first_hit(ray_origins, ray_directions)
            index_ray = np.flatnonzero(first.triangle >= 0).astype(np.int64)
            hits = RayHits(first.distance[index_ray], first.triangle[index_ray], first.barycentric[index_ray],
                           first.location[index_ray])
        if return_locations:
            return hits.triangle, index_ray, hits.location
        return hits.triangle, index_ray
