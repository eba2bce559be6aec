"""Surface rendering: ``Camera``, and ``Scene`` (triangle meshes, sphere
glyphs, tubes) rendered into premultiplied RGBA and depth."""

from __future__ import annotations

import math
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _rtvis
from ._checks import _array, _choice, _integer, _number, _vector
from ._volume import _Bounds, _xyz
from ._watch import ProgressCallback, _progress

#: A material: ``"matte"``, ``"glossy"`` or a dict of its fields.
_Material = Union[str, Dict[str, float]]
#: A light: ``("ambient", rgb)``, ``("directional", toward_light, rgb)`` or
#: ``("point", position, rgb)``.
_Light = Union[Tuple[str, ArrayLike], Tuple[str, ArrayLike, ArrayLike]]


class Camera:
    """A pinhole camera at ``eye`` looking at ``target``; ``up`` fixes the
    roll; ``fov`` is the vertical field of view in degrees. With
    ``ortho_height`` the projection is orthographic, that many scene
    units tall."""

    def __init__(self, eye: ArrayLike, target: ArrayLike, up: ArrayLike = (0.0, 1.0, 0.0), fov: float = 30.0,
                 ortho_height: Optional[float] = None) -> None:
        self.eye = _vector("eye", eye)
        self.target = _vector("target", target)
        self.up = _vector("up", up)
        self.fov = _number("fov", fov, positive=True)
        if not self.fov < 180.0:
            raise ValueError(f"fov must be below 180 degrees (got {self.fov})")
        self.ortho_height = _number("ortho_height", ortho_height, positive=True, optional=True)

    @classmethod
    def fit(cls, bounds: Sequence[ArrayLike], direction: ArrayLike = (0.0, 0.0, 1.0),
            up: ArrayLike = (0.0, 1.0, 0.0), fov: float = 30.0, aspect: float = 1.0) -> "Camera":
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
DEFAULT_LIGHTS: List[_Light] = [("ambient", (0.25, 0.25, 0.25)),
                                ("directional", (-0.5, 1.0, 0.35), (0.8, 0.8, 0.8))]


def _material(m: _Material) -> Tuple[float, ...]:
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


Colormap = Union[str, ArrayLike]
"""A colour map: a name (``cool_to_warm``, ``viridis``, ``grayscale``) or
stops, an (n, 4) array of ``(position, r, g, b)``: positions rising from
0 to 1 across the range, colours 0–1 on the sRGB curve (a table's 8-bit
values divided by 255), interpolated linearly between stops."""


def _paint_args(n: int, scalars: Optional[ArrayLike], color: Optional[ArrayLike], colormap: Colormap,
                range: Optional[ArrayLike]
                ) -> Tuple[Optional[NDArray[np.float32]], Optional[Tuple[float, float, float]], Any,
                           Optional[Tuple[float, float]]]:
    s = None
    if scalars is not None:
        s = np.ascontiguousarray(_array_allow_nan("scalars", scalars, n), dtype=np.float32)
    c = None if color is None else _vector("color", color)
    r = None if range is None else _vector("range", range, 2)
    cm: Any = _choice("colormap", colormap, _COLORMAPS) if isinstance(colormap, str) \
        else _array("colormap", colormap, 2, np.float32, last=4)
    return s, c, cm, r


def _array_allow_nan(name: str, value: ArrayLike, n: int) -> NDArray[Any]:
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
    (``cool_to_warm``, ``viridis``, ``grayscale``, or your own stops: see
    :data:`Colormap`) over ``range`` (default:
    the scalars' own finite extent; give the same range to every rank or
    piece). ``material`` is ``"matte"``, ``"glossy"`` or a dict of
    ``diffuse``, ``specular``, ``shininess``, ``opacity``, ``mirror``.
    """

    def __init__(self) -> None:
        self._s = _rtvis._Scene()

    def add_mesh(self, points: ArrayLike, triangles: ArrayLike, scalars: Optional[ArrayLike] = None,
                 color: Optional[ArrayLike] = None, colormap: Colormap = "cool_to_warm", range: Optional[ArrayLike] = None,
                 material: _Material = "glossy", smooth: bool = True, normals: Optional[ArrayLike] = None) -> "Scene":
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

    def add_spheres(self, centers: ArrayLike, radii: ArrayLike, scalars: Optional[ArrayLike] = None,
                    color: Optional[ArrayLike] = None, colormap: Colormap = "cool_to_warm",
                    range: Optional[ArrayLike] = None, material: _Material = "glossy") -> "Scene":
        """Adds sphere glyphs: ``centers`` (n, 3), ``radii`` one number or
        (n,), ``scalars`` (n,)."""
        p = _array("centers", centers, 2, np.float32, last=3)
        r = np.asarray(radii, dtype=np.float32) if np.ndim(radii) else np.full(len(p), _number("radii", radii, positive=True), dtype=np.float32)
        r = _array("radii", r, 1, np.float32)
        s, c, cm, rg = _paint_args(len(p), scalars, color, colormap, range)
        self._s.add_spheres(p, r, s, c, cm, rg, _material(material))
        return self

    def add_tubes(self, polyline: ArrayLike, radius: float, scalars: Optional[ArrayLike] = None,
                  color: Optional[ArrayLike] = None, colormap: Colormap = "cool_to_warm",
                  range: Optional[ArrayLike] = None, material: _Material = "glossy") -> "Scene":
        """Adds a tube of ``radius`` along ``polyline`` ((n, 3) points,
        n ≥ 2), or one tube per polyline given a list of them (then
        ``scalars`` is a list too); ``scalars`` (n,) per point."""
        if isinstance(polyline, (list, tuple)) and polyline and np.ndim(polyline[0]) == 2:
            each: Any = scalars  # a list too, one array per polyline
            if each is not None and len(each) != len(polyline):
                raise ValueError(f"scalars: expected one array per polyline ({len(polyline)}), got {len(each)}")
            for i, line in enumerate(polyline):
                self.add_tubes(line, radius, None if each is None else each[i], color, colormap, range, material)
            return self
        p = _array("polyline", polyline, 2, np.float32, last=3)
        s, c, cm, r = _paint_args(len(p), scalars, color, colormap, range)
        self._s.add_tube(p, _number("radius", radius, positive=True), s, c, cm, r, _material(material))
        return self

    def __len__(self) -> int:
        return len(self._s)

    def bounds(self) -> Optional[_Bounds]:
        """``((xmin, ymin, zmin), (xmax, ymax, zmax))`` over every object
        (spheres and tubes with their radii), or ``None`` when empty."""
        b = self._s.bounds()
        return None if b is None else (_xyz(b[0]), _xyz(b[1]))

    def render(self, camera: Optional[Camera] = None, size: Union[int, Tuple[int, int]] = 512,
               ao: int = 0, ao_distance: Optional[float] = None, shadows: bool = True,
               passes: int = 1, seed: int = 0, lights: Optional[Sequence[_Light]] = None,
               progress: Union[None, bool, ProgressCallback] = None
               ) -> Tuple[NDArray[np.float32], NDArray[np.float32]]:
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
        progress : True or callable, optional
            ``True``: a progress bar on stderr; a callable: called as
            ``progress(done, total)`` (tiles over all passes) on the
            calling thread. Ctrl-C stops the render at the end of the pass
            under way and raises ``KeyboardInterrupt``.

        Returns
        -------
        rgba : ndarray, float32, (h, w, 4)
            Linear premultiplied colour; alpha 0 where nothing was hit.
        depth : ndarray, float32, (h, w)
            Distance along each camera ray to the first hit, ``inf`` where
            nothing was hit (ready for :func:`composite`).

        :func:`to_srgb8` makes the colour display-ready (8-bit sRGB over a
        background). Accumulators too large for memory raise
        ``MemoryError``.
        """
        wh: Any = size  # np.ndim does not narrow the Union
        w, h = (wh, wh) if np.ndim(wh) == 0 else tuple(wh)
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
            _progress(progress, "rtvis.Scene.render"),
        )
