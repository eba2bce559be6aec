"""Python conventions: images placed in physical space (extent), NaN
cells as the ambient medium, VTK and PyVista images in."""

import numpy as np
import pytest

import rtvis


def off_centre_bump(centre, n=(40, 48, 56), h=1e-3):
    """A density bump at `centre` (x, y, z) in a box of nz×ny×nx cells
    of `h`, origin at its corner (0, 0, 0)."""
    z, y, x = np.indices(n) * h
    r2 = (x - centre[0]) ** 2 + (y - centre[1]) ** 2 + (z - centre[2]) ** 2
    return 1.2 + 0.3 * np.exp(-r2 / (2 * (3e-3) ** 2))


@pytest.mark.parametrize("axis", ["x", "y", "z"])
def test_the_extent_puts_a_feature_where_it_is(axis):
    # A shadowgraph of a bump off the volume's centre: its disturbance's
    # centroid, mapped through extent as imshow maps pixels, lands on the
    # bump's own coordinates (within a pixel); a transposed or flipped
    # extent puts it millimetres away.
    centre = (0.035, 0.014, 0.026)
    vol = rtvis.Volume(off_centre_bump(centre), spacing=(1e-3,) * 3)
    img = rtvis.shadowgraph(vol, axis=axis, size=200, photons=4).astype(np.float64)
    left, right, bottom, top = vol.extent(axis)
    h, w = img.shape
    weight = np.abs(img - 1.0)
    rows, cols = np.indices(img.shape) + 0.5
    u = left + (right - left) * (weight * cols).sum() / weight.sum() / w
    v = top - (top - bottom) * (weight * rows).sum() / weight.sum() / h
    iu, iv = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]
    pixel = (right - left) / w
    assert abs(u - centre[iu]) < pixel and abs(v - centre[iv]) < pixel, (u, v, centre)


def test_nan_cells_can_be_the_ambient_medium():
    rho = off_centre_bump((0.028, 0.024, 0.02))
    holes = rho.copy()
    holes[:3, :, :] = np.nan  # blanked cells along one face
    holes[20, 20, 20] = np.nan  # and one inside
    with pytest.raises(ValueError, match="not finite"):
        rtvis.Volume(holes)
    vol = rtvis.Volume(holes, nan="ambient")
    # Filled with the far field: the faces' median (1.2, the bump is far).
    filled = rtvis.Volume(np.where(np.isnan(holes), np.float32(1.2), holes))
    assert np.array_equal(vol.index(), filled.index())
    with pytest.raises(ValueError, match="not finite"):
        rtvis.Volume(np.where(np.isnan(holes), np.inf, holes), nan="ambient")
    with pytest.raises(ValueError, match="no finite sample on the volume's faces"):
        rtvis.Volume(np.full((3, 3, 3), np.nan), nan="ambient")
    with pytest.raises(ValueError, match="nan: unknown 'zero'"):
        rtvis.Volume(rho, nan="zero")


def test_vtk_and_pyvista_images_become_the_same_volume():
    pv = pytest.importorskip("pyvista")
    rho = off_centre_bump((0.02, 0.03, 0.02), n=(10, 12, 14)).astype(np.float32)
    want = rtvis.Volume(rho, spacing=(1e-3, 2e-3, 3e-3), origin=(0.1, 0.2, 0.3))
    grid = pv.ImageData(dimensions=(14, 12, 10), spacing=(1e-3, 2e-3, 3e-3), origin=(0.1, 0.2, 0.3))
    grid.point_data["density"] = rho.ravel()  # x fastest, as VTK stores it
    for got in (rtvis.Volume.from_pyvista(grid), rtvis.Volume.from_vtk(grid, "density")):
        assert got.shape == want.shape and got.spacing == want.spacing and got.origin == want.origin
        assert np.array_equal(got.index(), want.index())
    # Cell data: samples at the cell centres.
    cells = pv.ImageData(dimensions=(15, 13, 11), spacing=(1e-3, 2e-3, 3e-3), origin=(0.1, 0.2, 0.3))
    cells.cell_data["rho"] = rho.ravel()
    got = rtvis.Volume.from_pyvista(cells)
    assert got.shape == want.shape and np.allclose(got.origin, (0.1005, 0.201, 0.3015))
    assert np.array_equal(got.index(), want.index())
    grid.point_data["other"] = rho.ravel()
    with pytest.raises(ValueError, match="no array 'pressure'"):
        rtvis.Volume.from_vtk(grid, "pressure")
    with pytest.raises(TypeError, match="pyvista.ImageData"):
        rtvis.Volume.from_pyvista(rho)
    with pytest.raises(TypeError, match="vtkImageData"):
        rtvis.Volume.from_vtk("image.vti")
