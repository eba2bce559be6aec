"""The schlieren bench: ``schlieren``, ``shadowgraph``, ``interferogram``
and ``color_schlieren`` (a parallel beam through the volume, a cutoff in
the focal plane), and ``record`` (a camera sensor's counts)."""

from __future__ import annotations

from typing import Any, Dict, Mapping, Optional, Sequence, Tuple, Union, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _rtvis
from ._checks import RtvisWarning, _array, _float, _integer, _number, _str, _uint
from ._volume import Mesh, Volume
from ._watch import Optics, ProgressCallback, _progress


# The function a progress bar names, by the bench's cutoff.
_NAMES = {"none": "rtvis.shadowgraph", "interferometry": "rtvis.interferogram", "color": "rtvis.color_schlieren"}


def _bench(volume: Union[Volume, Mesh], cutoff: str, *, angle: float = 0.0, f: float = 1.0,
           h: Optional[float] = None, radius: Optional[float] = None, half_range: Optional[float] = None,
           wavelength: float = 10.6e-6, fringe_spacing: Optional[float] = None,
           film_distance: Optional[float] = None, axis: str = "z", size: int = 512, photons: int = 16,
           seed: int = 1, estimator: str = "sheet",
           output: Tuple[bool, bool, bool, bool, bool] = (True, True, False, True, True),
           progress: Union[None, bool, ProgressCallback] = None, device: str = "cpu"
           ) -> Tuple[NDArray[Any], Optional[NDArray[np.float32]], Optional[NDArray[np.float64]], Dict[str, Any], str]:
    """The bench's film: ``(image, deflection, phase, chosen, description)``;
    ``output = (rgb, float64, relative, deflection, phase)`` says what to
    make (the default: the film's own RGB in float64, everything)."""
    if not isinstance(volume, (Volume, Mesh)):
        raise TypeError(f"volume: expected an rtvis.Volume or rtvis.Mesh, got {type(volume).__name__}")
    image, deflection, phase, chosen, said, warning = _rtvis._optics(
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
        cast(Tuple[bool, bool, bool, bool, bool], tuple(bool(o) for o in output)),
        _progress(progress, _NAMES.get(cutoff, "rtvis.schlieren")),
        _str("device", device),
    )
    if warning is not None:
        import warnings

        warnings.warn(warning, RtvisWarning, stacklevel=4)
    return image, deflection, phase, chosen, said


def _dtype(dtype: Any) -> np.dtype[Any]:
    d: np.dtype[Any] = np.dtype(dtype)
    if d not in (np.dtype(np.float32), np.dtype(np.float64)):
        raise ValueError(f"dtype: expected float32 or float64, got {d}")
    return d


def _grey(image: NDArray[Any], background: Sequence[float], dtype: Any) -> NDArray[Any]:
    """Channel 0 (in f64) divided by the background's level (when it is
    not 0), as `dtype`."""
    b = float(background[0])
    g = image[:, :, 0]
    return np.ascontiguousarray(g / b if b > 0.0 else g, dtype=_dtype(dtype))


def _render(volume: Union[Volume, Mesh], cutoff: str, keywords: Sequence[str], renamed: Mapping[str, str],
            fixed: Mapping[str, Any], *, deflection: bool, phase: bool = False, dtype: Any,
            chosen: bool, progress: Union[None, bool, ProgressCallback], **options: Any) -> Any:
    """One of the public renders: the image, then the deflection, the
    phase and the chosen optics as asked for. ``keywords`` are the
    function's own optics keywords (the chosen values' names, as
    ``renamed`` maps the bench's names to them), ``fixed`` those it was
    called with that the bench did not choose."""
    wide = _dtype(dtype) == np.dtype(np.float64)
    image, eps, phi, picked, said = _bench(
        volume, cutoff, output=(cutoff == "color", wide, True, deflection, phase), progress=progress, **options
    )
    out: Tuple[Any, ...] = (image,)
    if deflection:
        out += (eps,)
    if phase:
        out += (phi,)
    if chosen:
        fields = dict(fixed)
        for name, value in picked.items():
            name = renamed.get(name, name)
            if name in keywords:
                fields[name] = value
        out += (Optics(said, **{k: fields[k] for k in keywords if k in fields}),)
    return out if len(out) > 1 else out[0]


def schlieren(
    volume: Union[Volume, Mesh],
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
    dtype: Any = np.float32,
    chosen: bool = False,
    progress: Union[None, bool, ProgressCallback] = None,
    device: str = "cpu",
) -> Any:
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
    chosen : bool
        Also return the optics used, automatic choices included, as an
        :class:`Optics` (last in the tuple): ``schlieren(other, **chosen)``
        repeats them exactly (a time series with one exposure).
    progress : True or callable, optional
        ``True``: a progress bar on stderr; a callable: called as
        ``progress(done, total)`` (photons) on the calling thread.
        Ctrl-C stops the render within a fraction of a second and raises
        ``KeyboardInterrupt``.
    device : "cpu", "gpu" or "auto"
        Where the photons are traced: ``cpu`` (the default: the same image
        on every machine), ``gpu`` (any Vulkan, Metal or DX12 driver, f32;
        volumes with ``interpolation="linear"`` only, else ``ValueError``;
        no adapter: ``RuntimeError``), ``auto`` (the GPU where it can,
        else the CPU). With ``chosen=True`` the optics' description
        names the device used.

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
    A film too large for memory raises ``MemoryError``.
    """
    cutoff = _str("cutoff", cutoff)
    keywords = ("cutoff", "angle", "f", "h", "radius", "half_range", "film_distance", "axis", "size",
                "photons", "seed", "estimator")
    fixed = dict(cutoff=cutoff, axis=axis, seed=seed, estimator=estimator)
    return _render(volume, cutoff, keywords, {}, fixed, deflection=deflection, dtype=dtype, chosen=chosen,
                   progress=progress, angle=angle, f=f, h=h, radius=radius, half_range=half_range,
                   film_distance=film_distance, axis=axis, size=size, photons=photons, seed=seed,
                   estimator=estimator, device=device)


def shadowgraph(
    volume: Union[Volume, Mesh],
    distance: Optional[float] = None,
    axis: str = "z",
    size: int = 512,
    photons: int = 16,
    seed: int = 1,
    deflection: bool = False,
    dtype: Any = np.float32,
    chosen: bool = False,
    progress: Union[None, bool, ProgressCallback] = None,
    device: str = "cpu",
) -> Any:
    """Synthetic shadowgraph: no cutoff, the film ``distance`` metres
    behind the volume's mid-plane (default: automatic, the strongest
    contrast about 0.5). Returns the intensity relative to the undisturbed
    beam, (h, w) of ``dtype`` (and the deflection, and the chosen optics,
    as :func:`schlieren`; ``device`` as there)."""
    keywords = ("distance", "axis", "size", "photons", "seed")
    return _render(volume, "none", keywords, {"film_distance": "distance"}, dict(axis=axis, seed=seed),
                   deflection=deflection, dtype=dtype, chosen=chosen, progress=progress,
                   film_distance=distance, axis=axis, size=size, photons=photons, seed=seed, device=device)


def interferogram(
    volume: Union[Volume, Mesh],
    wavelength: float = 10.6e-6,
    fringe_spacing: Optional[float] = None,
    axis: str = "z",
    size: int = 512,
    photons: int = 16,
    seed: int = 1,
    deflection: bool = False,
    phase: bool = False,
    dtype: Any = np.float32,
    chosen: bool = False,
    progress: Union[None, bool, ProgressCallback] = None,
    device: str = "cpu",
) -> Any:
    """Synthetic interferogram: ``I = (1 + cos(φ + 2π x/Λ))/2`` with the
    phase ``φ = (2π/λ)·∫(n − n_ref) ds`` along each curved path (``n_ref``:
    the first sample's index). ``wavelength`` λ in metres (default: CO₂
    laser, 10.6 µm); ``fringe_spacing`` Λ on the film in metres (default:
    infinite fringe). Returns (h, w) of ``dtype`` in [0, 1]; with
    ``deflection=True`` also the deflection (as :func:`schlieren`); with
    ``phase=True`` also φ itself, float64 (h, w) in radians, **unwrapped**
    (each photon's own phase, averaged per pixel; no 2π ambiguity; NaN
    where no photon landed); with ``chosen=True`` the optics, last."""
    keywords = ("wavelength", "fringe_spacing", "axis", "size", "photons", "seed")
    return _render(volume, "interferometry", keywords, {}, dict(axis=axis, seed=seed),
                   deflection=deflection, phase=phase, dtype=dtype, chosen=chosen, progress=progress,
                   wavelength=wavelength, fringe_spacing=fringe_spacing, axis=axis, size=size,
                   photons=photons, seed=seed, device=device)


def color_schlieren(
    volume: Union[Volume, Mesh],
    half_range: Optional[float] = None,
    axis: str = "z",
    size: int = 512,
    photons: int = 16,
    seed: int = 1,
    deflection: bool = False,
    dtype: Any = np.float32,
    chosen: bool = False,
    progress: Union[None, bool, ProgressCallback] = None,
    device: str = "cpu",
) -> Any:
    """Colour (rainbow) schlieren: a hue-wheel filter in the focal plane,
    hue = direction of the deflection, saturation = its size relative to
    ``half_range`` (radians; default automatic). Returns linear RGB,
    float32 (h, w, 3), white where nothing deflects (and the deflection,
    and the chosen optics, as :func:`schlieren`)."""
    keywords = ("half_range", "axis", "size", "photons", "seed")
    return _render(volume, "color", keywords, {}, dict(axis=axis, seed=seed), deflection=deflection,
                   dtype=dtype, chosen=chosen, progress=progress, half_range=half_range, axis=axis,
                   size=size, photons=photons, seed=seed, device=device)


def record(image: ArrayLike, exposure: float = 10_000.0, full_well: float = 20_000.0, bits: int = 16,
           shot_noise: bool = False, read_noise: float = 0.0, seed: int = 0,
           airy: Optional[Tuple[float, float, float]] = None) -> NDArray[np.uint16]:
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
