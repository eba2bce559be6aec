"""What the optics look through: ``Volume`` (a gridded array, or
``read_volume``'s file) and ``Mesh`` (an unstructured CFD mesh, or
``read_mesh``'s file)."""

from __future__ import annotations

import importlib
import os
from typing import Any, Dict, Optional, Sequence, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _rtvis
from ._checks import _array, _choice, _number, _vector


#: Gladstone–Dale constant of air at 589 nm, m³/kg (``n = 1 + K·ρ``).
GLADSTONE_DALE_AIR: float = _rtvis.GLADSTONE_DALE_AIR

_QUANTITIES = ("density", "index")
_INTERPOLATIONS = ("linear", "cubic")
_ORDERS = ("zyx", "xyz")
_NANS = ("error", "ambient")
# The image's (u, v) world axes for each beam axis: u to the right, v up.
_IMAGE_AXES = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}

#: ``((xmin, ymin, zmin), (xmax, ymax, zmax))``.
_Bounds = Tuple[Tuple[float, float, float], Tuple[float, float, float]]


def _xyz(v: Sequence[float]) -> Tuple[float, float, float]:
    """A native ``[x, y, z]`` list as a tuple."""
    return (v[0], v[1], v[2])


def _extent(bounds: _Bounds, axis: str) -> Tuple[float, float, float, float]:
    u, v = _IMAGE_AXES[_choice("axis", axis, tuple(_IMAGE_AXES))]
    lo, hi = bounds
    return (lo[u], hi[u], lo[v], hi[v])


def _far_field(values: NDArray[Any]) -> float:
    """The median of the finite samples on the volume's six faces: the
    undisturbed medium around a flow."""
    faces = [values[0], values[-1], values[:, 0], values[:, -1], values[:, :, 0], values[:, :, -1]]
    edge = np.concatenate([f.ravel() for f in faces])
    edge = edge[np.isfinite(edge)]
    if edge.size == 0:
        raise ValueError("values: no finite sample on the volume's faces to take as the ambient medium "
                         "(nan=\"ambient\" needs one)")
    return float(np.median(edge))


class Volume:
    """A gridded volume of density or refractive index, ready for the
    optical bench.

    Parameters
    ----------
    values : ndarray, shape (nz, ny, nx) (or (nx, ny, nz), see ``order``)
        Samples, float32 or float64: ``values[k, j, i]`` at ``origin +
        (i·dx, j·dy, k·dz)`` (x varies fastest, as VTK and NRRD store
        it). Any strides; copied. Stored as float32.
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
    order : "zyx" or "xyz"
        How ``values`` is indexed: ``"zyx"`` (the default), ``values[k, j,
        i]`` as above; ``"xyz"``, ``values[i, j, k]``, as yt's arrays and
        Fortran codes index them. Nothing else changes: ``shape`` and
        :meth:`index` stay ``[z, y, x]``.
    nan : "error" or "ambient"
        What a NaN sample is (blanked cells, a solid body, no data):
        ``"error"`` (the default) refuses it; ``"ambient"`` makes it the
        undisturbed medium, the median of the finite samples on the
        volume's six faces. Infinities are always refused.

    The index outside the volume is that of sample ``[0, 0, 0]``.
    """

    def __init__(
        self,
        values: ArrayLike,
        spacing: ArrayLike = (1.0, 1.0, 1.0),
        origin: ArrayLike = (0.0, 0.0, 0.0),
        quantity: str = "density",
        k: float = GLADSTONE_DALE_AIR,
        interpolation: str = "cubic",
        allow_nonphysical: bool = False,
        order: str = "zyx",
        nan: str = "error",
    ) -> None:
        xyz = _choice("order", order, _ORDERS) == "xyz"
        ambient = _choice("nan", nan, _NANS) == "ambient"
        # Checked in the caller's order (a bad sample is named by its own
        # indices), then laid out x fastest.
        arr = _array("values", values, 3, np.float32, nan=ambient)
        if ambient:
            holes = np.isnan(arr)
            if holes.any():
                arr = np.where(holes, np.float32(_far_field(arr)), arr)
        if xyz:
            arr = np.ascontiguousarray(arr.transpose(2, 1, 0))
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
    def from_vtk(cls, image: Any, array: Optional[str] = None, **options: Any) -> "Volume":
        """A volume from a VTK image (``vtkImageData``: what ParaView's
        readers and ``vtkXMLImageDataReader`` give; a PyVista
        ``ImageData`` is one too): its dimensions, spacing and origin, and
        the point-data array ``array`` (default: the active scalars, else
        the only array), or, failing that, a cell-data array sampled at
        the cell centres. ``options`` as for :class:`Volume` (``quantity``,
        ``nan``, …). An image with a rotated direction matrix is refused."""
        for method in ("GetDimensions", "GetSpacing", "GetOrigin", "GetPointData", "GetCellData"):
            if not callable(getattr(image, method, None)):
                raise TypeError(f"image: expected a vtkImageData (or pyvista.ImageData), got {type(image).__name__}")
        try:  # VTK's own modules, untyped: Any
            numpy_support: Any = importlib.import_module("vtkmodules.util.numpy_support")
        except ImportError:  # VTK before 8.2
            numpy_support = importlib.import_module("vtk.util.numpy_support")
        matrix = getattr(image, "GetDirectionMatrix", None)
        if matrix is not None and not matrix().IsIdentity():
            raise ValueError("image: its direction matrix is not the identity (a rotated image is not supported)")
        dims = tuple(int(d) for d in image.GetDimensions())
        spacing = tuple(float(h) for h in image.GetSpacing())
        origin = tuple(float(o) for o in image.GetOrigin())
        found = None
        for where, data in (("point", image.GetPointData()), ("cell", image.GetCellData())):
            names = [data.GetArrayName(i) for i in range(data.GetNumberOfArrays())]
            if array is not None:
                if array in names:
                    found = (where, data.GetArray(array))
            elif data.GetScalars() is not None:
                found = (where, data.GetScalars())
            elif len(names) == 1:
                found = (where, data.GetArray(0))
            if found is not None:
                break
        if found is None:
            points = [image.GetPointData().GetArrayName(i) for i in range(image.GetPointData().GetNumberOfArrays())]
            cells = [image.GetCellData().GetArrayName(i) for i in range(image.GetCellData().GetNumberOfArrays())]
            want = f"no array {array!r}" if array is not None else "no active scalars and not exactly one array"
            raise ValueError(f"image: {want} (point data: {points or 'none'}; cell data: {cells or 'none'})")
        where, vtk_array = found
        if vtk_array.GetNumberOfComponents() != 1:
            raise ValueError(f"image: array {vtk_array.GetName()!r} has {vtk_array.GetNumberOfComponents()} components, "
                             "not 1")
        if where == "cell":
            dims = tuple(max(d - 1, 1) for d in dims)
            origin = tuple(o + 0.5 * h for o, h in zip(origin, spacing))
        values = numpy_support.vtk_to_numpy(vtk_array).reshape(dims[::-1])
        return cls(values, spacing=spacing, origin=origin, **options)

    @classmethod
    def from_pyvista(cls, grid: Any, array: Optional[str] = None, **options: Any) -> "Volume":
        """A volume from a PyVista ``ImageData`` (``UniformGrid`` before
        PyVista 0.43), as :meth:`from_vtk`."""
        if type(grid).__module__.split(".")[0] != "pyvista":
            raise TypeError(f"grid: expected a pyvista.ImageData, got {type(grid).__name__}")
        return cls.from_vtk(grid, array, **options)

    @classmethod
    def _wrap(cls, native: _rtvis._Volume) -> "Volume":
        v = cls.__new__(cls)
        v._v = native
        return v

    @property
    def shape(self) -> Tuple[int, int, int]:
        """Samples per axis, ``(nz, ny, nx)``."""
        return self._v.shape

    @property
    def spacing(self) -> Tuple[float, float, float]:
        """Sample spacing ``(dx, dy, dz)``."""
        return _xyz(self._v.spacing)

    @property
    def origin(self) -> Tuple[float, float, float]:
        """Centre of sample ``[0, 0, 0]``, ``(x, y, z)``."""
        return _xyz(self._v.origin)

    @property
    def bounds(self) -> _Bounds:
        """``((xmin, ymin, zmin), (xmax, ymax, zmax))``: the box the
        samples span."""
        lo, hi = self._v.bounds
        return _xyz(lo), _xyz(hi)

    def index(self) -> NDArray[np.float32]:
        """The refractive index samples, float32 ``[z, y, x]``."""
        return self._v.index()

    def extent(self, axis: str = "z") -> Tuple[float, float, float, float]:
        """``(left, right, bottom, top)`` of the schlieren, shadowgraph,
        interferogram and colour schlieren images along ``axis`` (they
        span the volume's cross-section), in the volume's unit: for
        ``matplotlib``'s ``imshow(image, extent=vol.extent(axis))`` (row 0
        at the top, imshow's default). Image axes: x right and y up along
        z; y and z along x; z and x along y."""
        return _extent(self.bounds, axis)

    def __repr__(self) -> str:
        return f"rtvis.Volume(shape={self.shape}, spacing={self.spacing}, origin={self.origin})"


def read_volume(
    path: Union[str, os.PathLike[str]],
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

    def __init__(self, points: ArrayLike, cells: Dict[str, Any], values: ArrayLike, quantity: str = "density",
                 k: float = GLADSTONE_DALE_AIR, trace: str = "smooth",
                 allow_nonphysical: bool = False) -> None:
        pts = _array("points", points, 2, np.float64, last=3)
        vals = _array("values", values, 1, np.float64)
        if not isinstance(cells, dict):
            raise TypeError(f"cells: expected a dict of kind → array, got {type(cells).__name__}")
        by_kind: Dict[str, NDArray[np.int64]] = {}
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
    def _wrap(cls, native: _rtvis._Volume) -> "Mesh":
        m = cls.__new__(cls)
        m._v = native
        return m

    @property
    def bounds(self) -> _Bounds:
        """``((xmin, ymin, zmin), (xmax, ymax, zmax))``: the box around the
        points."""
        lo, hi = self._v.bounds
        return _xyz(lo), _xyz(hi)

    @property
    def counts(self) -> Tuple[int, int, int, int]:
        """``(points, cells, tetrahedra, boundary faces)``."""
        return self._v.mesh_counts

    def extent(self, axis: str = "z") -> Tuple[float, float, float, float]:
        """``(left, right, bottom, top)`` of the images along ``axis``, as
        :meth:`Volume.extent` (the images span the points' box)."""
        return _extent(self.bounds, axis)

    def __repr__(self) -> str:
        p, c, t, _ = self.counts
        return f"rtvis.Mesh(points={p}, cells={c}, tetrahedra={t})"


def read_mesh(
    path: Union[str, os.PathLike[str]],
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
