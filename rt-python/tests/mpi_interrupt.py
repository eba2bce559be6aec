"""Run by test_mpi.py under mpirun: a render across ranks that takes
about ten seconds, stopped by SIGINT sent to one rank (``sys.argv[1]``)
two seconds in, while photons are traded, or by an exception from rank
0's progress callback at its first call (``"callback"``). The stopped rank raises ``KeyboardInterrupt`` (or the
callback's exception), every other rank a ``ValueError`` naming it, all
well within the transport's 60 s timeout; each prints how long it took."""

import os
import signal
import sys
import threading
import time

import numpy as np
from mpi4py import MPI

import rtvis

comm = MPI.COMM_WORLD
rank, n = comm.Get_rank(), comm.Get_size()
how = sys.argv[1]
shape, h = (48, 48, 48), 1e-3
z, y, x = (np.indices(shape) - 24)[:, :, :, :] * h
rho = (1.2 + 0.4 * np.exp(-(x**2 + y**2 + z**2) / (2 * 0.008**2))).astype(np.float32)
(z0, y0, x0), (z1, y1, x1) = rtvis.brick_box(shape, n, rank, spacing=(h, h, h))
piece = rho[z0:z1, y0:y1, x0:x1]


class Enough(Exception):
    pass


def enough(done, total):
    if done > 0:
        raise Enough(f"{done} of {total}")


comm.Barrier()
start = time.monotonic()
if how != "callback" and rank == int(how):
    threading.Timer(2.0, os.kill, (os.getpid(), signal.SIGINT)).start()
try:
    rtvis.schlieren_pieces(piece, (z0, y0, x0), shape, comm, spacing=(h, h, h), size=512, strata=2,
                           progress=enough if how == "callback" and rank == 0 else None)
    outcome = "finished"
except KeyboardInterrupt:
    outcome = "KeyboardInterrupt"
except Enough:
    outcome = "Enough"
except ValueError as e:
    outcome = f"ValueError: {e}"
took = time.monotonic() - start
print(f"rank {rank}: {outcome} after {took:.2f} s", flush=True)
