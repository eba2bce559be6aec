"""rtvis_view against ParaView's own raster of the same view (run by
run-tests.sh under xvfb-run): a contour coloured by a point array, a
sphere coloured by a cell array and a solid sphere, flat shading on both
sides (ParaView: Ambient 1, Diffuse 0; rtvis: lights="flat"). The pixels
each covers agree (≥ 99 %), and so do their colours where both cover.

    pvpython pvpython_view.py OUT_DIR
"""

import os
import sys

import rtvis_pvcompat  # noqa: F401

import numpy as np
from paraview.simple import (Calculator, Contour, CreateRenderView, Elevation, GetColorTransferFunction,
                             PointDatatoCellData, SaveScreenshot, Show, Sphere, Wavelet, ColorBy)
from vtkmodules.util import numpy_support
from vtkmodules.vtkIOImage import vtkPNGReader

import rtvis
import rtvis_view

out_dir = sys.argv[1]
os.makedirs(out_dir, exist_ok=True)
W, H = 400, 300

view = CreateRenderView()
view.ViewSize = [W, H]
view.OrientationAxesVisibility = 0
view.Background = [0.32, 0.34, 0.43]
if view.GetProperty("UseColorPaletteForBackground") is not None:
    view.UseColorPaletteForBackground = 0

contour = Contour(Input=Wavelet(), ContourBy=["POINTS", "RTData"], Isosurfaces=[150.0])
height = Calculator(Input=contour, ResultArrayName="height", Function="coordsY")
d1 = Show(height, view)
ColorBy(d1, ("POINTS", "height"))
lut = GetColorTransferFunction("height")
lut.RescaleTransferFunction(-10.0, 10.0)

ball = Elevation(Input=Sphere(Center=[14.0, 0.0, 0.0], Radius=5.0, ThetaResolution=32, PhiResolution=32),
                 LowPoint=[14.0, -5.0, 0.0], HighPoint=[14.0, 5.0, 0.0])
cells = PointDatatoCellData(Input=ball)
d2 = Show(cells, view)
ColorBy(d2, ("CELLS", "Elevation"))
GetColorTransferFunction("Elevation").RescaleTransferFunction(0.0, 1.0)

solid = Sphere(Center=[-14.0, 4.0, 0.0], Radius=4.0, ThetaResolution=32, PhiResolution=32)
d3 = Show(solid, view)
d3.ColorArrayName = ['POINTS', '']
d3.DiffuseColor = [0.9, 0.5, 0.1]
d3.AmbientColor = [0.9, 0.5, 0.1]

for d in (d1, d2, d3):
    d.Ambient, d.Diffuse, d.Specular = 1.0, 0.0, 0.0
    d.SetScalarBarVisibility(view, False)
view.CameraPosition = [0.0, 10.0, 80.0]
view.CameraFocalPoint = [0.0, 0.0, 0.0]
view.CameraViewUp = [0.0, 1.0, 0.0]
view.CameraViewAngle = 30.0



def screenshot(shown, name, w, h):
    """``shown``'s screenshot, written to OUT_DIR/``name`` and read back:
    (h, w, 3) ints, row 0 at the bottom as VTK has it."""
    path = os.path.join(out_dir, name)
    SaveScreenshot(path, shown, ImageResolution=[w, h])
    reader = vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    return numpy_support.vtk_to_numpy(reader.GetOutput().GetPointData().GetScalars()).reshape(h, w, -1)[..., :3] \
        .astype(int)


raster = screenshot(view, "view-paraview.png", W, H)[::-1]

rgba, depth = rtvis_view.raytrace(view, lights="flat")
background = rtvis_view._linear(view.Background)
traced = rtvis.to_srgb8(rgba, background=background).astype(int)
rtvis.save_png(os.path.join(out_dir, "view-rtvis.png"), traced.astype(np.uint8))

bg8 = np.round(np.array(view.Background) * 255).astype(int)
raster_cover = np.abs(raster - bg8).max(axis=2) > 3
traced_cover = np.isfinite(depth)
agree = float((raster_cover == traced_cover).mean())
print(f"coverage: ParaView {raster_cover.mean():.1%}, rtvis {traced_cover.mean():.1%}, agreement {agree:.2%}")
assert 0.15 < traced_cover.mean() < 0.8, traced_cover.mean()
assert agree >= 0.99, agree

# Colours where both cover, a pixel in from every edge (edges are
# antialiased differently).
inner = traced_cover & raster_cover
inner[1:-1, 1:-1] &= inner[:-2, 1:-1] & inner[2:, 1:-1] & inner[1:-1, :-2] & inner[1:-1, 2:]
diff = np.abs(traced - raster)[inner]
print(f"colour: mean |Δ| {diff.mean():.2f} of 255, 99th percentile {np.percentile(diff, 99):.0f}")
assert diff.mean() < 4.0 and np.percentile(diff, 99) < 24, (diff.mean(), np.percentile(diff, 99))
print("rtvis_view: the ray-traced view agrees with ParaView's raster")
# The same view with a head light, shadows and ambient occlusion.
rtvis_view.save(os.path.join(out_dir, "view-rtvis-lit.png"), view, shadows=True, ao=8, passes=4)
print("wrote view-paraview.png, view-rtvis.png (flat) and view-rtvis-lit.png")

# The ray-traced pane beside the view (a PythonView): its screenshot is
# the view ray traced at the pane's size.
from paraview.simple import Render  # noqa: E402

pane = rtvis_view.show(view, lights="flat")
pane.ViewSize = [W, H]
Render(pane)
got = screenshot(pane, "view-pane.png", W, H)[::-1]
same = float((np.abs(got - traced).max(axis=2) <= 1).mean())
print(f"the ray-traced pane: {same:.2%} of pixels as rtvis_view.raytrace")
assert same > 0.99, same

# The colour schlieren's RGB (8-bit sRGB) shown as it is by default (Map
# Scalars unticked): the render view draws its colours as they are.
from paraview.simple import Hide, LoadPlugin  # noqa: E402

LoadPlugin(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "rtvis_plugin.py"), ns=globals())
bump = Calculator(Input=Wavelet(WholeExtent=[-24, 23, -24, 23, -24, 23]), ResultArrayName="density",
                  Function="1.2 + 0.3*exp(-((coordsX*0.001)^2+(coordsY*0.001)^2+(coordsZ*0.001)^2)/(2*0.008^2))")
colour = RTSchlieren(Input=bump, Array=["POINTS", "density"], Cutoff=4, Size=64)  # noqa: F821
colour.UpdatePipeline()
out = colour.GetClientSideObject().GetOutputDataObject(0)
rgb = numpy_support.vtk_to_numpy(out.GetPointData().GetArray("RGB")).reshape(64, 64, 3)
for d in (d1, d2, d3):
    Hide(d.Input, view)
shown = Show(colour, view)
# As shown by default: coloured by RGB, Map Scalars unticked by the plugin.
assert list(shown.ColorArrayName) == ["POINTS", "RGB"] and shown.MapScalars == 0, \
    (list(shown.ColorArrayName), shown.MapScalars)
b = out.GetBounds()
view.CameraPosition = [(b[0] + b[1]) / 2, (b[2] + b[3]) / 2, 100.0]
view.CameraFocalPoint = [(b[0] + b[1]) / 2, (b[2] + b[3]) / 2, 0.0]
view.CameraViewUp = [0.0, 1.0, 0.0]
view.CameraParallelProjection = 1
view.CameraParallelScale = (b[3] - b[2] + out.GetSpacing()[1]) / 2  # the image fills the view's height
view.ViewSize = [H, H]
Render(view)
shot = screenshot(view, "view-colour-schlieren.png", H, H)
# Each image pixel's centre in the screenshot, against the array.
centres = ((np.arange(64) + 0.5) * H / 64).astype(int)
seen = shot[np.ix_(centres, centres)]
match = float((np.abs(seen - rgb.astype(int)).max(axis=2) <= 2).mean())
print(f"the colour schlieren shown by default: {match:.1%} of its pixels in their own colour")
assert match > 0.98, match
