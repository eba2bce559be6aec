"""Synthetic schlieren, shadowgraph, interferogram and colour schlieren of
a volume built in numpy: a hot jet (low density) rising from a nozzle,
with a ring vortex at its head. Writes PNGs into the folder given (default
`out/rtvis-volume`).

    python examples/numpy_volume.py [OUT_DIR]
"""

import sys
import time
from pathlib import Path
from typing import Callable, Dict

import numpy as np
from numpy.typing import NDArray

import rtvis

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/rtvis-volume")
out.mkdir(parents=True, exist_ok=True)

# 96 × 64 × 64 cells of 1 mm: x across, y up (the jet's axis), z the beam.
n = (64, 96, 64)  # (nz, ny, nx)
h = 1e-3
z, y, x = (np.indices(n) - np.array([32, 8, 32])[:, None, None, None]) * h
r = np.hypot(x, z)
# Jet: density drops from 1.2 (air) to 0.6 kg/m³ inside a radius that
# spreads with height; a ring vortex (denser torus) at its head.
radius = 6e-3 + 0.08 * np.clip(y, 0, None)
jet = 0.6 * 0.5 * (1 - np.tanh((r - radius) / 1.5e-3)) * (y > -2e-3) * (y < 60e-3)
ring = 0.25 * np.exp(-((r - 14e-3) ** 2 + (y - 62e-3) ** 2) / (2 * 3e-3**2))
rho = 1.2 - jet + ring

vol = rtvis.Volume(rho, spacing=(h, h, h), origin=(-32 * h, -8 * h, -32 * h), interpolation="cubic")
print(vol)
images: Dict[str, Callable[[], NDArray[np.uint8]]] = {
    "schlieren-knife.png": lambda: rtvis.to_gray8(rtvis.schlieren(vol, cutoff="knife", angle=0, size=384)),
    "schlieren-knife-vertical.png": lambda: rtvis.to_gray8(rtvis.schlieren(vol, cutoff="knife", angle=90, size=384)),
    "shadowgraph.png": lambda: rtvis.to_gray8(rtvis.shadowgraph(vol, size=384)),
    "interferogram.png": lambda: rtvis.to_gray8(rtvis.interferogram(vol, wavelength=632.8e-9, size=384), white=1.0),
    "schlieren-color.png": lambda: rtvis.to_srgb8(np.dstack([rtvis.color_schlieren(vol, size=384), np.ones((576, 384, 1), np.float32)])),
}
for name, make in images.items():
    t = time.perf_counter()
    img = make()
    rtvis.save_png(out / name, img)
    print(f"wrote {out / name} ({img.shape[1]}×{img.shape[0]}, {time.perf_counter() - t:.2f} s)")
