"""Run under mpirun by test_mpi.py: every rank renders its share of a
scene and `rtvis.composite_mpi` composites them over mpi4py's world.

`compose`: rank 0 checks the result equals the whole scene rendered in one
process, bit for bit, for each schedule, and prints OK.
`silent`: rank 1 never composites; every other rank must raise ValueError
within the timeout (never hang), and prints it; rank 1 then drains what
they sent it.
"""

import sys

import numpy as np
from mpi4py import MPI

import rtvis

comm = MPI.COMM_WORLD
rank, size = comm.Get_rank(), comm.Get_size()
rng = np.random.default_rng(3)
centres = rng.uniform(-1.0, 1.0, size=(24, 3))
radii = rng.uniform(0.1, 0.35, size=24)
cam = rtvis.Camera((0.3, 0.4, 4.0), (0.0, 0.0, 0.0), fov=40.0)
common = dict(size=(80, 60), shadows=False, seed=11)


def render(sel):
    s = rtvis.Scene().add_spheres(centres[sel], radii[sel], scalars=centres[sel, 2], range=(-1, 1))
    return s.render(cam, **common)


rgba, depth = render(slice(rank, None, size))
if sys.argv[1] == "compose":
    whole = render(slice(None))
    for schedule in ("binary-swap", "radix-k", "direct-send"):
        out = rtvis.composite_mpi(rgba, depth, schedule=schedule, radix=3)
        if rank == 0:
            assert out is not None
            assert np.array_equal(out[1], whole[1]), schedule
            assert np.array_equal(out[0], whole[0]), schedule
        else:
            assert out is None
    if rank == 0:
        print(f"OK {size} ranks")
else:
    if rank != 1:
        try:
            rtvis.composite_mpi(rgba, depth, timeout=2.0)
            print(f"rank {rank}: NO ERROR")
        except ValueError as e:
            print(f"rank {rank}: ValueError: {e}", flush=True)
    # Once the others have raised, the silent rank takes the messages they
    # sent it, so that no rank reaches MPI_Finalize with a send pending
    # (which Open MPI may report as an improper exit under load).
    comm.Barrier()
    if rank == 1:
        status = MPI.Status()
        while comm.Iprobe(source=MPI.ANY_SOURCE, tag=MPI.ANY_TAG, status=status):
            buf = bytearray(status.Get_count(MPI.BYTE))
            comm.Recv([buf, MPI.BYTE], source=status.Get_source(), tag=status.Get_tag())
    comm.Barrier()
