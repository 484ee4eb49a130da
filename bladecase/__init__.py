"""bladecase: nonsmooth modal analysis of blade–casing contact.

Public API (a contract for later stages and external scripts), in the order data flows:

- geometry: :class:`BladeGeometry`, :class:`PlateGeometry`, :func:`blade_mesh` (gmsh);
  :class:`Mesh`, :func:`load_mesh`, :func:`save_mesh` (any meshio format, named groups);
- fem: :class:`Material`, :func:`assemble` → :class:`FEModel` (scikit-fem, sparse K and M),
  :func:`natural_frequencies` (shift-invert);
- model: :class:`LinearSystem`, :func:`chain`, :class:`Spectrum` — the system the solver consumes;
- nsm: :func:`orbit_1ipp`, :func:`orbits_kipp`, :func:`impact_matrices`, :class:`PeriodicOrbit`;
- scan / continuation: :func:`backbone` → :class:`Backbone`; :func:`nonsmooth_mode` → :class:`Family`;
- simulate: :func:`simulate` → :class:`Trajectory` — exact event-driven simulation (the independent check).
"""

from .nsm.branches import Arc, Family, nonsmooth_mode
from .fe.assembly import DofMap, FEModel, Material, assemble, natural_frequencies
from .fe.geometry import BladeGeometry, PlateGeometry, blade_mesh
from .fe.mesh import Mesh, load_mesh, save_mesh
from .nsm.system import LinearSystem, Spectrum, chain
from .nsm.orbits import PeriodicOrbit, impact_matrices, make_orbit, orbit_1ipp, orbits_kipp
from .nsm.scan import Backbone, Interval, backbone
from .nsm.simulation import Trajectory, simulate

__all__ = [
    "Arc", "Backbone", "BladeGeometry", "DofMap", "FEModel", "Family", "Interval", "LinearSystem", "Material",
    "Mesh", "PeriodicOrbit", "PlateGeometry", "Spectrum", "Trajectory",
    "assemble", "backbone", "blade_mesh", "chain", "impact_matrices", "load_mesh", "make_orbit",
    "natural_frequencies", "nonsmooth_mode", "orbit_1ipp", "orbits_kipp", "save_mesh", "simulate",
]
__version__ = "0.1.0"

# Reduction layer: the contact of an FE model and the Lanczos chain (theory §2).
from .reduction.contact import Contact, radial_normal
from .reduction.lanczos import LanczosChain, MassFactor, PerDofDefect, SymmetryBasis, lanczos_chain, mass_factor, per_dof_defect

__all__ += [
    "Contact", "LanczosChain", "MassFactor", "PerDofDefect", "SymmetryBasis",
    "lanczos_chain", "mass_factor", "per_dof_defect", "radial_normal",
]

# Reduction layer: the front door, FE model + contact -> the reduced system the solver consumes.
from .reduction.methods import FULL_LIMIT, ReducedModel, reduce

__all__ += ["FULL_LIMIT", "ReducedModel", "reduce"]

# Studies: a TOML file through every stage, and the results (animations, VTK, report).
from .study.pipeline import RunResult, run
from .study.schema import Study, StudyError, demo_study, load_study

__all__ += ["RunResult", "Study", "StudyError", "demo_study", "load_study", "run"]
