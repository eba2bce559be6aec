"""8-bit images: ``to_srgb8`` (surfaces), ``to_gray8`` (optics images) and
``save_png``."""

from __future__ import annotations

import os
import struct
import sys
import zlib
from typing import Any, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._checks import _array, _number, _vector


def to_srgb8(rgba: ArrayLike, background: ArrayLike = (1.0, 1.0, 1.0)) -> NDArray[np.uint8]:
    """Premultiplied linear RGBA (h, w, 4) over a linear ``background``
    colour, as 8-bit sRGB (h, w, 3) ``uint8``: ready for any image
    writer."""
    c = _array("rgba", rgba, 3, np.float32, last=4)
    bg = np.asarray(_vector("background", background), dtype=np.float32)
    return _srgb8(c[..., :3] + (1.0 - c[..., 3:4]) * bg)


def _srgb8(linear: NDArray[Any]) -> NDArray[np.uint8]:
    lin = np.clip(linear, 0.0, 1.0)
    srgb: NDArray[Any] = np.where(lin <= 0.0031308, 12.92 * lin, 1.055 * np.power(lin, 1 / 2.4) - 0.055)
    return np.round(srgb * 255.0).astype(np.uint8)


def to_gray8(image: ArrayLike, white: float = 2.0) -> NDArray[np.uint8]:
    """An optics image (intensity, 1 = background) as 8-bit sRGB grey
    ``uint8`` (h, w): ``white`` maps to 255, 0 to 0, linearly in light
    (so the background of a normalised image, 1 of 2, is mid grey)."""
    a = _array("image", image, 2, np.float64)
    return _srgb8(a / _number("white", white, positive=True))


def save_png(path: Union[str, os.PathLike[str]], image: ArrayLike) -> None:
    """Writes an 8-bit image, ``uint8`` (h, w) grey, (h, w, 3) RGB or
    (h, w, 4) RGBA, as a PNG (no other package needed). Convert first:
    :func:`to_srgb8` for surfaces, :func:`to_gray8` for optics images,
    ``to_gray8``/``np.clip(... * 255)`` for your own.

    As ``rt`` does with ``--out``: a missing folder is created (and said
    on stderr), a path that is a folder raises ``IsADirectoryError``
    before anything is encoded, and the file appears whole or not at all
    (written beside it, then moved into place)."""
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
