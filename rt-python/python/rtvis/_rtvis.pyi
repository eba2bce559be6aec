# Type stub of the native half, `rtvis._rtvis` (rt-python/src). The
# public API is the Python half's; these are its exactly typed calls.
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np
from numpy.typing import NDArray

GLADSTONE_DALE_AIR: float

_Progress = Optional[Callable[[int, int], Any]]
_Vec3 = Sequence[float]

class _Volume:
    def __init__(self, values: NDArray[np.float32], spacing: _Vec3, origin: _Vec3, quantity: str, k: float,
                 interpolation: str, allow_nonphysical: bool) -> None: ...
    @staticmethod
    def mesh(points: NDArray[np.float64], tetra: NDArray[np.int64], pyramid: NDArray[np.int64],
             wedge: NDArray[np.int64], hexahedron: NDArray[np.int64], values: NDArray[np.float64], quantity: str,
             k: float, trace: str, allow_nonphysical: bool) -> _Volume: ...
    @property
    def shape(self) -> Tuple[int, int, int]: ...
    @property
    def spacing(self) -> List[float]: ...
    @property
    def origin(self) -> List[float]: ...
    @property
    def bounds(self) -> Tuple[List[float], List[float]]: ...
    @property
    def mesh_counts(self) -> Tuple[int, int, int, int]: ...
    def index(self) -> NDArray[np.float32]: ...

def _read_volume(path: Any, quantity: str, k: float, interpolation: str, allow_nonphysical: bool) -> _Volume: ...
def _read_mesh(path: Any, array: Optional[str], quantity: str, k: float, trace: str,
               allow_nonphysical: bool) -> _Volume: ...
def _optics(volume: _Volume, cutoff_name: str, angle: float, f: float, h: Optional[float], radius: Optional[float],
            half_range: Optional[float], wavelength: float, fringe_spacing: Optional[float],
            film_distance: Optional[float], axis_name: str, size: int, photons: int, seed: int, estimator_name: str,
            output: Tuple[bool, bool, bool, bool, bool], progress: _Progress = None
            ) -> Tuple[NDArray[Any], Optional[NDArray[np.float32]], Optional[NDArray[np.float64]], Dict[str, Any],
                       str, Optional[str]]: ...
def _record(image: NDArray[np.float64], exposure: float, full_well: float, bits: int, shot_noise: bool,
            read_noise: float, seed: int, airy: Optional[Tuple[float, float, float]] = None) -> NDArray[np.uint16]: ...
def _bos(volume: _Volume, axis_name: str, size: int, focal_length: Optional[float], f_number: float,
         pixel: Optional[float], distance: Optional[float], background_distance: Optional[float], dot: float,
         spacing: float, samples: int, seed: int, background: str, image: Optional[NDArray[np.float64]] = None,
         image_pixel: Optional[float] = None, progress: _Progress = None
         ) -> Tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], str, Dict[str, float]]: ...
def _focusing(volume: _Volume, axis_name: str, size: int, focal_length: Optional[float], aperture: Optional[float],
              pixel: Optional[float], distance: Optional[float], focus: float, source_distance: Optional[float],
              pitch: Optional[float], duty: float, angle: float, offset: float, bands: Optional[int], samples: int,
              seed: int, progress: _Progress = None
              ) -> Tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], str, Dict[str, float]]: ...

class _Scene:
    def __init__(self) -> None: ...
    def add_mesh(self, points: NDArray[np.float32], triangles: NDArray[np.int64],
                 scalars: Optional[NDArray[np.float32]], color: Optional[_Vec3], colormap: Any,
                 range: Optional[Tuple[float, float]], material: Sequence[float], smooth: bool,
                 normals: Optional[NDArray[np.float32]]) -> None: ...
    def add_spheres(self, centers: NDArray[np.float32], radii: NDArray[np.float32],
                    scalars: Optional[NDArray[np.float32]], color: Optional[_Vec3], colormap: Any,
                    range: Optional[Tuple[float, float]], material: Sequence[float]) -> None: ...
    def add_tube(self, polyline: NDArray[np.float32], radius: float, scalars: Optional[NDArray[np.float32]],
                 color: Optional[_Vec3], colormap: Any, range: Optional[Tuple[float, float]],
                 material: Sequence[float]) -> None: ...
    def __len__(self) -> int: ...
    def bounds(self) -> Optional[Tuple[List[float], List[float]]]: ...
    def render(self, eye: _Vec3, target: _Vec3, up: _Vec3, fov: float, ortho_height: Optional[float], width: int,
               height: int, lights: Sequence[Tuple[str, _Vec3, _Vec3]], shadows: bool, ao: int, ao_distance: float,
               passes: int, seed: int, progress: _Progress = None
               ) -> Tuple[NDArray[np.float32], NDArray[np.float32]]: ...

def _composite(rgba: Sequence[NDArray[np.float32]], depth: Sequence[NDArray[np.float32]]
               ) -> Tuple[NDArray[np.float32], NDArray[np.float32]]: ...
def _composite_comm(rgba: NDArray[np.float32], depth: NDArray[np.float32], comm: Any, schedule: str,
                    radix: int) -> Optional[Tuple[NDArray[np.float32], NDArray[np.float32]]]: ...
def _brick_box(dims: Sequence[int], spacing: _Vec3, origin: _Vec3, interpolation: str, ranks: int,
               rank: int) -> Tuple[List[int], List[int]]: ...
def _schlieren_piece(piece: NDArray[np.float32], lo: Sequence[int], dims: Sequence[int], spacing: _Vec3,
                     origin: _Vec3, first: float, quantity: str, k: float, interpolation: str, optics: str,
                     wavelength: float, fringe_spacing: Optional[float], size: int, strata: int, seed: int,
                     comm: Any, progress: _Progress = None) -> Optional[NDArray[np.float64]]: ...
def _bos_piece(piece: NDArray[np.float32], lo: Sequence[int], dims: Sequence[int], spacing: _Vec3, origin: _Vec3,
               first: float, quantity: str, k: float, interpolation: str, axis_name: str, size: int,
               focal_length: Optional[float], f_number: float, pixel: Optional[float], distance: Optional[float],
               background_distance: Optional[float], dot: float, spacing_dots: float, samples: int, seed: int,
               background: str, image: Optional[NDArray[np.float64]], image_pixel: Optional[float], comm: Any,
               progress: _Progress = None) -> Optional[Tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], str, Dict[str, float]]]: ...
def _focusing_piece(piece: NDArray[np.float32], lo: Sequence[int], dims: Sequence[int], spacing: _Vec3,
                    origin: _Vec3, first: float, quantity: str, k: float, interpolation: str,
                    axis_name: str, size: int, focal_length: Optional[float], aperture: Optional[float],
                    pixel: Optional[float], distance: Optional[float], focus: float,
                    source_distance: Optional[float], pitch: Optional[float], duty: float, angle: float,
                    offset: float, bands: Optional[int], samples: int, seed: int, comm: Any,
                    progress: _Progress = None) -> Optional[Tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], str, Dict[str, float]]]: ...
