"""pvpython test of the filters (run by run-tests.sh): the plugin loads on
a stock ParaView 5.11 + Python 3.11 (through rtvis_pvcompat), RT Schlieren
turns a vtkImageData of density into the same image rtvis makes from the
same samples, and RT Surface Render draws a contour.

    pvpython pvpython_filters.py OUT_DIR
"""

import os
import sys

import rtvis_pvcompat  # noqa: F401  (before anything imports paraview.detail.pythonalgorithm)

import numpy as np
from paraview.simple import LoadPlugin, Contour, Wavelet, Calculator
from vtkmodules.util import numpy_support

import rtvis

HERE = os.path.dirname(os.path.abspath(__file__))
out_dir = sys.argv[1]
os.makedirs(out_dir, exist_ok=True)
LoadPlugin(os.path.join(HERE, "..", "rtvis_plugin.py"), ns=globals())


def arrays(proxy):
    proxy.UpdatePipeline()
    data = proxy.GetClientSideObject().GetOutputDataObject(0)
    ext = data.GetExtent()
    w, h = ext[1] - ext[0] + 1, ext[3] - ext[2] + 1
    pd = data.GetPointData()
    got = {}
    for i in range(pd.GetNumberOfArrays()):
        a = numpy_support.vtk_to_numpy(pd.GetArray(i))
        a = a.reshape((h, w) + a.shape[1:])[::-1]  # row 0 at the top again
        got[pd.GetArrayName(i)] = a
    return got


# A Gaussian density bump as vtkImageData (a Wavelet's grid, its RTData
# replaced by a Calculator expression): 48³ points, 1 mm apart.
src = Wavelet(WholeExtent=[-24, 23, -24, 23, -24, 23])
bump = Calculator(Input=src, ResultArrayName="density",
                  Function="1.2 + 0.3*exp(-((coordsX*0.001)^2+(coordsY*0.001)^2+(coordsZ*0.001)^2)/(2*0.008^2))")
bump.UpdatePipeline()
image = bump.GetClientSideObject().GetOutputDataObject(0)
rho = numpy_support.vtk_to_numpy(image.GetPointData().GetArray("density")).reshape(48, 48, 48)

knife = RTSchlieren(Input=bump, Array=["POINTS", "density"], Cutoff=0, Size=96, Photons=16, Seed=3)
# The Wavelet's own spacing is 1 (unit): the bump is in those units too.
got = arrays(knife)
vol = rtvis.Volume(rho, spacing=(1.0, 1.0, 1.0), origin=(-24.0, -24.0, -24.0))
mine = rtvis.schlieren(vol, cutoff="knife", size=96, photons=16, seed=3)
assert got["Intensity"].shape == mine.shape, (got["Intensity"].shape, mine.shape)
assert np.array_equal(got["Intensity"], mine), "RT Schlieren differs from rtvis.schlieren"
assert got["Deflection"].shape == mine.shape + (2,)
assert mine.min() < 0.8 and mine.max() > 1.2, (mine.min(), mine.max())
rtvis.save_png(os.path.join(out_dir, "paraview-schlieren.png"), rtvis.to_gray8(got["Intensity"]))
print(f"RT Schlieren: {mine.shape[1]}×{mine.shape[0]}, equal to rtvis.schlieren; wrote paraview-schlieren.png")

color = RTSchlieren(Input=bump, Array=["POINTS", "density"], Cutoff=4, Size=64)
rgb = arrays(color)
assert rgb["RGB"].shape == (64, 64, 3) and rgb["RGB"].dtype == np.uint8
lin = rgb["LinearRGB"]
assert np.array_equal(rgb["RGB"], rtvis.to_srgb8(np.dstack([lin, np.ones_like(lin[..., 0])])))
assert rgb["RGB"].std() > 5, "the colour filter shows no colour"
shadow = RTSchlieren(Input=bump, Array=["POINTS", "density"], Cutoff=5, Size=64)
assert arrays(shadow)["Intensity"].std() > 0.01
fringes = arrays(RTSchlieren(Input=bump, Array=["POINTS", "density"], Cutoff=6, Size=64, Wavelength=2e-4))
assert fringes["Phase"].shape == (64, 64) and fringes["Phase"].max() > 2 * np.pi
assert 0.0 <= fringes["Fringes"].min() and fringes["Fringes"].max() <= 1.0 and "Intensity" not in fringes
print("RT Schlieren colour, shadowgraph and interferogram (with its phase): ok")

# BOS and focusing schlieren: the same images as rtvis's from the same
# samples (the displacement shown y up), the chosen optics shown. The
# grid's unit is a metre here: a strong bump deflects enough to see.
strong = Calculator(Input=src, ResultArrayName="density",
                    Function="1.2 + 30*exp(-((coordsX)^2+(coordsY)^2+(coordsZ)^2)/(2*8^2))")
strong.UpdatePipeline()
rho_strong = numpy_support.vtk_to_numpy(
    strong.GetClientSideObject().GetOutputDataObject(0).GetPointData().GetArray("density")).reshape(48, 48, 48)
vol = rtvis.Volume(rho_strong, spacing=(1.0, 1.0, 1.0), origin=(-24.0, -24.0, -24.0))
bos = RTBOS(Input=strong, Array=["POINTS", "density"], Size=64, Background=1)
got = arrays(bos)
ref, flow, disp, _ = rtvis.bos(vol, size=64, background="grid")
assert np.array_equal(got["Flow"], flow) and np.array_equal(got["Reference"], ref)
assert np.array_equal(got["Displacement"][..., 0], disp[..., 0])
assert np.array_equal(got["Displacement"][..., 1], -disp[..., 1])
assert np.abs(disp).max() > 0.5, np.abs(disp).max()
bos.UpdatePropertyInformation()
assert bos.GetPropertyValue("ChosenOptics").startswith("f/16"), bos.GetPropertyValue("ChosenOptics")
focus = RTFocusingSchlieren(Input=strong, Array=["POINTS", "density"], Size=48, Samples=3)
got = arrays(focus)
assert np.array_equal(got["Relative"], rtvis.focusing(vol, size=48, samples=3)[2])
assert got["Relative"].std() > 1e-3
rtvis.save_png(os.path.join(out_dir, "paraview-focusing.png"), rtvis.to_gray8(got["Relative"], white=2.0))
print("RT BOS and RT Focusing Schlieren: equal to rtvis.bos and rtvis.focusing")

# A time series with the exposure locked: the second step keeps the
# first step's knife edge (a stronger flow then shows more contrast)
# where the automatic exposure would choose again.
weak = Calculator(Input=src, ResultArrayName="density",
                  Function="1.2 + 0.15*exp(-((coordsX*0.001)^2+(coordsY*0.001)^2+(coordsZ*0.001)^2)/(2*0.008^2))")
locked = RTSchlieren(Input=weak, Array=["POINTS", "density"], Size=48, Photons=4, LockExposure=1)
first = arrays(locked)["Intensity"]
locked.UpdatePropertyInformation()
chosen_first = locked.GetPropertyValue("ChosenOptics")
locked.Input = bump  # the next time step: the same property values
second = arrays(locked)["Intensity"]
locked.UpdatePropertyInformation()
assert locked.GetPropertyValue("ChosenOptics") == chosen_first, (chosen_first, locked.GetPropertyValue("ChosenOptics"))
auto = arrays(RTSchlieren(Input=bump, Array=["POINTS", "density"], Size=48, Photons=4))["Intensity"]
assert np.abs(second - 1).mean() > 1.5 * np.abs(auto - 1).mean(), "the locked exposure was chosen again"
print(f"LockExposure: {chosen_first} kept across the series")

# Progress reaches ParaView (vtkCommand ProgressEvent, up to 1).
seen = []
algorithm = RTSchlieren(Input=bump, Array=["POINTS", "density"], Size=64, Photons=16)
algorithm.GetClientSideObject().AddObserver("ProgressEvent", lambda o, e: seen.append(o.GetProgress()))
arrays(algorithm)
assert seen and max(seen) == 1.0 and len(set(seen)) > 2, seen
print(f"progress: {len(seen)} reports up to {max(seen)}")

contour = Contour(Input=Wavelet(), ContourBy=["POINTS", "RTData"], Isosurfaces=[130.0, 200.0])
elev = Calculator(Input=contour, ResultArrayName="height", Function="coordsY")
surface = RTSurfaceRender(Input=elev, ColorArray=["POINTS", "height"], ImageSize=[320, 240],
                          AOSamples=4, Shadows=1, ViewDirection=[1.0, 0.8, 1.6])
img = arrays(surface)
assert img["RGBA"].shape == (240, 320, 4) and img["Depth"].shape == (240, 320)
hit = np.isfinite(img["Depth"])
assert 0.1 < hit.mean() < 0.9, hit.mean()
assert np.all(img["RGBA"][~hit] == 0.0) and np.all(img["RGBA"][hit, 3] > 0.99)
rtvis.save_png(os.path.join(out_dir, "paraview-surface.png"), img["RGB"].astype(np.uint8))
print(f"RT Surface Render: 320×240, {hit.mean():.0%} of pixels hit; wrote paraview-surface.png")
# Every property says what it is, with its unit, as a tooltip; the menu
# labels are the README's.
from paraview import servermanager  # noqa: E402

for proxy, label in [(knife, "RT Schlieren"), (bos, "RT BOS"), (focus, "RT Focusing Schlieren"),
                     (surface, "RT Surface Render")]:
    assert proxy.SMProxy.GetXMLLabel() == label, proxy.SMProxy.GetXMLLabel()
    it = proxy.SMProxy.NewPropertyIterator()
    it.Begin()
    undocumented = []
    while not it.IsAtEnd():
        prop = it.GetProperty()
        doc = prop.GetDocumentation()
        if it.GetKey() != "Input" and not prop.GetInformationOnly() and (
                doc is None or not (doc.GetDescription() or "").strip()):
            undocumented.append(it.GetKey())
        it.Next()
    assert not undocumented, f"{label}: no tooltip on {undocumented}"
# Non-physical samples: refused by default, accepted on request.
neg = Calculator(Input=src, ResultArrayName="density", Function="-1.0 + 0.0*coordsX")
try:
    refused = "Intensity" not in arrays(RTSchlieren(Input=neg, Array=["POINTS", "density"], Size=32, Photons=1))
except Exception:  # noqa: BLE001 (ParaView reports the filter's error; the output is empty)
    refused = True
assert refused, "a negative density was accepted without AllowNonphysical"
img = arrays(RTSchlieren(Input=neg, Array=["POINTS", "density"], Size=32, Photons=1, AllowNonphysical=1))
assert img["Intensity"].shape == (32, 32), img.keys()
print("labels and tooltips: every property documented; AllowNonphysical=1 accepts what the default refuses")
print("pvpython: every filter ok")
