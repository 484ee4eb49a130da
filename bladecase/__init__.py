"""bladecase: nonsmooth modal analysis of blade–casing contact.

Public API (a contract for later stages and external scripts):

- :class:`LinearSystem`, :func:`chain`, :class:`Spectrum` — the system that travels between stages;
- :func:`orbit_1ipp`, :class:`PeriodicOrbit` — periodic orbits with impacts;
- :func:`backbone`, :class:`Backbone` — orbits over a period scan, admissible intervals;
- :func:`simulate`, :class:`Trajectory` — exact event-driven simulation (the independent check).
"""

from .scan import Backbone, Interval, backbone
from .model import LinearSystem, Spectrum, chain
from .nsm import PeriodicOrbit, make_orbit, orbit_1ipp
from .simulate import Trajectory, simulate

__all__ = [
    "Backbone", "Interval", "LinearSystem", "PeriodicOrbit", "Spectrum", "Trajectory",
    "backbone", "chain", "make_orbit", "orbit_1ipp", "simulate",
]
__version__ = "0.1.0"
