"""The forced-response study (``[forcing]``).

- :mod:`~bladecase.study.forcing.stage` — the forced-response stage: load, sweeps, ``forced.csv``, steady states to
  animate.

The names of :mod:`~bladecase.study.forcing.stage` are re-exported here.
"""

from .stage import (
    COLUMNS,
    DEFAULTS,
    ForcedOrbit,
    build_load,
    check_sweep_work,
    contact_load,
    contact_reach,
    forced_response,
    forced_scene,
    forcing_frequencies,
    steady_orbit,
)

__all__ = ["COLUMNS", "DEFAULTS", "ForcedOrbit", "build_load", "check_sweep_work", "contact_load", "contact_reach",
           "forced_response", "forced_scene", "forcing_frequencies", "steady_orbit"]
