"""bladecase: nonsmooth modal analysis of blade–casing contact.

The package is laid out as the pipeline it runs (see ``docs/architecture.md``):

- :mod:`bladecase.fe` — geometry (gmsh), meshes (meshio), assembly (scikit-fem) → :class:`FEModel`;
- :mod:`bladecase.reduction` — contact, orthogonal-symmetry basis, Lanczos chain, reduced models
  → :class:`ReducedModel` whose ``.system`` is a :class:`LinearSystem`;
- :mod:`bladecase.nsm` — the solver: :class:`LinearSystem`, orbits, branches (nonsmooth modes),
  event-driven simulation;
- :mod:`bladecase.post` — plots, animations, VTK, reports;
- :mod:`bladecase.study` — TOML studies run through every stage; :mod:`bladecase.cli` on top.

Each package's ``__init__`` docstring is its module map. Beside the packages, the shared modules, which belong to
no stage:

- :mod:`bladecase.linalg` — the one SPD factorisation (CHOLMOD where installed, else SuperLU; chosen in
  ``factor_backend()``) and the one lowest-modes solver; a factorisation is passed on and reused, never recomputed;
- :mod:`bladecase.linalg_backends` — the sparse factorisations: SuperLU, scikit-sparse's and cvxopt's CHOLMOD;
- :mod:`bladecase.linalg_block` — block shift-invert Lanczos for a CHOLMOD factor;
- :mod:`bladecase.ordering` — METIS's fill-reducing ordering of large sparse Cholesky factorisations;
- :mod:`bladecase.threads` — how many BLAS threads a stage may use on a busy machine;
- :mod:`bladecase.checks` — validators that name the value and what would be valid;
- :mod:`bladecase.io` — atomic files and folder swaps;
- :mod:`bladecase.progress` — tqdm's plain bar, or nothing when ``progress=False``;
- :mod:`bladecase.log` — messages to the ``bladecase`` logger and into a run's own transcript;
- :mod:`bladecase.registry` — the one ``Registry`` behind reduction methods and output formats;
- :mod:`bladecase.cli` — argparse over the study stages, the only place that configures logging;
  :mod:`bladecase.cli_input` (argument types, input files, outputs that would overwrite an input) and
  :mod:`bladecase.cli_backbone` (the ``backbone`` command) beside it; ``python -m bladecase`` runs it.

Every public name is re-exported here:

>>> import bladecase as bc
>>> system = bc.chain(2, k=1.0, m=0.5, gap=1.0)
>>> orbit = bc.orbit_1ipp(system, T=6.0)
>>> bool(orbit.admissible), round(orbit.energy, 6)
(True, 0.602841)
"""

import importlib
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # what a type checker and an IDE see; at run time each name is imported on first use
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

#: Where each public name lives: it is imported from there on first use (a fast ``import bladecase``).
_EXPORTS = {
    "fe": (
        "BladeGeometry", "DofMap", "FEModel", "Material", "Mesh", "PlateGeometry", "assemble", "blade_mesh",
        "load_mesh", "natural_frequencies", "save_mesh", "select_nodes", "stiffness_factor",
    ),
    "nsm": (
        "Arc", "Backbone", "Branch", "Damping", "Family", "Floquet", "ForcedTrajectory", "Interval", "LinearSystem",
        "MasslessSystem", "PeriodicOrbit", "PhasedOrbit", "Spectrum", "SweepPoint", "Trajectory", "backbone", "bar",
        "chain", "floquet", "forced_point", "forced_sweep", "impact_matrices", "make_orbit", "massless_mode",
        "nonsmooth_mode", "orbit_1ipp", "orbits_kipp", "simulate", "simulate_forced", "simulate_forced_massless",
        "verify",
    ),
    "reduction": (
        "FULL_LIMIT", "METHODS", "Contact", "EngineOrderLoad", "LanczosChain", "MassFactor", "PerDofDefect",
        "ReducedModel", "SymmetryBasis", "engine_order_load", "lanczos_chain", "mass_factor", "nodal_load",
        "per_dof_defect", "pressure_load", "project_load", "radial_normal", "reduce",
    ),
    "study": (
        "RunResult", "Study", "StudyError", "demo_study", "load_study", "run",
    ),
}
_WHERE = {name: module for module, names in _EXPORTS.items() for name in names}

#: The subpackages and modules reachable as attributes (``bladecase.fe``), imported on first use.
_SUBMODULES = frozenset({"fe", "reduction", "nsm", "post", "study", "cli", "linalg", "checks", "io", "log",
                         "progress", "registry"})


def __getattr__(name: str):
    """Import a public name (or a subpackage) the first time it is used (PEP 562)."""
    if name in _WHERE:
        value = getattr(importlib.import_module(f".{_WHERE[name]}", __name__), name)
    elif name in _SUBMODULES:
        value = importlib.import_module(f".{name}", __name__)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__) | _SUBMODULES)


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
__version__ = "0.11.0"
