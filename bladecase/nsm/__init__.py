"""Stage 3 — the nonsmooth-mode solver: systems, orbits, branches, simulation.

Data in: a :class:`LinearSystem` (from a chain, a reduced model or a full FE model — the solver never
knows which). Data out: periodic orbits, branches (nonsmooth modes) and simulated trajectories.

Each contact model has its own subpackage — :mod:`bladecase.nsm.newton` (Newton's impact law, the impulsive
model) and :mod:`bladecase.nsm.massless` (the massless contact model); what both share lives here. The pipeline
inside, one module per step:

- :mod:`~bladecase.nsm.system` — :class:`LinearSystem`, its contact :class:`Spectrum`, :func:`chain`;
- :mod:`~bladecase.nsm.newton.modal` — :class:`ModalKernel` (periodic impulse response at a period) and the k-ipp
  equations: :func:`impact_matrices`, :func:`kipp_residual`, :func:`kipp_jacobian`, :func:`newton_times`,
  :func:`solve_times`;
- :mod:`~bladecase.nsm.signals` — certified bounds and first roots of trigonometric sums;
- :mod:`~bladecase.nsm.newton.orbits` — :class:`PeriodicOrbit` (a small record; pickles without its system),
  :func:`make_orbit` (certified admissibility), :func:`orbit_1ipp`;
- :mod:`~bladecase.nsm.newton.kipp` — every k-ipp orbit at one period: :func:`orbits_kipp`;
- :mod:`~bladecase.nsm.continuation` — pseudo-arclength following of ``R(z) = 0`` for any residual with an
  exact Jacobian (:class:`Curve`, :func:`trace`, :func:`bisect`);
- :mod:`~bladecase.nsm.newton.families` — the k-ipp residual as such a curve (:class:`KippCurve`);
- :mod:`~bladecase.nsm.arcs` — the period range of a mode search and the admissible arcs along a followed curve,
  for either contact model;
- :mod:`~bladecase.nsm.branches` — :class:`Branch` and :class:`Arc`, the one result type of
  :func:`nonsmooth_mode` (:mod:`~bladecase.nsm.modes`: continuation, any k, either contact model) and
  :func:`backbone` (:mod:`~bladecase.nsm.newton.scan`, 1-ipp scan);
  ``Family``, ``Backbone``, ``Interval`` are their former names;
- :mod:`~bladecase.nsm.newton.flight` and :mod:`~bladecase.nsm.newton.simulation` — the event-driven simulator:
  a flight propagator (:class:`ModalFlight`), an impact law (:class:`NewtonImpact`), the event loop
  (:func:`integrate`) and :func:`simulate`;
- :mod:`~bladecase.nsm.newton.forced` (+ :mod:`~bladecase.nsm.damped_signals`) — forced–damped exact flight and
  simulation (:func:`simulate_forced`); :mod:`~bladecase.nsm.damping` — :class:`Damping` and
  :class:`EnergyBalance`, either contact model; :mod:`~bladecase.nsm.sweep` — forcing-period sweeps
  with steady-state detection and classification (:func:`forced_sweep`), either contact model;
  :mod:`~bladecase.nsm.massless.forced` — the massless contact model forced and damped
  (:func:`simulate_forced_massless`);
- :mod:`~bladecase.nsm.verify` — the independent check of an orbit by simulation (:func:`verify`);
- :mod:`~bladecase.nsm.floquet` — stability: monodromy with saltation matrices, multipliers, a verdict
  (:func:`floquet`, :func:`branch_stability`, :func:`stable_arcs`);
- :mod:`~bladecase.nsm.energy` — where an orbit's energy sits (:func:`~bladecase.nsm.energy.modal_energy_split`);
- :mod:`~bladecase.nsm.massless.model`, :mod:`~bladecase.nsm.massless.orbits` (one contact phase),
  :mod:`~bladecase.nsm.massless.phases` (any number: :class:`PhasedOrbit`), :mod:`~bladecase.nsm.massless.follow`
  and :func:`massless_mode` (:mod:`~bladecase.nsm.massless.branches`: a mode followed through phase changes),
  :mod:`~bladecase.nsm.massless.bar` — the massless contact model (theory §8).
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
