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

from .fe import (
    BladeGeometry,
    DofMap,
    FEModel,
    Material,
    Mesh,
    PlateGeometry,
    assemble,
    blade_mesh,
    load_mesh,
    natural_frequencies,
    save_mesh,
    select_nodes,
    stiffness_factor,
)
from .nsm import (
    Arc,
    Backbone,
    Branch,
    Damping,
    Family,
    Floquet,
    ForcedTrajectory,
    Interval,
    LinearSystem,
    MasslessSystem,
    PeriodicOrbit,
    PhasedOrbit,
    Spectrum,
    SweepPoint,
    Trajectory,
    backbone,
    bar,
    chain,
    floquet,
    forced_point,
    forced_sweep,
    impact_matrices,
    make_orbit,
    massless_mode,
    nonsmooth_mode,
    orbit_1ipp,
    orbits_kipp,
    simulate,
    simulate_forced,
    simulate_forced_massless,
    verify,
)
from .reduction import (
    FULL_LIMIT,
    METHODS,
    Contact,
    EngineOrderLoad,
    LanczosChain,
    MassFactor,
    PerDofDefect,
    ReducedModel,
    SymmetryBasis,
    engine_order_load,
    lanczos_chain,
    mass_factor,
    nodal_load,
    per_dof_defect,
    pressure_load,
    project_load,
    radial_normal,
    reduce,
)
from .study import RunResult, Study, StudyError, demo_study, load_study, run

__all__ = [
    # fe
    "BladeGeometry", "DofMap", "FEModel", "Material", "Mesh", "PlateGeometry",
    "assemble", "blade_mesh", "load_mesh", "natural_frequencies", "save_mesh", "select_nodes",
    "stiffness_factor",
    # reduction
    "Contact", "EngineOrderLoad", "FULL_LIMIT", "LanczosChain", "METHODS", "MassFactor", "PerDofDefect",
    "ReducedModel", "SymmetryBasis", "engine_order_load", "lanczos_chain", "mass_factor", "nodal_load",
    "per_dof_defect", "pressure_load", "project_load", "radial_normal", "reduce",
    # nsm
    "Arc", "Backbone", "Branch", "Damping", "Family", "Floquet", "ForcedTrajectory", "Interval", "LinearSystem",
    "MasslessSystem", "PeriodicOrbit", "PhasedOrbit", "Spectrum", "SweepPoint", "Trajectory", "backbone", "bar",
    "chain", "floquet", "forced_point", "forced_sweep", "impact_matrices", "make_orbit", "massless_mode",
    "nonsmooth_mode", "orbit_1ipp", "orbits_kipp", "simulate", "simulate_forced", "simulate_forced_massless", "verify",
    # study
    "RunResult", "Study", "StudyError", "demo_study", "load_study", "run",
]
__version__ = "0.5.0"
