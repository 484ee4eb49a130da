"""bladecase: nonsmooth modal analysis of blade–casing contact.

The package is laid out as the pipeline it runs (see ``docs/architecture.md``):

- :mod:`bladecase.fe` — geometry (gmsh), meshes (meshio), assembly (scikit-fem) → :class:`FEModel`;
- :mod:`bladecase.reduction` — contact, orthogonal-symmetry basis, Lanczos chain, reduced models
  → :class:`ReducedModel` whose ``.system`` is a :class:`LinearSystem`;
- :mod:`bladecase.nsm` — the solver: :class:`LinearSystem`, orbits, branches (nonsmooth modes),
  event-driven simulation;
- :mod:`bladecase.post` — plots, animations, VTK, reports;
- :mod:`bladecase.study` — TOML studies run through every stage; :mod:`bladecase.cli` on top.

Every public name is re-exported here:

>>> import bladecase as bc
>>> system = bc.chain(2, k=1.0, m=0.5, gap=1.0)
>>> orbit = bc.orbit_1ipp(system, T=6.0)
>>> bool(orbit.admissible), round(orbit.energy, 6)
(True, 0.602841)
"""

from .fe.assembly import DofMap, FEModel, Material, assemble, natural_frequencies
from .fe.geometry import BladeGeometry, PlateGeometry, blade_mesh
from .fe.mesh import Mesh, load_mesh, save_mesh
from .nsm.branches import Arc, Family, nonsmooth_mode
from .nsm.orbits import PeriodicOrbit, impact_matrices, make_orbit, orbit_1ipp, orbits_kipp
from .nsm.scan import Backbone, Interval, backbone
from .nsm.simulation import Trajectory, simulate
from .nsm.system import LinearSystem, Spectrum, chain
from .reduction.contact import Contact, radial_normal
from .reduction.lanczos import (
    LanczosChain,
    MassFactor,
    PerDofDefect,
    SymmetryBasis,
    lanczos_chain,
    mass_factor,
    per_dof_defect,
)
from .reduction.methods import FULL_LIMIT, ReducedModel, reduce
from .study.pipeline import RunResult, run
from .study.schema import Study, StudyError, demo_study, load_study

__all__ = [
    # fe
    "BladeGeometry", "DofMap", "FEModel", "Material", "Mesh", "PlateGeometry",
    "assemble", "blade_mesh", "load_mesh", "natural_frequencies", "save_mesh",
    # nsm
    "Arc", "Backbone", "Family", "Interval", "LinearSystem", "PeriodicOrbit", "Spectrum", "Trajectory",
    "backbone", "chain", "impact_matrices", "make_orbit", "nonsmooth_mode", "orbit_1ipp", "orbits_kipp", "simulate",
    # reduction
    "Contact", "FULL_LIMIT", "LanczosChain", "MassFactor", "PerDofDefect", "ReducedModel", "SymmetryBasis",
    "lanczos_chain", "mass_factor", "per_dof_defect", "radial_normal", "reduce",
    # study
    "RunResult", "Study", "StudyError", "demo_study", "load_study", "run",
]
__version__ = "0.1.0"
