"""ParaView filters backed by rtvis: RT Schlieren, RT BOS, RT Focusing
Schlieren and RT Surface Render.

Load with Tools → Manage Plugins → Load New (this file), or put this
folder on ``PV_PLUGIN_PATH`` to load it at start-up, or from Python::

    import rtvis_pvcompat            # ParaView 5.11 on Python 3.11, see there
    from paraview.simple import *
    LoadPlugin("/path/to/rtvis_plugin.py", ns=globals())

``rtvis`` must be importable by ParaView's Python (``pip install`` it for
that Python, or put the folder it was installed into on ``PYTHONPATH``).

Under MPI (``mpirun -np N pvbatch --symmetric script.py``), RT Surface
Render renders each rank's own piece and depth-composites the pieces with
rt-composite over ParaView's MPI world (through mpi4py); the camera and the
colour-map range are reduced over all ranks, so the image equals the
one-process render of the whole data. Rank 0's output holds the image, the
other ranks' outputs are empty.
"""

import json
import math
import re

import numpy as np
from paraview.util.vtkAlgorithm import smdomain, smhint, smproperty, smproxy
from vtkmodules.numpy_interface import dataset_adapter as dsa
from vtkmodules.util import numpy_support
from vtkmodules.util.vtkAlgorithm import VTKPythonAlgorithmBase
from vtkmodules.vtkCommonCore import vtkStringArray
from vtkmodules.vtkCommonDataModel import vtkDataObject, vtkDataSet, vtkImageData, vtkPolyData
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline
from vtkmodules.vtkFiltersCore import vtkTriangleFilter
from vtkmodules.vtkFiltersGeometry import vtkGeometryFilter
from vtkmodules.vtkParallelCore import vtkMultiProcessController

_CUTOFFS = ["knife", "graded", "pinhole", "dark-field", "color", "none", "interferometry"]
_AXES = ["x", "y", "z"]
_MAPS = ["cool_to_warm", "viridis", "grayscale"]


def _enum(name, command, entries, default, doc):
    items = "".join(f'<Entry value="{i}" text="{t}"/>' for i, t in enumerate(entries))
    return smproperty.xml(
        f'<IntVectorProperty name="{name}" command="{command}" number_of_elements="1" '
        f'default_values="{default}"><EnumerationDomain name="enum">{items}</EnumerationDomain>'
        f"<Documentation>{doc}</Documentation></IntVectorProperty>"
    )


def _doc(text):
    """The property's tooltip (ParaView shows a property's Documentation
    as its tooltip); units in it."""
    return smdomain.xml(f"<Documentation>{text}</Documentation>")


def _array_selection(name, attribute, doc):
    return smproperty.xml(
        f'<StringVectorProperty name="{name}" command="SetInputArrayToProcess" number_of_elements="5" '
        f'element_types="0 0 0 0 2" animateable="0">'
        f'<ArrayListDomain name="array_list" attribute_type="{attribute}" input_domain_name="input_array">'
        f'<RequiredProperties><Property name="Input" function="Input"/></RequiredProperties>'
        f"</ArrayListDomain><Documentation>{doc}</Documentation></StringVectorProperty>"
    )


def _image_output(out_info, w, h, spacing, origin):
    out_info.GetInformationObject(0).Set(
        vtkStreamingDemandDrivenPipeline.WHOLE_EXTENT(), 0, w - 1, 0, h - 1, 0, 0)
    out_info.GetInformationObject(0).Set(vtkDataObject.SPACING(), spacing[0], spacing[1], 1.0)
    out_info.GetInformationObject(0).Set(vtkDataObject.ORIGIN(), origin[0], origin[1], 0.0)


def _add_array(image, name, values, components):
    """Adds a (h, w[, c]) numpy image (row 0 at the top) as point data,
    flipped so row 0 is at the bottom as VTK images have it."""
    flat = np.ascontiguousarray(values[::-1]).reshape(-1, components) if components > 1 \
        else np.ascontiguousarray(values[::-1]).reshape(-1)
    arr = numpy_support.numpy_to_vtk(flat, deep=True)
    arr.SetName(name)
    image.GetPointData().AddArray(arr)
    return arr


def _selected_array(algorithm, data):
    """The array chosen for input array 0 (``SetInputArrayToProcess``;
    ``GetInputArrayToProcess`` is not wrapped for Python), or None."""
    info = algorithm.GetInputArrayInformation(0)
    name = info.Get(vtkDataObject.FIELD_NAME()) if info.Has(vtkDataObject.FIELD_NAME()) else None
    if not name:
        return None
    cells = info.Get(vtkDataObject.FIELD_ASSOCIATION()) == vtkDataObject.FIELD_ASSOCIATION_CELLS
    return (data.GetCellData() if cells else data.GetPointData()).GetArray(name)


def _rank():
    """(rank, size) of ParaView's processes (0, 1 without MPI)."""
    ctrl = vtkMultiProcessController.GetGlobalController()
    return (ctrl.GetLocalProcessId(), ctrl.GetNumberOfProcesses()) if ctrl else (0, 1)


def _world():
    """(rank, size, mpi4py communicator or None) of ParaView's processes."""
    ctrl = vtkMultiProcessController.GetGlobalController()
    if ctrl is None or ctrl.GetNumberOfProcesses() < 2:
        return 0, 1, None
    from mpi4py import MPI

    comm = MPI.COMM_WORLD
    return comm.Get_rank(), comm.Get_size(), comm


def _display_defaults():
    """Shows the optics images as photographs rather than through a
    colour map: grey, with fixed ranges (1 = the undisturbed background
    at mid-grey for ``Intensity`` and ``Relative``, 0–1 for ``Fringes``,
    ``Flow`` and ``Reference``), kept across time steps. ParaView picks a
    lookup table by array name; these are settings for this session only,
    below the user's and the site's own (which win), never saved."""
    try:
        from paraview.servermanager import vtkSMSettings
    except ImportError:  # a process without the server manager
        return

    def grey(top):
        return {"PVLookupTable": {"RGBPoints": [0.0, 0.0, 0.0, 0.0, top, 1.0, 1.0, 1.0], "ColorSpace": "RGB",
                                  "AutomaticRescaleRangeMode": -1, "ScalarRangeInitialized": 1}}

    tables = {"Intensity": grey(2.0), "Relative": grey(2.0), "Fringes": grey(1.0), "Flow": grey(1.0),
              "Reference": grey(1.0)}
    vtkSMSettings.GetInstance().AddCollectionFromString(json.dumps({"array_lookup_tables": tables}), 0.25)


_display_defaults()


def _rgb_as_is():
    """Shows the colour images (``RGB``, 8-bit sRGB: RT Surface Render,
    RT Schlieren's colour filter) as they are, not through a colour map:
    when ParaView colours a display of theirs by ``RGB`` (as it does on
    Apply, ``RGB`` being their active scalars), Map Scalars is unticked,
    once per display, so the user's own later choice stands. ParaView 5.11
    has no per-filter default for Map Scalars, so this watches the proxy
    manager: the colour map that colouring registers is the cue."""
    try:
        from paraview import servermanager
        from paraview.servermanager import vtkSMProxyManager
    except ImportError:  # a process without the server manager
        return
    done = set()

    def look(_object, _event):
        if servermanager.ActiveConnection is None:
            return
        for rep in servermanager.ProxyManager().GetProxiesInGroup("representations").values():
            key = rep.GetGlobalID()
            if key in done or rep.GetProperty("MapScalars") is None or rep.GetProperty("Input") is None:
                continue
            source = rep.Input
            colour = rep.GetProperty("ColorArrayName")
            if source is None or colour is None or source.GetXMLName() not in ("RTSurfaceRender", "RTSchlieren"):
                continue
            if list(colour)[-1] == "RGB":
                done.add(key)
                rep.MapScalars = 0

    vtkSMProxyManager.GetProxyManager().AddObserver("RegisterEvent", look)


_rgb_as_is()


class _Aborted(Exception):
    """ParaView asked the filter to abort (its progress bar's button)."""


class _VolumeInput:
    """What every optics filter shares: the volume (array, quantity,
    interpolation), the view (axis, size, seed), the image's geometry,
    progress and abort, and the optics it chose (shown, and locked
    across a time series on request). The properties are declared once
    here and copied into each filter's class (``_volume_filter``), since
    ParaView reads a proxy's properties from the class's own dict."""

    _quantity, _k, _cubic, _nonphysical, _axis, _size, _seed = 0, 2.26e-4, 1, 0, 2, 512, 1
    _lock, _locked, _chosen, _across = 0, None, "", 1

    def _set(self, name, value):
        if getattr(self, name) != value:
            setattr(self, name, value)
            self._locked = None  # other optics: choose again
            self.Modified()

    @_array_selection("Array", "Scalars", "The volume's scalar: density (kg/m³) or refractive index.")
    def SetInputArrayToProcess(self, idx, port, connection, field, name):
        self._locked = None
        return VTKPythonAlgorithmBase.SetInputArrayToProcess(self, idx, port, connection, field, name)

    @_enum("Quantity", "SetQuantity", ["Density (Gladstone-Dale)", "Refractive index"], 0,
           "What the array holds; density is mapped by n = 1 + K·ρ.")
    def SetQuantity(self, v):
        self._set("_quantity", int(v))

    @smproperty.doublevector(name="K", default_values=[2.26e-4])
    @smdomain.doublerange(min=0.0)
    @_doc("Gladstone–Dale constant K in m³/kg (n = 1 + K·ρ); 2.26e-4 is air at visible wavelengths. Used for density only.")
    def SetK(self, v):
        self._set("_k", float(v))

    @_enum("Axis", "SetAxis", ["x", "y", "z"], 2, "Beam direction.")
    def SetAxis(self, v):
        self._set("_axis", int(v))

    @smproperty.intvector(name="Size", default_values=[512])
    @smdomain.intrange(min=1, max=16384)
    @_doc("Image width in pixels (the height follows the volume's aspect).")
    def SetSize(self, v):
        self._set("_size", int(v))

    @smproperty.intvector(name="Seed", default_values=[1])
    @_doc("Random seed of the photon jitter: the same seed gives the same image, bit for bit, at any thread count.")
    def SetSeed(self, v):
        self._set("_seed", int(v))

    @_enum("Interpolation", "SetInterpolation", ["Trilinear", "Catmull-Rom cubic"], 1,
           "Interpolation between samples: Catmull-Rom (C1, smooth shadowgraphs) by default; "
           "trilinear is about twice as fast but its gradient jumps at cell faces.")
    def SetInterpolation(self, v):
        self._set("_cubic", int(v))

    @smproperty.intvector(name="AllowNonphysical", default_values=[0])
    @smdomain.xml('<BooleanDomain name="bool"/>')
    @_doc("Accept samples no gas has (negative density, an index below 1) instead of refusing the volume.")
    def SetAllowNonphysical(self, v):
        self._set("_nonphysical", int(v))

    @smproperty.intvector(name="LockExposure", default_values=[0])
    @smdomain.xml('<BooleanDomain name="bool"/>')
    @_doc("Keep the optics chosen automatically (knife-edge height, film distance, grid pitch, …) from the next render on, across the time steps of a series, instead of choosing them per step (which flickers). Changing another property chooses again.")
    def SetLockExposure(self, v):
        v = int(v)
        if v != self._lock:
            self._lock, self._locked = v, None
            self.Modified()

    @smproperty.xml('<StringVectorProperty name="ChosenOptics" command="GetChosenOptics" '
                    'information_only="1" number_of_elements="1"><SimpleStringInformationHelper/>'
                    "<Documentation>The optics the last render used, automatic choices made explicit.</Documentation>"
                    "</StringVectorProperty>")
    def GetChosenOptics(self):
        return self._chosen

    def _geometry(self, in_info):
        """(dims, origin, spacing) of the samples: points, or cell centres
        for cell data; and the image's (w, h, pixel size, origin) over the
        volume's cross-section."""
        info = in_info[0].GetInformationObject(0)
        ext = info.Get(vtkStreamingDemandDrivenPipeline.WHOLE_EXTENT())
        spacing = np.array(info.Get(vtkDataObject.SPACING()), dtype=np.float64)
        origin = np.array(info.Get(vtkDataObject.ORIGIN()), dtype=np.float64)
        dims = np.array([ext[1] - ext[0] + 1, ext[3] - ext[2] + 1, ext[5] - ext[4] + 1])
        origin = origin + spacing * np.array([ext[0], ext[2], ext[4]])
        arr_info = self.GetInputArrayInformation(0)
        if arr_info.Get(vtkDataObject.FIELD_ASSOCIATION()) == vtkDataObject.FIELD_ASSOCIATION_CELLS:
            dims = np.maximum(dims - 1, 1)
            origin = origin + 0.5 * spacing
        lo, hi = origin - 0.5 * spacing, origin + (dims - 0.5) * spacing  # as rt's Grid::bounds
        u, v = {0: (1, 2), 1: (2, 0), 2: (0, 1)}[self._axis]
        width, height = hi[u] - lo[u], hi[v] - lo[v]
        w = self._size
        h = max(1, int(math.floor(w * height / width + 0.5)))
        px = (width / w, height / h)
        return dims, origin, spacing, (w, h, px, (lo[u] + 0.5 * px[0], lo[v] + 0.5 * px[1]))

    def RequestInformation(self, request, in_info, out_info):
        *_, (w, h, px, o) = self._geometry(in_info)
        _image_output(out_info, w, h, px, o)
        return 1

    @smproperty.intvector(name="AcrossRanks", default_values=[1])
    @smdomain.xml('<BooleanDomain name="bool"/>')
    @_doc("Under MPI (pvbatch, pvserver): each rank reads only its brick of the volume (point data) and the photons or camera rays are handed from rank to rank, so the image is the same on any number of ranks. Rays are traced exactly through the grid (no skipping of still air), so it differs slightly from one process's render. RT Schlieren does this for a knife edge at 0° with its height chosen, or interferometry, along z; its knife edge is then chosen from the photons' deflections, not from a survey. Off: rank 0 reads the whole volume.")
    def SetAcrossRanks(self, v):
        self._set("_across", int(v))

    def _supports_pieces(self):
        """Whether these optics can be rendered across ranks."""
        return True

    def _pieces(self):
        """Whether this render hands rays across ranks (AcrossRanks)."""
        # pvbatch and pvserver ranks, at any count; not pvpython or the
        # GUI's built-in server (MPI-enabled too, but one process).
        from paraview.modules.vtkRemotingCore import vtkProcessModule

        kind = vtkProcessModule.GetProcessType()
        ranks = (vtkProcessModule.PROCESS_BATCH, vtkProcessModule.PROCESS_SERVER,
                 vtkProcessModule.PROCESS_DATA_SERVER)
        ctrl = vtkMultiProcessController.GetGlobalController()
        mpi = kind in ranks and ctrl is not None and ctrl.IsA("vtkMPIController")
        cells = self.GetInputArrayInformation(0).Get(vtkDataObject.FIELD_ASSOCIATION()) == \
            vtkDataObject.FIELD_ASSOCIATION_CELLS
        return bool(self._across) and mpi and not cells and self._supports_pieces()

    def _whole(self, in_info):
        """The whole grid: (whole extent, shape (nz, ny, nx), spacing,
        origin of its first sample)."""
        info = in_info[0].GetInformationObject(0)
        ext = info.Get(vtkStreamingDemandDrivenPipeline.WHOLE_EXTENT())
        spacing = tuple(float(v) for v in info.Get(vtkDataObject.SPACING()))
        origin = tuple(o + h * e for o, h, e in zip(info.Get(vtkDataObject.ORIGIN()), spacing, ext[::2]))
        shape = (ext[5] - ext[4] + 1, ext[3] - ext[2] + 1, ext[1] - ext[0] + 1)
        return ext, shape, spacing, origin

    def RequestUpdateExtent(self, request, in_info, out_info):
        sddp = vtkStreamingDemandDrivenPipeline
        info = in_info[0].GetInformationObject(0)
        rank, size = _rank()
        if self._pieces():
            import rtvis

            # This rank's brick and its ghost layers, as one piece.
            ext, shape, spacing, origin = self._whole(in_info)
            (z0, y0, x0), (z1, y1, x1) = rtvis.brick_box(shape, size, rank, spacing, origin,
                                                         ["linear", "cubic"][self._cubic])
            info.Set(sddp.UPDATE_PIECE_NUMBER(), 0)
            info.Set(sddp.UPDATE_NUMBER_OF_PIECES(), 1)
            info.Set(sddp.UPDATE_EXTENT(), ext[0] + x0, ext[0] + x1 - 1, ext[2] + y0, ext[2] + y1 - 1,
                     ext[4] + z0, ext[4] + z1 - 1)
        elif rank == 0:
            # Rank 0 renders: it asks for the whole volume as one piece (a
            # reader under MPI would otherwise hand it its piece only); the
            # other ranks keep their own piece, unused, and output nothing,
            # so N ranks take one rank's time instead of N renders
            # contending for the cores.
            info.Set(sddp.UPDATE_PIECE_NUMBER(), 0)
            info.Set(sddp.UPDATE_NUMBER_OF_PIECES(), 1)
            info.Set(sddp.UPDATE_EXTENT(), info.Get(sddp.WHOLE_EXTENT()), 6)
        return 1

    def _piece(self, in_info, label):
        """This rank's piece of the chosen array, ``[z, y, x]``; its first
        sample's index in the whole grid ``(z, y, x)``; the whole grid's
        shape, spacing and origin."""
        ext, shape, spacing, origin = self._whole(in_info)
        data = vtkImageData.GetData(in_info[0], 0)
        array = _selected_array(self, data)
        if array is None:
            raise ValueError(f"{label}: choose a scalar array (Array)")
        e = data.GetExtent()
        piece = numpy_support.vtk_to_numpy(array).reshape(e[5] - e[4] + 1, e[3] - e[2] + 1, e[1] - e[0] + 1)
        start = (e[4] - ext[4], e[2] - ext[2], e[0] - ext[0])
        return piece, start, shape, spacing, origin

    def _render_pieces(self, run, options, in_info, out_info, label):
        """``run`` (an ``rtvis.*_pieces`` function) of this rank's piece
        with ``options`` (the locked optics, if any, on every rank alike);
        rank 0 gets the images, the others ``None`` and an empty output."""
        from mpi4py import MPI

        comm = MPI.COMM_WORLD
        piece, start, shape, spacing, origin = self._piece(in_info, label)
        if self._lock and self._locked is not None:
            options = {**options, **self._locked}
        stopped, out = self._watched(run, piece, start, shape, comm, spacing=spacing, origin=origin,
                                     quantity=["density", "index"][self._quantity], k=self._k,
                                     interpolation=["linear", "cubic"][self._cubic], chosen=True, **options)
        if stopped:
            vtkImageData.GetData(out_info).SetExtent(0, -1, 0, -1, 0, -1)
            return None
        # Rank 0's choice on every rank: a locked rig must be the same
        # everywhere, or the ranks would ask for different rays.
        chosen = comm.bcast(None if out is None else (dict(out[-1]), out[-1].description), root=0)
        if self._lock and self._locked is None:
            self._locked = chosen[0]
        self._chosen = f"across {comm.Get_size()} ranks: {chosen[1]}"
        if out is None:
            vtkImageData.GetData(out_info).SetExtent(0, -1, 0, -1, 0, -1)
            return None
        return out[:-1]

    def _watched(self, run, *args, **kwargs):
        """``(stopped, run(*args, progress=…, **kwargs))`` across ranks:
        rank 0 reports progress to ParaView and stops every rank on its
        abort; stopped is True (and the result None) on rank 0 then, and
        on the others, which hear only that rank 0 stopped (when it failed
        instead, it says why itself)."""
        try:
            return False, run(*args, progress=self._progress, **kwargs)
        except _Aborted:
            return True, None
        except ValueError as e:
            if _rank()[0] != 0 and re.search(r"^rank \d+: rank 0 failed", str(e)):
                return True, None
            raise

    def _idle(self, out_info):
        """True on a rank other than 0, its output left empty (see
        ``RequestUpdateExtent``)."""
        if _rank()[0] == 0:
            return False
        vtkImageData.GetData(out_info).SetExtent(0, -1, 0, -1, 0, -1)
        return True

    def _volume(self, in_info, label):
        """The rtvis.Volume of the chosen array; the image's geometry."""
        import rtvis

        dims, origin, spacing, image = self._geometry(in_info)
        array = _selected_array(self, vtkImageData.GetData(in_info[0], 0))
        if array is None:
            raise ValueError(f"{label}: choose a scalar array (Array)")
        values = numpy_support.vtk_to_numpy(array).reshape(dims[2], dims[1], dims[0])
        try:
            vol = rtvis.Volume(values, spacing=tuple(spacing), origin=tuple(origin),
                               quantity=["density", "index"][self._quantity], k=self._k,
                               interpolation=["linear", "cubic"][self._cubic],
                               allow_nonphysical=bool(self._nonphysical))
        except ValueError as e:
            # rtvis names its keywords; here they are properties.
            what = str(e).split("; check quantity=")[0]
            raise ValueError(f"{label}: {what}; check Quantity, or tick Allow Nonphysical") from e
        return vol, image

    def _progress(self, done, total):
        """rtvis's progress callback: ParaView's progress bar, its abort."""
        self.UpdateProgress(done / total if total else 1.0)
        if self.GetAbortExecute():
            raise _Aborted()

    def _render(self, render, vol, options):
        """``render(vol, **options)`` with the locked optics if any (else
        choosing them, and locking them when asked), reporting progress
        to ParaView and honouring its abort; ``None`` if aborted."""
        if self._lock and self._locked is not None:
            options = {**options, **self._locked}
        try:
            *out, chosen = render(vol, chosen=True, progress=self._progress, **options)
        except _Aborted:
            return None
        if self._lock and self._locked is None:
            self._locked = dict(chosen)
        self._chosen = chosen.description
        return out

    def _image(self, out_info, image, arrays, label):
        """The output image over the volume's cross-section: ``arrays``
        ``(name, (h, w[, c]) array)``, the first one active, and the
        chosen optics as field data."""
        w, h, px, o = image
        out = vtkImageData.GetData(out_info)
        out.SetExtent(0, w - 1, 0, h - 1, 0, 0)
        out.SetSpacing(px[0], px[1], 1.0)
        out.SetOrigin(o[0], o[1], 0.0)
        for i, (name, values) in enumerate(arrays):
            if values.shape[:2] != (h, w):
                raise RuntimeError(f"{label}: image {values.shape[:2]} differs from the announced {(h, w)}")
            arr = _add_array(out, name, values, values.shape[2] if values.ndim == 3 else 1)
            if i == 0:
                out.GetPointData().SetScalars(arr)
        said = vtkStringArray()
        said.SetName("ChosenOptics")
        said.InsertNextValue(self._chosen)
        out.GetFieldData().AddArray(said)
        return 1


def _volume_filter(cls):
    """Copies the shared properties into ``cls``'s own dict (see
    :class:`_VolumeInput`), ahead of ParaView's proxy decorator."""
    for name, value in vars(_VolumeInput).items():
        if callable(value) and name.startswith(("Set", "Get")) and name not in vars(cls):
            setattr(cls, name, value)
    return cls


@smproxy.filter(name="RTSchlieren", label="RT Schlieren")
@smhint.xml('<ShowInMenu category="rt"/>')
@smproperty.input(name="Input", port_index=0)
@smdomain.datatype(dataTypes=["vtkImageData"], composite_data_supported=False)
@smdomain.xml('<InputArrayDomain name="input_array" number_of_components="1"/>')
@_volume_filter
class RTSchlieren(_VolumeInput, VTKPythonAlgorithmBase):
    """Synthetic schlieren, shadowgraph, interferogram or colour schlieren
    of a volume (density or refractive index) by rtvis: photons traced
    along curved paths through the field. Output: a 2-D image with
    ``Intensity`` (1 = undisturbed background; for the colour filter
    ``RGB``, 8-bit sRGB for display, and ``LinearRGB``, float; ``Fringes``, 0–1, and ``Phase``, radians unwrapped, for
    interferometry) and ``Deflection`` (radians, along the image's axes),
    shown in grey as a photograph (see ``_display_defaults``)."""

    def __init__(self):
        VTKPythonAlgorithmBase.__init__(self, nInputPorts=1, nOutputPorts=1, outputType="vtkImageData")
        self._cutoff, self._angle = 0, 0.0
        self._f, self._h, self._film, self._wavelength, self._fringes = 1.0, 0.0, 0.0, 10.6e-6, 0.0
        self._photons = 16

    @_enum("Cutoff", "SetCutoff", ["Knife edge", "Graded filter", "Pinhole", "Dark field", "Colour (hue wheel)",
                                   "None (shadowgraph)", "Interferometry"], 0, "The optical set-up.")
    def SetCutoff(self, v):
        self._set("_cutoff", int(v))

    @smproperty.doublevector(name="Angle", default_values=[0.0])
    @_doc("Knife-edge (or graded filter) orientation in degrees, counter-clockwise from the image's +x axis.")
    def SetAngle(self, v):
        self._set("_angle", float(v))

    @smproperty.doublevector(name="FocalLength", default_values=[1.0])
    @_doc("Focal length of the schlieren head in metres: the cutoff sees deflection × focal length.")
    def SetFocalLength(self, v):
        self._set("_f", float(v))

    @smproperty.doublevector(name="SourceHeight", default_values=[0.0])
    @_doc("Unobstructed source height at the cutoff in metres (knife edge, graded filter; the pinhole's and dark field's radius). 0: chosen from the data (automatic exposure).")
    def SetSourceHeight(self, v):
        self._set("_h", float(v))

    @smproperty.doublevector(name="FilmDistance",
                             default_values=[0.0])
    @_doc("Distance in metres from the test section to the film: the shadowgraph's (0: chosen from the data), or the schlieren film's defocus (0: focused on the test section).")
    def SetFilmDistance(self, v):
        self._set("_film", float(v))

    @smproperty.doublevector(name="Wavelength", default_values=[10.6e-6])
    @_doc("Wavelength in metres (interferometry). 10.6e-6 is a CO₂ laser.")
    def SetWavelength(self, v):
        self._set("_wavelength", float(v))

    @smproperty.doublevector(name="FringeSpacing",
                             default_values=[0.0])
    @_doc("Spacing of the reference fringes in metres (interferometry). 0: chosen from the data.")
    def SetFringeSpacing(self, v):
        self._set("_fringes", float(v))

    @smproperty.intvector(name="Photons", default_values=[16])
    @smdomain.intrange(min=1, max=65536)
    @_doc("Photons traced per pixel (jittered): more is smoother, time grows with it.")
    def SetPhotons(self, v):
        self._set("_photons", int(v))

    def _supports_pieces(self):
        knife = _CUTOFFS[self._cutoff] == "knife" and self._angle == 0.0 and self._h == 0.0 and self._film == 0.0
        fringes = _CUTOFFS[self._cutoff] == "interferometry" and self._film == 0.0
        return self._axis == 2 and (knife or fringes)

    def _across_ranks(self, in_info, out_info):
        """The image with photons handed across ranks (``_pieces``)."""
        import rtvis
        from mpi4py import MPI

        piece, start, shape, spacing, origin = self._piece(in_info, "RT Schlieren")
        fringes = _CUTOFFS[self._cutoff] == "interferometry"
        _, image = self._watched(
            rtvis.schlieren_pieces, piece, start, shape, MPI.COMM_WORLD, spacing=spacing, origin=origin,
            quantity=["density", "index"][self._quantity], k=self._k, interpolation=["linear", "cubic"][self._cubic],
            cutoff="interferometry" if fringes else "knife", wavelength=self._wavelength,
            fringe_spacing=self._fringes or None, size=self._size,
            strata=max(1, math.ceil(math.sqrt(self._photons))), seed=self._seed)
        if image is None:
            vtkImageData.GetData(out_info).SetExtent(0, -1, 0, -1, 0, -1)
            return 1
        ranks = MPI.COMM_WORLD.Get_size()
        self._chosen = f"across {ranks} ranks: " + (
            f"interferometry, λ = {self._wavelength} m" if fringes
            else "knife edge at 0°, its height from the photons' deflections (0.5 ± 0.45 at the 99th percentile)")
        *_, geometry = self._geometry(in_info)
        return self._image(out_info, geometry, [("Fringes" if fringes else "Intensity", image)], "RT Schlieren")

    def RequestData(self, request, in_info, out_info):
        import rtvis

        if self._pieces():
            return self._across_ranks(in_info, out_info)
        if self._idle(out_info):
            return 1
        vol, image = self._volume(in_info, "RT Schlieren")
        cutoff = _CUTOFFS[self._cutoff]
        common = dict(axis=_AXES[self._axis], size=self._size, photons=self._photons, seed=self._seed,
                      deflection=True)
        if cutoff == "none":
            out = self._render(rtvis.shadowgraph, vol, dict(distance=self._film or None, **common))
        elif cutoff == "interferometry":
            out = self._render(rtvis.interferogram, vol, dict(
                wavelength=self._wavelength, fringe_spacing=self._fringes or None, phase=True, **common))
        else:
            out = self._render(rtvis.schlieren, vol, dict(
                cutoff=cutoff, angle=self._angle, f=self._f, h=self._h or None, film_distance=self._film,
                **common))
        if out is None:
            return 1
        img, eps, *phase = out
        if img.ndim == 3:
            # 8-bit sRGB first: with Map Scalars unticked ParaView shows
            # unsigned char colours as they are (float ones not at all).
            opaque = np.concatenate([img, np.ones_like(img[..., :1])], axis=-1)
            arrays = [("RGB", rtvis.to_srgb8(opaque)), ("LinearRGB", img)]
        else:
            arrays = [("Fringes" if cutoff == "interferometry" else "Intensity", img)]
        arrays += [("Deflection", eps)]
        arrays += [("Phase", p) for p in phase]
        return self._image(out_info, image, arrays, "RT Schlieren")


@smproxy.filter(name="RTBOS", label="RT BOS")
@smhint.xml('<ShowInMenu category="rt"/>')
@smproperty.input(name="Input", port_index=0)
@smdomain.datatype(dataTypes=["vtkImageData"], composite_data_supported=False)
@smdomain.xml('<InputArrayDomain name="input_array" number_of_components="1"/>')
@_volume_filter
class RTBOS(_VolumeInput, VTKPythonAlgorithmBase):
    """Background-oriented schlieren of a volume by rtvis, set up as ``rt
    bos`` sets it up (a laboratory rig where left at 0). Output: an image
    with ``Displacement`` (the background's apparent motion from the
    reference to the flow image, pixels, x right and y up as shown),
    ``Flow`` and ``Reference`` (the background seen with and without the
    flow, 0–1), placed over the volume's cross-section."""

    def __init__(self):
        VTKPythonAlgorithmBase.__init__(self, nInputPorts=1, nOutputPorts=1, outputType="vtkImageData")
        self._background, self._fnumber, self._focal, self._pixel = 0, 16.0, 0.0, 0.0
        self._distance, self._zd, self._dot, self._spacing, self._samples = 0.0, 0.0, 3.0, 4.0, 2

    @_enum("Background", "SetBackground", ["Random dots", "Grid of dots"], 0, "The background pattern.")
    def SetBackground(self, v):
        self._set("_background", int(v))

    @smproperty.doublevector(name="FNumber", default_values=[16.0])
    @smdomain.doublerange(min=0.0)
    @_doc("The lens's f-number N (dimensionless): larger keeps the background sharp through the flow.")
    def SetFNumber(self, v):
        self._set("_fnumber", float(v))

    @smproperty.doublevector(name="FocalLength", default_values=[0.0])
    @_doc("The lens's focal length in metres. 0: the usual lens that fills the image with the volume about 1.5 m away.")
    def SetFocalLength(self, v):
        self._set("_focal", float(v))

    @smproperty.doublevector(name="PixelPitch", default_values=[0.0])
    @_doc("The sensor's pixel pitch in metres. 0: a 2048 × 5.5 µm sensor binned to Size pixels.")
    def SetPixelPitch(self, v):
        self._set("_pixel", float(v))

    @smproperty.doublevector(name="CameraDistance", default_values=[0.0])
    @_doc("From the lens to the volume's centre (Z_A), metres. 0: chosen with the lens.")
    def SetCameraDistance(self, v):
        self._set("_distance", float(v))

    @smproperty.doublevector(name="BackgroundDistance", default_values=[0.0])
    @_doc("From the volume's centre to the background (Z_D), metres. 0: chosen so the strongest 1 % of deflections move the background 4 pixels.")
    def SetBackgroundDistance(self, v):
        self._set("_zd", float(v))

    @smproperty.doublevector(name="Dot", default_values=[3.0])
    @_doc("Dot diameter as imaged, pixels.")
    def SetDot(self, v):
        self._set("_dot", float(v))

    @smproperty.doublevector(name="DotSpacing", default_values=[4.0])
    @_doc("Mean dot spacing as imaged, pixels.")
    def SetDotSpacing(self, v):
        self._set("_spacing", float(v))

    @smproperty.intvector(name="Samples", default_values=[2])
    @smdomain.intrange(min=1, max=64)
    @_doc("k: k² aperture samples per pixel (the lens's blur).")
    def SetSamples(self, v):
        self._set("_samples", int(v))

    def RequestData(self, request, in_info, out_info):
        import rtvis

        options = dict(axis=_AXES[self._axis], size=self._size, seed=self._seed, f_number=self._fnumber,
                       focal_length=self._focal or None, pixel=self._pixel or None,
                       distance=self._distance or None, background_distance=self._zd or None, dot=self._dot,
                       spacing=self._spacing, samples=self._samples,
                       background=["random", "grid"][self._background])
        if self._pieces():
            *_, image = self._geometry(in_info)
            options["dot_spacing"] = options.pop("spacing")  # bos_pieces's spacing is the grid's
            out = self._render_pieces(rtvis.bos_pieces, options, in_info, out_info, "RT BOS")
        elif self._idle(out_info):
            return 1
        else:
            vol, image = self._volume(in_info, "RT BOS")
            out = self._render(rtvis.bos, vol, options)
        if out is None:
            return 1
        reference, flow, disp, _ = out
        shown = np.stack([disp[..., 0], -disp[..., 1]], axis=-1)  # y up, as ParaView shows the image
        return self._image(out_info, image, [("Displacement", shown), ("Flow", flow), ("Reference", reference)],
                           "RT BOS")


@smproxy.filter(name="RTFocusingSchlieren", label="RT Focusing Schlieren")
@smhint.xml('<ShowInMenu category="rt"/>')
@smproperty.input(name="Input", port_index=0)
@smdomain.datatype(dataTypes=["vtkImageData"], composite_data_supported=False)
@smdomain.xml('<InputArrayDomain name="input_array" number_of_components="1"/>')
@_volume_filter
class RTFocusingSchlieren(_VolumeInput, VTKPythonAlgorithmBase):
    """Focusing schlieren (a lens-and-grid system) of a volume by rtvis,
    set up as ``rt focusing`` sets it up. Output: an image with
    ``Relative`` (I/I₀: 1 undisturbed), ``Flow`` and ``Reference``,
    placed over the volume's cross-section."""

    def __init__(self):
        VTKPythonAlgorithmBase.__init__(self, nInputPorts=1, nOutputPorts=1, outputType="vtkImageData")
        self._focus, self._aperture, self._focal, self._source, self._pitch = 0.0, 0.0, 0.0, 0.0, 0.0
        self._duty, self._angle, self._offset, self._samples = 0.5, 0.0, 0.25, 6

    @smproperty.doublevector(name="Focus", default_values=[0.0])
    @_doc("The plane in focus: its distance from the volume's centre toward the lens, metres (negative: beyond the centre).")
    def SetFocus(self, v):
        self._set("_focus", float(v))

    @smproperty.doublevector(name="Aperture", default_values=[0.0])
    @_doc("The lens's diameter, metres; larger focuses more sharply. 0: f/2.")
    def SetAperture(self, v):
        self._set("_aperture", float(v))

    @smproperty.doublevector(name="FocalLength", default_values=[0.0])
    @_doc("The schlieren lens's focal length, metres. 0: a quarter of the camera distance.")
    def SetFocalLength(self, v):
        self._set("_focal", float(v))

    @smproperty.doublevector(name="SourceDistance", default_values=[0.0])
    @_doc("From the lens to the source grid, metres, beyond the focus plane. 0: twice the focus plane's distance.")
    def SetSourceDistance(self, v):
        self._set("_source", float(v))

    @smproperty.doublevector(name="Pitch", default_values=[0.0])
    @_doc("The source grid's period on its plane, metres. 0: chosen from the flow (the strongest 1 % of deflections use 80 % of the linear range).")
    def SetPitch(self, v):
        self._set("_pitch", float(v))

    @smproperty.doublevector(name="Duty", default_values=[0.5])
    @smdomain.doublerange(min=0.0, max=1.0)
    @_doc("Bright fraction of each grid period (dimensionless, between 0 and 1).")
    def SetDuty(self, v):
        self._set("_duty", float(v))

    @smproperty.doublevector(name="Angle", default_values=[0.0])
    @_doc("Band orientation in degrees: 0, bands along the image's vertical (sensitive to horizontal deflection).")
    def SetAngle(self, v):
        self._set("_angle", float(v))

    @smproperty.doublevector(name="Offset", default_values=[0.25])
    @smdomain.doublerange(min=0.0, max=1.0)
    @_doc("The cutoff grid's shift across the bands, in pitches (0 is dark field).")
    def SetOffset(self, v):
        self._set("_offset", float(v))

    @smproperty.intvector(name="Samples", default_values=[6])
    @smdomain.intrange(min=1, max=64)
    @_doc("k: k² aperture samples per pixel.")
    def SetSamples(self, v):
        self._set("_samples", int(v))

    def RequestData(self, request, in_info, out_info):
        import rtvis

        options = dict(axis=_AXES[self._axis], size=self._size, seed=self._seed, focus=self._focus,
                       aperture=self._aperture or None, focal_length=self._focal or None,
                       source_distance=self._source or None, pitch=self._pitch or None, duty=self._duty,
                       angle=self._angle, offset=self._offset, samples=self._samples)
        if self._pieces():
            *_, image = self._geometry(in_info)
            out = self._render_pieces(rtvis.focusing_pieces, options, in_info, out_info, "RT Focusing Schlieren")
        elif self._idle(out_info):
            return 1
        else:
            vol, image = self._volume(in_info, "RT Focusing Schlieren")
            out = self._render(rtvis.focusing, vol, options)
        if out is None:
            return 1
        reference, flow, relative, _ = out
        return self._image(out_info, image, [("Relative", relative), ("Flow", flow), ("Reference", reference)],
                           "RT Focusing Schlieren")


@smproxy.filter(name="RTSurfaceRender", label="RT Surface Render")
@smhint.xml('<ShowInMenu category="rt"/>')
@smproperty.input(name="Input", port_index=0)
@smdomain.datatype(dataTypes=["vtkDataSet"], composite_data_supported=False)
@smdomain.xml('<InputArrayDomain name="input_array" attribute_type="point" number_of_components="1"/>')
class RTSurfaceRender(VTKPythonAlgorithmBase):
    """Ray-traces the input's surface by rtvis: polygons as triangles
    (coloured by a point array through a colour map), lines as tubes,
    vertices as spheres; with ambient occlusion and shadows. Output: an
    image with ``RGB`` (8-bit sRGB over white, for display), ``RGBA``
    (linear premultiplied float) and ``Depth`` (inf = background). Under
    MPI each rank renders its piece and the pieces are depth-composited."""

    def __init__(self):
        VTKPythonAlgorithmBase.__init__(self, nInputPorts=1, nOutputPorts=1, outputType="vtkImageData")
        self._colored, self._map, self._color = 1, 0, (0.8, 0.8, 0.8)
        self._custom_range, self._range = 0, (0.0, 1.0)
        self._size = (512, 512)
        self._direction, self._up, self._angle = (0.0, 0.0, 1.0), (0.0, 1.0, 0.0), 30.0
        self._ao, self._ao_distance, self._shadows, self._passes, self._seed = 0, 0.0, 1, 1, 0
        self._normals, self._sphere_radius, self._tube_radius = 0, 0.0, 0.0

    def _set(self, name, value):
        if getattr(self, name) != value:
            setattr(self, name, value)
            self.Modified()

    @_array_selection("ColorArray", "Scalars", "Point array to colour by.")
    def SetInputArrayToProcess(self, idx, port, connection, field, name):
        return VTKPythonAlgorithmBase.SetInputArrayToProcess(self, idx, port, connection, field, name)

    @smproperty.intvector(name="ColorByArray", default_values=[1])
    @smdomain.xml('<BooleanDomain name="bool"/>')
    @_doc("Colour by the chosen point array through the colour map; off: the solid colour.")
    def SetColorByArray(self, v):
        self._set("_colored", int(v))

    @_enum("ColorMap", "SetColorMap", ["Cool to Warm", "Viridis", "Grayscale"], 0, "Colour map.")
    def SetColorMap(self, v):
        self._set("_map", int(v))

    @smproperty.doublevector(name="SolidColor", default_values=[0.8, 0.8, 0.8])
    @_doc("Colour (linear RGB, 0–1) when not coloured by an array.")
    def SetSolidColor(self, r, g, b):
        self._set("_color", (float(r), float(g), float(b)))

    @smproperty.intvector(name="UseCustomRange", default_values=[0])
    @smdomain.xml('<BooleanDomain name="bool"/>')
    @_doc("Map the array over Range instead of its range over all ranks.")
    def SetUseCustomRange(self, v):
        self._set("_custom_range", int(v))

    @smproperty.doublevector(name="Range", default_values=[0.0, 1.0])
    @_doc("Array values at the colour map's two ends (in the array's units), with UseCustomRange.")
    def SetRange(self, lo, hi):
        self._set("_range", (float(lo), float(hi)))

    @smproperty.intvector(name="ImageSize", default_values=[512, 512])
    @_doc("Image width and height in pixels.")
    def SetImageSize(self, w, h):
        self._set("_size", (int(w), int(h)))

    @smproperty.doublevector(name="ViewDirection",
                             default_values=[0.0, 0.0, 1.0])
    @_doc("Direction from the data toward the camera (any length); the camera frames the data's bounds.")
    def SetViewDirection(self, x, y, z):
        self._set("_direction", (float(x), float(y), float(z)))

    @smproperty.doublevector(name="ViewUp", default_values=[0.0, 1.0, 0.0])
    @_doc("Up direction of the image.")
    def SetViewUp(self, x, y, z):
        self._set("_up", (float(x), float(y), float(z)))

    @smproperty.doublevector(name="ViewAngle", default_values=[30.0])
    @_doc("Vertical field of view in degrees.")
    def SetViewAngle(self, v):
        self._set("_angle", float(v))

    @smproperty.intvector(name="AOSamples", default_values=[0])
    @smdomain.intrange(min=0, max=64)
    @_doc("Ambient-occlusion rays per pixel and pass (0: off).")
    def SetAOSamples(self, v):
        self._set("_ao", int(v))

    @smproperty.doublevector(name="AODistance",
                             default_values=[0.0])
    @_doc("Longest ambient-occlusion ray in the data's units (0: a tenth of the bounds' diagonal).")
    def SetAODistance(self, v):
        self._set("_ao_distance", float(v))

    @smproperty.intvector(name="Shadows", default_values=[1])
    @smdomain.xml('<BooleanDomain name="bool"/>')
    @_doc("Shadow rays toward the light.")
    def SetShadows(self, v):
        self._set("_shadows", int(v))

    @smproperty.intvector(name="Passes", default_values=[1])
    @smdomain.intrange(min=1, max=256)
    @_doc("Progressive passes averaged (anti-aliasing, less AO noise).")
    def SetPasses(self, v):
        self._set("_passes", int(v))

    @smproperty.intvector(name="Seed", default_values=[0])
    @_doc("Random seed of the pixel jitter and AO rays: the same seed gives the same image at any thread and rank count.")
    def SetSeed(self, v):
        self._set("_seed", int(v))

    @_enum("Normals", "SetNormals", ["Data's Normals array, else smooth", "Smooth (averaged)", "Flat"], 0,
           "Shading normals. Flat shading is the same whichever rank holds a triangle's neighbours.")
    def SetNormals(self, v):
        self._set("_normals", int(v))

    @smproperty.doublevector(name="SphereRadius",
                             default_values=[0.0])
    @_doc("Radius of the spheres drawn for vertices, in the data's units (0: 0.5 % of the bounds' diagonal).")
    def SetSphereRadius(self, v):
        self._set("_sphere_radius", float(v))

    @smproperty.doublevector(name="TubeRadius",
                             default_values=[0.0])
    @_doc("Radius of the tubes drawn for lines, in the data's units (0: 0.2 % of the bounds' diagonal).")
    def SetTubeRadius(self, v):
        self._set("_tube_radius", float(v))

    def FillInputPortInformation(self, port, info):
        info.Set(self.INPUT_REQUIRED_DATA_TYPE(), "vtkDataSet")
        return 1

    def RequestInformation(self, request, in_info, out_info):
        w, h = self._size
        _image_output(out_info, w, h, (1.0, 1.0), (0.0, 0.0))
        return 1

    def RequestUpdateExtent(self, request, in_info, out_info):
        # This process's piece of the input, whatever part of the image is
        # asked for (the image is whole on rank 0).
        rank, size = _rank()
        info = in_info[0].GetInformationObject(0)
        sddp = vtkStreamingDemandDrivenPipeline
        info.Set(sddp.UPDATE_PIECE_NUMBER(), rank)
        info.Set(sddp.UPDATE_NUMBER_OF_PIECES(), size)
        info.Set(sddp.UPDATE_NUMBER_OF_GHOST_LEVELS(), 0)
        if info.Has(sddp.UPDATE_EXTENT()):
            info.Remove(sddp.UPDATE_EXTENT())
        return 1

    def _surface(self, in_info):
        data = vtkDataSet.GetData(in_info[0], 0)
        if not isinstance(data, vtkPolyData):
            g = vtkGeometryFilter()
            g.SetInputData(data)
            g.Update()
            data = g.GetOutput()
        return data

    def RequestData(self, request, in_info, out_info):
        import rtvis

        rank, size, comm = _world()
        poly = self._surface(in_info)
        points = numpy_support.vtk_to_numpy(poly.GetPoints().GetData()) if poly.GetNumberOfPoints() else np.zeros((0, 3))
        scalars = None
        if self._colored:
            array = _selected_array(self, vtkDataSet.GetData(in_info[0], 0))
            if array is not None:
                name = array.GetName()
                pa = poly.GetPointData().GetArray(name) if name else None
                if pa is not None:
                    scalars = numpy_support.vtk_to_numpy(pa).astype(np.float64)
                    if scalars.ndim == 2:
                        scalars = np.linalg.norm(scalars, axis=1)
        # Bounds and scalar range over every rank (a rank may hold nothing).
        lo = points.min(axis=0) if len(points) else np.full(3, np.inf)
        hi = points.max(axis=0) if len(points) else np.full(3, -np.inf)
        finite = scalars[np.isfinite(scalars)] if scalars is not None else np.zeros(0)
        srange = np.array([finite.min(), finite.max()]) if len(finite) else np.array([np.inf, -np.inf])
        if comm is not None:
            from mpi4py import MPI

            # One reduction each, on every rank, before anything can raise.
            mins = np.ascontiguousarray(np.concatenate([lo, srange[:1]]), dtype=np.float64)
            maxs = np.ascontiguousarray(np.concatenate([hi, srange[1:]]), dtype=np.float64)
            comm.Allreduce(MPI.IN_PLACE, mins, op=MPI.MIN)
            comm.Allreduce(MPI.IN_PLACE, maxs, op=MPI.MAX)
            lo, hi, srange = mins[:3], maxs[:3], np.array([mins[3], maxs[3]])
        w, h = self._size
        out = vtkImageData.GetData(out_info)
        if not np.all(lo <= hi):
            raise ValueError("RT Surface Render: the input has no points on any rank")
        diag = float(np.linalg.norm(hi - lo)) or 1.0
        if self._custom_range:
            rng = self._range
        elif srange[0] < srange[1]:
            rng = (float(srange[0]), float(srange[1]))
        elif np.isfinite(srange[0]):
            rng = (float(srange[0]) - 0.5, float(srange[0]) + 0.5)
        else:
            rng = (0.0, 1.0)
        paint = dict(scalars=None, color=self._color) if scalars is None else \
            dict(scalars=scalars, colormap=_MAPS[self._map], range=rng)

        scene = rtvis.Scene()
        tri = vtkTriangleFilter()
        tri.SetInputData(poly)
        tri.PassVertsOff()
        tri.PassLinesOff()
        tri.Update()
        polys = tri.GetOutput().GetPolys()
        if polys.GetNumberOfCells():
            t = numpy_support.vtk_to_numpy(polys.GetConnectivityArray()).reshape(-1, 3)
            normals = poly.GetPointData().GetNormals()
            smooth = self._normals != 2
            mesh_paint = dict(paint)
            if scalars is not None:
                mesh_paint["scalars"] = scalars
            scene.add_mesh(points, t, smooth=smooth and (normals is None or self._normals == 1),
                           normals=numpy_support.vtk_to_numpy(normals) if (normals is not None and self._normals == 0) else None,
                           **mesh_paint)
        lines = poly.GetLines()
        if lines.GetNumberOfCells():
            off = numpy_support.vtk_to_numpy(lines.GetOffsetsArray())
            con = numpy_support.vtk_to_numpy(lines.GetConnectivityArray())
            radius = self._tube_radius or 0.002 * diag
            for a, b in zip(off[:-1], off[1:]):
                ids = con[a:b]
                if len(ids) >= 2:
                    scene.add_tubes(points[ids], radius, **({**paint, "scalars": scalars[ids]} if scalars is not None else paint))
        verts = poly.GetVerts()
        if verts.GetNumberOfCells():
            ids = numpy_support.vtk_to_numpy(verts.GetConnectivityArray())
            radius = self._sphere_radius or 0.005 * diag
            scene.add_spheres(points[ids], radius, **({**paint, "scalars": scalars[ids]} if scalars is not None else paint))

        camera = rtvis.Camera.fit((tuple(lo), tuple(hi)), direction=self._direction, up=self._up,
                                  fov=self._angle, aspect=w / h)
        if len(scene):
            rgba, depth = scene.render(camera, size=(w, h), ao=self._ao,
                                       ao_distance=self._ao_distance or 0.1 * diag,
                                       shadows=bool(self._shadows), passes=self._passes, seed=self._seed)
        else:  # this rank's piece is empty: it still takes part in compositing
            rgba, depth = np.zeros((h, w, 4), np.float32), np.full((h, w), np.inf, np.float32)
        if comm is not None:
            result = rtvis.composite_mpi(rgba, depth, comm=comm)
            if result is None:
                out.SetExtent(0, -1, 0, -1, 0, -1)
                return 1
            rgba, depth = result
        out.SetExtent(0, w - 1, 0, h - 1, 0, 0)
        out.SetSpacing(1.0, 1.0, 1.0)
        out.SetOrigin(0.0, 0.0, 0.0)
        rgb = _add_array(out, "RGB", rtvis.to_srgb8(rgba), 3)
        _add_array(out, "RGBA", rgba, 4)
        _add_array(out, "Depth", depth, 1)
        out.GetPointData().SetScalars(rgb)
        return 1
