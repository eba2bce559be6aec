"""The thesis's set-up inside ParaView (run by run-tests.sh):

    mpirun -np N pvbatch --symmetric pvbatch_surface.py OUT_DIR

ParaView distributes a Wavelet over the N ranks and contours it; RT
Surface Render renders each rank's piece with rtvis (camera and colour
range reduced over all ranks, local lighting) and depth-composites the
pieces with rt-composite over ParaView's MPI world. Rank 0 writes
OUT_DIR/surface-N.png and OUT_DIR/surface-N.npz (RGBA and depth), which
run-tests.sh compares, bit for bit, across N."""

import os
import sys

import rtvis_pvcompat  # noqa: F401

import numpy as np
from mpi4py import MPI
from paraview.simple import Calculator, Contour, LoadPlugin, Wavelet
from vtkmodules.util import numpy_support

import rtvis

HERE = os.path.dirname(os.path.abspath(__file__))
out_dir = sys.argv[1]
comm = MPI.COMM_WORLD
rank, size = comm.Get_rank(), comm.Get_size()
LoadPlugin(os.path.join(HERE, "..", "rtvis_plugin.py"), ns=globals())

wavelet = Wavelet(WholeExtent=[-16, 16, -16, 16, -16, 16])
contour = Contour(Input=wavelet, ContourBy=["POINTS", "RTData"], Isosurfaces=[120.0, 170.0, 220.0],
                  ComputeNormals=0)
height = Calculator(Input=contour, ResultArrayName="height", Function="coordsY")
render = RTSurfaceRender(Input=height, ColorArray=["POINTS", "height"], ImageSize=[400, 300],
                         ViewDirection=[1.0, 0.7, 1.5], Normals=2, Shadows=0, AOSamples=0)
render.UpdatePipeline()

local = height.GetClientSideObject().GetOutputDataObject(0)
triangles = comm.gather(local.GetNumberOfCells(), root=0)
image = render.GetClientSideObject().GetOutputDataObject(0)
if rank == 0:
    ext = image.GetExtent()
    w, h = ext[1] - ext[0] + 1, ext[3] - ext[2] + 1
    pd = image.GetPointData()
    rgba = numpy_support.vtk_to_numpy(pd.GetArray("RGBA")).reshape(h, w, 4)[::-1]
    depth = numpy_support.vtk_to_numpy(pd.GetArray("Depth")).reshape(h, w)[::-1]
    rgb = numpy_support.vtk_to_numpy(pd.GetArray("RGB")).reshape(h, w, 3)[::-1]
    os.makedirs(out_dir, exist_ok=True)
    np.savez(os.path.join(out_dir, f"surface-{size}.npz"), rgba=rgba, depth=depth)
    rtvis.save_png(os.path.join(out_dir, f"surface-{size}.png"), np.ascontiguousarray(rgb))
    print(f"{size} ranks, triangles per rank {triangles}: {w}×{h}, "
          f"{np.isfinite(depth).mean():.0%} of pixels hit; wrote surface-{size}.png")
else:
    assert image.GetNumberOfPoints() == 0  # the image lives on rank 0
