"""Rays at a trimesh mesh through rtvis, in trimesh's own names: build
``rtvis.RayMesh`` once from ``mesh.vertices`` and ``mesh.faces`` and call
it where ``mesh.ray`` was called (``intersects_first``, ``intersects_any``,
``intersects_location``, ``intersects_id``). Writes a depth image of the
mesh, cast from a camera grid, to OUT/trimesh-depth.png.

    python trimesh_rays.py OUT_DIR    (needs trimesh: pip install trimesh)
"""

import os
import sys

import numpy as np
import trimesh  # type: ignore[import-untyped, unused-ignore]

import rtvis

out = sys.argv[1] if len(sys.argv) > 1 else "."
os.makedirs(out, exist_ok=True)
mesh = trimesh.creation.torus(major_radius=1.0, minor_radius=0.35)
ray = rtvis.RayMesh(mesh.vertices, mesh.faces)  # instead of mesh.ray

# A 256² camera grid looking down the torus's axis at an angle.
side = 256
u, v = np.meshgrid(np.linspace(-1.6, 1.6, side), np.linspace(1.6, -1.6, side))
eye = np.array([0.0, -3.0, 3.0])
window = np.stack([u.ravel(), v.ravel() * 0.7, v.ravel() * 0.7], axis=1)
origins = np.repeat(eye[None], side * side, axis=0)
directions = window - eye

hits = ray.first_hit(origins, directions)
covered = hits.triangle >= 0
print(f"{len(mesh.faces)} triangles; {covered.mean():.0%} of {side * side} rays hit")
locations, index_ray, index_tri = ray.intersects_location(origins, directions)
print(f"every crossing: {len(locations)} (a ray through both sides of the ring crosses it 4 times)")
assert np.array_equal(ray.intersects_first(origins, directions), hits.triangle)

depth = np.where(covered, hits.distance, np.nan).reshape(side, side)
near, far = np.nanmin(depth), np.nanmax(depth)
shade = np.where(np.isnan(depth), 0.0, 1.0 - 0.8 * (depth - near) / (far - near))
rtvis.save_png(os.path.join(out, "trimesh-depth.png"), rtvis.to_gray8(shade))
print(f"wrote {os.path.join(out, 'trimesh-depth.png')}")
