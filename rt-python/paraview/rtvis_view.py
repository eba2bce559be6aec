"""Ray traces what a ParaView render view shows, with rtvis.

    import rtvis_pvcompat            # ParaView 5.11 on Python 3.11
    from paraview.simple import *
    import rtvis_view
    ...                              # the pipeline, shown in a render view
    rtvis_view.save("view.png")      # the active view, ray traced

Every visible representation of the view is traced as ParaView shows it:
its surface as triangles, with its colouring (the array ParaView colours
by, through the view's own lookup table and range, point or cell data,
vector magnitude or component; or its solid colour) and opacity; lines
(and Wireframe / Outline representations) as tubes ``LineWidth`` pixels
across, vertices (and the Points representation) as spheres
``PointSize`` pixels across. The camera is the view's (position, focal
point, view-up, view angle, parallel projection and scale), the image
the view's size over its background; ``shadows``, ``ao`` and ``passes``
are rtvis's. Lights: a head light and an ambient term like ParaView's
light kit, or ``lights="flat"`` (every surface its own colour: what
ParaView shows with Ambient 1, Diffuse 0).

Under ``mpirun … pvbatch --symmetric`` every rank traces the pieces it
holds and rt-composite merges them by depth (through mpi4py): rank 0 gets
the image, equal bit for bit to one process tracing everything.
"""

import numpy as np
from vtkmodules.util import numpy_support
from vtkmodules.vtkCommonDataModel import vtkCompositeDataSet, vtkPolyData
from vtkmodules.vtkFiltersCore import vtkAppendPolyData, vtkExtractEdges, vtkTriangleFilter
from vtkmodules.vtkFiltersGeometry import vtkGeometryFilter
from vtkmodules.vtkFiltersModeling import vtkOutlineFilter
from vtkmodules.vtkParallelCore import vtkMultiProcessController

import rtvis

# Lookup-table samples per colour map: ParaView interpolates in its own
# colour space (diverging, Lab, …); 256 samples follow it within 8 bits.
_LUT_SAMPLES = 256


def _linear(srgb):
    """sRGB (0–1, as ParaView's colour properties hold them) to linear."""
    c = np.asarray(srgb, dtype=np.float64)
    return tuple(np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4))


def _world():
    ctrl = vtkMultiProcessController.GetGlobalController()
    if ctrl is None or ctrl.GetNumberOfProcesses() < 2:
        return None
    from mpi4py import MPI

    return MPI.COMM_WORLD


def camera_of(view):
    """The rtvis camera of a render view (its camera properties)."""
    parallel = bool(view.CameraParallelProjection)
    return rtvis.Camera(tuple(view.CameraPosition), tuple(view.CameraFocalPoint), tuple(view.CameraViewUp),
                        fov=float(view.CameraViewAngle),
                        ortho_height=2.0 * float(view.CameraParallelScale) if parallel else None)


def _pixel(view, camera, height):
    """World units per pixel at the focal point."""
    if camera.ortho_height is not None:
        return camera.ortho_height / height
    d = float(np.linalg.norm(np.subtract(camera.target, camera.eye)))
    return 2.0 * d * np.tan(np.radians(camera.fov) / 2.0) / height


def _local_data(rep, time):
    """This process's data for ``rep`` at ``time`` (its piece under MPI),
    as one vtkPolyData of its surface (blocks of composite data
    appended)."""
    prop = rep.GetProperty("Input")
    source = prop.GetProxy(0)
    port = prop.GetOutputPortForConnection(0)
    source.UpdatePipeline(time)  # what a render of the view would update
    data = source.GetClientSideObject().GetOutputDataObject(port)
    blocks = []
    if isinstance(data, vtkCompositeDataSet):
        it = data.NewIterator()
        it.InitTraversal()
        while not it.IsDoneWithTraversal():
            blocks.append(it.GetCurrentDataObject())
            it.GoToNextItem()
    elif data is not None:
        blocks.append(data)
    polys = []
    for b in blocks:
        if b is None or b.GetNumberOfPoints() == 0:
            continue
        if not isinstance(b, vtkPolyData):
            g = vtkGeometryFilter()
            g.SetInputData(b)
            g.Update()
            b = g.GetOutput()
        polys.append(b)
    if len(polys) == 1:
        return polys[0]
    out = vtkAppendPolyData()
    for p in polys:
        out.AddInputData(p)
    out.Update()
    return out.GetOutput()


def _paint(rep, poly):
    """``(paint, point_values, cell_values)``: the keyword arguments every
    rtvis object takes (a solid linear colour, or stops and range of the
    view's lookup table), and the scalar per point or per cell that the
    colouring reads (None for a solid colour)."""
    assoc, name = rep.ColorArrayName
    lut = rep.LookupTable
    if name and lut is not None:
        attrs = poly.GetCellData() if assoc == "CELLS" else poly.GetPointData()
        array = attrs.GetArray(name)
        if array is not None:
            values = numpy_support.vtk_to_numpy(array).astype(np.float64)
            if values.ndim == 2:
                values = values[:, int(lut.VectorComponent)] if lut.VectorMode == "Component" \
                    else np.linalg.norm(values, axis=1)
            points = list(lut.RGBPoints)
            lo, hi = float(points[0]), float(points[-4])
            ctf = lut.GetClientSideObject()
            rgb = [0.0, 0.0, 0.0]
            stops = []
            for i in range(_LUT_SAMPLES):
                t = i / (_LUT_SAMPLES - 1)
                ctf.GetColor(lo + t * (hi - lo), rgb)
                stops.append((t, rgb[0], rgb[1], rgb[2]))
            paint = dict(colormap=np.array(stops, np.float32), range=(lo, hi) if lo < hi else (lo - 0.5, lo + 0.5))
            return paint, (None if assoc == "CELLS" else values), (values if assoc == "CELLS" else None)
    return dict(color=_linear(rep.DiffuseColor)), None, None


def _material(rep, flat):
    opacity = float(rep.Opacity)
    if flat:
        return {"diffuse": 1.0, "specular": 0.0, "shininess": 1.0, "opacity": opacity, "mirror": 0.0}
    return {"diffuse": 1.0, "specular": float(rep.Specular), "shininess": max(float(rep.SpecularPower), 1.0),
            "opacity": opacity, "mirror": 0.0}


def _add(scene, rep, pixel, flat, time):
    """Adds ``rep``'s visible geometry to ``scene``; whether it held any."""
    poly = _local_data(rep, time)
    if poly is None or poly.GetNumberOfPoints() == 0:
        return False
    kind = rep.Representation
    if kind == "Outline":
        f = vtkOutlineFilter()
        f.SetInputData(poly)
        f.Update()
        poly = f.GetOutput()
    elif kind == "Wireframe":
        f = vtkExtractEdges()
        f.SetInputData(poly)
        f.Update()
        poly = f.GetOutput()
    paint, per_point, per_cell = _paint(rep, poly)
    material = _material(rep, flat)
    points = numpy_support.vtk_to_numpy(poly.GetPoints().GetData()).astype(np.float32)
    added = False
    if kind == "Points":
        radius = 0.5 * float(rep.PointSize) * pixel
        s = {} if per_point is None else {"scalars": per_point}
        scene.add_spheres(points, radius, material=material, **paint, **s)
        return True
    tri = vtkTriangleFilter()
    tri.SetInputData(poly)
    tri.PassVertsOff()
    tri.PassLinesOff()
    tri.Update()
    surface = tri.GetOutput()
    if surface.GetNumberOfPolys():
        t = numpy_support.vtk_to_numpy(surface.GetPolys().GetConnectivityArray()).reshape(-1, 3)
        if per_cell is not None:
            # Cell data: each triangle its own corners, one colour.
            cells = numpy_support.vtk_to_numpy(surface.GetCellData().GetArray(rep.ColorArrayName[1]))
            cells = cells.astype(np.float64)
            if cells.ndim == 2:
                lut = rep.LookupTable
                cells = cells[:, int(lut.VectorComponent)] if lut.VectorMode == "Component" \
                    else np.linalg.norm(cells, axis=1)
            scene.add_mesh(points[t].reshape(-1, 3), np.arange(3 * len(t)).reshape(-1, 3),
                           scalars=np.repeat(cells, 3), smooth=False, material=material, **paint)
        else:
            s = {} if per_point is None else {"scalars": per_point}
            # The data's own normals where it has them (a contour's), as
            # ParaView shades with them: the same on every piece.
            normals = surface.GetPointData().GetNormals()
            gouraud = rep.Interpolation == "Gouraud"
            n = numpy_support.vtk_to_numpy(normals).astype(np.float32) if normals is not None and gouraud else None
            scene.add_mesh(points, t, smooth=gouraud and n is None, normals=n, material=material, **paint, **s)
        added = True
    radius = 0.5 * float(rep.LineWidth) * pixel
    lines = poly.GetLines()
    if lines.GetNumberOfCells():
        off = numpy_support.vtk_to_numpy(lines.GetOffsetsArray())
        con = numpy_support.vtk_to_numpy(lines.GetConnectivityArray())
        for cell, (a, b) in enumerate(zip(off[:-1], off[1:])):
            ids = con[a:b]
            if len(ids) < 2:
                continue
            if per_point is not None:
                s = {"scalars": per_point[ids]}
            elif per_cell is not None:
                s = {"scalars": np.full(len(ids), per_cell[poly.GetNumberOfVerts() + cell])}
            else:
                s = {}
            scene.add_tubes(points[ids], radius, material=material, **paint, **s)
            added = True
    verts = poly.GetVerts()
    if verts.GetNumberOfCells():
        ids = numpy_support.vtk_to_numpy(verts.GetConnectivityArray())
        s = {} if per_point is None else {"scalars": per_point[ids]}
        scene.add_spheres(points[ids], 0.5 * float(rep.PointSize) * pixel, material=material, **paint, **s)
        added = True
    return added


def raytrace(view=None, shadows=False, ao=0, passes=1, lights="view", seed=0, size=None):
    """``(rgba, depth)`` of ``view`` (default: the active view) ray traced
    by rtvis: premultiplied linear RGBA (h, w, 4) and the distance to
    the first hit (inf: background), both float32, the view's size (or
    ``size = (w, h)``). Under MPI, rank 0 gets the image and the others
    ``None``."""
    import paraview.simple as pvs

    view = view or pvs.GetActiveView()
    w, h = (int(v) for v in (size or view.ViewSize))
    camera = camera_of(view)
    pixel = _pixel(view, camera, h)
    flat = lights == "flat"
    scene = rtvis.Scene()
    held = False
    for rep in view.Representations:
        if rep.GetProperty("Input") is None or rep.GetProperty("Visibility") is None or not rep.Visibility:
            continue
        if rep.GetProperty("Representation") is None or rep.GetProperty("ColorArrayName") is None:
            continue  # not a geometry representation (scalar bars, …)
        held = _add(scene, rep, pixel, flat, float(view.ViewTime)) or held
    if flat:
        light_list = [("ambient", (1.0, 1.0, 1.0))]
    else:
        toward = np.subtract(camera.eye, camera.target)
        light_list = [("ambient", (0.2, 0.2, 0.2)), ("directional", tuple(toward), (0.8, 0.8, 0.8))]
    if held:
        rgba, depth = scene.render(camera, size=(w, h), ao=int(ao), shadows=bool(shadows), passes=int(passes),
                                   seed=int(seed), lights=light_list)
    else:  # nothing here: this rank still takes part in compositing
        rgba, depth = np.zeros((h, w, 4), np.float32), np.full((h, w), np.inf, np.float32)
    comm = _world()
    if comm is not None:
        return rtvis.composite_mpi(rgba, depth, comm=comm)
    return rgba, depth


def save(path, view=None, **options):
    """Writes ``view`` ray traced (``raytrace``'s options) as an 8-bit
    sRGB PNG over the view's background (rank 0 under MPI)."""
    import paraview.simple as pvs

    view = view or pvs.GetActiveView()
    result = raytrace(view, **options)
    if result is None:
        return None
    rgba, depth = result
    rtvis.save_png(path, rtvis.to_srgb8(rgba, background=_linear(view.Background)))
    return rgba, depth


_PANE = """\
# A ray-traced copy of the render view {name!r} (rtvis_view.show).
def setup_data(view):
    pass


def render(view, width, height):
    import numpy as np
    import paraview.simple as pvs
    from paraview import python_view
    import rtvis
    import rtvis_view

    source = pvs.FindView({name!r})
    if source is None:
        return None
    rgba, _ = rtvis_view.raytrace(source, size=(width, height), **{options!r})
    rgb = rtvis.to_srgb8(rgba, background=rtvis_view._linear(source.Background))
    image = np.dstack([rgb, np.full(rgb.shape[:2], 255, np.uint8)])[::-1]
    return python_view.numpy_to_image(np.ascontiguousarray(image))
"""


def show(view=None, **options):
    """A Python view (ParaView's ``PythonView``) beside ``view`` (default:
    the active render view) that shows it ray traced, ``raytrace``'s
    ``options`` applied (``shadows``, ``ao``, ``passes``, ``lights``), at
    the pane's own size; it re-traces whenever ParaView renders it (a
    change of the pipeline, the pane resized). In one process (the GUI
    without a server, pvpython). Returns the Python view."""
    import paraview.simple as pvs
    from paraview import servermanager

    view = view or pvs.GetActiveView()
    name = servermanager.ProxyManager().GetProxyName("views", view)
    unknown = set(options) - {"shadows", "ao", "passes", "lights", "seed"}
    if unknown:
        raise TypeError(f"rtvis_view.show: unknown options {sorted(unknown)}")
    pane = pvs.CreateView("PythonView")
    pane.Script = _PANE.format(name=name, options=options)
    return pane


__all__ = ["camera_of", "raytrace", "save", "show"]
