"""Stage 3 — the nonsmooth-mode solver: systems, orbits, branches, simulation.

Data in: a :class:`LinearSystem` (from a chain, a reduced model or a full FE model — the solver never
knows which). Data out: periodic orbits, branches (nonsmooth modes) and simulated trajectories.

The pipeline inside, one module per step:

- :mod:`~bladecase.nsm.system` — :class:`LinearSystem`, its contact :class:`Spectrum`, :func:`chain`;
- :mod:`~bladecase.nsm.modal` — :class:`ModalKernel` (periodic impulse response at a period) and the k-ipp
  equations: :func:`impact_matrices`, :func:`kipp_residual`, :func:`kipp_jacobian`, :func:`newton_times`,
  :func:`solve_times`;
- :mod:`~bladecase.nsm.signals` — certified bounds and first roots of trigonometric sums;
- :mod:`~bladecase.nsm.orbits` — :class:`PeriodicOrbit` (a small record; pickles without its system),
  :func:`make_orbit` (certified admissibility), :func:`orbit_1ipp`;
- :mod:`~bladecase.nsm.kipp` — every k-ipp orbit at one period: :func:`orbits_kipp`;
- :mod:`~bladecase.nsm.continuation` — pseudo-arclength following of ``R(z) = 0`` for any residual with an
  exact Jacobian (:class:`Curve`, :func:`trace`, :func:`bisect`);
- :mod:`~bladecase.nsm.families` — the k-ipp residual as such a curve (:class:`KippCurve`);
- :mod:`~bladecase.nsm.branches` — :class:`Branch` and :class:`Arc`, the one result type of
  :func:`nonsmooth_mode` (:mod:`~bladecase.nsm.modes`: continuation, any k, either contact model) and
  :func:`backbone` (:mod:`~bladecase.nsm.scan`, 1-ipp scan);
  ``Family``, ``Backbone``, ``Interval`` are their former names;
- :mod:`~bladecase.nsm.flight` and :mod:`~bladecase.nsm.simulation` — the event-driven simulator:
  a flight propagator (:class:`ModalFlight`), an impact law (:class:`NewtonImpact`), the event loop
  (:func:`integrate`) and :func:`simulate`;
- :mod:`~bladecase.nsm.forced` (+ :mod:`~bladecase.nsm.damped_signals`) — forced–damped exact flight and
  simulation (:func:`simulate_forced`, :class:`Damping`); :mod:`~bladecase.nsm.sweep` — forcing-period sweeps
  with steady-state detection and classification (:func:`forced_sweep`), either contact model;
  :mod:`~bladecase.nsm.forced_massless` — the massless contact model forced and damped
  (:func:`simulate_forced_massless`);
- :mod:`~bladecase.nsm.verify` — the independent check of an orbit by simulation (:func:`verify`);
- :mod:`~bladecase.nsm.floquet` — stability: monodromy with saltation matrices, multipliers, a verdict
  (:func:`floquet`, :func:`branch_stability`, :func:`stable_arcs`);
- :mod:`~bladecase.nsm.energy` — where an orbit's energy sits (:func:`~bladecase.nsm.energy.modal_energy_split`);
- :mod:`~bladecase.nsm.massless`, :mod:`~bladecase.nsm.massless_orbits` (one contact phase),
  :mod:`~bladecase.nsm.massless_phases` (any number: :class:`PhasedOrbit`), :mod:`~bladecase.nsm.massless_follow`
  and :func:`massless_mode` (a mode followed through phase changes), :mod:`~bladecase.nsm.bar` — the massless
  contact model (theory §8).
"""

from .bar import bar, bar_continuum_energy
from .branches import Arc, Backbone, Branch, Family, Interval
from .continuation import Curve, bisect, trace
from .families import KippCurve
from .flight import FlightPropagator, ImpactLaw, ModalFlight, NewtonImpact
from .floquet import FLOQUET_TOL, Floquet, branch_stability, floquet, stable_arcs
from .forced import Damping, EnergyBalance, ForcedFlight, ForcedTrajectory, simulate_forced
from .forced_massless import MasslessForcedFlight, MasslessForcedTrajectory, simulate_forced_massless
from .kipp import canonical_rotation, orbits_kipp
from .massless import (
                       MASSLESS_DENSE_LIMIT,
                       MasslessSystem,
                       condense,
                       redistribute_mass,
                       series_stiffness,
                       simulate_massless,
)
from .massless_branches import massless_mode
from .massless_phases import PhasedOrbit
from .modal import (
                       ModalKernel,
                       check_period,
                       impact_matrices,
                       kipp_jacobian,
                       kipp_residual,
                       newton_times,
                       solve_times,
)
from .modes import nonsmooth_mode
from .orbits import PeriodicOrbit, make_orbit, orbit_1ipp
from .scan import backbone
from .simulation import Trajectory, integrate, simulate
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
