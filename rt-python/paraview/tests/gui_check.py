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
except Exception:
    ok, msg = False, [traceback.format_exc()]
with open(os.path.join(out, "gui-result.txt"), "w") as fh:
    fh.write(("OK: " if ok else "FAIL: ") + "; ".join(msg) + "\n")
os._exit(0 if ok else 1)
