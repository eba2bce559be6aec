"""rtvis: the rt ray tracers from Python, numpy in and numpy out.

- Volumes and optics: ``Volume`` (a numpy array of density or refractive
  index) or ``read_volume`` (NRRD, raw + JSON, VTK image data), or an
  unstructured CFD mesh: ``Mesh`` (points, cells by kind, values) or
  ``read_mesh`` (VTK ``.vtu``/``.vtk``), then
  ``schlieren``, ``shadowgraph``, ``interferogram`` and
  ``color_schlieren``: photons traced along curved paths through the
  field, each returning a float32 image normalised to the undisturbed
  background; ``bos`` and ``focusing`` (background-oriented and focusing
  schlieren, set up as ``rt bos`` and ``rt focusing`` set them up), and
  ``record`` for a camera sensor's counts.
- Surfaces: ``Scene`` with meshes coloured by a scalar, sphere glyphs and
  tubes, rendered by ``Scene.render`` into premultiplied RGBA and depth.
- Compositing: ``composite`` (images in one process) and
  ``composite_mpi`` (one image per MPI rank, through an ``mpi4py``
  communicator), sort-last by depth.

Lengths are in the volume's or the scene's own unit (metres for the optics
defaults), angles in degrees. Images are ``[row, column]`` with row 0 at
the top. Every function releases the GIL while it renders. Bad input
raises ``TypeError`` (wrong kind of value) or ``ValueError`` (wrong shape,
NaN, out of range, unknown option), never crashes the interpreter.
"""

from __future__ import annotations

import math
import os
import struct
import time
import zlib
from typing import Optional, Sequence, Tuple, Union

import numpy as np

from . import _rtvis

__all__ = [
    "GLADSTONE_DALE_AIR",
    "bos",
    "Camera",
    "Mesh",
    "Scene",
    "Volume",
    "color_schlieren",
    "composite",
    "composite_mpi",
    "focusing",
    "interferogram",
    "read_mesh",
    "read_volume",
    "record",
    "schlieren",
    "save_png",
    "shadowgraph",
    "to_gray8",
    "to_srgb8",
]

__version__ = "0.1.0"

#: Gladstone–Dale constant of air at 589 nm, m³/kg (``n = 1 + K·ρ``).
GLADSTONE_DALE_AIR: float = _rtvis.GLADSTONE_DALE_AIR

_QUANTITIES = ("density", "index")
_INTERPOLATIONS = ("linear", "cubic")


def _choice(name: str, value, known: Sequence[str]) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{name}: expected one of {', '.join(known)} (a str), got {type(value).__name__}")
    if value not in known:
        raise ValueError(f"{name}: unknown {value!r} (known: {', '.join(known)})")
    return value


def _number(name: str, value, *, positive: bool = False, optional: bool = False) -> Optional[float]:
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name}: expected a number, got {type(value).__name__}")
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite (got {v})")
    if positive and v <= 0.0:
        raise ValueError(f"{name} must be > 0 (got {v})")
    return v


def _integer(name: str, value, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name}: expected an int, got {type(value).__name__}")
    v = int(value)
    if not lo <= v <= hi:
        raise ValueError(f"{name} must be {lo} to {hi} (got {v})")
    return v


def _vector(name: str, value, n: int = 3) -> Tuple[float, ...]:
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name}: expected {n} numbers") from None
    if a.shape != (n,):
        raise ValueError(f"{name}: expected {n} numbers, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite (got {tuple(a)})")
    return tuple(float(v) for v in a)


def _array(name: str, value, ndim: int, dtype, *, last: Optional[int] = None, integer: bool = False) -> np.ndarray:
    """``value`` as a C-contiguous array of ``dtype`` (copied if needed),
    its kind and shape checked."""
    if not isinstance(value, np.ndarray):
        try:
            value = np.asarray(value)
        except (TypeError, ValueError):
            raise TypeError(f"{name}: expected an array of numbers") from None
    kinds = "iu" if integer else "fiu"
    if value.dtype.kind not in kinds:
        what = "integers" if integer else "float32 or float64 numbers"
        raise TypeError(f"{name}: expected {what}, got dtype {value.dtype}")
    if value.ndim != ndim or (last is not None and value.shape[-1] != last):
        want = f"{ndim} dimensions" + (f", the last of length {last}" if last is not None else "")
        raise ValueError(f"{name}: expected {want}; got shape {value.shape}")
    if value.size == 0:
        raise ValueError(f"{name} is empty (shape {value.shape})")
    if integer:
        return np.ascontiguousarray(value, dtype=np.int64)
    with np.errstate(over="ignore", invalid="ignore"):  # reported below
        out = np.ascontiguousarray(value, dtype=dtype)
    bad = ~np.isfinite(out)
    if bad.any():
        where = tuple(int(i) for i in np.argwhere(bad)[0])
        raise ValueError(f"{name}: value at {where} is not finite ({out[where]})")
    return out


class Volume:
    """A gridded volume of density or refractive index, ready for the
    optical bench.

    Parameters
    ----------
    values : ndarray, shape (nz, ny, nx), float32 or float64
        Samples, ``values[k, j, i]`` at ``origin + (i·dx, j·dy, k·dz)``
        (x varies fastest, as VTK and NRRD store it). Any strides; copied.
        Stored as float32.
    spacing : 3 numbers, default (1, 1, 1)
        Sample spacing ``(dx, dy, dz)``, > 0, in metres (or your unit).
    origin : 3 numbers, default (0, 0, 0)
        Centre of sample ``[0, 0, 0]``.
    quantity : "density" or "index"
        ``density`` (kg/m³) is mapped to refractive index by
        Gladstone–Dale ``n = 1 + k·ρ``; ``index`` is used as is.
    k : float
        Gladstone–Dale constant in m³/kg (air at 589 nm by default).
    interpolation : "cubic" or "linear"
        Catmull–Rom tricubic (the default; C¹: smooth shadowgraphs), or
        trilinear (about twice as fast; its gradient jumps at cell faces,
        so shadowgraphs show the grid).
    allow_nonphysical : bool
        Accept densities ≤ 0 or indices below 1.

    The index outside the volume is that of sample ``[0, 0, 0]``.
    """

    def __init__(
        self,
        values,
        spacing=(1.0, 1.0, 1.0),
        origin=(0.0, 0.0, 0.0),
        quantity: str = "density",
        k: float = GLADSTONE_DALE_AIR,
        interpolation: str = "cubic",
        allow_nonphysical: bool = False,
    ):
        arr = _array("values", values, 3, np.float32)
        self._v = _rtvis._Volume(
            arr,
            _vector("spacing", spacing),
            _vector("origin", origin),
            _choice("quantity", quantity, _QUANTITIES),
            _number("k", k, positive=True),
            _choice("interpolation", interpolation, _INTERPOLATIONS),
            bool(allow_nonphysical),
        )

    @classmethod
    def _wrap(cls, native) -> "Volume":
        v = cls.__new__(cls)
        v._v = native
        return v

    @property
    def shape(self) -> Tuple[int, int, int]:
        """Samples per axis, ``(nz, ny, nx)``."""
        return tuple(self._v.shape)

    @property
    def spacing(self) -> Tuple[float, float, float]:
        """Sample spacing ``(dx, dy, dz)``."""
        return tuple(self._v.spacing)

    @property
    def origin(self) -> Tuple[float, float, float]:
        """Centre of sample ``[0, 0, 0]``, ``(x, y, z)``."""
        return tuple(self._v.origin)

    @property
    def bounds(self):
        """``((xmin, ymin, zmin), (xmax, ymax, zmax))``: the box the
        samples span."""
        lo, hi = self._v.bounds
        return tuple(lo), tuple(hi)

    def index(self) -> np.ndarray:
        """The refractive index samples, float32 ``[z, y, x]``."""
        return self._v.index()

    def __repr__(self) -> str:
        return f"rtvis.Volume(shape={self.shape}, spacing={self.spacing}, origin={self.origin})"


def read_volume(
    path,
    quantity: str = "density",
    k: float = GLADSTONE_DALE_AIR,
    interpolation: str = "cubic",
    allow_nonphysical: bool = False,
) -> Volume:
    """Reads a volume file: NRRD (``.nrrd``/``.nhdr``), raw + JSON sidecar
    (``.json``) or VTK image data (``.vtk``/``.vti``).

    ``quantity``, ``k``, ``interpolation`` and ``allow_nonphysical`` as for
    :class:`Volume`. Raises ``OSError`` if the file cannot be read and
    ``ValueError`` if it is malformed or holds no usable grid.
    """
    import os

    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path: expected a str or path, got {type(path).__name__}")
    native = _rtvis._read_volume(
        os.fspath(path),
        _choice("quantity", quantity, _QUANTITIES),
        _number("k", k, positive=True),
        _choice("interpolation", interpolation, _INTERPOLATIONS),
        bool(allow_nonphysical),
    )
    return Volume._wrap(native)


_MESH_KINDS = {"tetra": 4, "pyramid": 5, "wedge": 6, "hexahedron": 8}
_TRACES = ("exact", "smooth")
_SURFACE_KINDS = {"vertex", "line", "line3", "triangle", "triangle6", "quad", "quad8", "quad9", "polygon"}


class Mesh:
    """An unstructured CFD mesh (tetrahedra, pyramids, wedges, hexahedra)
    with one value per point, ready for the optical bench.

    Parameters
    ----------
    points : array_like, shape (n, 3)
        Point coordinates.
    cells : dict
        Cells by kind, meshio's names and VTK's point order: ``"tetra"``
        ``(m, 4)``, ``"pyramid"`` ``(m, 5)``, ``"wedge"`` ``(m, 6)``,
        ``"hexahedron"`` ``(m, 8)`` integer arrays of point indices
        (``meshio.Mesh.cells_dict`` fits: its vertices, lines, triangles
        and quads are skipped, other kinds raise ``ValueError``).
    values : array_like, shape (n,)
        Density (kg/m³) or refractive index at each point.
    quantity, k, allow_nonphysical
        As for :class:`Volume`.
    trace : "smooth" or "exact"
        ``smooth`` (the default: it reaches a given error sooner): gradients
        recovered at the points and integrated (second order per ray, no
        facets on coarse meshes); ``exact``: through the data's
        piecewise-linear interpolant, cell by cell in closed form (first
        order per ray).

    Cells are split into tetrahedra about their face and cell centres (24
    per hexahedron; no preferred direction; neighbours meet face to face); bad
    meshes (NaN, zero-volume or inverted cells, indices out of range, a
    face shared by three cells) raise ``ValueError`` naming the cell. The
    index outside the mesh is that of its first point.
    """

    def __init__(self, points, cells, values, quantity: str = "density",
                 k: float = GLADSTONE_DALE_AIR, trace: str = "smooth",
                 allow_nonphysical: bool = False):
        pts = _array("points", points, 2, np.float64, last=3)
        vals = _array("values", values, 1, np.float64)
        if not isinstance(cells, dict):
            raise TypeError(f"cells: expected a dict of kind → array, got {type(cells).__name__}")
        by_kind = {}
        for kind, arr in cells.items():
            if kind in _SURFACE_KINDS or np.asarray(arr).size == 0:
                continue  # no volume (meshio lists boundary patches too)
            if kind not in _MESH_KINDS:
                raise ValueError(f"cells: unknown kind {kind!r} (known: {', '.join(_MESH_KINDS)})")
            by_kind[kind] = _array(f"cells[{kind!r}]", arr, 2, np.int64, last=_MESH_KINDS[kind], integer=True)
        empty = {kind: np.zeros((0, width), np.int64) for kind, width in _MESH_KINDS.items()}
        empty.update(by_kind)
        self._v = _rtvis._Volume.mesh(
            pts, empty["tetra"], empty["pyramid"], empty["wedge"], empty["hexahedron"], vals,
            _choice("quantity", quantity, _QUANTITIES),
            _number("k", k, positive=True),
            _choice("trace", trace, _TRACES),
            bool(allow_nonphysical),
        )

    @classmethod
    def _wrap(cls, native) -> "Mesh":
        m = cls.__new__(cls)
        m._v = native
        return m

    @property
    def bounds(self):
        """``((xmin, ymin, zmin), (xmax, ymax, zmax))``: the box around the
        points."""
        lo, hi = self._v.bounds
        return tuple(lo), tuple(hi)

    @property
    def counts(self) -> Tuple[int, int, int, int]:
        """``(points, cells, tetrahedra, boundary faces)``."""
        return tuple(self._v.mesh_counts)

    def __repr__(self) -> str:
        p, c, t, _ = self.counts
        return f"rtvis.Mesh(points={p}, cells={c}, tetrahedra={t})"


def read_mesh(
    path,
    array: Optional[str] = None,
    quantity: str = "density",
    k: float = GLADSTONE_DALE_AIR,
    trace: str = "smooth",
    allow_nonphysical: bool = False,
) -> Mesh:
    """Reads an unstructured mesh: VTK XML ``.vtu`` or legacy ``.vtk``
    (``UNSTRUCTURED_GRID``), tetrahedra, pyramids, wedges, hexahedra and
    voxels (lower-dimensional cells are skipped).

    ``array`` names the point- or cell-data array (default: the first
    scalar point array, else the first scalar cell array, averaged to the
    points); the others as for :class:`Mesh`. Raises ``OSError`` if the
    file cannot be read and ``ValueError`` if it is malformed.
    """
    import os

    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path: expected a str or path, got {type(path).__name__}")
    if array is not None and not isinstance(array, str):
        raise TypeError(f"array: expected a str, got {type(array).__name__}")
    native = _rtvis._read_mesh(
        os.fspath(path),
        array,
        _choice("quantity", quantity, _QUANTITIES),
        _number("k", k, positive=True),
        _choice("trace", trace, _TRACES),
        bool(allow_nonphysical),
    )
    return Mesh._wrap(native)


def _bench(volume, cutoff, *, angle=0.0, f=1.0, h=None, radius=None, half_range=None,
           wavelength=10.6e-6, fringe_spacing=None, film_distance=None, axis="z", size=512,
           photons=16, seed=1, estimator="sheet"):
    if not isinstance(volume, (Volume, Mesh)):
        raise TypeError(f"volume: expected an rtvis.Volume or rtvis.Mesh, got {type(volume).__name__}")
    *out, warning = _rtvis._optics(
        volume._v,
        cutoff,
        _number("angle", angle),
        _number("f", f, positive=True),
        _number("h", h, positive=True, optional=True),
        _number("radius", radius, positive=True, optional=True),
        _number("half_range", half_range, positive=True, optional=True),
        _number("wavelength", wavelength, positive=True),
        _number("fringe_spacing", fringe_spacing, positive=True, optional=True),
        _number("film_distance", film_distance, optional=True),
        _choice("axis", axis, ("x", "y", "z")),
        _integer("size", size, 1, 16384),
        _integer("photons", photons, 1, 65536),
        _integer("seed", seed, 0, 2**64 - 1),
        _choice("estimator", estimator, ("sheet", "photons")),
    )
    if warning is not None:
        import warnings

        warnings.warn(warning, stacklevel=3)
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


_CUTOFFS = ("knife", "graded", "pinhole", "dark-field", "color", "none", "interferometry")


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
        volume, _choice("cutoff", cutoff, _CUTOFFS), angle=angle, f=f, h=h, radius=radius,
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


def bos(volume: Union[Volume, Mesh], axis: str = "z", size: int = 512, focal_length: Optional[float] = None,
        f_number: float = 16.0, pixel: Optional[float] = None, distance: Optional[float] = None,
        background_distance: Optional[float] = None, dot: float = 3.0, spacing: float = 4.0,
        samples: int = 2, seed: int = 1, background="random",
        background_pixel: Optional[float] = None):
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

    Example: ``ref, flow, disp, info = rtvis.bos(vol, background="grid")``.
    """
    if not isinstance(volume, (Volume, Mesh)):
        raise TypeError(f"volume: expected an rtvis.Volume or rtvis.Mesh, got {type(volume).__name__}")
    image = None
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
    return _rtvis._bos(
        volume._v,
        _choice("axis", axis, ("x", "y", "z")),
        _integer("size", size, 1, 8192),
        _number("focal_length", focal_length, positive=True, optional=True),
        _number("f_number", f_number, positive=True),
        _number("pixel", pixel, positive=True, optional=True),
        _number("distance", distance, positive=True, optional=True),
        _number("background_distance", background_distance, positive=True, optional=True),
        _number("dot", dot, positive=True),
        _number("spacing", spacing, positive=True),
        _integer("samples", samples, 1, 64),
        _integer("seed", seed, 0, 2**64 - 1),
        name,
        image,
        _number("background_pixel", background_pixel, positive=True, optional=True),
    )


def focusing(volume: Union[Volume, Mesh], axis: str = "z", size: int = 512, focal_length: Optional[float] = None,
             aperture: Optional[float] = None, pixel: Optional[float] = None, distance: Optional[float] = None,
             focus: float = 0.0, source_distance: Optional[float] = None, pitch: Optional[float] = None,
             duty: float = 0.5, angle: float = 0.0, offset: float = 0.25, bands: Optional[int] = None,
             samples: int = 6, seed: int = 1):
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

    Example: ``ref, flow, rel, info = rtvis.focusing(vol, focus=0.01,
    aperture=0.3)``.
    """
    if not isinstance(volume, (Volume, Mesh)):
        raise TypeError(f"volume: expected an rtvis.Volume or rtvis.Mesh, got {type(volume).__name__}")
    duty = _number("duty", duty)
    if not 0.0 < duty < 1.0:
        raise ValueError(f"duty must be in (0, 1) (got {duty})")
    offset = _number("offset", offset)
    if not 0.0 <= offset < 1.0:
        raise ValueError(f"offset must be in [0, 1) pitches (got {offset})")
    return _rtvis._focusing(
        volume._v,
        _choice("axis", axis, ("x", "y", "z")),
        _integer("size", size, 1, 8192),
        _number("focal_length", focal_length, positive=True, optional=True),
        _number("aperture", aperture, positive=True, optional=True),
        _number("pixel", pixel, positive=True, optional=True),
        _number("distance", distance, positive=True, optional=True),
        _number("focus", focus),
        _number("source_distance", source_distance, positive=True, optional=True),
        _number("pitch", pitch, positive=True, optional=True),
        duty,
        _number("angle", angle),
        offset,
        None if bands is None else _integer("bands", bands, 1, 2**32 - 1),
        _integer("samples", samples, 1, 64),
        _integer("seed", seed, 0, 2**64 - 1),
    )


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


class Camera:
    """A pinhole camera at ``eye`` looking at ``target``; ``up`` fixes the
    roll; ``fov`` is the vertical field of view in degrees. With
    ``ortho_height`` the projection is orthographic, that many scene
    units tall."""

    def __init__(self, eye, target, up=(0.0, 1.0, 0.0), fov: float = 30.0,
                 ortho_height: Optional[float] = None):
        self.eye = _vector("eye", eye)
        self.target = _vector("target", target)
        self.up = _vector("up", up)
        self.fov = _number("fov", fov, positive=True)
        if not self.fov < 180.0:
            raise ValueError(f"fov must be below 180 degrees (got {self.fov})")
        self.ortho_height = _number("ortho_height", ortho_height, positive=True, optional=True)

    @classmethod
    def fit(cls, bounds, direction=(0.0, 0.0, 1.0), up=(0.0, 1.0, 0.0), fov: float = 30.0,
            aspect: float = 1.0) -> "Camera":
        """A camera looking at the centre of ``bounds`` (``(lo, hi)``
        corners) from ``direction`` (toward the eye), far enough back that
        the bounding sphere fills the view (``aspect`` = width / height)."""
        lo, hi = np.asarray(_vector("bounds[0]", bounds[0])), np.asarray(_vector("bounds[1]", bounds[1]))
        d = np.asarray(_vector("direction", direction))
        if not np.any(d):
            raise ValueError("direction must not be zero")
        d = d / np.linalg.norm(d)
        centre = 0.5 * (lo + hi)
        r = max(0.5 * float(np.linalg.norm(hi - lo)), 1e-6)
        half = math.radians(_number("fov", fov, positive=True)) / 2.0
        half = min(half, math.atan(math.tan(half) * _number("aspect", aspect, positive=True)))
        dist = r / math.sin(half)
        return cls(tuple(centre + d * dist), tuple(centre), up, fov)

    def __repr__(self) -> str:
        return f"rtvis.Camera(eye={self.eye}, target={self.target}, up={self.up}, fov={self.fov})"


_MATERIALS = {
    "matte": (1.0, 0.0, 32.0, 1.0, 0.0),
    "glossy": (0.8, 0.3, 48.0, 1.0, 0.0),
}
_COLORMAPS = ("cool_to_warm", "viridis", "grayscale")

#: The default lights: dim ambient light and a directional key light.
DEFAULT_LIGHTS = [("ambient", (0.25, 0.25, 0.25)), ("directional", (-0.5, 1.0, 0.35), (0.8, 0.8, 0.8))]


def _material(m) -> Tuple[float, ...]:
    if isinstance(m, str):
        return _MATERIALS[_choice("material", m, tuple(_MATERIALS))]
    if isinstance(m, dict):
        keys = ("diffuse", "specular", "shininess", "opacity", "mirror")
        unknown = set(m) - set(keys)
        if unknown:
            raise ValueError(f"material: unknown keys {sorted(unknown)} (known: {', '.join(keys)})")
        base = dict(zip(keys, _MATERIALS["matte"]))
        base.update(m)
        return tuple(_number(f"material[{k!r}]", base[k]) for k in keys)
    raise TypeError(f"material: expected 'matte', 'glossy' or a dict, got {type(m).__name__}")


def _paint_args(n: int, scalars, color, colormap, range):
    s = None
    if scalars is not None:
        s = np.ascontiguousarray(_array_allow_nan("scalars", scalars, n), dtype=np.float32)
    c = None if color is None else _vector("color", color)
    r = None if range is None else _vector("range", range, 2)
    return s, c, _choice("colormap", colormap, _COLORMAPS), r


def _array_allow_nan(name: str, value, n: int) -> np.ndarray:
    """One number per item (NaN allowed: it maps to the colour map's NaN
    colour)."""
    a = np.asarray(value)
    if a.dtype.kind not in "fiu":
        raise TypeError(f"{name}: expected numbers, got dtype {a.dtype}")
    if a.shape != (n,):
        raise ValueError(f"{name}: expected shape ({n},), one per point, got {a.shape}")
    return a


class Scene:
    """Surfaces to ray trace: triangle meshes coloured by a per-point
    scalar, sphere glyphs and tubes along polylines.

    Colouring: ``color`` (linear RGB, each 0–1) paints an object one
    colour; otherwise its ``scalars`` go through ``colormap``
    (``cool_to_warm``, ``viridis``, ``grayscale``) over ``range`` (default:
    the scalars' own finite extent; give the same range to every rank or
    piece). ``material`` is ``"matte"``, ``"glossy"`` or a dict of
    ``diffuse``, ``specular``, ``shininess``, ``opacity``, ``mirror``.
    """

    def __init__(self):
        self._s = _rtvis._Scene()

    def add_mesh(self, points, triangles, scalars=None, color=None, colormap: str = "cool_to_warm",
                 range=None, material="glossy", smooth: bool = True, normals=None) -> "Scene":
        """Adds a triangle mesh: ``points`` (n, 3), ``triangles`` (m, 3)
        integer indices into the points, ``scalars`` (n,) per point.
        Shading normals: ``normals`` (n, 3) per point if given (e.g. a
        contour's gradient normals), else with ``smooth`` the face normals
        averaged around each point, else each triangle flat."""
        p = _array("points", points, 2, np.float32, last=3)
        t = _array("triangles", triangles, 2, None, last=3, integer=True)
        s, c, cm, r = _paint_args(len(p), scalars, color, colormap, range)
        nrm = None
        if normals is not None:
            nrm = _array("normals", normals, 2, np.float32, last=3)
            if len(nrm) != len(p):
                raise ValueError(f"normals: expected one per point ({len(p)}), got {len(nrm)}")
        self._s.add_mesh(p, t, s, c, cm, r, _material(material), bool(smooth), nrm)
        return self

    def add_spheres(self, centers, radii, scalars=None, color=None, colormap: str = "cool_to_warm",
                    range=None, material="glossy") -> "Scene":
        """Adds sphere glyphs: ``centers`` (n, 3), ``radii`` one number or
        (n,), ``scalars`` (n,)."""
        p = _array("centers", centers, 2, np.float32, last=3)
        r = np.asarray(radii, dtype=np.float32) if np.ndim(radii) else np.full(len(p), _number("radii", radii, positive=True), dtype=np.float32)
        r = _array("radii", r, 1, np.float32)
        s, c, cm, rg = _paint_args(len(p), scalars, color, colormap, range)
        self._s.add_spheres(p, r, s, c, cm, rg, _material(material))
        return self

    def add_tubes(self, polyline, radius: float, scalars=None, color=None, colormap: str = "cool_to_warm",
                  range=None, material="glossy") -> "Scene":
        """Adds a tube of ``radius`` along ``polyline`` ((n, 3) points,
        n ≥ 2), or one tube per polyline given a list of them (then
        ``scalars`` is a list too); ``scalars`` (n,) per point."""
        if isinstance(polyline, (list, tuple)) and polyline and np.ndim(polyline[0]) == 2:
            if scalars is not None and len(scalars) != len(polyline):
                raise ValueError(f"scalars: expected one array per polyline ({len(polyline)}), got {len(scalars)}")
            for i, line in enumerate(polyline):
                self.add_tubes(line, radius, None if scalars is None else scalars[i], color, colormap, range, material)
            return self
        p = _array("polyline", polyline, 2, np.float32, last=3)
        s, c, cm, r = _paint_args(len(p), scalars, color, colormap, range)
        self._s.add_tube(p, _number("radius", radius, positive=True), s, c, cm, r, _material(material))
        return self

    def __len__(self) -> int:
        return len(self._s)

    def bounds(self):
        """``((xmin, ymin, zmin), (xmax, ymax, zmax))`` over every object
        (spheres and tubes with their radii), or ``None`` when empty."""
        b = self._s.bounds()
        return None if b is None else (tuple(b[0]), tuple(b[1]))

    def render(self, camera: Optional[Camera] = None, size: Union[int, Tuple[int, int]] = 512,
               ao: int = 0, ao_distance: Optional[float] = None, shadows: bool = True,
               passes: int = 1, seed: int = 0, lights=None):
        """Ray traces the scene.

        Parameters
        ----------
        camera : Camera, optional
            Default: :meth:`Camera.fit` to the scene's bounds, from +z.
        size : int or (width, height)
            Pixels.
        ao : int
            Ambient-occlusion rays per hit (0: off).
        ao_distance : float, optional
            Longest AO ray; default 10 % of the scene's diagonal.
        shadows : bool
            Hard shadows from directional and point lights.
        passes : int
            Progressive passes (jittered pixel positions, fresh AO
            directions), averaged.
        seed : int
            Seed of every random choice; the same seed, the same image at
            any thread count.
        lights : list, optional
            ``("ambient", rgb)``, ``("directional", toward_light, rgb)``,
            ``("point", position, rgb)``; default :data:`DEFAULT_LIGHTS`.

        Returns
        -------
        rgba : ndarray, float32, (h, w, 4)
            Linear premultiplied colour; alpha 0 where nothing was hit.
        depth : ndarray, float32, (h, w)
            Distance along each camera ray to the first hit, ``inf`` where
            nothing was hit (ready for :func:`composite`).
        """
        w, h = (size, size) if np.ndim(size) == 0 else tuple(size)
        w = _integer("size[0]", w, 1, 16384)
        h = _integer("size[1]", h, 1, 16384)
        b = self.bounds()
        if camera is None:
            if b is None:
                raise ValueError("the scene is empty: add an object or give a camera")
            camera = Camera.fit(b, aspect=w / h)
        if not isinstance(camera, Camera):
            raise TypeError(f"camera: expected an rtvis.Camera, got {type(camera).__name__}")
        if ao_distance is None:
            diag = 0.0 if b is None else float(np.linalg.norm(np.subtract(b[1], b[0])))
            ao_distance = max(0.1 * diag, 1e-6)
        native_lights = []
        for i, light in enumerate(DEFAULT_LIGHTS if lights is None else lights):
            if not isinstance(light, (list, tuple)) or not light:
                raise TypeError(f"lights[{i}]: expected a tuple like ('ambient', rgb)")
            kind = _choice(f"lights[{i}][0]", light[0], ("ambient", "directional", "point"))
            if kind == "ambient":
                if len(light) != 2:
                    raise ValueError(f"lights[{i}]: expected ('ambient', rgb)")
                native_lights.append((kind, (0.0, 0.0, 0.0), _vector(f"lights[{i}] rgb", light[1])))
            else:
                if len(light) != 3:
                    raise ValueError(f"lights[{i}]: expected ({kind!r}, vector, rgb)")
                native_lights.append((kind, _vector(f"lights[{i}] vector", light[1]),
                                      _vector(f"lights[{i}] rgb", light[2])))
        return self._s.render(
            camera.eye, camera.target, camera.up, camera.fov, camera.ortho_height, w, h,
            native_lights, bool(shadows), _integer("ao", ao, 0, 4096),
            _number("ao_distance", ao_distance, positive=True),
            _integer("passes", passes, 1, 65536), _integer("seed", seed, 0, 2**64 - 1),
        )


def _image_pair(i, rgba, depth):
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


def composite(rgba_list, depth_list):
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


class _Mpi4pyComm:
    """The transport rt-composite's schedule runs over: tagged byte
    messages on an ``mpi4py`` communicator (non-blocking sends, probed
    receives with a timeout)."""

    def __init__(self, comm, timeout: float):
        from mpi4py import MPI

        self._mpi = MPI
        self._comm = comm
        self._timeout = timeout
        self._pending = []

    def rank(self) -> int:
        return self._comm.Get_rank()

    def size(self) -> int:
        return self._comm.Get_size()

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
_ABANDONED_SENDS: list = []


def composite_mpi(rgba, depth, comm=None, schedule: str = "binary-swap", radix: int = 4,
                  timeout: float = 60.0):
    """Depth-composites this rank's image with every other rank's of the
    ``mpi4py`` communicator ``comm`` (default ``MPI.COMM_WORLD``), with
    rt-composite's ``schedule`` (``binary-swap``, ``radix-k`` with
    ``radix``, or ``direct-send``). Call it on every rank with images of
    one size. Rank 0 gets ``(rgba, depth)``, the others ``None``; the
    result equals :func:`composite` of all ranks' images in rank order,
    bit for bit. A rank that fails or stays silent for ``timeout`` seconds
    makes every rank raise ``ValueError`` instead of hanging.
    """
    try:
        from mpi4py import MPI
    except ImportError as e:
        raise ImportError("composite_mpi needs mpi4py (pip install mpi4py, or Debian's python3-mpi4py)") from e
    if comm is None:
        comm = MPI.COMM_WORLD
    if not isinstance(comm, MPI.Comm):
        raise TypeError(f"comm: expected an mpi4py communicator, got {type(comm).__name__}")
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


def to_srgb8(rgba, background=(1.0, 1.0, 1.0)) -> np.ndarray:
    """Premultiplied linear RGBA (h, w, 4) over a linear ``background``
    colour, as 8-bit sRGB (h, w, 3) ``uint8``: ready for any image
    writer."""
    c = _array("rgba", rgba, 3, np.float32, last=4)
    bg = np.asarray(_vector("background", background), dtype=np.float32)
    return _srgb8(c[..., :3] + (1.0 - c[..., 3:4]) * bg)


def _srgb8(linear: np.ndarray) -> np.ndarray:
    lin = np.clip(linear, 0.0, 1.0)
    srgb = np.where(lin <= 0.0031308, 12.92 * lin, 1.055 * np.power(lin, 1 / 2.4) - 0.055)
    return np.round(srgb * 255.0).astype(np.uint8)


def to_gray8(image, white: float = 2.0) -> np.ndarray:
    """An optics image (intensity, 1 = background) as 8-bit sRGB grey
    ``uint8`` (h, w): ``white`` maps to 255, 0 to 0, linearly in light
    (so the background of a normalised image, 1 of 2, is mid grey)."""
    a = _array("image", image, 2, np.float64)
    return _srgb8(a / _number("white", white, positive=True))


def save_png(path, image) -> None:
    """Writes an 8-bit image, ``uint8`` (h, w) grey, (h, w, 3) RGB or
    (h, w, 4) RGBA, as a PNG (no other package needed). Convert first:
    :func:`to_srgb8` for surfaces, :func:`to_gray8` for optics images,
    ``to_gray8``/``np.clip(... * 255)`` for your own.

    As ``rt`` does with ``--out``: a missing folder is created (and said
    on stderr), a path that is a folder raises ``IsADirectoryError``
    before anything is encoded, and the file appears whole or not at all
    (written beside it, then moved into place)."""
    import os
    import sys

    path = os.fspath(path)
    if os.path.isdir(path):
        raise IsADirectoryError(f"{path}: is a folder; give a file name (e.g. {os.path.join(path, 'image.png')})")
    folder = os.path.dirname(path)
    if folder and not os.path.isdir(folder):
        os.makedirs(folder)
        print(f"rtvis: created folder {folder}", file=sys.stderr)
    a = np.asarray(image)
    if a.dtype != np.uint8:
        raise TypeError(f"image: expected uint8 (convert with to_srgb8 or to_gray8), got dtype {a.dtype}")
    if a.ndim == 2:
        a = a[:, :, None]
    if a.ndim != 3 or a.shape[2] not in (1, 3, 4) or a.shape[0] == 0 or a.shape[1] == 0:
        raise ValueError(f"image: expected shape (h, w), (h, w, 3) or (h, w, 4), got {np.shape(image)}")
    h, w, c = a.shape
    color = {1: 0, 3: 2, 4: 6}[c]
    rows = np.concatenate([np.zeros((h, 1), dtype=np.uint8), np.ascontiguousarray(a).reshape(h, w * c)], axis=1)

    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)

    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, color, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(rows.tobytes(), 6)) + chunk(b"IEND", b""))
    staging = os.path.join(folder, f".{os.path.basename(path)}.rt-partial")
    try:
        with open(staging, "wb") as f:
            f.write(png)
        os.replace(staging, path)
    finally:
        if os.path.exists(staging):
            os.remove(staging)
