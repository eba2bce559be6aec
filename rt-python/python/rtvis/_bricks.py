"""Schlieren, BOS and focusing schlieren of a grid split over MPI ranks,
each holding its own piece (as ParaView hands a rank its extent): photons
are handed from brick to brick by rt's protocol over an mpi4py
communicator."""

from __future__ import annotations

import inspect
from typing import Any, Callable, Dict, Optional, Sequence, Tuple, TypeVar, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _rtvis
from ._checks import _array, _choice, _float, _integer, _number, _uint, _vector
from ._bos import _bos_args, _bos_result
from ._composite import _Mpi4pyComm, _mpi_comm
from ._focusing import _focusing_args, _focusing_result
from ._volume import GLADSTONE_DALE_AIR, _INTERPOLATIONS, _QUANTITIES
from ._watch import ProgressCallback, _progress

_T = TypeVar("_T")
Box = Tuple[Tuple[int, int, int], Tuple[int, int, int]]
# What every `_rtvis._*_piece` takes first: the piece, its start and the
# grid's dims (x, y, z), spacing, origin, first sample, quantity, k and
# interpolation.
_Held = Tuple[NDArray[np.float32], Tuple[int, int, int], Tuple[int, int, int], Tuple[float, float, float],
              Tuple[float, float, float], float, str, float, str]


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
                     size: int = 512, strata: int = 4, seed: int = 1, timeout: float = 60.0,
                     progress: Union[None, bool, ProgressCallback] = None) -> Optional[NDArray[np.float64]]:
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

    ``progress``: ``True`` draws a progress bar on stderr, a callable is
    called as ``progress(done, total)`` (photons whose results rank 0
    holds), both on rank 0 only. Ctrl-C (or an exception from the
    callback) on any rank stops every rank within a round of the trade:
    that rank raises ``KeyboardInterrupt`` (or the callback's exception),
    the others ``ValueError`` naming it.
    """
    optics = _choice("cutoff", cutoff, ("knife", "interferometry"))
    extra = (_float("wavelength", wavelength), _float("fringe_spacing", fringe_spacing, optional=True),
             _uint("size", size), _integer("strata", strata, 1, 64), _uint("seed", seed, 64))
    out: Optional[NDArray[np.float64]] = _on_ranks(
        "schlieren_pieces", piece, start, shape, comm, spacing, origin, quantity, k, interpolation, timeout,
        progress, lambda held, transport, told: _rtvis._schlieren_piece(*(held + (optics,) + extra),
                                                                        comm=transport, progress=told))
    return out


def bos_pieces(piece: ArrayLike, start: Sequence[int], shape: Sequence[int], comm: Any = None,
               spacing: ArrayLike = (1.0, 1.0, 1.0), origin: ArrayLike = (0.0, 0.0, 0.0),
               quantity: str = "density", k: float = GLADSTONE_DALE_AIR, interpolation: str = "cubic",
               timeout: float = 60.0, chosen: bool = False, progress: Union[None, bool, ProgressCallback] = None,
               **options: Any) -> Optional[Tuple[Any, ...]]:
    """:func:`bos` of a grid split over the ranks of ``comm`` as for
    :func:`schlieren_pieces` (each rank its ``piece``): the survey that
    chooses the rig and every camera ray are traced across the ranks, so
    rank 0 gets :func:`bos`'s tuple (``chosen`` as there) and the others
    ``None`` — bit for bit the images of one process holding the whole
    grid, at any rank count. ``options`` are :func:`bos`'s keywords
    (``axis``, ``size``, ``background``, …), but the dots' spacing is
    ``dot_spacing`` (``spacing`` is the grid's; the :class:`Optics` says
    ``dot_spacing`` too, so it repeats with this function). Every ray is traced exactly
    through the grid (no skipping of still air), so the images differ
    slightly from :func:`bos` of a :class:`Volume`, which skips within a
    tenth of a pixel. ``progress`` (camera rays) and Ctrl-C as for
    :func:`schlieren_pieces`."""
    if "dot_spacing" in options:
        options["spacing"] = options.pop("dot_spacing")
    args, fixed = _options(_bos_args, "bos_pieces", options)
    fixed["dot_spacing"] = fixed.pop("spacing")
    out = _on_ranks("bos_pieces", piece, start, shape, comm, spacing, origin, quantity, k, interpolation, timeout,
                    progress, lambda held, transport, told: _rtvis._bos_piece(*(held + args), comm=transport,
                                                                              progress=told))
    if out is None:
        return None
    *images, said, rig = out
    return _bos_result(images, said, rig, fixed if chosen else None)


def focusing_pieces(piece: ArrayLike, start: Sequence[int], shape: Sequence[int], comm: Any = None,
                    spacing: ArrayLike = (1.0, 1.0, 1.0), origin: ArrayLike = (0.0, 0.0, 0.0),
                    quantity: str = "density", k: float = GLADSTONE_DALE_AIR, interpolation: str = "cubic",
                    timeout: float = 60.0, chosen: bool = False, progress: Union[None, bool, ProgressCallback] = None,
                    **options: Any) -> Optional[Tuple[Any, ...]]:
    """:func:`focusing` of a grid split over the ranks of ``comm`` as for
    :func:`schlieren_pieces` (each rank its ``piece``): the survey that
    chooses the grid's pitch and every camera ray are traced across the
    ranks, so rank 0 gets :func:`focusing`'s tuple (``chosen`` as there)
    and the others ``None`` — bit for bit the images of one process
    holding the whole grid, at any rank count. ``options`` are
    :func:`focusing`'s keywords. Every ray is traced exactly through the
    grid (no skipping of still air), so the images differ slightly from
    :func:`focusing` of a :class:`Volume`. ``progress`` (camera rays)
    and Ctrl-C as for :func:`schlieren_pieces`."""
    args, fixed = _options(_focusing_args, "focusing_pieces", options)
    out = _on_ranks("focusing_pieces", piece, start, shape, comm, spacing, origin, quantity, k, interpolation,
                    timeout, progress, lambda held, transport, told: _rtvis._focusing_piece(
                        *(held + args), comm=transport, progress=told))
    if out is None:
        return None
    *images, said, rig = out
    return _focusing_result(images, said, rig, fixed if chosen else None)


def _options(check: Callable[..., Tuple[_T, Dict[str, Any]]], name: str,
             options: Dict[str, Any]) -> Tuple[_T, Dict[str, Any]]:
    """``check(**options)``, an unknown keyword named as ``name``'s."""
    known = inspect.signature(check).parameters
    for key in options:
        if key not in known:
            raise TypeError(f"{name}() got an unexpected keyword argument {key!r}")
    return check(**options)


def _on_ranks(name: str, piece: ArrayLike, start: Sequence[int], shape: Sequence[int], comm: Any,
              spacing: ArrayLike, origin: ArrayLike, quantity: str, k: float, interpolation: str, timeout: float,
              progress: Union[None, bool, ProgressCallback],
              run: Callable[[_Held, _Mpi4pyComm, Optional[ProgressCallback]], Any]) -> Any:
    """``run(held, transport, told)`` on every rank of ``comm``: ``held``
    is the piece and the grid as ``_rtvis``'s ``_*_piece`` functions take
    them first, ``transport`` the communicator they trade over, ``told``
    the progress callback (rank 0 alone is told)."""
    comm = _mpi_comm(comm, name)
    told = _progress(progress, f"rtvis.{name}")
    values = _array("piece", piece, 3, np.float32)
    if len(start) != 3:
        raise ValueError(f"start: expected (z, y, x), got {tuple(start)}")
    z0, y0, x0 = (_integer(f"start[{i}]", v, 0, 1 << 31) for i, v in enumerate(start))
    z, y, x = _shape("shape", shape)
    space = (_vector("spacing", spacing), _vector("origin", origin))
    grid = (_choice("quantity", quantity, _QUANTITIES), _number("k", k, positive=True),
            _choice("interpolation", interpolation, _INTERPOLATIONS))
    # The whole grid's first sample (the medium around it): from the rank
    # that holds it.
    mine = float(values[0, 0, 0]) if (z0, y0, x0) == (0, 0, 0) else None
    firsts = [v for v in comm.allgather(mine) if v is not None]
    if not firsts:
        raise ValueError("no rank holds sample (0, 0, 0) of the grid (the ambient medium)")
    transport = _Mpi4pyComm(comm, _number("timeout", timeout, positive=True))
    ok = False
    try:
        held: _Held = (values, (x0, y0, z0), (x, y, z), *space, float(firsts[0]), *grid)
        out = run(held, transport, told)
        ok = True
        return out
    finally:
        transport.finish(ok)
