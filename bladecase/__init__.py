"""bladecase: nonsmooth modal analysis of blade–casing contact.

Public API (a contract for later stages and external scripts):

- :class:`LinearSystem`, :func:`chain`, :class:`Spectrum` — the system that travels between stages;
- :func:`orbit_1ipp`, :class:`PeriodicOrbit` — periodic orbits with impacts;
- :func:`backbone`, :class:`Backbone` — orbits over a period scan, admissible intervals;
- :func:`orbits_kipp`, :func:`impact_matrices` — orbits with k impacts per period at a given period;
- :func:`nonsmooth_mode`, :class:`Family` — k-ipp families followed by pseudo-arclength continuation;
- :func:`simulate`, :class:`Trajectory` — exact event-driven simulation (the independent check).
"""

from .continuation import Arc, Family, nonsmooth_mode
from .model import LinearSystem, Spectrum, chain
from .nsm import PeriodicOrbit, impact_matrices, make_orbit, orbit_1ipp, orbits_kipp
from .scan import Backbone, Interval, backbone
from .simulate import Trajectory, simulate

__all__ = [
    "Arc", "Backbone", "Family", "Interval", "LinearSystem", "PeriodicOrbit", "Spectrum", "Trajectory",
    "backbone", "chain", "impact_matrices", "make_orbit", "nonsmooth_mode", "orbit_1ipp", "orbits_kipp",
    "simulate",
]
__version__ = "0.1.0"

# Geometry and meshing front end (gmsh, meshio; imported lazily inside the functions).
from .geometry import BladeGeometry, PlateGeometry, blade_mesh  # noqa: E402
from .mesh import Mesh, load_mesh, save_mesh  # noqa: E402

__all__ += ["BladeGeometry", "Mesh", "PlateGeometry", "blade_mesh", "load_mesh", "save_mesh"]
