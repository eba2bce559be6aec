"""Run by test_mpi.py (one process, mpi4py's COMM_SELF): bad input to
bos_pieces and focusing_pieces raises a clear exception naming what is
wrong, before or instead of any rendering."""

import numpy as np
from mpi4py import MPI

import rtvis

rho = np.full((8, 8, 8), 1.2, np.float32)
self_ = MPI.COMM_SELF
cases = [
    (TypeError, "bos_pieces() got an unexpected keyword argument 'colour'",
     lambda: rtvis.bos_pieces(rho, (0, 0, 0), rho.shape, self_, colour=3)),
    (TypeError, "focusing_pieces() got an unexpected keyword argument 'spacing_dots'",
     lambda: rtvis.focusing_pieces(rho, (0, 0, 0), rho.shape, self_, spacing_dots=3)),
    (ValueError, "size must be 1 to 8192", lambda: rtvis.bos_pieces(rho, (0, 0, 0), rho.shape, self_, size=0)),
    (ValueError, "duty must be in (0, 1)", lambda: rtvis.focusing_pieces(rho, (0, 0, 0), rho.shape, self_, duty=2.0)),
    (ValueError, "not finite", lambda: rtvis.bos_pieces(np.full_like(rho, np.nan), (0, 0, 0), rho.shape, self_)),
    (ValueError, "too few ghost layers",
     lambda: rtvis.focusing_pieces(rho[:4], (0, 0, 0), rho.shape, self_, size=8)),
    (ValueError, "start: expected (z, y, x)", lambda: rtvis.bos_pieces(rho, (0, 0), rho.shape, self_)),
    (TypeError, "expected an mpi4py communicator", lambda: rtvis.bos_pieces(rho, (0, 0, 0), rho.shape, 3)),
    (ValueError, "4294967296 photons is more than a distributed run traces",
     lambda: rtvis.bos_pieces(rho, (0, 0, 0), rho.shape, self_, size=8192, samples=8)),
]
for kind, words, call in cases:
    try:
        call()
    except kind as e:
        assert words in str(e), f"{words!r} not in {e!r}"
    else:
        raise AssertionError(f"no {kind.__name__} for {words!r}")
print(f"bad pieces: {len(cases)} cases raise")
