"""Run by run-tests.sh inside the ParaView GUI (``xvfb-run paraview
--script=gui_check.py``), started with the plugin folder on PYTHONPATH and
PV_PLUGIN_PATH, as a user would set it up: the plugin must have been
auto-loaded by the GUI itself; RT Schlieren is applied and shown in the
render view, whose screenshot is saved. Writes OK/FAIL to
$RTVIS_GUI_OUT/gui-result.txt and quits the GUI."""

import os
import traceback

out = os.environ["RTVIS_GUI_OUT"]
try:
    import paraview.simple as pvs

    ok = hasattr(pvs, "RTSchlieren") and hasattr(pvs, "RTSurfaceRender")
    msg = ["plugin auto-loaded by the GUI" if ok else "plugin NOT loaded"]
    if ok:
        src = pvs.Wavelet(WholeExtent=[-24, 23, -24, 23, -24, 23])
        bump = pvs.Calculator(Input=src, ResultArrayName="density",
                              Function="1.2 + 0.3*exp(-(coordsX^2+coordsY^2+coordsZ^2)/128)")
        image = pvs.RTSchlieren(Input=bump, Array=["POINTS", "density"], Size=256)
        view = pvs.GetActiveViewOrCreate("RenderView")
        display = pvs.Show(image, view)  # coloured by its active scalars, Intensity
        view.InteractionMode = "2D"
        pvs.ResetCamera(view)
        pvs.Render(view)
        n = image.GetDataInformation().GetNumberOfPoints()
        msg.append(f"RT Schlieren applied and shown: {n} pixels")
        # Shown as a photograph: grey, 0 to 2 (the background mid-grey),
        # not rescaled to the data.
        lut = pvs.GetColorTransferFunction("Intensity")
        points = [round(float(x), 6) for x in lut.RGBPoints]
        grey = points == [0.0, 0.0, 0.0, 0.0, 2.0, 1.0, 1.0, 1.0] and lut.AutomaticRescaleRangeMode == "Never"
        msg.append(f"Intensity's colour map {points} ({lut.AutomaticRescaleRangeMode})")
        ok = n == 256 * 256 and grey
        pvs.SaveScreenshot(os.path.join(out, "paraview-gui.png"), view, ImageResolution=[640, 480])
        # The view ray traced in a pane of the GUI (rtvis_view.show): a
        # contour coloured by elevation, traced with shadows.
        import numpy as np
        import rtvis_view

        pvs.Hide(image, view)
        contour = pvs.Contour(Input=src, ContourBy=["POINTS", "RTData"], Isosurfaces=[150.0])
        # RT Surface Render's RGB shown as it is, not through a colour map.
        surface = pvs.Show(pvs.RTSurfaceRender(Input=contour, ImageSize=[64, 48]), view)
        as_is = list(surface.ColorArrayName) == ["POINTS", "RGB"] and surface.MapScalars == 0
        msg.append(f"RT Surface Render shown by {list(surface.ColorArrayName)}, Map Scalars {surface.MapScalars}")
        ok = ok and as_is
        pvs.Hide(surface.Input, view)
        shown = pvs.Show(pvs.Elevation(Input=contour, LowPoint=[0, -10, 0], HighPoint=[0, 10, 0]), view)
        pvs.ColorBy(shown, ("POINTS", "Elevation"))
        view.InteractionMode = "3D"
        pvs.ResetCamera(view)
        pane = rtvis_view.show(view, shadows=True, ao=4)
        pvs.AssignViewToLayout(pane)
        pvs.Render(pane)
        # At the pane's own size: a Python view's image is not magnified.
        pvs.SaveScreenshot(os.path.join(out, "paraview-gui-pane.png"), pane)
        rgba, depth = rtvis_view.raytrace(view, size=(320, 240))
        covered = float(np.isfinite(depth).mean())
        msg.append(f"the view ray traced in a pane: {covered:.0%} of pixels covered")
        ok = ok and 0.05 < covered < 0.95
except Exception:
    ok, msg = False, [traceback.format_exc()]
with open(os.path.join(out, "gui-result.txt"), "w") as fh:
    fh.write(("OK: " if ok else "FAIL: ") + "; ".join(msg) + "\n")
os._exit(0 if ok else 1)
