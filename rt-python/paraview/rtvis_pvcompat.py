"""Lets ParaView 5.11's Python plugins load on Python ≥ 3.11.

ParaView 5.11's ``paraview.detail.pythonalgorithm`` (which every Python
plugin, and the plugin loader itself, imports) does
``from inspect import getargspec``; Python 3.11 removed ``getargspec``, so
on Debian 12 (ParaView 5.11 on Python 3.11) every Python plugin fails with
"Failed to import paraview.detail.pythonalgorithm". Importing this module
first puts ``inspect.getargspec`` back, built on ``getfullargspec`` (the
loader only reads ``.args``). On Pythons that still have it, nothing
changes.

Import it before ``LoadPlugin`` in a script, or put this folder on
``PYTHONPATH`` so that its ``sitecustomize.py`` imports it at start-up (the
ParaView GUI, ``pvpython`` and ``pvbatch`` alike).
"""

import inspect
from collections import namedtuple

if not hasattr(inspect, "getargspec"):
    ArgSpec = namedtuple("ArgSpec", "args varargs keywords defaults")

    def getargspec(func):
        """``inspect.getargspec`` as Python 3.10 had it."""
        spec = inspect.getfullargspec(func)
        return ArgSpec(spec.args, spec.varargs, spec.varkw, spec.defaults)

    inspect.getargspec = getargspec
