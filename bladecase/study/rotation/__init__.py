"""A rotating blade in a study (``[rotation]``): the operating speed, the running clearance and the
Campbell stage, and a study of its linear modes alone.

- :mod:`~bladecase.study.rotation.stage` — the operating speed, running clearance and Campbell stage;
- :mod:`~bladecase.study.rotation.modes_run` — a study with ``[rotation] speeds`` and no ``[contact]``: the linear
  modes and the Campbell diagram alone, published as any run.

The names of :mod:`~bladecase.study.rotation.stage` are re-exported here.
"""

from .stage import (
    band_risks,
    campbell_stage,
    operating_point,
    rotation_axis,
    running_clearance,
    speeds,
)

__all__ = ["band_risks", "campbell_stage", "operating_point", "rotation_axis", "running_clearance", "speeds"]
