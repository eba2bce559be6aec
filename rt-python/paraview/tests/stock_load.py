"""Loads the plugin the way the ParaView GUI does (LoadPlugin with no
compatibility import in the script): passes only when this folder's
sitecustomize.py ran at start-up (PYTHONPATH), as run-tests.sh arranges."""

import os
import sys

from paraview.simple import LoadPlugin

LoadPlugin(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "rtvis_plugin.py"), ns=globals())
assert "RTSchlieren" in globals() and "RTSurfaceRender" in globals(), "the plugin did not load"
print(f"plugin loaded on Python {sys.version.split()[0]}: RTSchlieren, RTSurfaceRender")
