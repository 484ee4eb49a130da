"""Output formats of a study run, one file per format and one registration each (see :mod:`.registry`).

A format is a module with ``write(scene, folder, formats) -> dict`` (scope ``"run"``: a ``PlotScene``; scope
``"orbit"``: an ``OrbitScene``) and one :func:`register` line below; the study schema's ``[output] formats``
follow :data:`FORMATS`.

- :mod:`~bladecase.post.outputs.registry` — the registry of formats, its scenes and scopes;
- :mod:`~bladecase.post.outputs.animation` — ``gif`` and ``mp4``: each chosen orbit animated on the blade;
- :mod:`~bladecase.post.outputs.vtu` — ``vtu``: ParaView time series and manifold samples;
- :mod:`~bladecase.post.outputs.png` — ``png``: the frequency–energy plot of every model.

>>> list(FORMATS)
['gif', 'mp4', 'vtu', 'png']
>>> FORMATS.entry("vtu").scope
'orbit'
"""

from __future__ import annotations

import importlib
from pathlib import Path

from .registry import OrbitScene, Output, OutputRegistry, PlotScene

__all__ = ["FORMATS", "Output", "OrbitScene", "OutputRegistry", "PlotScene", "register"]

#: The formats ``[output] formats`` may name, in registration order.
FORMATS = OutputRegistry()


def register(name: str, writer, scope: str, summary: str) -> Output:
    """Register an output format in :data:`FORMATS` (see :mod:`bladecase.post.outputs.registry`)."""
    return FORMATS.register(name, writer, scope, summary)


def _built_in(module: str):
    """The ``write`` of the built-in format module ``module``, imported at its first call: the figures' and the
    animations' libraries are imported only by a run that writes them, not by every module that reads the list
    of formats (the study's schema)."""

    def write(scene, folder: Path, formats: set[str]) -> dict[str, str]:
        return importlib.import_module(f".{module}", __name__).write(scene, folder, formats)

    write.__qualname__ = f"{module}.write"
    return write


_animation = _built_in("animation")
register("gif", _animation, "orbit", "looping GIF animation of each chosen orbit on the blade")
register("mp4", _animation, "orbit", "MP4 animation of each chosen orbit (needs imageio-ffmpeg)")
register("vtu", _built_in("vtu"), "orbit", "ParaView time series (.pvd + .vtu frames) and manifold samples")
register("png", _built_in("png"), "run", "frequency–energy plot of every model")
