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

from . import animation, png, vtu
from .registry import OrbitScene, Output, OutputRegistry, PlotScene

__all__ = ["FORMATS", "Output", "OrbitScene", "OutputRegistry", "PlotScene", "register"]

#: The formats ``[output] formats`` may name, in registration order.
FORMATS = OutputRegistry()


def register(name: str, writer, scope: str, summary: str) -> Output:
    """Register an output format in :data:`FORMATS` (see :mod:`bladecase.post.outputs.registry`)."""
    return FORMATS.register(name, writer, scope, summary)


register("gif", animation.write, "orbit", "looping GIF animation of each chosen orbit on the blade")
register("mp4", animation.write, "orbit", "MP4 animation of each chosen orbit (needs imageio-ffmpeg)")
register("vtu", vtu.write, "orbit", "ParaView time series (.pvd + .vtu frames) and manifold samples")
register("png", png.write, "run", "frequency–energy plot of every model")
