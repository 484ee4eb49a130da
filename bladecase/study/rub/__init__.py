"""The rub study (``[rub]``): the blade turning inside an out-of-round casing, over speeds.

- :mod:`~bladecase.study.rub.stage` — the rub stage: each speed's centrifugal state, its nodal model, the response
  through the executor; ``rub.csv``, ``rub_nodes.csv``, ``rub.png``;
- :mod:`~bladecase.study.rub.contact` — its contact selection checked before any factorisation: a face, or a line of
  tip nodes weighted by tributary length;
- :mod:`~bladecase.study.rub.keys` — the keys ``[contact] friction`` and ``[casing] abradable``;
- :mod:`~bladecase.study.rub.friction` — each speed with friction: energy per revolution, the sliding check;
- :mod:`~bladecase.study.rub.friction_modes` — each speed's first mode with friction against its amplitude, checked
  by its free decay: ``friction_modes.csv``, ``friction_modes.png``;
- :mod:`~bladecase.study.rub.wear` — each speed wearing the coating: ``wear.csv``, ``wear.png``, ``wear.vtu``.

The names of :mod:`~bladecase.study.rub.stage` are re-exported here.
"""

from .stage import (
    check_rub_contact,
    contact_measure,
    crossing_speed,
    node_angles,
    rub_stage,
)

__all__ = ["check_rub_contact", "contact_measure", "crossing_speed", "node_angles", "rub_stage"]
