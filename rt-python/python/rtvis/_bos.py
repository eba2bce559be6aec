"""Background-oriented schlieren, set up as ``rt bos`` sets it up."""

from __future__ import annotations

import os
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _rtvis
from ._checks import _array, _float, _str, _uint
from ._volume import Mesh, Volume
from ._watch import Optics, ProgressCallback, _progress


def bos(volume: Union[Volume, Mesh], axis: str = "z", size: int = 512, focal_length: Optional[float] = None,
        f_number: float = 16.0, pixel: Optional[float] = None, distance: Optional[float] = None,
        background_distance: Optional[float] = None, dot: float = 3.0, spacing: float = 4.0,
        samples: int = 2, seed: int = 1, background: Union[str, os.PathLike[str], ArrayLike] = "random",
        background_pixel: Optional[float] = None, chosen: bool = False,
        progress: Union[None, bool, ProgressCallback] = None) -> Tuple[Any, ...]:
    """Background-oriented schlieren of ``volume``, set up as ``rt bos``
    sets it up: a thin-lens camera (``focal_length`` and ``pixel`` pitch in
    metres, ``f_number``) at ``distance`` Z_A from the volume's centre on
    the +``axis`` side, focused on a background ``background_distance``
    Z_D behind the centre; ``samples``² stratified aperture samples per
    pixel traced backward through the field. What is not given is chosen
    as a laboratory rig (``rt bos --help``): the pixel pitch of a 2048 ×
    5.5 µm sensor binned to ``size`` pixels, the usual lens that fills the
    image with the volume about 1.5 m away, and Z_D so that the flow's
    99th-percentile deflection (from a quick survey) moves the image 4 px.

    ``background``: ``"random"`` dots or a ``"grid"`` of dots (both
    ``dot`` pixels wide, ``spacing`` pixels apart as imaged), the path of a
    PNG image (grey or colour, read as linear luminance, as ``rt bos
    --background FILE``), or a 2-D array of grey values ≥ 0 (1 = white,
    row 0 at the top). An image is centred on the optical axis, each of
    its pixels ``background_pixel`` sensor pixels as imaged (default: it
    spans the image width); outside it the background is its mean.

    Returns ``(reference, flow, displacement, info)``: the background
    without and with the flow (float64 (h, w), about 0–1; record them with
    :func:`record` for a camera's counts, noise and diffraction), the
    ground-truth displacement, float64 (h, w, 2) in pixels (x right, y
    down) in the convention of PIV/BOS software (OpenPIV, LaVision,
    PIVlab): the apparent motion of the background pattern from the
    reference image to the flow image, what cross-correlating reference →
    flow measures; and a line describing the set-up (with the working
    f-number ``N·(1 + M)`` that :func:`record`'s ``airy`` wants).
    Paraxially ``|Δ| = M·Z_D·|ε|/pitch``, ``M = f/(Z_A + Z_D − f)``.

    With ``chosen=True`` also the rig used, automatic choices included,
    as an :class:`Optics` (last in the tuple): ``rtvis.bos(other,
    **chosen)`` repeats it exactly (the same Z_D across a time series).
    ``progress``: ``True`` draws a progress bar on stderr, a callable is
    called as ``progress(done, total)`` (rays) on the calling thread.
    Ctrl-C stops the render within a fraction of a second
    (``KeyboardInterrupt``).

    Example: ``ref, flow, disp, info = rtvis.bos(vol, background="grid")``.
    """
    if not isinstance(volume, (Volume, Mesh)):
        raise TypeError(f"volume: expected an rtvis.Volume or rtvis.Mesh, got {type(volume).__name__}")
    args, fixed = _bos_args(axis, size, focal_length, f_number, pixel, distance, background_distance, dot,
                            spacing, samples, seed, background, background_pixel)
    *out, said, rig = _rtvis._bos(volume._v, *args, progress=_progress(progress, "rtvis.bos"))
    return _bos_result(out, said, rig, fixed if chosen else None)


# `_rtvis._bos`'s arguments after the volume.
_BosArgs = Tuple[str, int, Optional[float], float, Optional[float], Optional[float], Optional[float], float, float,
                 int, int, str, Optional[NDArray[np.float64]], Optional[float]]


def _bos_args(axis: str = "z", size: int = 512, focal_length: Optional[float] = None, f_number: float = 16.0,
              pixel: Optional[float] = None, distance: Optional[float] = None,
              background_distance: Optional[float] = None, dot: float = 3.0, spacing: float = 4.0,
              samples: int = 2, seed: int = 1, background: Union[str, os.PathLike[str], ArrayLike] = "random",
              background_pixel: Optional[float] = None) -> Tuple[_BosArgs, Dict[str, Any]]:
    """:func:`bos`'s keywords checked, as ``_rtvis._bos`` takes them after
    the volume; and those an :class:`Optics` repeats as given."""
    image: Optional[NDArray[np.float64]] = None
    name = "random"
    if isinstance(background, (str, os.PathLike)):
        name = os.fspath(background)
        if name == "":
            raise ValueError("background: \"random\", \"grid\", the path of a PNG image or a 2-D array")
    else:
        image = _array("background", background, 2, np.float64)
        if (image < 0).any():
            where = tuple(int(i) for i in np.argwhere(image < 0)[0])
            raise ValueError(f"background: value at {where} is negative ({image[where]})")
    args: _BosArgs = (
        _str("axis", axis),
        _uint("size", size),
        _float("focal_length", focal_length, optional=True),
        _float("f_number", f_number),
        _float("pixel", pixel, optional=True),
        _float("distance", distance, optional=True),
        _float("background_distance", background_distance, optional=True),
        _float("dot", dot),
        _float("spacing", spacing),
        _uint("samples", samples),
        _uint("seed", seed, 64),
        name,
        image,
        _float("background_pixel", background_pixel, optional=True),
    )
    fixed: Dict[str, Any] = dict(axis=axis, size=size, f_number=f_number, dot=dot, spacing=spacing,
                                 samples=samples, seed=seed)
    if image is None:
        fixed.update(background=background, background_pixel=background_pixel)
    return args, fixed


def _bos_result(out: List[Any], said: str, rig: Dict[str, Any],
                fixed: Optional[Dict[str, Any]]) -> Tuple[Any, ...]:
    """:func:`bos`'s tuple (with the :class:`Optics` when ``fixed`` is
    given)."""
    result: Tuple[Any, ...] = (*out, said)
    if fixed is not None:
        result += (Optics(said, **fixed, **rig),)
    return result
