"""The schlieren bench: ``schlieren``, ``shadowgraph``, ``interferogram``
and ``color_schlieren`` (a parallel beam through the volume, a cutoff in
the focal plane), and ``record`` (a camera sensor's counts)."""

from __future__ import annotations

from typing import Optional, Tuple

import numpy as np

from . import _rtvis
from ._checks import RtvisWarning, _array, _float, _integer, _number, _str, _uint
from ._volume import Mesh, Volume


def _bench(volume, cutoff, *, angle=0.0, f=1.0, h=None, radius=None, half_range=None,
           wavelength=10.6e-6, fringe_spacing=None, film_distance=None, axis="z", size=512,
           photons=16, seed=1, estimator="sheet"):
    if not isinstance(volume, (Volume, Mesh)):
        raise TypeError(f"volume: expected an rtvis.Volume or rtvis.Mesh, got {type(volume).__name__}")
    *out, warning = _rtvis._optics(
        volume._v,
        cutoff,
        _float("angle", angle),
        _float("f", f),
        _float("h", h, optional=True),
        _float("radius", radius, optional=True),
        _float("half_range", half_range, optional=True),
        _float("wavelength", wavelength),
        _float("fringe_spacing", fringe_spacing, optional=True),
        _float("film_distance", film_distance, optional=True),
        _str("axis", axis),
        _uint("size", size),
        _uint("photons", photons),
        _uint("seed", seed, 64),
        _str("estimator", estimator),
    )
    if warning is not None:
        import warnings

        warnings.warn(warning, RtvisWarning, stacklevel=3)
    return tuple(out)


def _dtype(dtype):
    d = np.dtype(dtype)
    if d not in (np.dtype(np.float32), np.dtype(np.float64)):
        raise ValueError(f"dtype: expected float32 or float64, got {d}")
    return d


def _grey(image: np.ndarray, background, dtype) -> np.ndarray:
    """Channel 0 (in f64) divided by the background's level (when it is
    not 0), as `dtype`."""
    b = float(background[0])
    g = image[:, :, 0]
    return np.ascontiguousarray(g / b if b > 0.0 else g, dtype=_dtype(dtype))


def schlieren(
    volume: Volume,
    cutoff: str = "knife",
    angle: float = 0.0,
    f: float = 1.0,
    h: Optional[float] = None,
    radius: Optional[float] = None,
    half_range: Optional[float] = None,
    film_distance: Optional[float] = None,
    axis: str = "z",
    size: int = 512,
    photons: int = 16,
    seed: int = 1,
    estimator: str = "sheet",
    deflection: bool = False,
    dtype=np.float32,
):
    """Synthetic schlieren of ``volume``: a parallel beam along ``axis``
    through the whole volume, photons bent along curved paths by the
    index gradient, then the cutoff in the focal plane of a lens of focal
    length ``f``; the film images the volume's mid-plane.

    Parameters
    ----------
    cutoff : str
        ``knife`` (knife edge across ``angle``), ``graded`` (transmission
        ramps with the deflection), ``pinhole`` (bright field),
        ``dark-field`` (opaque disc), ``color`` (hue wheel: see
        :func:`color_schlieren`), ``none`` (no cutoff: a shadowgraph when
        ``film_distance`` ≠ 0) or ``interferometry`` (see
        :func:`interferogram`).
    angle : float
        Direction the knife edge or graded filter is sensitive to, degrees
        from the image's horizontal axis.
    f : float
        Focal length of the schlieren head, metres.
    h : float, optional
        Knife edge: source image height; graded: ramp width (metres).
        Default: automatic, the 99th-percentile deflection reaches 0.45 of
        the range.
    radius : float, optional
        Pinhole / dark-field stop radius (metres); default automatic.
    half_range : float, optional
        Colour filter: the deflection (radians) at the wheel's rim.
    film_distance : float, optional
        Film distance behind the mid-plane (metres); default 0.
    axis : "x", "y" or "z"
        Beam direction (image axes: y,z for x; z,x for y; x,y for z).
    size : int
        Image width in pixels; the height follows the volume's aspect.
    photons : int
        Photons per pixel (rounded up to whole passes of a k×k lattice).
    seed : int
        Seed of every random choice: the same seed, the same image.
    estimator : "sheet" or "photons"
        ``sheet`` carries each pass's lattice onto the film by exact area
        (no grain); ``photons`` splats photons one by one (grainy).
    deflection : bool
        Also return the mean deflection per pixel.
    dtype : float32 or float64
        The image's type; the film accumulates in float64, so float64
        keeps differences below float32's 6e-8 relative step (weak
        signals, two renders compared).

    Returns
    -------
    image : ndarray, float32, shape (h, w) — (h, w, 3) for ``color``
        Intensity divided by the undisturbed background's (1 where nothing
        deflects; a knife edge's background passes half the beam, so its
        image is twice the fraction of the beam that passes). For
        ``dark-field``, whose background is black, the fraction of the
        uncut beam.
    deflection : ndarray, float32, shape (h, w, 2)
        Only with ``deflection=True``: the mean deflection (εu, εv) of the
        photons landing in each pixel, radians along the image's
        horizontal and vertical axes; NaN where none landed.

    The same options and seed give the same image as ``rt schlieren``.
    """
    image, eps, _, background, _ = _bench(
        volume, _str("cutoff", cutoff), angle=angle, f=f, h=h, radius=radius,
        half_range=half_range, film_distance=film_distance, axis=axis, size=size,
        photons=photons, seed=seed, estimator=estimator,
    )
    if cutoff == "color":
        out = image / np.asarray(background, dtype=np.float64)
        out = np.ascontiguousarray(out, dtype=_dtype(dtype))
    else:
        out = _grey(image, background, dtype)
    return (out, eps) if deflection else out


def shadowgraph(
    volume: Volume,
    distance: Optional[float] = None,
    axis: str = "z",
    size: int = 512,
    photons: int = 16,
    seed: int = 1,
    deflection: bool = False,
    dtype=np.float32,
):
    """Synthetic shadowgraph: no cutoff, the film ``distance`` metres
    behind the volume's mid-plane (default: automatic, the strongest
    contrast about 0.5). Returns the intensity relative to the undisturbed
    beam, (h, w) of ``dtype`` (and the deflection, as :func:`schlieren`)."""
    image, eps, _, background, _ = _bench(
        volume, "none", film_distance=distance, axis=axis, size=size, photons=photons, seed=seed
    )
    out = _grey(image, background, dtype)
    return (out, eps) if deflection else out


def interferogram(
    volume: Volume,
    wavelength: float = 10.6e-6,
    fringe_spacing: Optional[float] = None,
    axis: str = "z",
    size: int = 512,
    photons: int = 16,
    seed: int = 1,
    deflection: bool = False,
    phase: bool = False,
    dtype=np.float32,
):
    """Synthetic interferogram: ``I = (1 + cos(φ + 2π x/Λ))/2`` with the
    phase ``φ = (2π/λ)·∫(n − n_ref) ds`` along each curved path (``n_ref``:
    the first sample's index). ``wavelength`` λ in metres (default: CO₂
    laser, 10.6 µm); ``fringe_spacing`` Λ on the film in metres (default:
    infinite fringe). Returns (h, w) of ``dtype`` in [0, 1]; with
    ``deflection=True`` also the deflection (as :func:`schlieren`); with
    ``phase=True`` also φ itself, float64 (h, w) in radians, **unwrapped**
    (each photon's own phase, averaged per pixel; no 2π ambiguity; NaN
    where no photon landed), last in the tuple."""
    image, eps, phi, background, _ = _bench(
        volume, "interferometry", wavelength=wavelength, fringe_spacing=fringe_spacing,
        axis=axis, size=size, photons=photons, seed=seed,
    )
    out = (_grey(image, background, dtype),)
    if deflection:
        out += (eps,)
    if phase:
        out += (phi,)
    return out if len(out) > 1 else out[0]


def color_schlieren(
    volume: Volume,
    half_range: Optional[float] = None,
    axis: str = "z",
    size: int = 512,
    photons: int = 16,
    seed: int = 1,
    deflection: bool = False,
    dtype=np.float32,
):
    """Colour (rainbow) schlieren: a hue-wheel filter in the focal plane,
    hue = direction of the deflection, saturation = its size relative to
    ``half_range`` (radians; default automatic). Returns linear RGB,
    float32 (h, w, 3), white where nothing deflects (and the deflection,
    as :func:`schlieren`)."""
    return schlieren(volume, "color", half_range=half_range, axis=axis, size=size,
                     photons=photons, seed=seed, deflection=deflection, dtype=dtype)


def record(image, exposure: float = 10_000.0, full_well: float = 20_000.0, bits: int = 16,
           shot_noise: bool = False, read_noise: float = 0.0, seed: int = 0,
           airy: Optional[Tuple[float, float, float]] = None) -> np.ndarray:
    """Records an optics image as a camera sensor would: a pixel of
    intensity ``I`` (1 = background) collects ``exposure·I`` electrons on
    average; with ``shot_noise`` the count is Poisson, plus Gaussian
    ``read_noise`` (electrons rms); clipped at ``full_well`` electrons and
    quantised to ``2**bits − 1`` levels there. Returns ``uint16`` counts of
    the image's shape. The same ``seed`` gives the same counts (each
    pixel's noise is its own stream); record a reference and a flow image
    with different seeds for independent noise. Noise is off by default.

    ``airy = (wavelength, f_number, pixel)`` (metres, the f-number of the
    light converging on the sensor — for a lens focused at magnification
    ``M``, ``N·(1 + M)`` — and the pixel pitch in metres) first blurs the
    image by the lens's diffraction: an Airy pattern whose first dark ring
    is ``2.44·wavelength·f_number`` across, integrated over each pixel,
    edges clamped. Off by default.

    Example: ``rtvis.record(rtvis.schlieren(vol), exposure=5000,
    full_well=10000, bits=12, shot_noise=True, read_noise=5, seed=1)``;
    ``rtvis.record(ref, airy=(532e-9, 16.8, 5e-6))``.
    """
    a = _array("image", image, 2, np.float64)
    if (a < 0).any():
        where = tuple(int(i) for i in np.argwhere(a < 0)[0])
        raise ValueError(f"image: intensity at {where} is negative ({a[where]})")
    diffraction = None
    if airy is not None:
        try:
            wavelength, f_number, pitch = airy
        except (TypeError, ValueError):
            raise TypeError("airy: expected (wavelength, f_number, pixel)") from None
        diffraction = (_number("airy wavelength", wavelength, positive=True),
                       _number("airy f_number", f_number, positive=True),
                       _number("airy pixel", pitch, positive=True))
    return _rtvis._record(a, _number("exposure", exposure), _number("full_well", full_well, positive=True),
                          _integer("bits", bits, 1, 16), bool(shot_noise), _number("read_noise", read_noise),
                          _integer("seed", seed, 0, 2**64 - 1), diffraction)
