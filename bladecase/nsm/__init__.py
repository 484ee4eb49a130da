"""Stage 3 — the nonsmooth-mode solver: systems, orbits, branches, simulation.

Data in: a :class:`LinearSystem` (from a chain, a reduced model or a full FE model — the solver never
knows which). Data out: periodic orbits, branches (nonsmooth modes) and simulated trajectories.

One subpackage per contact model, the rest shared: :mod:`bladecase.nsm.newton` (Newton's impact law, the
impulsive model) and :mod:`bladecase.nsm.massless` (the massless contact model: contact phases, the several-node
system, rub, wear and friction), each with its own module map. A model's subpackage imports the shared modules
here, never another model; a piece two models need moves here. The shared modules that dispatch on the model
(:mod:`~bladecase.nsm.modes`, :mod:`~bladecase.nsm.sweep`, :mod:`~bladecase.nsm.branches`,
:mod:`~bladecase.nsm.verify`, :mod:`~bladecase.nsm.energy`) import the subpackages; this package re-exports the
public names of all three. The shared :mod:`~bladecase.nsm.branches` uses the Newton model's orbit types and
:mod:`bladecase.nsm.newton.scan` builds :class:`Branch` es, so the subpackages are imported first below (an
``isort: split`` keeps that order).

Orbits and branches hold a reference to their system but pickle without it (:meth:`Branch.bind`,
:meth:`Branch.compact`); a branch is serialised in one place, :meth:`Branch.to_dict` / :meth:`Branch.from_dict`.

Module map of the shared modules, one entry per module (the details are in each module's own docstring):

- :mod:`~bladecase.nsm.system` — :class:`LinearSystem` (the type that carries a linear system between stages),
  its contact :class:`Spectrum`, :func:`chain`;
- :mod:`~bladecase.nsm.signals` — certified bounds and first roots of trigonometric sums;
- :mod:`~bladecase.nsm.continuation` — pseudo-arclength following of ``R(z) = 0`` for any residual with an exact
  Jacobian (:class:`Curve`, :func:`trace`, :func:`bisect`);
- :mod:`~bladecase.nsm.arcs` — a mode search's period range and the admissible arcs along a followed curve, for
  either contact model;
- :mod:`~bladecase.nsm.branches` — :class:`Branch` and :class:`Arc`: one type for backbones and k-ipp families
  (``Family``, ``Backbone``, ``Interval`` are its former names);
- :mod:`~bladecase.nsm.modes` — :func:`nonsmooth_mode`: continuation, any k, either contact model;
- :mod:`~bladecase.nsm.verify` — the independent check of an orbit by simulation (:func:`verify`);
- :mod:`~bladecase.nsm.floquet` — stability: monodromy with saltation matrices, multipliers, a verdict
  (:func:`floquet`, :func:`branch_stability`, :func:`stable_arcs`);
- :mod:`~bladecase.nsm.energy` — an orbit's energy split over its system's linear modes;
- :mod:`~bladecase.nsm.damped_signals` — forced–damped exact flight, its certified first contact;
- :mod:`~bladecase.nsm.damping` — :class:`Damping`, :class:`EnergyBalance`, the forcing inputs, either contact
  model;
- :mod:`~bladecase.nsm.sweep` — forcing-period sweeps with steady-state detection and classification
  (:func:`forced_sweep`), either contact model.

Where to start: :func:`chain` or :func:`bar` for a small system, :func:`nonsmooth_mode` for its modes,
:func:`verify` and :func:`floquet` for their checks, :func:`simulate` (Newton) and :func:`simulate_forced` /
:func:`simulate_forced_massless` for time responses.
"""

# The contact models' subpackages first: bladecase.nsm.newton.scan imports the shared .branches, which imports
# bladecase.nsm.newton's families, kipp, modal and orbits — so bladecase.nsm.newton is imported before .branches.
from .massless import (
    MASSLESS_DENSE_LIMIT,
    MasslessForcedFlight,
    MasslessForcedTrajectory,
    MasslessSystem,
    PhasedOrbit,
    bar,
    bar_continuum_energy,
    condense,
    massless_mode,
    redistribute_mass,
    series_stiffness,
    simulate_forced_massless,
    simulate_massless,
)
from .newton import (
    FlightPropagator,
    ForcedFlight,
    ForcedTrajectory,
    ImpactLaw,
    KippCurve,
    ModalFlight,
    ModalKernel,
    NewtonImpact,
    PeriodicOrbit,
    Trajectory,
    backbone,
    canonical_rotation,
    check_period,
    impact_matrices,
    integrate,
    kipp_jacobian,
    kipp_residual,
    make_orbit,
    newton_times,
    orbit_1ipp,
    orbits_kipp,
    simulate,
    simulate_forced,
    solve_times,
)

# isort: split
from .branches import Arc, Backbone, Branch, Family, Interval
from .continuation import Curve, bisect, trace
from .damping import Damping, EnergyBalance
from .floquet import FLOQUET_TOL, Floquet, branch_stability, floquet, stable_arcs
from .modes import nonsmooth_mode
from .sweep import SweepPoint, forced_point, forced_sweep, settles_linear
from .system import LinearSystem, Spectrum, chain
from .verify import VERIFY_RTOL, verify

__all__ = [
    "Arc", "Backbone", "Branch", "Curve", "Damping", "EnergyBalance", "FLOQUET_TOL", "Family", "FlightPropagator",
    "Floquet", "ForcedFlight", "ForcedTrajectory", "ImpactLaw", "SweepPoint", "forced_point", "forced_sweep",
    "settles_linear", "simulate_forced", "MasslessForcedFlight", "MasslessForcedTrajectory",
    "simulate_forced_massless",
    "Interval", "KippCurve", "LinearSystem", "MASSLESS_DENSE_LIMIT", "MasslessSystem", "ModalFlight", "ModalKernel",
    "NewtonImpact", "PeriodicOrbit", "PhasedOrbit", "Spectrum", "Trajectory", "VERIFY_RTOL",
    "backbone", "bar", "bar_continuum_energy", "bisect", "branch_stability", "canonical_rotation", "chain",
    "check_period", "condense", "floquet", "impact_matrices", "integrate", "kipp_jacobian", "kipp_residual",
    "make_orbit", "massless_mode", "newton_times", "nonsmooth_mode", "orbit_1ipp", "orbits_kipp",
    "redistribute_mass", "series_stiffness", "simulate", "simulate_massless", "solve_times", "stable_arcs", "trace",
    "verify",
]
