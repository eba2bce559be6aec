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
- Rays at meshes: ``RayMesh`` (first hit, any hit, every crossing of
  batches of rays; trimesh's ``mesh.ray`` names), watertight.
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

# What the single-file package imported at top level, kept so that every
# attribute of ``rtvis`` it had still resolves.
import math  # noqa: F401
import os  # noqa: F401
import struct  # noqa: F401
import time  # noqa: F401
import zlib  # noqa: F401
from typing import Optional, Sequence, Tuple, Union  # noqa: F401

import numpy as np  # noqa: F401

# The package's names, each from the module that defines it; the private
# ones too (the tests call ``rtvis._bench`` and ``rtvis._rtvis``), so that
# every name ``rtvis`` had before the split is still one of its attributes.
from . import _rtvis
from ._checks import RtvisWarning, _array, _choice, _integer, _number, _vector
from ._volume import (
    _INTERPOLATIONS,
    _MESH_KINDS,
    _QUANTITIES,
    _SURFACE_KINDS,
    _TRACES,
    GLADSTONE_DALE_AIR,
    Mesh,
    Volume,
    read_mesh,
    read_volume,
)
from ._optics import (
    _bench,
    _dtype,
    _grey,
    color_schlieren,
    interferogram,
    record,
    schlieren,
    shadowgraph,
)
from ._bos import bos
from ._focusing import focusing
from ._surface import (
    _COLORMAPS,
    _MATERIALS,
    DEFAULT_LIGHTS,
    Camera,
    Scene,
    _array_allow_nan,
    _material,
    _paint_args,
)
from ._rays import RayHits, RayMesh
from ._bricks import bos_pieces, brick_box, focusing_pieces, schlieren_pieces
from ._composite import _ABANDONED_SENDS, _image_pair, _Mpi4pyComm, composite, composite_mpi
from ._image import _srgb8, save_png, to_gray8, to_srgb8
from ._watch import Optics, ProgressCallback

__all__ = [
    "GLADSTONE_DALE_AIR",
    "bos",
    "bos_pieces",
    "brick_box",
    "Camera",
    "Mesh",
    "Optics",
    "ProgressCallback",
    "RayHits",
    "RayMesh",
    "RtvisWarning",
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
    "focusing_pieces",
    "schlieren_pieces",
    "save_png",
    "shadowgraph",
    "to_gray8",
    "to_srgb8",
    "DEFAULT_LIGHTS",
]

__version__ = "0.1.0"
