"""rtvis_view under MPI (run by run-tests.sh):

    mpirun -np N pvbatch --symmetric pvbatch_view.py OUT_DIR

ParaView distributes a Wavelet over the N ranks and contours it; the
render view's representations are ray traced by rtvis_view on every rank
(each its own piece, the view's camera, a head light) and composited by
depth. Rank 0 writes OUT_DIR/view-N.npz (RGBA and depth), which
run-tests.sh compares, bit for bit, across N, and view-N.png."""

import os
import sys

import rtvis_pvcompat  # noqa: F401

import numpy as np
from mpi4py import MPI
from paraview.simple import Calculator, ColorBy, Contour, CreateRenderView, GetColorTransferFunction, Show, Wavelet

import rtvis
import rtvis_view

out_dir = sys.argv[1]
comm = MPI.COMM_WORLD
view = CreateRenderView()
view.ViewSize = [400, 300]
wavelet = Wavelet(WholeExtent=[-16, 16, -16, 16, -16, 16])
contour = Contour(Input=wavelet, ContourBy=["POINTS", "RTData"], Isosurfaces=[120.0, 170.0, 220.0],
                  ComputeNormals=0)
height = Calculator(Input=contour, ResultArrayName="height", Function="coordsY")
shown = Show(height, view)
ColorBy(shown, ("POINTS", "height"))
GetColorTransferFunction("height").RescaleTransferFunction(-16.0, 16.0)
shown.Interpolation = "Flat"  # facet normals: the same on every piece
view.CameraPosition = [45.0, 32.0, 70.0]
view.CameraFocalPoint = [0.0, 0.0, 0.0]
view.CameraViewUp = [0.0, 1.0, 0.0]
view.CameraViewAngle = 30.0

triangles = comm.gather(height.GetClientSideObject().GetOutputDataObject(0).GetNumberOfCells()
                        if height.GetClientSideObject().GetOutputDataObject(0) else 0, root=0)
result = rtvis_view.raytrace(view)
n = comm.Get_size()
if comm.Get_rank() == 0:
    rgba, depth = result
    np.savez(os.path.join(out_dir, f"view-{n}.npz"), rgba=rgba, depth=depth)
    rtvis.save_png(os.path.join(out_dir, f"view-{n}.png"), rtvis.to_srgb8(rgba))
    hit = np.isfinite(depth).mean()
    print(f"rtvis_view on {n} ranks, triangles per rank {triangles}: {hit:.0%} of pixels hit")
    assert 0.1 < hit < 0.9, hit
else:
    assert result is None
