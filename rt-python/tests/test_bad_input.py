"""Bad input raises TypeError or ValueError with a message naming the
problem; nothing crashes the interpreter; strided arrays are read right."""

import numpy as np
import pytest

import rtvis


@pytest.fixture(scope="module")
def vol():
    v = np.full((6, 7, 8), 1.2)
    v[3, 3, 4] = 1.5
    return rtvis.Volume(v, spacing=(1e-3,) * 3)


@pytest.mark.parametrize("values,exc,match", [
    (np.zeros((4, 4)), ValueError, "3 dimensions"),
    (np.zeros((0, 4, 4)), ValueError, "empty"),
    (np.ones((3, 3, 3), dtype=np.complex64), TypeError, "dtype complex64"),
    (np.array([["a"]]), TypeError, "dtype"),
    ("not an array", TypeError, "dtype"),
    (np.full((3, 3, 3), np.nan), ValueError, r"value at \(0, 0, 0\) is not finite"),
    (np.full((3, 3, 3), np.inf), ValueError, "not finite"),
    (np.full((3, 3, 3), 1e300), ValueError, "not finite"),  # overflows float32
    (np.zeros((3, 3, 3)), ValueError, "density ≤ 0"),
])
def test_bad_volumes(values, exc, match):
    with pytest.raises(exc, match=match):
        rtvis.Volume(values)


def test_bad_volume_options():
    ok = np.ones((3, 3, 3))
    with pytest.raises(ValueError, match="quantity: unknown 'pressure'"):
        rtvis.Volume(ok, quantity="pressure")
    with pytest.raises(ValueError, match="spacing must be finite"):
        rtvis.Volume(ok, spacing=(1, np.nan, 1))
    with pytest.raises(ValueError, match="spacing: expected 3 numbers"):
        rtvis.Volume(ok, spacing=(1, 1))
    with pytest.raises(ValueError, match="grid origin/spacing"):
        rtvis.Volume(ok, spacing=(1, 0, 1))
    with pytest.raises(ValueError, match="k must be > 0"):
        rtvis.Volume(ok, k=-1.0)
    with pytest.raises(ValueError, match="index below 1"):
        rtvis.Volume(ok * 0.5, quantity="index")
    # Accepted with the flag.
    rtvis.Volume(ok * 0.5, quantity="index", allow_nonphysical=True)


def test_xyz_ordered_arrays_are_the_same_volume():
    # A density bump off centre along +x only: indexed [x, y, z] (yt,
    # Fortran) with order="xyz", it is the same volume as the [z, y, x]
    # array, and its knife-edge image is bright on the side the bump's
    # gradient says, not mirrored across the diagonal.
    x = np.linspace(-1, 1, 24)
    zz, yy, xx = np.meshgrid(x, x, x, indexing="ij")
    zyx = 1.2 + 0.3 * np.exp(-((xx - 0.3) ** 2 + yy**2 + zz**2) / 0.05)
    xyz = np.ascontiguousarray(zyx.transpose(2, 1, 0))
    a = rtvis.Volume(zyx, spacing=(1e-2,) * 3)
    b = rtvis.Volume(xyz, spacing=(1e-2,) * 3, order="xyz")
    assert b.shape == a.shape == (24, 24, 24)
    assert np.array_equal(a.index(), b.index())
    ia = rtvis.schlieren(a, cutoff="knife", size=48)
    ib = rtvis.schlieren(b, cutoff="knife", size=48)
    assert np.array_equal(ia, ib)
    # Read as [z, y, x] by mistake, the bump moves to +z: off the image's
    # centre no more along x.
    c = rtvis.Volume(xyz, spacing=(1e-2,) * 3)
    assert not np.array_equal(rtvis.schlieren(c, cutoff="knife", size=48), ia)
    with pytest.raises(ValueError, match="order: unknown 'yxz'"):
        rtvis.Volume(zyx, order="yxz")
    # Nested lists too, and a bad sample is named by the caller's indices.
    assert np.array_equal(rtvis.Volume(xyz.tolist(), spacing=(1e-2,) * 3, order="xyz").index(), a.index())
    bad = xyz.copy()
    bad[5, 1, 0] = np.nan
    with pytest.raises(ValueError, match=r"\(5, 1, 0\) is not finite"):
        rtvis.Volume(bad, order="xyz")


def test_strided_and_fortran_arrays_are_read_in_logical_order():
    base = np.random.default_rng(0).uniform(1.0, 2.0, size=(10, 12, 14))
    strided = base[::2, ::3, ::2]  # not contiguous
    fortran = np.asfortranarray(strided)
    for a in (strided, fortran, strided.astype(np.float32)):
        v = rtvis.Volume(a, quantity="index")
        assert v.shape == strided.shape
        assert np.array_equal(v.index(), strided.astype(np.float32))


def test_bad_optics(vol):
    # The library's set-up checks the options (once); its messages.
    with pytest.raises(ValueError, match="cutoff: unknown `knif`"):
        rtvis.schlieren(vol, cutoff="knif")
    with pytest.raises(TypeError, match="unexpected keyword argument 'focal'"):
        rtvis.schlieren(vol, focal=1.0)
    with pytest.raises(ValueError, match=r"f must be finite and > 0 \(got 0\)"):
        rtvis.schlieren(vol, f=0.0)
    with pytest.raises(ValueError, match="angle must be finite"):
        rtvis.schlieren(vol, angle=float("nan"))
    with pytest.raises(ValueError, match="size must be 1 to 16384"):
        rtvis.schlieren(vol, size=0)
    with pytest.raises(TypeError, match="size: expected an int"):
        rtvis.schlieren(vol, size=12.5)
    with pytest.raises(ValueError, match="photons must be 1 to 65536"):
        rtvis.shadowgraph(vol, photons=10**6)
    with pytest.raises(ValueError, match="axis: unknown `w`"):
        rtvis.interferogram(vol, axis="w")
    with pytest.raises(ValueError, match="wavelength must be finite and > 0"):
        rtvis.interferogram(vol, wavelength=-1.0)
    with pytest.raises(TypeError, match="volume: expected an rtvis.Volume"):
        rtvis.schlieren(np.ones((3, 3, 3)))
    with pytest.raises(ValueError, match="dtype: expected float32 or float64"):
        rtvis.schlieren(vol, dtype=np.int16)


def test_bad_files(tmp_path):
    with pytest.raises(OSError, match="No such file"):
        rtvis.read_volume(tmp_path / "missing.nrrd")
    bad = tmp_path / "bad.nrrd"
    bad.write_bytes(b"NRRD0004\ntype: banana\n\n")
    with pytest.raises(ValueError):
        rtvis.read_volume(bad)
    unknown = tmp_path / "x.xyz"
    unknown.write_text("hello")
    with pytest.raises(ValueError):
        rtvis.read_volume(unknown)
    with pytest.raises(TypeError, match="path"):
        rtvis.read_volume(42)


def test_bad_surfaces():
    s = rtvis.Scene()
    tri = [[0, 1, 2]]
    pts = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    with pytest.raises(ValueError, match="triangle 0 refers to point 3"):
        s.add_mesh(pts, [[0, 1, 3]])
    with pytest.raises(ValueError, match="triangle 0 refers to point -1"):
        s.add_mesh(pts, [[0, 1, -1]])
    with pytest.raises(TypeError, match="triangles: expected integers"):
        s.add_mesh(pts, [[0.0, 1.0, 2.0]])
    with pytest.raises(ValueError, match="points: expected 2 dimensions, the last of length 3"):
        s.add_mesh([[0, 0], [1, 0], [0, 1]], tri)
    with pytest.raises(ValueError, match=r"points: value at \(1, 0\) is not finite"):
        s.add_mesh([[0, 0, 0], [np.nan, 0, 0], [0, 1, 0]], tri)
    with pytest.raises(ValueError, match="scalars: expected shape"):
        s.add_mesh(pts, tri, scalars=[1.0, 2.0])
    with pytest.raises(ValueError, match="colormap: unknown 'jet'"):
        s.add_mesh(pts, tri, scalars=[1, 2, 3], colormap="jet")
    with pytest.raises(ValueError, match="range must be finite with lo < hi"):
        s.add_mesh(pts, tri, scalars=[1, 2, 3], range=(2, 1))
    with pytest.raises(ValueError, match="material: unknown keys"):
        s.add_mesh(pts, tri, material={"shiny": 1})
    with pytest.raises(ValueError, match="material"):
        s.add_mesh(pts, tri, material={"diffuse": 2.0})
    with pytest.raises(ValueError, match="radius 0 must be finite and > 0"):
        s.add_spheres([[0, 0, 0]], [-1.0])
    with pytest.raises(ValueError, match="radii must be > 0"):
        s.add_spheres([[0, 0, 0]], 0.0)
    with pytest.raises(ValueError, match="at least 2 points"):
        s.add_tubes([[0, 0, 0]], 0.1)
    assert len(s) == 0  # nothing half-added
    with pytest.raises(ValueError, match="the scene is empty"):
        s.render()
    s.add_mesh(pts, tri)
    with pytest.raises(ValueError, match="camera"):
        s.render(rtvis.Camera((0, 0, 1), (0, 0, 0), up=(0, 0, 1)))
    with pytest.raises(ValueError, match="ao must be 0 to 4096"):
        s.render(ao=-1)
    with pytest.raises(ValueError, match=r"lights\[0\]\[0\]: unknown 'spot'"):
        s.render(lights=[("spot", (0, 0, 1), (1, 1, 1))])
    with pytest.raises(ValueError, match="size"):
        s.render(size=(0, 10))
    with pytest.raises(ValueError, match="fov must be below 180"):
        rtvis.Camera((0, 0, 1), (0, 0, 0), fov=200)


def test_bad_composites():
    c = np.zeros((4, 5, 4), dtype=np.float32)
    d = np.full((4, 5), np.inf, dtype=np.float32)
    with pytest.raises(ValueError, match="at least one"):
        rtvis.composite([], [])
    with pytest.raises(ValueError, match="as many depth images"):
        rtvis.composite([c, c], [d])
    with pytest.raises(ValueError, match="match rgba"):
        rtvis.composite([c], [d[:3]])
    with pytest.raises(ValueError, match="NaN"):
        rtvis.composite([c], [np.full((4, 5), np.nan, dtype=np.float32)])
    with pytest.raises(ValueError, match="image 1 is 5×3"):
        rtvis.composite([c, c[:3]], [d, d[:3]])
    with pytest.raises(TypeError, match="depth"):
        rtvis.composite([c], [np.zeros((4, 5), dtype=np.int32)])
    out, depth = rtvis.composite([c], [d])
    assert np.array_equal(out, c) and np.all(np.isinf(depth))
