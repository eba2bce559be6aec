"""BOS checked by an outside tool: rt renders a background-oriented
schlieren pair of a Gaussian density bump, OpenPIV (PyPI ``openpiv``)
processes it as an experimentalist would — window cross-correlation from
the reference image to the flow image — and its vectors are compared with
rt's ground-truth displacement averaged over each interrogation window.

Each case renders the pair through ``rtvis.bos`` or the ``rt bos``
command, with the sensor's noise off or on (shot noise and 5 e⁻ read
noise), and reports: the correlation between OpenPIV's vectors and the
truth (u and v together), the rms difference in pixels, and the vectors'
range. A sign error would give a correlation near −1.

Usage::

    python bos_openpiv.py              # the rtvis cases, a table on stdout
    python bos_openpiv.py --rt PATH    # and the `rt bos` cases
    python bos_openpiv.py --json OUT   # the numbers as JSON too

Needs ``numpy``, ``openpiv`` and ``imageio`` (which openpiv installs).
"""

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
from numpy.typing import NDArray

import rtvis

#: The image: 512 px wide, OpenPIV's windows of 32 px, half overlapping.
SIZE, WINDOW, OVERLAP = 512, 32, 16


def density_bump(n: int = 64, width: float = 0.2, amplitude: float = 3.0,
                 sigma_cells: float = 8.0) -> Tuple[NDArray[np.float64], float, float]:
    """Air at 1.2 kg/m³ with a Gaussian bump of ``amplitude`` (relative),
    σ = ``sigma_cells`` cells, on an n³ grid ``width`` metres across,
    indexed ``[z, y, x]``."""
    h = width / n
    c = 0.5 * (n - 1) * h
    z, y, x = np.mgrid[0:n, 0:n, 0:n] * h - c
    sigma = sigma_cells * h
    rho = 1.2 * (1.0 + amplitude * np.exp(-(x**2 + y**2 + z**2) / (2 * sigma**2)))
    return rho, h, -c


def openpiv_convention() -> Tuple[float, float]:
    """OpenPIV's (u, v) for a pattern moved 2 px right and 1 px down:
    checked, not assumed, so a change in its convention shows here."""
    from openpiv import pyprocess  # type: ignore[import-untyped]

    rng = np.random.default_rng(0)
    a = (rng.random((128, 128)) * 4000).astype(np.int32)
    b = np.roll(np.roll(a, 2, axis=1), 1, axis=0)
    u, v, _ = pyprocess.extended_search_area_piv(a, b, window_size=32, overlap=16,
                                                 search_area_size=32, sig2noise_method="peak2peak")
    return float(np.median(u)), float(np.median(v))


def piv(reference: NDArray[Any], flow: NDArray[Any]
        ) -> Tuple[NDArray[Any], NDArray[Any], NDArray[Any], NDArray[Any]]:
    """OpenPIV's vectors from ``reference`` to ``flow``: (x, y) window
    centres and (u, v) in pixels, x right and y down (see
    :func:`openpiv_convention`)."""
    from openpiv import pyprocess

    u, v, _ = pyprocess.extended_search_area_piv(
        reference.astype(np.int32), flow.astype(np.int32), window_size=WINDOW, overlap=OVERLAP,
        search_area_size=WINDOW, sig2noise_method="peak2peak", subpixel_method="gaussian")
    x, y = pyprocess.get_coordinates(reference.shape, WINDOW, OVERLAP)
    return x, y, u, v


def window_means(truth: NDArray[np.float64], x: NDArray[Any], y: NDArray[Any]) -> NDArray[np.float64]:
    """The truth (h, w, 2) averaged over each interrogation window."""
    half = WINDOW // 2
    out = np.zeros(x.shape + (2,))
    for j in range(x.shape[0]):
        for i in range(x.shape[1]):
            cx, cy = int(round(x[j, i])), int(round(y[j, i]))
            out[j, i] = truth[cy - half:cy + half, cx - half:cx + half].reshape(-1, 2).mean(axis=0)
    return out


def compare(reference: NDArray[Any], flow: NDArray[Any], truth: NDArray[np.float64]) -> Dict[str, Any]:
    """Correlation, rms difference (px) and the truth's largest |Δ| over
    the windows, OpenPIV's (u, v) against the window-averaged truth."""
    x, y, u, v = piv(reference, flow)
    want = window_means(truth, x, y)
    got = np.stack([u, v], axis=-1)
    ok = np.isfinite(got).all(axis=-1)
    a, b = got[ok].ravel(), want[ok].ravel()
    return {
        "windows": int(ok.sum()),
        "correlation": float(np.corrcoef(a, b)[0, 1]),
        "rms_px": float(np.sqrt(np.mean((a - b) ** 2))),
        "max_truth_px": float(np.abs(want).max()),
    }


def record(image: NDArray[np.float64], noise: bool, seed: int) -> NDArray[np.uint16]:
    """A 12-bit camera's counts of ``image`` (1 ≈ a dot's centre at 8000
    e⁻ of a 10 000 e⁻ well, as ``rt bos`` records)."""
    kw: Dict[str, Any] = dict(shot_noise=True, read_noise=5.0) if noise else {}
    return rtvis.record(image, exposure=8000.0, full_well=10000.0, bits=12, seed=seed, **kw)


def rtvis_case(noise: bool) -> Dict[str, Any]:
    rho, h, origin = density_bump()
    vol = rtvis.Volume(rho, spacing=(h,) * 3, origin=(origin,) * 3, quantity="density")
    ref, flow, disp, info = rtvis.bos(vol, size=SIZE, seed=3)
    result = compare(record(ref, noise, 3), record(flow, noise, 4), disp)
    result["set_up"] = info
    return result


def rt_case(rt: str, noise: bool, folder: Union[str, Path]) -> Dict[str, Any]:
    """The same bump written as raw + JSON and rendered by ``rt bos``; its
    12-bit PNGs and ``.raw`` truth read back."""
    import imageio.v3 as iio

    rho, h, origin = density_bump()
    n = rho.shape[0]
    folder = Path(folder)
    rho.astype("<f4").tofile(folder / "bump.raw")
    (folder / "bump.json").write_text(json.dumps({
        "file": "bump.raw", "dims": [n, n, n], "dtype": "float32", "endian": "little",
        "spacing": [h] * 3, "origin": [origin] * 3, "quantity": "density"}))
    out = folder / ("noisy.png" if noise else "clean.png")
    extra = ["--shot-noise", "--read-noise", "5"] if noise else []
    run = subprocess.run([rt, "bos", str(folder / "bump.json"), "--size", str(SIZE), "--seed", "3",
                          "--out", str(out), *extra], check=True, capture_output=True, text=True)
    stem = out.with_suffix("")
    ref = iio.imread(f"{stem}-reference.png").astype(np.int64) >> 4  # 12 bits in the high bits
    flow = iio.imread(f"{stem}-flow.png").astype(np.int64) >> 4
    truth = np.fromfile(f"{stem}-displacement.raw", dtype="<f4").reshape(ref.shape + (2,))
    result = compare(ref, flow, truth)
    result["set_up"] = run.stdout.strip()
    return result


def closure(rt: Optional[str] = None) -> List[Dict[str, Any]]:
    """Every case: a list of dicts (``case``, ``windows``, ``correlation``,
    ``rms_px``, ``max_truth_px``, ``set_up``)."""
    u, v = openpiv_convention()
    if abs(u - 2.0) > 0.1 or abs(v - 1.0) > 0.1:
        raise RuntimeError(f"OpenPIV's convention changed: a (2, 1) px shift reads ({u}, {v})")
    rows = []
    for noise in (False, True):
        rows.append({"case": "rtvis.bos" + (", noise" if noise else ""), **rtvis_case(noise)})
    if rt:
        with tempfile.TemporaryDirectory() as tmp:
            for noise in (False, True):
                rows.append({"case": "rt bos" + (", noise" if noise else ""), **rt_case(rt, noise, tmp)})
    return rows


def main(argv: Optional[Sequence[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--rt", help="the rt command, for the `rt bos` cases")
    p.add_argument("--json", help="also write the numbers here")
    a = p.parse_args(argv)
    rows = closure(a.rt)
    print("| case | windows | correlation | rms (px) | truth max (px) |")
    print("|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['case']} | {r['windows']} | {r['correlation']:.4f} | {r['rms_px']:.3f} "
              f"| {r['max_truth_px']:.2f} |")
    print(f"set-up: {rows[0]['set_up']}")
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
