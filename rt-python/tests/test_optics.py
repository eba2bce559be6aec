"""The optical bench from Python against docs/oracles.md §5's Gaussian bump, and
against the `rt` command's own output for the same volume and seed."""

import json
import math
import os
import subprocess

import numpy as np
import pytest

import rtvis
from helpers import bump, bump_deflection, pixel_centres, read_png16, rt_binary


@pytest.fixture(scope="module")
def gaussian():
    return bump()


def test_aliasing_fringes_warn_as_a_runtime_warning_of_rtvis(gaussian):
    vol, _, _ = gaussian
    assert issubclass(rtvis.RtvisWarning, RuntimeWarning)
    # Green light through the bump on 16 pixels: many radians a pixel.
    with pytest.warns(rtvis.RtvisWarning, match="fringes alias"):
        rtvis.interferogram(vol, wavelength=532e-9, size=16)
    # A millimetre wave does not alias: no warning at all.
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rtvis.interferogram(vol, wavelength=1e-3, size=16)


def test_deflection_matches_the_analytic_bump(gaussian):
    vol, sigma, delta = gaussian
    _, eps = rtvis.schlieren(vol, f=1.0, h=4e-4, size=96, deflection=True)
    ex, ey = bump_deflection(*pixel_centres(vol, eps.shape[:2]), sigma, delta)
    peak = np.abs(ex).max()
    # First order in δ, a bump truncated at 4σ, cubic interpolation of 1 mm
    # samples: within 1.5 % of the peak everywhere.
    assert np.abs(eps[..., 0] - ex).max() < 0.015 * peak
    assert np.abs(eps[..., 1] - ey).max() < 0.015 * peak


def test_knife_edge_matches_the_analytic_signal(gaussian):
    vol, sigma, delta = gaussian
    f, h = 1.0, 4e-4
    img = rtvis.schlieren(vol, cutoff="knife", angle=0.0, f=f, h=h, size=128)
    assert img.dtype == np.float32 and img.shape == (128, 128)
    ex, _ = bump_deflection(*pixel_centres(vol, img.shape), sigma, delta)
    expected = 2.0 * np.clip(0.5 + (f / h) * ex, 0.0, 1.0)
    # Normalised to the background: 1 where nothing deflects.
    assert img[0, 0] == pytest.approx(1.0, abs=1e-6)
    assert np.abs(img - expected).max() < 0.02
    # The signal is strong (up to ±0.76 about the background), so the
    # bound above is a real check: a sign or axis error would be ~1.5.
    assert np.abs(expected - 1.0).max() > 0.7


def test_shadowgraph_matches_the_linearised_oracle(gaussian):
    vol, sigma, delta = gaussian
    L = 2.0
    img = rtvis.shadowgraph(vol, distance=L, size=64, photons=64)
    X, Y = pixel_centres(vol, img.shape)
    r2 = (X**2 + Y**2) / sigma**2
    A = math.sqrt(2 * math.pi) * delta / sigma
    expected = 1.0 + L * A * np.exp(-r2 / 2) * (2.0 - r2)
    contrast = np.abs(expected - 1.0).max()
    assert contrast > 0.05
    # Linearised in L·δ: the exact intensity differs by O(contrast²).
    assert np.abs(img - expected).max() < 0.2 * contrast


def test_interferogram_phase_matches_the_oracle(gaussian):
    vol, sigma, delta = gaussian
    lam = 10.6e-6
    img = rtvis.interferogram(vol, wavelength=lam, size=128, dtype=np.float64)
    X, Y = pixel_centres(vol, img.shape)
    phi = 2 * math.pi / lam * math.sqrt(2 * math.pi) * sigma * delta * np.exp(-(X**2 + Y**2) / (2 * sigma**2))
    assert 1.0 < phi.max() < math.pi  # phase recoverable from the intensity
    measured = np.arccos(np.clip(2.0 * img - 1.0, -1.0, 1.0))
    # The command line's bench (two-cell leapfrog steps, octree skipping):
    # within 0.5 % of the oracle (measured 0.09 %; 1–4 % before leapfrog
    # measured its optical path along its chords). Where the phase is
    # small the arccos amplifies intensity round-off, so only φ > 0.5.
    big = phi > 0.5
    assert np.abs(measured / phi - 1.0)[big].max() < 5e-3
    assert np.abs(img - 0.5 * (1.0 + np.cos(phi))).max() < 2e-3


def test_interferogram_phase_map_is_unwrapped_and_matches_the_oracle(gaussian):
    vol, sigma, delta = gaussian
    lam = 532e-9  # φ(0) ≈ 24 rad: almost four fringes, no 2π ambiguity
    img, phase = rtvis.interferogram(vol, wavelength=lam, size=96, phase=True)
    assert phase.dtype == np.float64 and phase.shape == img.shape
    X, Y = pixel_centres(vol, img.shape)
    phi = 2 * math.pi / lam * math.sqrt(2 * math.pi) * sigma * delta * np.exp(-(X**2 + Y**2) / (2 * sigma**2))
    assert phi.max() > 3 * 2 * math.pi
    # The intensity is the cosine of the phase map, pixel for pixel, up
    # to the spread of φ over a pixel's photons (up to ~1.2 rad here: the
    # pixel's mean of cos φ is not cos of its mean φ by up to ~0.06).
    assert np.abs(img - 0.5 * (1 + np.cos(phase))).max() < 0.1
    # Against the oracle: within 1 % where φ is not small (measured 0.34 %).
    big = phi > 0.1 * phi.max()
    assert np.abs(phase / phi - 1.0)[big].max() < 0.01


def test_color_schlieren_is_white_where_nothing_deflects(gaussian):
    vol, _, _ = gaussian
    img = rtvis.color_schlieren(vol, size=48)
    assert img.shape == (48, 48, 3)
    np.testing.assert_allclose(img[0, 0], [1.0, 1.0, 1.0], atol=1e-6)
    # Deflected pixels are coloured (channels differ).
    assert (img.max(axis=2) - img.min(axis=2)).max() > 0.2


def test_same_seed_same_image_and_float64_agrees(gaussian):
    vol, _, _ = gaussian
    a = rtvis.schlieren(vol, size=48, seed=7, estimator="photons", photons=4)
    b = rtvis.schlieren(vol, size=48, seed=7, estimator="photons", photons=4)
    c = rtvis.schlieren(vol, size=48, seed=8, estimator="photons", photons=4)
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    d = rtvis.schlieren(vol, size=48, seed=7, estimator="photons", photons=4, dtype=np.float64)
    assert d.dtype == np.float64 and np.array_equal(d.astype(np.float32), a)


@pytest.mark.parametrize("cutoff,extra,color", [
    ("knife", ["--angle", "30"], False),
    ("none", ["--film-distance", "3"], False),
    ("color", [], True),
])
def test_equals_the_rt_command_bit_for_bit(tmp_path, cutoff, extra, color):
    """The same volume through `rt schlieren --raw16` (which writes
    round(32768 × I/I0) of the film's float64 values): every pixel equal."""
    rt = rt_binary()
    if rt is None:
        pytest.skip("no `rt` binary (cargo build --release -p rt-cli, or set RT_BIN)")
    n, h = 40, 1e-3
    c = 0.5 * (n - 1) * h
    z, y, x = np.mgrid[0:n, 0:n, 0:n] * h - c
    rho = (1.2 + 0.4 * np.exp(-((x - 3e-3) ** 2 + y**2 + z**2) / (2 * 6e-3**2))).astype(np.float32)
    rho.tofile(tmp_path / "v.raw")
    (tmp_path / "v.json").write_text(json.dumps(
        {"dims": [n, n, n], "dtype": "float32", "spacing": [h] * 3, "origin": [-c] * 3, "file": "v.raw"}))
    out = tmp_path / "s.png"
    subprocess.run([rt, "schlieren", str(tmp_path / "v.json"), "--cutoff", cutoff, "--size", "64",
                    "--photons", "16", "--seed", "5", "--raw16", "--no-figure", "--out", str(out), *extra],
                   check=True, capture_output=True)
    png = read_png16(tmp_path / "s-16bit.png")
    vol = rtvis.Volume(rho, spacing=(h,) * 3, origin=(-c,) * 3)
    kw = dict(size=64, photons=16, seed=5, dtype=np.float64)
    if cutoff == "knife":
        img = rtvis.schlieren(vol, cutoff="knife", angle=30.0, **kw) * 0.5  # background passes half
    elif cutoff == "none":
        img = rtvis.shadowgraph(vol, distance=3.0, **kw)
    else:
        # The public result is divided by the filter's own colour at zero
        # deflection (not exactly white: a 256-pixel hue wheel); compare
        # the film itself.
        kw.pop("dtype")
        img = rtvis._bench(vol, "color", **kw)[0]

    def to16(v):
        return np.where(v > 0.0, np.minimum(np.floor(v * 32768.0 + 0.5), 65535.0), 0.0).astype(np.int64)

    if color:
        mine = to16(img)
    else:
        mine = to16((img + img + img) / 3.0)
    assert png.shape == mine.shape
    assert np.array_equal(png, mine), f"{np.count_nonzero(png != mine)} pixels differ"
    assert len(np.unique(png)) > 20  # a real image, not a flat one


def test_read_volume_reads_what_rt_reads(tmp_path):
    n = 8
    data = np.linspace(1.0, 2.0, n**3, dtype=np.float32).reshape(n, n, n)
    data.tofile(tmp_path / "v.raw")
    (tmp_path / "v.json").write_text(json.dumps(
        {"dims": [n, n, n], "dtype": "float32", "spacing": [0.5, 1.0, 2.0], "origin": [1.0, 2.0, 3.0], "file": "v.raw"}))
    vol = rtvis.read_volume(tmp_path / "v.json", quantity="index")
    assert vol.shape == (n, n, n)
    assert vol.spacing == (0.5, 1.0, 2.0) and vol.origin == (1.0, 2.0, 3.0)
    assert np.array_equal(vol.index(), data)
    # Density is mapped by Gladstone–Dale.
    d = rtvis.read_volume(tmp_path / "v.json", k=1e-3)
    # (rounded to float32 once, from float64: within one float32 step)
    np.testing.assert_allclose(d.index(), 1.0 + 1e-3 * data.astype(np.float64), rtol=6e-8)


def test_record_is_the_sensor_model(gaussian):
    vol, _, _ = gaussian
    img = rtvis.schlieren(vol, size=64, f=1.0, h=4e-4, dtype=np.float64)
    counts = rtvis.record(img, exposure=1000.0, full_well=4000.0, bits=12)
    assert counts.dtype == np.uint16 and counts.shape == img.shape
    want = np.floor(np.minimum(1000.0 * img, 4000.0) / 4000.0 * 4095.0 + 0.5).astype(np.uint16)
    assert np.array_equal(counts, want)  # noise off: the definition, exactly
    flat = np.ones((128, 128))
    noisy = rtvis.record(flat, exposure=2000.0, full_well=65535.0, bits=16, shot_noise=True, seed=3)
    assert abs(noisy.mean() - 2000.0) < 4 * (2000.0 / flat.size) ** 0.5
    assert abs(noisy.var() / 2000.0 - 1.0) < 0.05
    assert np.array_equal(noisy, rtvis.record(flat, exposure=2000.0, full_well=65535.0, shot_noise=True, seed=3))
    with pytest.raises(ValueError, match="bits must be 1 to 16"):
        rtvis.record(flat, bits=17)
    with pytest.raises(ValueError, match="negative"):
        rtvis.record(-flat)
    with pytest.raises(ValueError, match="exposure must be finite and ≥ 0"):
        rtvis.record(flat, exposure=-1.0)


def test_bos_displacement_is_the_paraxial_relation(gaussian):
    vol, sigma, delta = gaussian  # refractive index, 1 mm cells, σ = 8 mm
    f, pitch, z_a, z_d = 0.1, 5e-6, 2.0, 1.5
    ref, flow, disp, info = rtvis.bos(vol, size=128, distance=z_a, background_distance=z_d,
                                      focal_length=f, pixel=pitch, f_number=200.0, samples=2)
    assert ref.shape == flow.shape == disp.shape[:2] == (128, 128)
    assert "f/200" in info
    m = f / (z_a + z_d - f)
    # The pixels of the row through the bump's centre: each sees impact
    # point x = (pixel's point on the background) · Z_A/(Z_A + Z_D).
    row = disp[64]
    xs = (np.arange(128) + 0.5 - 64) * pitch / m * z_a / (z_a + z_d)
    y = (64 - 64.5) * pitch / m * z_a / (z_a + z_d)
    g = np.exp(-(xs**2 + y**2) / (2 * sigma**2))
    eps = -math.sqrt(2 * math.pi) * delta * (xs / sigma) * g
    # The camera looks back along −z (x is x); rays land shifted by
    # M·Z_D·ε, so the background pattern appears shifted the other way
    # (the convention of PIV software): the bump magnifies it outward.
    want = -m * z_d * eps / pitch
    peak = np.abs(want).max()
    assert peak > 0.5
    assert np.abs(row[:, 0] - want).max() < 0.02 * peak
    # Nothing moves without a flow.
    flat = rtvis.Volume(np.full((8, 8, 8), 1.0), quantity="index", spacing=(1e-3,) * 3)
    ref2, flow2, disp2, _ = rtvis.bos(flat, size=16)
    assert np.abs(disp2).max() < 1e-9 and np.abs(flow2 - ref2).max() < 1e-9
    with pytest.raises(ValueError, match="farther from the lens"):
        rtvis.bos(vol, focal_length=0.1, distance=0.05)
    with pytest.raises(ValueError, match="f_number must be finite and > 0"):
        rtvis.bos(vol, f_number=-1)


def test_bos_backgrounds_and_diffraction(tmp_path):
    flat = rtvis.Volume(np.full((8, 8, 8), 1.0), quantity="index", spacing=(1e-3,) * 3)
    # A dot grid 6 pixels apart as imaged repeats every 6 pixels, not 3.
    grid, flow, _, info = rtvis.bos(flat, size=48, background="grid", dot=2.5, spacing=6.0, samples=8)
    assert grid.shape == (48, 48) and np.abs(flow - grid).max() < 1e-9
    assert np.abs(grid[:, 6:] - grid[:, :-6]).max() < 0.02
    assert np.abs(grid[6:] - grid[:-6]).max() < 0.02
    assert np.abs(grid[:, 3:] - grid[:, :-3]).max() > 0.3
    assert "working f/" in info
    # A smooth grey array imaged pixel for pixel comes back through no flow.
    y, x = np.mgrid[0:48, 0:48] + 0.5
    img = 0.5 + 0.4 * np.sin(2 * np.pi * x / 32) * np.cos(2 * np.pi * y / 24)
    ref, flow, disp, _ = rtvis.bos(flat, size=48, background=img, samples=4)
    assert np.abs(ref - img).max() < 0.02 and np.abs(flow - ref).max() < 1e-9
    assert np.abs(disp).max() < 1e-9
    # Half as many pixels, each 2 sensor pixels wide: the same picture.
    half = rtvis.bos(flat, size=48, background=img[::2, ::2], background_pixel=2.0, samples=4)[0]
    assert np.abs(half - img).max() < 0.1
    # The same image as an 8-bit PNG, read as linear luminance (sRGB decoded).
    g8 = np.round(img * 255).astype(np.uint8)
    rtvis.save_png(tmp_path / "bg.png", g8)
    c = g8 / 255.0
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    from_png = rtvis.bos(flat, size=48, background=str(tmp_path / "bg.png"), samples=4)[0]
    assert np.abs(from_png - rtvis.bos(flat, size=48, background=lin, samples=4)[0]).max() < 1e-12
    # Diffraction at the sensor: the grid's contrast drops, its light stays.
    sharp = rtvis.record(grid, exposure=8000.0, full_well=20000.0).astype(float)
    soft = rtvis.record(grid, exposure=8000.0, full_well=20000.0, airy=(532e-9, 16.0, 5e-6)).astype(float)
    assert soft.std() < 0.8 * sharp.std()
    assert abs(soft.mean() / sharp.mean() - 1.0) < 0.03
    # Bad input.
    with pytest.raises(ValueError, match="negative"):
        rtvis.bos(flat, size=8, background=-np.ones((4, 4)))
    with pytest.raises(ValueError, match="not finite"):
        rtvis.bos(flat, size=8, background=np.full((4, 4), np.nan))
    (tmp_path / "junk.png").write_bytes(b"not a png")
    with pytest.raises(ValueError, match="junk.png"):
        rtvis.bos(flat, size=8, background=str(tmp_path / "junk.png"))
    with pytest.raises(ValueError, match="background_pixel must be finite and > 0"):
        rtvis.bos(flat, size=8, background=img, background_pixel=0.0)
    with pytest.raises(ValueError, match="airy pixel must be > 0"):
        rtvis.record(grid, airy=(532e-9, 16.0, 0.0))
    with pytest.raises(TypeError, match="airy"):
        rtvis.record(grid, airy=1.0)
    with pytest.raises(ValueError, match="λN"):
        rtvis.record(grid, airy=(532e-9, 1000.0, 1e-6))


def test_the_gpu_makes_the_cpus_image_or_says_why_not():
    """``device="gpu"`` traces the photons on the GPU (Mesa's lavapipe in
    CI, where ``RT_GPU_REQUIRE`` makes it a must): the image is the CPU's
    to the octree's skipping, which only the CPU does; ``auto`` picks the
    GPU where it can. Where it cannot: a ``ValueError`` naming why, or a
    ``RuntimeError`` without an adapter."""
    vol, _, _ = bump(n=48, interpolation="linear")
    cpu = rtvis.schlieren(vol, size=48, photons=4, dtype=np.float64)
    with pytest.raises(ValueError, match="device"):
        rtvis.schlieren(vol, size=16, device="tpu")
    cubic, _, _ = bump(n=24)
    with pytest.raises(ValueError, match="trilinear"):
        rtvis.schlieren(cubic, size=16, device="gpu")
    try:
        gpu, optics = rtvis.schlieren(vol, size=48, photons=4, dtype=np.float64, device="gpu", chosen=True)
    except RuntimeError as e:
        if os.environ.get("RT_GPU_REQUIRE"):
            raise
        assert "no GPU adapter" in str(e)
        return
    assert "traced on gpu (" in optics.description
    # Measured on lavapipe: 4.7e-5 of the image's contrast.
    assert np.abs(gpu - cpu).max() < 3e-4 * np.abs(cpu - 1.0).max()
    auto = rtvis.shadowgraph(vol, size=32, photons=4, device="auto")
    assert auto.shape == (32, 32) and np.isfinite(auto).all()
