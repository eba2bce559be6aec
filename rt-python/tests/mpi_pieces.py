"""Run by test_mpi.py under mpirun: schlieren_pieces with each rank
holding only its piece of a density bump (its brick_box), against the
image of one rank holding the whole grid (computed on rank 0 with a
one-rank communicator of its own)."""

import sys

import numpy as np
from mpi4py import MPI

import rtvis

comm = MPI.COMM_WORLD
rank, n = comm.Get_rank(), comm.Get_size()
shape, h = (36, 40, 44), 1e-3
z, y, x = (np.indices(shape) - (np.array(shape) / 2)[:, None, None, None]) * h
rho = (1.2 + 0.4 * np.exp(-(x**2 + (y - 0.003) ** 2 + z**2) / (2 * 0.006**2))).astype(np.float32)
kw = dict(spacing=(h, h, h), origin=(-0.022, -0.02, -0.018), size=48, strata=2, seed=3)
cutoff = sys.argv[1]
if cutoff == "interferometry":
    kw.update(cutoff="interferometry", wavelength=633e-9)
(z0, y0, x0), (z1, y1, x1) = rtvis.brick_box(shape, n, rank, spacing=kw["spacing"], origin=kw["origin"])
piece = rho[z0:z1, y0:y1, x0:x1]
image = rtvis.schlieren_pieces(piece, (z0, y0, x0), shape, comm, **kw)
held = piece.size / rho.size
helds = comm.gather(held, root=0)
if rank == 0:
    whole = rtvis.schlieren_pieces(rho, (0, 0, 0), shape, MPI.COMM_SELF, **kw)
    assert image.shape == whole.shape and image.shape[1] == 48
    same = np.array_equal(image, whole)
    contrast = float(np.abs(whole - 1).max())
    print(f"{cutoff}: {n} ranks {'OK' if same else 'DIFFERENT'}; pieces hold {[f'{v:.0%}' for v in helds]}; "
          f"contrast {contrast:.2f}")
    assert same and contrast > 0.1
    if n > 1:
        assert max(helds) < 1.0
else:
    assert image is None
