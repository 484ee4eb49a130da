"""Output formats of a study run, one file per format and one registration each (see :mod:`.registry`).

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
