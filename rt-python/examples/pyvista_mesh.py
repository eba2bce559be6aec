"""A PyVista mesh ray traced by rtvis: ParaView's Wavelet source
contoured at three values (PyVista runs VTK's filters), its points,
triangles and point data handed to `rtvis.Scene`, rendered with shadows
and ambient occlusion. Writes `pyvista-wavelet.png` into the folder given
(default `out/rtvis-pyvista`). Needs `pip install pyvista`.

    python examples/pyvista_mesh.py [OUT_DIR]
"""

import sys
import time
from pathlib import Path

import numpy as np
import pyvista as pv

import rtvis

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/rtvis-pyvista")
out.mkdir(parents=True, exist_ok=True)

mesh = pv.Wavelet().contour([110.0, 160.0, 210.0]).triangulate().clean()
triangles = mesh.faces.reshape(-1, 4)[:, 1:]  # [3, i, j, k] per cell
scalars = mesh.point_data["RTData"]
print(f"{mesh.n_points} points, {len(triangles)} triangles, RTData {scalars.min():.0f}–{scalars.max():.0f}")

scene = rtvis.Scene()
scene.add_mesh(mesh.points, triangles, scalars=scalars, colormap="cool_to_warm", material="glossy")
# A floor under it, to catch the shadows.
bounds = scene.bounds()
assert bounds is not None
(lo, hi) = bounds
y0 = lo[1] - 0.5
floor = np.array([[-30, y0, -30], [30, y0, -30], [30, y0, 30], [-30, y0, 30]], dtype=np.float32)
scene.add_mesh(floor, [[0, 2, 1], [0, 3, 2]], color=(0.8, 0.8, 0.8), material="matte")

camera = rtvis.Camera((28.0, 22.0, 34.0), (0.0, -1.0, 0.0), fov=35.0)
t = time.perf_counter()
rgba, depth = scene.render(camera, size=(640, 480), ao=8, ao_distance=6.0, shadows=True, passes=4, seed=1)
rtvis.save_png(out / "pyvista-wavelet.png", rtvis.to_srgb8(rgba, background=(1.0, 1.0, 1.0)))
print(f"wrote {out / 'pyvista-wavelet.png'} (640×480, {time.perf_counter() - t:.2f} s)")
