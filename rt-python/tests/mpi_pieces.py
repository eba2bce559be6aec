"""Run by test_mpi.py under mpirun: schlieren_pieces, bos_pieces and
focusing_pieces with each rank holding only its piece of a density bump
(its brick_box), against the images of one rank holding the whole grid
(computed on rank 0 with a one-rank communicator of its own)."""

import sys

import numpy as np
from mpi4py import MPI

import rtvis

comm = MPI.COMM_WORLD
rank, n = comm.Get_rank(), comm.Get_size()
shape, h = (36, 40, 44), 1e-3
z, y, x = (np.indices(shape) - (np.array(shape) / 2)[:, None, None, None]) * h
rho = (1.2 + 0.4 * np.exp(-(x**2 + (y - 0.003) ** 2 + z**2) / (2 * 0.006**2))).astype(np.float32)
grid = dict(spacing=(h, h, h), origin=(-0.022, -0.02, -0.018))
cutoff = sys.argv[1]


def check_progress(told, rays):
    """Rank 0 alone is told its progress, rising to the total (``rays``
    if known), the last call at the total."""
    if rank != 0:
        assert told == [], told
        return
    assert told, "no progress told"
    total = told[-1][1]
    assert told[-1] == (total, total) and (rays is None or total == rays), told[-3:]
    assert all(a[0] <= b[0] and a[1] == b[1] for a, b in zip(told, told[1:])), told[:5]

(z0, y0, x0), (z1, y1, x1) = rtvis.brick_box(shape, n, rank, **grid)
piece = rho[z0:z1, y0:y1, x0:x1]
held = piece.size / rho.size
helds = comm.gather(held, root=0)
if n > 1 and rank == 0:
    assert max(helds) < 1.0
if cutoff in ("bos", "focusing"):
    # The rig from a survey across the ranks; every camera ray handed
    # between bricks.
    run = rtvis.bos_pieces if cutoff == "bos" else rtvis.focusing_pieces
    kw = dict(size=96, samples=2, seed=3)
    told = []
    out = run(piece, (z0, y0, x0), shape, comm, chosen=True, progress=lambda d, t: told.append((d, t)),
              **grid, **kw)
    # Counted in camera rays: samples² a pixel.
    check_progress(told, out[0].shape[0] * out[0].shape[1] * 2 * 2 if rank == 0 else None)
    if rank == 0:
        whole = run(rho, (0, 0, 0), shape, MPI.COMM_SELF, chosen=True, **grid, **kw)
        images = [a for a in out if isinstance(a, np.ndarray)]
        same = all(np.array_equal(a, b) for a, b in zip(images, whole)) and out[-1] == whole[-1]
        assert len(images) == 3 and images[0].shape[1] == 96
        # Against rtvis's own render of the whole Volume with the rig
        # chosen here (it skips still air within a tenth of a pixel, so
        # close, not equal).
        vol = rtvis.Volume(rho, quantity="density", **grid)
        rig = {k: v for k, v in out[-1].items() if k not in kw}
        if "dot_spacing" in rig:  # bos_pieces's name for bos's spacing
            rig["spacing"] = rig.pop("dot_spacing")
        own = (rtvis.bos if cutoff == "bos" else rtvis.focusing)(vol, **rig, **kw)
        signal = images[2] if cutoff == "bos" else images[2] - 1
        gap = float(np.abs(images[2] - own[2]).max()) / float(np.abs(signal).max())
        print(f"{cutoff}: {n} ranks {'OK' if same else 'DIFFERENT'}; signal {float(np.abs(signal).max()):.3g}, "
              f"rtvis.{cutoff} of the Volume within {gap:.1%}")
        assert same and float(np.abs(signal).max()) > 0.1 and gap < 0.05
    else:
        assert out is None
    sys.exit(0)
kw = dict(grid, size=48, strata=2, seed=3)
if cutoff == "interferometry":
    kw.update(cutoff="interferometry", wavelength=633e-9)
told = []
image = rtvis.schlieren_pieces(piece, (z0, y0, x0), shape, comm, progress=lambda d, t: told.append((d, t)), **kw)
check_progress(told, None)
if rank == 0:
    whole = rtvis.schlieren_pieces(rho, (0, 0, 0), shape, MPI.COMM_SELF, **kw)
    assert image.shape == whole.shape and image.shape[1] == 48
    same = np.array_equal(image, whole)
    contrast = float(np.abs(whole - 1).max())
    print(f"{cutoff}: {n} ranks {'OK' if same else 'DIFFERENT'}; pieces hold {[f'{v:.0%}' for v in helds]}; "
          f"contrast {contrast:.2f}")
    assert same and contrast > 0.1
else:
    assert image is None
