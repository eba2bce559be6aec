"""Surfaces and compositing from Python: a sphere against the analytic
Lambert image, and pieces rendered apart then composited against the
whole scene rendered at once, bit for bit."""

from pathlib import Path

import numpy as np
import pytest

import rtvis

ONLY_KEY_LIGHT = [("directional", (0.0, 0.0, 1.0), (1.0, 1.0, 1.0))]


def test_sphere_matches_the_analytic_lambert_image():
    albedo = np.array([0.9, 0.6, 0.3], dtype=np.float32)
    scene = rtvis.Scene().add_spheres([[0.0, 0.0, 0.0]], 1.0, color=tuple(albedo), material="matte")
    w, h, height = 96, 64, 2.5
    cam = rtvis.Camera((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), fov=30.0, ortho_height=height)
    rgba, depth = scene.render(cam, size=(w, h), lights=ONLY_KEY_LIGHT, shadows=False)
    assert rgba.shape == (h, w, 4) and depth.shape == (h, w)
    assert rgba.dtype == np.float32 and depth.dtype == np.float32
    # Pixel centres (pass 0), orthographic: the ray through pixel (i, j)
    # starts at (x, y) on the view plane.
    x = (2.0 * (np.arange(w) + 0.5) / w - 1.0) * height / 2 * (w / h)
    y = (1.0 - 2.0 * (np.arange(h) + 0.5) / h) * height / 2
    X, Y = np.meshgrid(x, y)
    r2 = X**2 + Y**2
    inside = r2 < 1.0 - 1e-3
    outside = r2 > 1.0 + 1e-3
    z = np.sqrt(np.clip(1.0 - r2, 0.0, None))
    # Lambert: albedo · (n·l) with n = (x, y, z), l = +z; opaque; depth 5 − z.
    expected = albedo[None, None, :] * z[..., None]
    assert np.abs(rgba[..., :3] - expected)[inside].max() < 1e-4
    assert np.all(rgba[..., 3][inside] == 1.0)
    assert np.abs(depth - (5.0 - z))[inside].max() < 1e-4
    # Background: transparent black at infinite depth.
    assert np.all(rgba[outside] == 0.0) and np.all(np.isinf(depth[outside]))


def test_meshes_tubes_and_colour_maps():
    # Two triangles (a square) coloured by x through viridis, a tube.
    pts = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=np.float64)
    tris = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int32)
    scene = rtvis.Scene().add_mesh(pts, tris, scalars=pts[:, 0], colormap="viridis", material="matte")
    scene.add_tubes([np.array([[-1.0, 0.0, 0.5], [1.0, 0.0, 0.5]])], 0.1, color=(1.0, 0.0, 0.0))
    assert len(scene) == 2
    lo, hi = scene.bounds()
    assert lo[2] == pytest.approx(0.0) and hi[2] == pytest.approx(0.6)
    rgba, depth = scene.render(size=64, lights=[("ambient", (1.0, 1.0, 1.0))], shadows=False)
    # Ambient light only: the colour is the albedo. Left edge viridis low
    # (dark blue-purple), right edge high (yellow), the tube red.
    assert np.isfinite(depth[20, 18]) and np.isfinite(depth[20, 46])
    left, right = rgba[20, 18, :3], rgba[20, 46, :3]
    assert left[2] > left[0] and right[0] > right[2] and right[1] > left[1]
    middle = rgba[32, 32, :3]
    assert middle[0] > 0.5 and middle[1] < 0.05 and middle[2] < 0.05
    assert depth[32, 32] < depth[20, 18]  # the tube is in front of the square


def _published_viridis():
    # matplotlib's 256 sRGB entries, copied into the repository beside
    # rt-core's own table test.
    path = Path(__file__).resolve().parents[2] / "rt-core" / "tests" / "data" / "viridis.csv"
    return np.loadtxt(path, delimiter=",", comments=("#", "r"))


def test_a_ramp_under_ambient_light_is_the_published_viridis():
    # Scalar = x on a square filling an orthographic view, ambient light 1:
    # the displayed 8-bit colour of each pixel is viridis at its scalar, as
    # matplotlib publishes it (interpolated between entries), within one
    # step: not encoded to sRGB a second time.
    pts = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=np.float64)
    tris = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int32)
    scene = rtvis.Scene().add_mesh(pts, tris, scalars=pts[:, 0], colormap="viridis",
                                   range=(-1.0, 1.0), material="matte")
    w, h = 256, 4
    cam = rtvis.Camera((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), ortho_height=2.0 * h / w)
    rgba, _ = scene.render(cam, size=(w, h), lights=[("ambient", (1.0, 1.0, 1.0))], shadows=False)
    shown = rtvis.to_srgb8(rgba).astype(np.int32)
    x = (2.0 * (np.arange(w) + 0.5) / w - 1.0)  # the scalar at each column
    table = _published_viridis()
    pos = np.linspace(0.0, 1.0, len(table))
    want = np.stack([np.interp((x + 1.0) / 2.0, pos, table[:, k]) for k in range(3)], axis=-1)
    want = np.round(want * 255.0).astype(np.int32)
    assert np.abs(shown[h // 2] - want).max() <= 1
    assert shown[h // 2, 128].tolist() == pytest.approx([33, 145, 140], abs=1)


def test_pieces_composite_to_the_whole_scene_bit_for_bit():
    rng = np.random.default_rng(3)
    centres = rng.uniform(-1.0, 1.0, size=(24, 3))
    radii = rng.uniform(0.1, 0.35, size=24)
    scalars = centres[:, 2]
    cam = rtvis.Camera((0.3, 0.4, 4.0), (0.0, 0.0, 0.0), fov=40.0)
    common = dict(size=(80, 60), shadows=False, seed=11)
    whole = rtvis.Scene().add_spheres(centres, radii, scalars=scalars, range=(-1, 1))
    ref_rgba, ref_depth = whole.render(cam, **common)
    parts = []
    for k in range(3):  # three "ranks", each its share of the spheres
        s = rtvis.Scene().add_spheres(centres[k::3], radii[k::3], scalars=scalars[k::3], range=(-1, 1))
        parts.append(s.render(cam, **common))
    rgba, depth = rtvis.composite([p[0] for p in parts], [p[1] for p in parts])
    assert np.array_equal(depth, ref_depth)
    assert np.array_equal(rgba, ref_rgba)
    assert np.count_nonzero(np.isfinite(depth)) > 500


def test_same_seed_same_image_with_ao():
    scene = rtvis.Scene().add_spheres([[0, 0, 0], [0.8, 0, 0]], [0.5, 0.4])
    a = scene.render(size=32, ao=8, passes=2, seed=4)
    b = scene.render(size=32, ao=8, passes=2, seed=4)
    c = scene.render(size=32, ao=8, passes=2, seed=5)
    assert np.array_equal(a[0], b[0]) and not np.array_equal(a[0], c[0])


def test_to_srgb8():
    rgba = np.zeros((1, 3, 4), dtype=np.float32)
    rgba[0, 1] = [0.5, 0.5, 0.5, 0.5]  # half-covered white-ish pixel
    rgba[0, 2] = [1.0, 0.0, 0.0, 1.0]
    out = rtvis.to_srgb8(rgba, background=(0.0, 0.0, 0.0))
    assert out.dtype == np.uint8 and out.shape == (1, 3, 3)
    assert out[0, 0].tolist() == [0, 0, 0]
    assert out[0, 1].tolist() == [188, 188, 188]  # sRGB(0.5) = 0.7354
    assert out[0, 2].tolist() == [255, 0, 0]


def test_save_png_makes_its_folder_and_refuses_a_folder(tmp_path, capsys):
    img = np.zeros((2, 3, 3), dtype=np.uint8)
    target = tmp_path / "new" / "deeper" / "a.png"
    rtvis.save_png(target, img)
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "created folder" in capsys.readouterr().err
    with pytest.raises(IsADirectoryError, match="is a folder"):
        rtvis.save_png(tmp_path / "new", img)
    # Nothing but the image is left in the folder (no staging file).
    assert [p.name for p in target.parent.iterdir()] == ["a.png"]


def test_a_colour_map_of_your_own_stops():
    # The grayscale map's own stops given as an array: the same image as
    # the named map, bit for bit; a red-to-blue map paints the low end red.
    centers = np.array([[-1.5, 0, 0], [0, 0, 0], [1.5, 0, 0]], np.float32)
    scalars = np.array([0.0, 0.5, 1.0], np.float32)
    cam = rtvis.Camera.fit(((-2.5, -1, -1), (2.5, 1, 1)), aspect=96 / 40)
    lights = [("ambient", (1.0, 1.0, 1.0))]

    def render(colormap):
        scene = rtvis.Scene().add_spheres(centers, 0.6, scalars=scalars, colormap=colormap, material="matte")
        return scene.render(cam, size=(96, 40), lights=lights, shadows=False)[0]

    named = render("grayscale")
    stops = np.array([[0, 0, 0, 0], [1, 1, 1, 1]], np.float32)
    assert np.array_equal(render(stops), named)
    red_blue = render(np.array([[0, 1, 0, 0], [1, 0, 0, 1]], np.float32))
    hit = red_blue[..., 3] > 0.99
    assert hit.mean() > 0.02
    cols = np.nonzero(hit.any(axis=0))[0]
    a, b = cols.min() + (cols.max() - cols.min()) // 5, cols.max() - (cols.max() - cols.min()) // 5
    left = red_blue[:, :a][hit[:, :a]].mean(axis=0)  # the sphere of scalar 0
    right = red_blue[:, b:][hit[:, b:]].mean(axis=0)  # the sphere of scalar 1
    assert left[0] > 0.3 and left[2] < 0.1 * left[0], left
    assert right[2] > 0.3 and right[0] < 0.1 * right[2], right
    with pytest.raises(ValueError, match="colormap"):
        render(np.array([[0.5, 1, 0, 0], [0.2, 0, 0, 1]], np.float32))  # positions fall
    with pytest.raises(ValueError, match="colormap"):
        render(np.array([[0, 1, 0, 0]], np.float32))
