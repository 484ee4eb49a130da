"""The casing-stiffness sweep (``[contact] casing_stiffness = [...]``).

- :mod:`~bladecase.study.casing.stage` — the search repeated per casing stiffness.

The names of :mod:`~bladecase.study.casing.stage` are re-exported here.
"""

from .stage import (
    casing_sweep,
    spread,
)

__all__ = ["casing_sweep", "spread"]
