"""Shared by the tests: the Gaussian bump of docs/oracles.md §5, pixel centres,
and a reader for the 16-bit PNGs `rt schlieren --raw16` writes."""

import math
import os
import shutil
import struct
import zlib
from pathlib import Path

import numpy as np

import rtvis

REPO = Path(__file__).resolve().parents[2]


def bump(n=64, spacing=1e-3, sigma=8e-3, delta=1e-4, interpolation="cubic"):
    """`n = 1 + δ·exp(−ρ²/(2σ²))` on an n³ grid centred on the origin."""
    c = 0.5 * (n - 1) * spacing
    z, y, x = np.mgrid[0:n, 0:n, 0:n] * spacing - c
    index = 1.0 + delta * np.exp(-(x**2 + y**2 + z**2) / (2 * sigma**2))
    vol = rtvis.Volume(index, spacing=(spacing,) * 3, origin=(-c,) * 3, quantity="index",
                       interpolation=interpolation)
    return vol, sigma, delta


def pixel_centres(vol, shape):
    """(X, Y) of each pixel centre of an image of `shape` looking along +z
    (row 0 at the top, the volume's x to the right, y up)."""
    (x0, y0, _), (x1, y1, _) = vol.bounds
    h, w = shape
    xs = x0 + (np.arange(w) + 0.5) * (x1 - x0) / w
    ys = y1 - (np.arange(h) + 0.5) * (y1 - y0) / h
    return np.meshgrid(xs, ys)


def bump_deflection(X, Y, sigma, delta):
    """docs/oracles.md §5: `ε = −√(2π)·δ·(r/σ)·g(r)·r̂`, as (εx, εy)."""
    g = np.exp(-(X**2 + Y**2) / (2 * sigma**2))
    k = -math.sqrt(2 * math.pi) * delta / sigma * g
    return k * X, k * Y


def rt_binary():
    """The `rt` command built in this repository (release, then debug),
    or one named by $RT_BIN, or one on PATH; None if there is none."""
    env = os.environ.get("RT_BIN")
    if env:
        return env
    for p in (REPO / "target" / "release" / "rt", REPO / "target" / "debug" / "rt"):
        if p.exists():
            return str(p)
    return shutil.which("rt")


def read_png16(path):
    """A non-interlaced 16-bit grey or RGB PNG as a uint16 array (h, w) or
    (h, w, 3)."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, ihdr = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    w, h, depth, color, _, _, interlace = ihdr
    assert depth == 16 and color in (0, 2) and interlace == 0, ihdr
    channels = 1 if color == 0 else 3
    bpp, stride = 2 * channels, 2 * channels * w
    raw = zlib.decompress(idat)
    out = np.zeros((h, stride), dtype=np.int64)
    prev = np.zeros(stride, dtype=np.int64)
    for row in range(h):
        f = raw[row * (stride + 1)]
        line = np.frombuffer(raw, dtype=np.uint8, count=stride, offset=row * (stride + 1) + 1).astype(np.int64)
        cur = np.zeros(stride, dtype=np.int64)
        for i in range(stride):
            a = cur[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 0:
                pred = 0
            elif f == 1:
                pred = a
            elif f == 2:
                pred = b
            elif f == 3:
                pred = (a + b) // 2
            else:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            cur[i] = (line[i] + pred) & 0xFF
        out[row] = cur
        prev = cur
    px = (out[:, 0::2] << 8) | out[:, 1::2]
    return px.reshape(h, w) if channels == 1 else px.reshape(h, w, 3)
