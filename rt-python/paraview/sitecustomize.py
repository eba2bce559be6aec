"""Start-up hook for ParaView (GUI, pvpython, pvbatch) with this folder on
PYTHONPATH: applies ``rtvis_pvcompat`` (ParaView 5.11's Python plugins on
Python 3.11), then runs the ``sitecustomize`` this one shadows (Debian
ships one), so nothing of the system's start-up is lost."""

import importlib.machinery
import importlib.util
import os
import sys

import rtvis_pvcompat  # noqa: F401  (its import is the fix)

_here = os.path.dirname(os.path.abspath(__file__))
_rest = [p for p in sys.path if os.path.abspath(p or os.curdir) != _here]
_spec = importlib.machinery.PathFinder.find_spec("sitecustomize", _rest)
if _spec is not None and _spec.loader is not None:
    _module = importlib.util.module_from_spec(_spec)
    _spec.loader.exec_module(_module)
