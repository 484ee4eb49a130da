"""Stage 3 — the nonsmooth-mode solver: systems, orbits, branches, simulation.

Data in: a :class:`LinearSystem` (from a chain, a reduced model or a full FE model — the solver never
knows which). Data out: orbits and branches (nonsmooth modes) and simulated trajectories.
"""

from .branches import Arc, Family, nonsmooth_mode
from .orbits import PeriodicOrbit, impact_matrices, make_orbit, orbit_1ipp, orbits_kipp
from .scan import Backbone, Interval, backbone
from .simulation import Trajectory, simulate
from .system import LinearSystem, Spectrum, chain

__all__ = [
    "Arc", "Backbone", "Family", "Interval", "LinearSystem", "PeriodicOrbit", "Spectrum", "Trajectory",
    "backbone", "chain", "impact_matrices", "make_orbit", "nonsmooth_mode", "orbit_1ipp", "orbits_kipp",
    "simulate",
]
