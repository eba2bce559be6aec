"""The optics filters under MPI with a real reader (run by run-tests.sh):

    mpirun -np N pvbatch --symmetric pvbatch_optics.py OUT_DIR

Rank 0 writes a density bump as a .vti file; every rank reads it with
ParaView's XML reader and applies RT Schlieren, RT BOS and RT Focusing
Schlieren, each rank reading only its brick and the photons or camera
rays handed across ranks. Rank 0 checks each image against one process
holding the whole grid (bit for bit) and writes OUT_DIR/optics-N.npz,
which run-tests.sh compares, bit for bit, across N; each filter's time
is printed."""

import os
import sys
import time

import rtvis_pvcompat  # noqa: F401

import numpy as np
from mpi4py import MPI
from paraview.simple import LoadPlugin, XMLImageDataReader
from vtkmodules.util import numpy_support
from vtkmodules.vtkCommonDataModel import vtkImageData
from vtkmodules.vtkIOXML import vtkXMLImageDataWriter

HERE = os.path.dirname(os.path.abspath(__file__))
out_dir = sys.argv[1]
comm = MPI.COMM_WORLD
rank, n = comm.Get_rank(), comm.Get_size()
LoadPlugin(os.path.join(HERE, "..", "rtvis_plugin.py"), ns=globals())

path = os.path.join(out_dir, "bump.vti")
if rank == 0:
    z, y, x = (np.indices((40, 48, 56)) - np.array([20, 24, 28])[:, None, None, None]) * 1e-3
    rho = 1.2 + 0.4 * np.exp(-(x**2 + y**2 + z**2) / (2 * 0.008**2))
    image = vtkImageData()
    image.SetDimensions(56, 48, 40)
    image.SetSpacing(1e-3, 1e-3, 1e-3)
    image.SetOrigin(-0.028, -0.024, -0.020)
    array = numpy_support.numpy_to_vtk(rho.ravel(), deep=True)
    array.SetName("density")
    image.GetPointData().SetScalars(array)
    writer = vtkXMLImageDataWriter()
    writer.SetFileName(path)
    writer.SetInputData(image)
    writer.Write()
comm.Barrier()

reader = XMLImageDataReader(FileName=[path])
filters = {
    "schlieren": (RTSchlieren(Input=reader, Array=["POINTS", "density"], Size=256, Photons=16), "Intensity"),
    "bos": (RTBOS(Input=reader, Array=["POINTS", "density"], Size=128), "Displacement"),
    "focusing": (RTFocusingSchlieren(Input=reader, Array=["POINTS", "density"], Size=96, Samples=3), "Relative"),
}
got = {}
for name, (proxy, array) in filters.items():
    comm.Barrier()
    t = time.perf_counter()
    proxy.UpdatePipeline()
    comm.Barrier()
    took = time.perf_counter() - t
    # Rays handed across ranks: each rank read its brick.
    held = comm.gather(reader.GetClientSideObject().GetOutputDataObject(0).GetNumberOfPoints(), root=0)
    if rank == 0:
        print(f"{name} on {n} ranks: each rank read {[f'{h / (56 * 48 * 40):.0%}' for h in held]} of the grid")
        assert n == 1 or max(held) < 56 * 48 * 40, held
    data = proxy.GetClientSideObject().GetOutputDataObject(0)
    values = data.GetPointData().GetArray(array)
    if rank == 0:
        assert values is not None, f"{name}: rank 0 has no {array}"
        got[name] = numpy_support.vtk_to_numpy(values)
        print(f"{name} on {n} ranks: {took:.2f} s, {data.GetNumberOfPoints()} pixels")
    else:
        assert data.GetNumberOfPoints() == 0, f"{name}: rank {rank} should output nothing"
if rank == 0:
    np.savez(os.path.join(out_dir, f"optics-{n}.npz"), **got)
    # The same image as one process holding the whole grid.
    import rtvis

    whole = rtvis.schlieren_pieces(rho.astype(np.float32), (0, 0, 0), rho.shape, MPI.COMM_SELF,
                                   spacing=(1e-3,) * 3, origin=(-0.028, -0.024, -0.020), size=256, strata=4, seed=1)
    shown = got["schlieren"].reshape(whole.shape)[::-1]  # VTK's rows go up
    assert np.array_equal(shown, whole), "RT Schlieren across ranks differs from one process"
    grid = dict(spacing=(1e-3,) * 3, origin=(-0.028, -0.024, -0.020))
    ref, flow, disp, _ = rtvis.bos_pieces(rho.astype(np.float32), (0, 0, 0), rho.shape, MPI.COMM_SELF, size=128,
                                          **grid)
    shown = got["bos"].reshape(disp.shape)[::-1]
    assert np.array_equal(shown[..., 0], disp[..., 0]) and np.array_equal(shown[..., 1], -disp[..., 1]), \
        "RT BOS across ranks differs from one process"
    assert np.abs(disp).max() > 0.1, np.abs(disp).max()
    *_, relative, _ = rtvis.focusing_pieces(rho.astype(np.float32), (0, 0, 0), rho.shape, MPI.COMM_SELF,
                                            size=96, samples=3, **grid)
    assert np.array_equal(got["focusing"].reshape(relative.shape)[::-1], relative), \
        "RT Focusing Schlieren across ranks differs from one process"
    print(f"schlieren, bos, focusing on {n} ranks: equal to one process holding the whole grid")

# Across ranks, rank 0 reports progress to ParaView (ProgressEvent, up to
# 1), and ParaView's abort there stops every rank: each output empty,
# none waiting for the exchange's 60 s timeout.
seen = []
watched = RTSchlieren(Input=reader, Array=["POINTS", "density"], Size=256, Photons=4)
watched.GetClientSideObject().AddObserver("ProgressEvent", lambda o, e: seen.append(o.GetProgress()))
watched.UpdatePipeline()
if rank == 0:
    assert seen and max(seen) == 1.0 and len(set(seen)) > 3, seen
    print(f"progress on {n} ranks: {len(seen)} reports up to {max(seen)}")
else:
    assert not [p for p in seen if 0 < p < 1], f"rank {rank} reported progress {seen}"


def abort(algorithm, _):
    if 0 < algorithm.GetProgress() < 1:
        algorithm.SetAbortExecute(1)


aborted = RTSchlieren(Input=reader, Array=["POINTS", "density"], Size=256, Photons=16, Seed=2)
if rank == 0:
    aborted.GetClientSideObject().AddObserver("ProgressEvent", abort)
comm.Barrier()
t = time.perf_counter()
aborted.UpdatePipeline()
took = comm.gather(time.perf_counter() - t, root=0)
points = comm.gather(aborted.GetClientSideObject().GetOutputDataObject(0).GetNumberOfPoints(), root=0)
if rank == 0:
    assert points == [0] * n, points
    print(f"abort on {n} ranks: every output empty after {max(took):.2f} s (all ranks)")
    assert max(took) < 30.0, took
