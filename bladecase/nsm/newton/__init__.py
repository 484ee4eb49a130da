"""Newton's impact law — the impulsive contact model (theory §1–5): its orbits, modes, simulator and forced runs.

A :class:`~bladecase.nsm.system.LinearSystem` hits the obstacle in instantaneous impacts (Moreau's form of
Newton's law, restitution ``e``). One module per step:

- :mod:`~bladecase.nsm.newton.modal` — :class:`ModalKernel` (periodic impulse response at a period) and the k-ipp
  equations with exact Jacobians: :func:`impact_matrices`, :func:`kipp_residual`, :func:`kipp_jacobian`,
  :func:`newton_times`, :func:`solve_times`;
- :mod:`~bladecase.nsm.newton.orbits` — :class:`PeriodicOrbit` (a small record; pickles without its system),
  :func:`make_orbit` (certified admissibility), :func:`orbit_1ipp`;
- :mod:`~bladecase.nsm.newton.certify` — the admissibility proofs of many flights at once, as the k-ipp search
  runs them (:func:`~bladecase.nsm.newton.certify.certify_flights`);
- :mod:`~bladecase.nsm.newton.kipp` — every k-ipp orbit at one period: :func:`orbits_kipp`;
- :mod:`~bladecase.nsm.newton.families` — the k-ipp residual as a curve for :mod:`bladecase.nsm.continuation`
  (:class:`KippCurve`), families followed together (:class:`FamilyTracer`);
- :mod:`~bladecase.nsm.newton.arc_ends` — the ends of admissible arcs bisected together (:func:`bisect_ends`);
- :mod:`~bladecase.nsm.newton.coverage` — which start orbits a followed family already passes
  (:func:`starts_passed`);
- :mod:`~bladecase.nsm.newton.scan` — the 1-ipp backbone over a scan of periods (:func:`backbone`);
- :mod:`~bladecase.nsm.newton.flight` and :mod:`~bladecase.nsm.newton.simulation` — the event-driven simulator:
  a flight propagator (:class:`ModalFlight`), an impact law (:class:`NewtonImpact`), the event loop
  (:func:`integrate`) and :func:`simulate`;
- :mod:`~bladecase.nsm.newton.forced` — forced–damped exact flight and simulation (:func:`simulate_forced`;
  damping and the energy balance are shared: :mod:`bladecase.nsm.damping`).

What both contact models share lives in :mod:`bladecase.nsm` (systems, signals, continuation, branches, the
period range and admissible arcs of :mod:`bladecase.nsm.arcs`, damping); :func:`~bladecase.nsm.nonsmooth_mode`
(:mod:`bladecase.nsm.modes`) dispatches to this package or to :mod:`bladecase.nsm.massless`.

Import order: :mod:`~bladecase.nsm.newton.scan` imports the shared :mod:`bladecase.nsm.branches`, which imports
:mod:`~bladecase.nsm.newton.families`, :mod:`~bladecase.nsm.newton.kipp`, :mod:`~bladecase.nsm.newton.modal` and
:mod:`~bladecase.nsm.newton.orbits`: these are imported before ``scan`` here, and :mod:`bladecase.nsm` imports this
package before :mod:`bladecase.nsm.branches`.
"""

from .arc_ends import bisect_ends
from .coverage import PASS_GATE, passes, phase_distance, phase_distances, starts_passed
from .families import (
    ARC_RTOL,
    MERGE_RTOL,
    FamilyTracer,
    FollowedFamily,
    KippCurve,
    KippCurves,
    complete_families,
    follow_family,
    polished_orbit,
    polished_orbits,
    trace_families,
)
from .flight import CONTACT_RTOL, FlightPropagator, ImpactLaw, ModalFlight, NewtonImpact
from .forced import ForcedFlight, ForcedTrajectory, simulate_forced
from .kipp import MAX_GRID_CELLS, MAX_K, canonical_rotation, check_k, check_resolution, check_search_k, orbits_kipp
from .modal import (
    DISTINCT_RTOL,
    RESONANCE_RTOL,
    ModalKernel,
    check_period,
    check_times,
    delay_terms,
    half_period_terms,
    impact_kernels,
    impact_matrices,
    impulses_for,
    kipp_jacobian,
    kipp_residual,
    newton_times,
    solve_pairs,
    solve_stack,
    solve_times,
    solve_times_stack,
)
from .orbits import (
    ADMISSIBILITY_RTOL,
    REPEAT_RTOL,
    PeriodicOrbit,
    check_newton_system,
    make_orbit,
    make_orbits,
    orbit_1ipp,
    repetitions,
)
from .scan import BISECTION_RTOL, backbone
from .simulation import STATE_MEMORY_BYTES, Trajectory, default_max_impacts, integrate, simulate

__all__ = [
    # arc_ends
    "bisect_ends",
    # coverage
    "PASS_GATE", "passes", "phase_distance", "phase_distances", "starts_passed",
    # families
    "ARC_RTOL", "MERGE_RTOL", "FamilyTracer", "FollowedFamily", "KippCurve", "KippCurves", "complete_families",
    "follow_family", "polished_orbit", "polished_orbits", "trace_families",
    # flight
    "CONTACT_RTOL", "FlightPropagator", "ImpactLaw", "ModalFlight", "NewtonImpact",
    # forced
    "ForcedFlight", "ForcedTrajectory", "simulate_forced",
    # kipp
    "MAX_GRID_CELLS", "MAX_K", "canonical_rotation", "check_k", "check_resolution", "check_search_k", "orbits_kipp",
    # modal
    "DISTINCT_RTOL", "RESONANCE_RTOL", "ModalKernel", "check_period", "check_times", "delay_terms",
    "half_period_terms", "impact_kernels", "impact_matrices", "impulses_for", "kipp_jacobian", "kipp_residual",
    "newton_times", "solve_pairs", "solve_stack", "solve_times", "solve_times_stack",
    # orbits
    "ADMISSIBILITY_RTOL", "REPEAT_RTOL", "PeriodicOrbit", "check_newton_system", "make_orbit", "make_orbits",
    "orbit_1ipp", "repetitions",
    # scan
    "BISECTION_RTOL", "backbone",
    # simulation
    "STATE_MEMORY_BYTES", "Trajectory", "default_max_impacts", "integrate", "simulate",
]
