"""Sort-last compositing by depth: ``composite`` (images in one process)
and ``composite_mpi`` (one image per rank of an ``mpi4py`` communicator)."""

from __future__ import annotations

import time
from typing import Any, List, Optional, Sequence, Tuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _rtvis
from ._checks import _array, _choice, _integer, _number


def _image_pair(i: int, rgba: ArrayLike, depth: ArrayLike) -> Tuple[NDArray[np.float32], NDArray[np.float32]]:
    c = _array(f"rgba[{i}]", rgba, 3, np.float32, last=4)
    d = np.asarray(depth)
    if d.dtype.kind != "f":
        raise TypeError(f"depth[{i}]: expected float32 or float64, got dtype {d.dtype}")
    d = np.ascontiguousarray(d, dtype=np.float32)
    if d.shape != c.shape[:2]:
        raise ValueError(f"depth[{i}]: expected shape {c.shape[:2]} to match rgba, got {d.shape}")
    if np.isnan(d).any():
        raise ValueError(f"depth[{i}] holds NaN (use inf where nothing was hit)")
    return c, d


def composite(rgba_list: Sequence[ArrayLike], depth_list: Sequence[ArrayLike]
              ) -> Tuple[NDArray[np.float32], NDArray[np.float32]]:
    """Depth-composites images rendered separately (sort-last): per pixel
    the fragment nearest the camera, ties to the earlier image.

    ``rgba_list``: premultiplied (h, w, 4) images; ``depth_list``: their
    (h, w) depths (``inf`` = background). Returns ``(rgba, depth)``.
    """
    if len(rgba_list) != len(depth_list) or not len(rgba_list):
        raise ValueError(f"expected as many depth images as colour images, at least one "
                         f"(got {len(rgba_list)} and {len(depth_list)})")
    pairs = [_image_pair(i, c, d) for i, (c, d) in enumerate(zip(rgba_list, depth_list))]
    return _rtvis._composite([p[0] for p in pairs], [p[1] for p in pairs])


def _mpi_comm(comm: Any, what: str) -> Any:
    """``comm``, an mpi4py communicator (default ``MPI.COMM_WORLD``), for
    ``what``; ``ImportError`` without mpi4py, ``TypeError`` for another
    kind of value."""
    try:
        from mpi4py import MPI  # type: ignore[import-not-found, unused-ignore]
    except ImportError as e:
        raise ImportError(f"{what} needs mpi4py (pip install mpi4py, or Debian's python3-mpi4py)") from e
    if comm is None:
        return MPI.COMM_WORLD
    if not isinstance(comm, MPI.Comm):
        raise TypeError(f"comm: expected an mpi4py communicator, got {type(comm).__name__}")
    return comm


class _Mpi4pyComm:
    """The transport rt-composite's schedule runs over: tagged byte
    messages on an ``mpi4py`` communicator (non-blocking sends, probed
    receives with a timeout)."""

    def __init__(self, comm: Any, timeout: float) -> None:
        from mpi4py import MPI  # type: ignore[import-not-found, unused-ignore]

        self._mpi = MPI
        self._comm = comm
        self._timeout = timeout
        self._pending: List[Tuple[Any, bytes]] = []

    def rank(self) -> int:
        rank: int = self._comm.Get_rank()
        return rank

    def size(self) -> int:
        size: int = self._comm.Get_size()
        return size

    def send(self, to: int, tag: int, data: bytes) -> None:
        req = self._comm.Isend([data, self._mpi.BYTE], dest=to, tag=tag)
        self._pending.append((req, data))
        self._pending = [(r, d) for r, d in self._pending if not r.Test()]

    def recv(self, source: int, tag: int) -> bytes:
        status = self._mpi.Status()
        deadline = time.monotonic() + self._timeout
        while not self._comm.Iprobe(source=source, tag=tag, status=status):
            if time.monotonic() > deadline:
                raise TimeoutError(f"no message from rank {source} (tag {tag}) within {self._timeout} s")
            time.sleep(1e-4)
        buf = bytearray(status.Get_count(self._mpi.BYTE))
        self._comm.Recv([buf, self._mpi.BYTE], source=source, tag=tag)
        return bytes(buf)

    def finish(self, ok: bool) -> None:
        """Waits for this rank's sends to complete; after a failure, sends
        a lost peer will never receive are left pending (their buffers
        kept alive) rather than waited for forever."""
        if ok:
            self._mpi.Request.Waitall([r for r, _ in self._pending])
        else:
            _ABANDONED_SENDS.extend(self._pending)
        self._pending = []


#: Sends left pending by a failed composite (the buffers must outlive them).
_ABANDONED_SENDS: List[Tuple[Any, bytes]] = []


def composite_mpi(rgba: ArrayLike, depth: ArrayLike, comm: Any = None, schedule: str = "binary-swap",
                  radix: int = 4, timeout: float = 60.0) -> Optional[Tuple[NDArray[np.float32], NDArray[np.float32]]]:
    """Depth-composites this rank's image with every other rank's of the
    ``mpi4py`` communicator ``comm`` (default ``MPI.COMM_WORLD``), with
    rt-composite's ``schedule`` (``binary-swap``, ``radix-k`` with
    ``radix``, or ``direct-send``). Call it on every rank with images of
    one size. Rank 0 gets ``(rgba, depth)``, the others ``None``; the
    result equals :func:`composite` of all ranks' images in rank order,
    bit for bit. A rank that fails or stays silent for ``timeout`` seconds
    makes every rank raise ``ValueError`` instead of hanging.
    """
    comm = _mpi_comm(comm, "composite_mpi")
    c, d = _image_pair(0, rgba, depth)
    sched = _choice("schedule", schedule, ("binary-swap", "radix-k", "direct-send"))
    k = _integer("radix", radix, 2, 1 << 20)
    transport = _Mpi4pyComm(comm, _number("timeout", timeout, positive=True))
    ok = False
    try:
        out = _rtvis._composite_comm(c, d, transport, sched, k)
        ok = True
        return out
    finally:
        transport.finish(ok)
