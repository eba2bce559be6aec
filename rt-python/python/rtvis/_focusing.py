"""Focusing schlieren (a lens-and-grid system), set up as ``rt focusing``
sets it up."""

from __future__ import annotations

from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np
from numpy.typing import NDArray

from . import _rtvis
from ._checks import _float, _str, _uint
from ._volume import Mesh, Volume
from ._watch import Optics, ProgressCallback, _progress


def focusing(volume: Union[Volume, Mesh], axis: str = "z", size: int = 512, focal_length: Optional[float] = None,
             aperture: Optional[float] = None, pixel: Optional[float] = None, distance: Optional[float] = None,
             focus: float = 0.0, source_distance: Optional[float] = None, pitch: Optional[float] = None,
             duty: float = 0.5, angle: float = 0.0, offset: float = 0.25, bands: Optional[int] = None,
             samples: int = 6, seed: int = 1, chosen: bool = False,
             progress: Union[None, bool, ProgressCallback] = None) -> Tuple[Any, ...]:
    """Focusing schlieren of ``volume`` (a lens-and-grid system, Weinstein
    1993), set up as ``rt focusing`` sets it up: the same defaults, the
    same automatic choices, the same image bit for bit. A source grid of
    bright bands lies behind the flow, a thin schlieren lens in front of it
    images the flow's focus plane on the sensor, and a cutoff grid (the
    source's negative, shifted by ``offset``) sits at the source's image:
    what lies in the focus plane is sharp, what lies before and behind it
    blurs away. Light travels along +``axis``; the image axes are those of
    :func:`schlieren`.

    Options (lengths in metres, angles in degrees):

    - ``axis``: ``"x"``, ``"y"`` or ``"z"`` (default ``"z"``).
    - ``size``: image width in pixels, 1–8192 (default 512); the height
      follows the volume's aspect.
    - ``focal_length``: the schlieren lens's focal length, > 0 (default: a
      quarter of ``distance``).
    - ``aperture``: the lens's diameter, > 0 (default: f/2); larger
      focuses more sharply (depth of sharp focus ≈ ``2·w·Z/D`` for a
      feature of width ``w`` at distance ``Z``).
    - ``pixel``: pitch of a pixel in the lens's image plane (relayed to a
      camera), > 0 (default: the volume's width and 5 % fill the image).
    - ``distance``: from the lens to the volume's centre, > 0 (default:
      twice the volume's width across the image).
    - ``focus``: the plane in focus, its distance from the volume's centre
      toward the lens (negative: beyond the centre; default 0).
    - ``source_distance``: from the lens to the source grid, beyond the
      focus plane (default: twice the focus plane's distance).
    - ``pitch``: the source grid's period on its plane, > 0 (default: from
      a survey of the flow, so that the strongest 1 % of deflections
      across the bands use 80 % of the linear range, finer saturating
      them, kept to 25–100 periods across the aperture's view of the
      source plane so the undisturbed image is flat).
    - ``duty``: bright fraction of each period, in (0, 1) (default 0.5).
    - ``angle``: band orientation (default 0: bands along the image's
      vertical, sensitive to horizontal deflection; 90: horizontal bands,
      vertical deflection).
    - ``offset``: the cutoff grid's shift across the bands in pitches, in
      [0, 1) (default 0.25; 0 is dark field; the sensitivity, up to
      ``min(duty, 1 − duty)``).
    - ``bands``: number of bands, centred on the axis, ≥ 1 (default
      unbounded); a few bands light only the part of the image that sees
      them through the lens.
    - ``samples``: k, k² aperture samples per pixel (stripes along the
      bands), 1–64 (default 6).
    - ``seed``: seed of the sample positions (default 1).

    Returns ``(reference, flow, relative, info)``: the fraction of the
    light each pixel receives without and with the flow, ``relative =
    flow / reference`` (float64 (h, w) each; I/I₀: 1 undisturbed, and 1
    where no band lights the pixel; ``rt focusing``'s ``.raw`` holds it as
    float32), and a line describing the set-up (focal length, aperture,
    focus and source distances from the lens, the grid's pitch, exact:
    passed back as ``pitch`` it gives the same image). For a camera's
    counts and noise, record ``flow / reference[reference > 1e-12].mean()``
    (1 = the mean lit background, as ``rt focusing`` records it) with
    :func:`record`. Within the linear range ``|relative − 1| ≈ ε·(Z_S − Z_F) /
    (offset·pitch)`` for a deflection ``ε`` across the bands in the focus
    plane at ``Z_F``, the source grid at ``Z_S``.

    With ``chosen=True`` also the rig used, automatic choices included
    (the pitch among them), as an :class:`Optics` (last in the tuple):
    ``rtvis.focusing(other, **chosen)`` repeats it exactly. ``progress``:
    ``True`` draws a progress bar on stderr, a callable is called as
    ``progress(done, total)`` (rays) on the calling thread. Ctrl-C stops
    the render within a fraction of a second (``KeyboardInterrupt``).

    Example: ``ref, flow, rel, info = rtvis.focusing(vol, focus=0.01,
    aperture=0.3)``.
    """
    if not isinstance(volume, (Volume, Mesh)):
        raise TypeError(f"volume: expected an rtvis.Volume or rtvis.Mesh, got {type(volume).__name__}")
    args, fixed = _focusing_args(axis, size, focal_length, aperture, pixel, distance, focus, source_distance,
                                 pitch, duty, angle, offset, bands, samples, seed)
    *out, said, rig = _rtvis._focusing(volume._v, *args, progress=_progress(progress, "rtvis.focusing"))
    return _focusing_result(out, said, rig, fixed if chosen else None)


# `_rtvis._focusing`'s arguments after the volume.
_FocusingArgs = Tuple[str, int, Optional[float], Optional[float], Optional[float], Optional[float], float,
                      Optional[float], Optional[float], float, float, float, Optional[int], int, int]


def _focusing_args(axis: str = "z", size: int = 512, focal_length: Optional[float] = None,
                   aperture: Optional[float] = None, pixel: Optional[float] = None,
                   distance: Optional[float] = None, focus: float = 0.0, source_distance: Optional[float] = None,
                   pitch: Optional[float] = None, duty: float = 0.5, angle: float = 0.0, offset: float = 0.25,
                   bands: Optional[int] = None, samples: int = 6,
                   seed: int = 1) -> Tuple[_FocusingArgs, Dict[str, Any]]:
    """:func:`focusing`'s keywords checked, as ``_rtvis._focusing`` takes
    them after the volume; and those an :class:`Optics` repeats as
    given."""
    args: _FocusingArgs = (
        _str("axis", axis),
        _uint("size", size),
        _float("focal_length", focal_length, optional=True),
        _float("aperture", aperture, optional=True),
        _float("pixel", pixel, optional=True),
        _float("distance", distance, optional=True),
        _float("focus", focus),
        _float("source_distance", source_distance, optional=True),
        _float("pitch", pitch, optional=True),
        _float("duty", duty),
        _float("angle", angle),
        _float("offset", offset),
        None if bands is None else _uint("bands", bands),
        _uint("samples", samples),
        _uint("seed", seed, 64),
    )
    fixed: Dict[str, Any] = dict(axis=axis, size=size, focus=focus, duty=duty, angle=angle, offset=offset,
                                 bands=bands, samples=samples, seed=seed)
    return args, fixed


def _focusing_result(out: List[Any], said: str, rig: Dict[str, Any],
                     fixed: Optional[Dict[str, Any]]) -> Tuple[Any, ...]:
    """:func:`focusing`'s tuple (with the :class:`Optics` when ``fixed``
    is given)."""
    result: Tuple[Any, ...] = (*out, said)
    if fixed is not None:
        result += (Optics(said, **fixed, **rig),)
    return result
