"""Schlieren of a grid split over MPI ranks, each holding its own piece
(as ParaView hands a rank its extent): photons are handed from brick to
brick by rt's protocol over an mpi4py communicator."""

from __future__ import annotations

from typing import Any, Optional, Sequence, Tuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _rtvis
from ._checks import _array, _choice, _float, _integer, _number, _uint, _vector
from ._composite import _Mpi4pyComm, _mpi_comm
from ._volume import GLADSTONE_DALE_AIR, _INTERPOLATIONS, _QUANTITIES

Box = Tuple[Tuple[int, int, int], Tuple[int, int, int]]


def _shape(name: str, shape: Sequence[int]) -> Tuple[int, int, int]:
    if len(shape) != 3:
        raise ValueError(f"{name}: expected (nz, ny, nx), got {tuple(shape)}")
    z, y, x = (_integer(f"{name}[{i}]", v, 1, 1 << 31) for i, v in enumerate(shape))
    return z, y, x


def brick_box(shape: Sequence[int], ranks: int, rank: int, spacing: ArrayLike = (1.0, 1.0, 1.0),
              origin: ArrayLike = (0.0, 0.0, 0.0), interpolation: str = "cubic") -> Box:
    """The samples rank ``rank`` of ``ranks`` must hold for
    :func:`schlieren_pieces` of a grid of ``shape`` ``(nz, ny, nx)``: its
    brick and the ghost layers a step reaches, as ``(start, stop)`` in
    ``[z, y, x]`` order (``whole[z0:z1, y0:y1, x0:x1]``). A larger piece
    is fine."""
    z, y, x = _shape("shape", shape)
    lo, hi = _rtvis._brick_box((x, y, z), _vector("spacing", spacing), _vector("origin", origin),
                               _choice("interpolation", interpolation, _INTERPOLATIONS),
                               _integer("ranks", ranks, 1, 1 << 20), _integer("rank", rank, 0, ranks - 1))
    return (int(lo[2]), int(lo[1]), int(lo[0])), (int(hi[2]), int(hi[1]), int(hi[0]))


def schlieren_pieces(piece: ArrayLike, start: Sequence[int], shape: Sequence[int], comm: Any = None,
                     spacing: ArrayLike = (1.0, 1.0, 1.0), origin: ArrayLike = (0.0, 0.0, 0.0),
                     quantity: str = "density", k: float = GLADSTONE_DALE_AIR, interpolation: str = "cubic",
                     cutoff: str = "knife", wavelength: float = 10.6e-6, fringe_spacing: Optional[float] = None,
                     size: int = 512, strata: int = 4, seed: int = 1,
                     timeout: float = 60.0) -> Optional[NDArray[np.float64]]:
    """Schlieren along z of a grid of ``shape`` ``(nz, ny, nx)`` whose
    samples are split over the ranks of ``comm`` (an mpi4py communicator,
    default ``MPI.COMM_WORLD``): this rank holds ``piece``, ``[z, y, x]``
    samples from index ``start`` ``(z, y, x)``, covering at least its
    :func:`brick_box`. Every rank traces the photons inside its brick and
    hands the others on; rank 0 gets the image (float64 (h, w), relative
    to the undisturbed background), the others ``None`` — bit for bit the
    image one process makes of the whole grid, at any rank count.

    ``cutoff`` is ``"knife"`` (edge along the image's vertical, its range
    chosen from the photons' deflections: 0.5 ± 0.45 at their 99th
    percentile) or ``"interferometry"`` (``wavelength``,
    ``fringe_spacing``); ``strata``² photons per pixel, one sheet pass.
    These optics differ from :func:`schlieren`'s automatic ones (which
    survey the whole volume first), so the images are not
    :func:`schlieren`'s. A piece short of its ghost layers raises
    ``ValueError`` naming the samples it lacks.
    """
    comm = _mpi_comm(comm, "schlieren_pieces")
    values = _array("piece", piece, 3, np.float32)
    z0, y0, x0 = (_integer(f"start[{i}]", v, 0, 1 << 31) for i, v in enumerate(start))
    z, y, x = _shape("shape", shape)
    optics = _choice("cutoff", cutoff, ("knife", "interferometry"))
    # The whole grid's first sample (the medium around it): from the rank
    # that holds it.
    held = float(values[0, 0, 0]) if (z0, y0, x0) == (0, 0, 0) else None
    firsts = [v for v in comm.allgather(held) if v is not None]
    if not firsts:
        raise ValueError("no rank holds sample (0, 0, 0) of the grid (the ambient medium)")
    transport = _Mpi4pyComm(comm, _number("timeout", timeout, positive=True))
    ok = False
    try:
        out: Optional[NDArray[np.float64]] = _rtvis._schlieren_piece(
            values, (x0, y0, z0), (x, y, z), _vector("spacing", spacing), _vector("origin", origin),
            float(firsts[0]), _choice("quantity", quantity, _QUANTITIES), _number("k", k, positive=True),
            _choice("interpolation", interpolation, _INTERPOLATIONS), optics, _float("wavelength", wavelength),
            _float("fringe_spacing", fringe_spacing, optional=True), _uint("size", size),
            _integer("strata", strata, 1, 64), _uint("seed", seed, 64), transport)
        ok = True
        return out
    finally:
        transport.finish(ok)
