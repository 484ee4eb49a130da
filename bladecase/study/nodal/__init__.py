"""``[contact] points = "nodes"``: the nonsmooth mode with every face node a contact.

- :mod:`~bladecase.study.nodal.stage` — the mode with every face node a contact beside the face mean;
- :mod:`~bladecase.study.nodal.render` — its orbit animated after the exact re-simulation and a reference converged
  in size.

The names of :mod:`~bladecase.study.nodal.stage` are re-exported here.
"""

from .stage import (
    nodal_stage,
    node_amplitude,
    orbit_load,
)

__all__ = ["nodal_stage", "node_amplitude", "orbit_load"]
