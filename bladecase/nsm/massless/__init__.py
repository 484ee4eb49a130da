"""The massless contact model (theory §8): contact dofs without inertia, Signorini without an impact law.

A :class:`MasslessSystem` (the interior after condensing the massless contact dofs, a unilateral spring ``k_c``)
has contact phases of finite duration instead of impacts. One module per step:

- :mod:`~bladecase.nsm.massless.model` — :class:`MasslessSystem`, :func:`condense`, :func:`redistribute_mass`,
  :func:`series_stiffness` (a compliant casing in series), the contact phases and the event-driven simulator
  (:func:`simulate_massless`);
- :mod:`~bladecase.nsm.massless.orbits` — symmetric orbits with one contact phase per period
  (:class:`SymmetricOrbit`, :func:`orbits_at_period`, :func:`follow_from_grazing`);
- :mod:`~bladecase.nsm.massless.phases` — orbits with any number of contact phases (:class:`PhasedOrbit`);
- :mod:`~bladecase.nsm.massless.follow` — a mode followed through changes of its phase pattern
  (:func:`follow_mode`);
- :mod:`~bladecase.nsm.massless.branches` — the modes as :class:`~bladecase.nsm.branches.Branch` es
  (:func:`massless_modes`, :func:`massless_mode`);
- :mod:`~bladecase.nsm.massless.orbit_at` — an orbit of a computed branch at any period
  (:func:`massless_orbit_at`), solved from its interpolated neighbours;
- :mod:`~bladecase.nsm.massless.nodal_system` — several contacts, one per contact node (:class:`NodalSystem`):
  the complementarity of their forces (:func:`lcp`), the clearances of an out-of-round casing (:class:`Rub`), a
  worn casing's clearance profile whose steps the flights cut at (:class:`Profile`);
- :mod:`~bladecase.nsm.massless.nodes` — its phases (sets of closed contacts) and the exact event-driven simulator
  (:func:`simulate_nodes`), damped, each phase's first switch found by :mod:`~bladecase.nsm.massless.nodal_switches`
  (a phase from one Cholesky solve of its closed block, cached per set: :mod:`~bladecase.nsm.massless.nodes_phase`);
- :mod:`~bladecase.nsm.massless.nodal_orbit` — a period's flow of a :class:`NodalSystem` with its exact Jacobian
  (:func:`flow_map`) and the periodic orbits it closes, with their Floquet multipliers (:class:`NodalOrbit`);
- :mod:`~bladecase.nsm.massless.nodal_modes` — the nonsmooth modes of a :class:`NodalSystem`: periodic orbits by
  shooting with exact sensitivities, a family followed from the first node's grazing through changes of the set of
  touching nodes (:func:`nodal_family`, :class:`NodalFamily`);
- :mod:`~bladecase.nsm.massless.nodal_resonance` — that family followed step by step through the internal-resonance
  tongues it meets, recorded and crossed (:func:`backbone_trend`, :func:`resonance_ratio`);
- :mod:`~bladecase.nsm.massless.friction` — Coulomb friction at the contact nodes, sliding dominated by the
  rotation (:class:`Friction`, :func:`simulate_friction`: non-symmetric phases flown exactly), and
  :mod:`~bladecase.nsm.massless.friction_energy` — the energy balance with friction, per revolution, and the rub
  with friction (:func:`energy_balance`, :func:`friction_rub`), and :mod:`~bladecase.nsm.massless.friction_modes` —
  a mode's frequency and damping ratio with friction by the extended periodic motion concept
  (:func:`friction_mode`); :mod:`~bladecase.nsm.massless.friction_rub` — the rub with friction over revolutions,
  each revolution's energy balance and the sliding check (:func:`friction_rub`);
  :mod:`~bladecase.nsm.massless.friction_coulomb` (with ``friction_coulomb_phase`` and ``friction_coulomb_rub``) —
  stick–slip Coulomb friction, the sliding speed free to vanish (:func:`simulate_coulomb`: each node open, sliding
  either way or sticking, every combination a linear phase flown exactly);
  :mod:`~bladecase.nsm.massless.friction_modes_coulomb` — a mode's damping ratio with stick–slip friction by the
  extended periodic motion concept, its free decay and the Jenkins element's closed form (:func:`coulomb_mode`),
  and :mod:`~bladecase.nsm.massless.friction_modes_forced` — the forced response with stick–slip friction, its
  resonance peak and half-power frequencies, and :mod:`~bladecase.nsm.massless.friction_modes_phase` — the mode
  read off one forced point by its fundamental harmonic's phase (:func:`phase_mode`); further friction models sit
  beside them, in modules named
  ``friction*``;
- :mod:`~bladecase.nsm.massless.wear` — an abradable coating round the casing worn by the tip (:class:`Abradable`,
  :class:`WearProfile`, :func:`pass_tip`), elastic–perfectly plastic: the profile each tip passage leaves;
- :mod:`~bladecase.nsm.massless.wear_rub` — the rub that wears the coating: each revolution flown against the
  profile the previous ones left (:func:`wear_rub`);
- :mod:`~bladecase.nsm.massless.coating_flight` — the coating yielding during the flight: each node's normal contact
  a Jenkins element (open, elastic, plastic: a constant force while its surface recedes), every combination a
  linear phase flown exactly (:func:`simulate_coating`), and :mod:`~bladecase.nsm.massless.coating_energy` — its
  energy balance: the casing's, friction's and damping's work, the coating's removal and the worn surface's steps,
  per span or per revolution (:func:`coating_balance`);
- :mod:`~bladecase.nsm.massless.wear_lobes` — the held-out check of the lobes worn over the last revolutions against
  the tip's vibration frequency over the same ones: agree, differ, or undefined with the reason (:func:`lobe_check`);
- :mod:`~bladecase.nsm.massless.disk_modes` — travelling-wave nonsmooth modes of a tuned bladed disk: shooting over
  a fraction of the period against the blade shift, checked on the whole disk without the symmetry, with its
  Floquet multipliers;
- :mod:`~bladecase.nsm.massless.disk_forced` — the forced rub of a (mistuned) disk, the harmonic load as a moving
  clearance, each blade's settled peak contact force;
- :mod:`~bladecase.nsm.massless.disk_rub` — the whole disk's rub in an out-of-round casing, each blade at its own
  angle: per blade its peak force, penetration and contact share, the response's nodal-diameter content
  (:func:`disk_rub`, :func:`disk_rub_sweep`);
- :mod:`~bladecase.nsm.massless.rub` — the rub response of a turning blade at one speed and over speeds
  (:func:`rub_response`, :func:`rub_sweep`; :func:`rub_run` with its trajectory);
- :mod:`~bladecase.nsm.massless.forced` — forced and damped simulation (:func:`simulate_forced_massless`;
  damping and the energy balance are shared: :mod:`bladecase.nsm.damping`);
- :mod:`~bladecase.nsm.massless.bar` — the 1-D benchmark bar (either contact model) and its continuum solution
  (:func:`bar`, :func:`bar_continuum_energy`).

What both contact models share lives in :mod:`bladecase.nsm` (systems, signals, continuation, branches, the
period range and admissible arcs of :mod:`bladecase.nsm.arcs`, damping); :func:`~bladecase.nsm.nonsmooth_mode`
(:mod:`bladecase.nsm.modes`) dispatches to this package or to :mod:`bladecase.nsm.newton`.  (The name ``bar`` of
this package is the function; the module is ``bladecase.nsm.massless.bar`` in ``from … import``.)
"""

from .bar import CONTACT_MODELS, bar, bar_continuum_band_energy, bar_continuum_energy, bar_continuum_field
from .branches import ARC_RTOL, massless_mode, massless_modes, massless_orbit_at
from .disk_modes import RotatingOrbit, full_orbit, return_error, rotating_family, rotating_orbit
from .follow import EDGE_RTOL, MAX_HALF_PHASES, VANISH_RTOL, follow_mode, solve_at_period
from .forced import ExpSignal, MasslessForcedFlight, MasslessForcedTrajectory, simulate_forced_massless
from .friction import (
    FRICTION_MODELS,
    Friction,
    FrictionFlight,
    SlidingCheck,
    friction_flight,
    lemke,
    simulate_friction,
    sliding_check,
)
from .friction_coulomb import CoulombFlight, CoulombTrajectory, simulate_coulomb
from .friction_energy import FrictionEnergy, energy_balance, per_revolution
from .friction_modes import FrictionMode, decay_ratio, friction_mode
from .friction_rub import FrictionRub, friction_rub
from .model import (
    MASSLESS_DENSE_LIMIT,
    BoundOrbit,
    MasslessSystem,
    MasslessTrajectory,
    Phase,
    condense,
    redistribute_mass,
    series_stiffness,
    simulate_massless,
)
from .nodal_modes import (
    NodalFamily,
    NodalOrbit,
    flow_map,
    grazing_orbit,
    nodal_family,
    nodal_orbit,
    transfer_state,
)
from .nodal_resonance import BACKBONE_SHARE, RESONANCE_SHARE, TONGUE_POINTS, backbone_trend, resonance_ratio
from .nodal_system import Profile
from .nodes import NodalFlight, NodalSystem, NodalTrajectory, Rub, lcp, simulate_nodes
from .orbits import (
    ADMISSIBILITY_RTOL,
    SymmetricOrbit,
    check_massless_system,
    closing_residual,
    follow_from_grazing,
    orbit_at_period,
    orbits_at_period,
    smoothest,
)
from .phases import PHASES, PhasedOrbit, solve_half, split_at, violation
from .rub import RubResponse, rub_response, rub_sweep
from .wear import Abradable, WearProfile, harmonic_lobes, pass_tip
from .wear_lobes import LobeCheck, lobe_check
from .wear_rub import WearRub, vibration_ratio, wear_rub

__all__ = [
    # nodes, nodal_modes, nodal_resonance, rub
    "RotatingOrbit", "full_orbit", "return_error", "rotating_family", "rotating_orbit",
    "NodalFamily", "NodalOrbit", "flow_map", "grazing_orbit", "nodal_family", "nodal_orbit", "transfer_state",
    "BACKBONE_SHARE", "RESONANCE_SHARE", "TONGUE_POINTS", "backbone_trend", "resonance_ratio",
    "NodalFlight", "NodalSystem", "NodalTrajectory", "Rub", "lcp", "simulate_nodes", "RubResponse", "rub_response",
    "rub_sweep",
    # friction, friction_energy, wear
    "FRICTION_MODELS", "Friction", "FrictionFlight", "SlidingCheck", "friction_flight", "lemke", "simulate_friction",
    "sliding_check", "FrictionEnergy", "FrictionRub", "energy_balance", "friction_rub", "per_revolution",
    "FrictionMode", "decay_ratio", "friction_mode", "CoulombFlight", "CoulombTrajectory", "simulate_coulomb",
    "Abradable", "Profile", "WearProfile", "WearRub", "pass_tip", "vibration_ratio", "wear_rub", "harmonic_lobes",
    "LobeCheck", "lobe_check",
    # bar
    "CONTACT_MODELS", "bar", "bar_continuum_band_energy", "bar_continuum_energy", "bar_continuum_field",
    # branches
    "ARC_RTOL", "massless_mode", "massless_modes", "massless_orbit_at",
    # follow
    "EDGE_RTOL", "MAX_HALF_PHASES", "VANISH_RTOL", "follow_mode", "solve_at_period",
    # forced
    "ExpSignal", "MasslessForcedFlight", "MasslessForcedTrajectory", "simulate_forced_massless",
    # model
    "MASSLESS_DENSE_LIMIT", "BoundOrbit", "MasslessSystem", "MasslessTrajectory", "Phase", "condense",
    "redistribute_mass", "series_stiffness", "simulate_massless",
    # orbits
    "ADMISSIBILITY_RTOL", "SymmetricOrbit", "check_massless_system", "closing_residual", "follow_from_grazing",
    "orbit_at_period", "orbits_at_period", "smoothest",
    # phases
    "PHASES", "PhasedOrbit", "solve_half", "split_at", "violation",
]
