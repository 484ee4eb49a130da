"""The rub of a blade in an abradable coating, the wear coupled to the blade's dynamics: :func:`wear_rub`.

The blade (a :class:`~bladecase.nsm.massless.nodes.NodalSystem`, one massless contact per tip node) turns at ``Ω``
inside an out-of-round casing (:class:`~bladecase.nsm.massless.nodes.Rub`) lined with an abradable coating
(:class:`~bladecase.nsm.massless.wear.Abradable`). Each revolution is flown exactly with the worn profile left by
the revolutions before as a clearance profile round the casing (:class:`~bladecase.nsm.massless.nodes.Profile`:
its steps cut the flights). The coating is an elastic–perfectly plastic layer at each node: a spring (its stiffness
per area × the node's tributary area: the ``casing`` of the system) in series with a plastic slider (its yield
pressure × that area), so a node in contact presses the coating with ``p = λ_j / A_j``. Two couplings
(:data:`COUPLINGS`):

- ``"in_flight"`` (the default): the coating yields during the flight, each node a Jenkins element
  open, elastic or plastic (:mod:`~bladecase.nsm.massless.coating_flight`): the pressure never exceeds the yield and
  a plastic node removes the coating as it goes, following its own receding surface;
- ``"staggered"``: within a revolution the coating is elastic, its removal taken at the
  revolution's end.

After the revolution each node's path is passed over the coating (:func:`~bladecase.nsm.massless.wear.pass_tip`):
its radial incursion beyond the unworn surface ``r_j(t) = y_j(t) − g_j(t)`` (``y_j`` the node's normal displacement,
``g_j`` the out-of-round clearance without wear) at the casing angle ``θ = Ωt + φ_j``, sampled on a grid finer than
the cells and at every switch, writes into the cells the depth ``r_j − p_y/k`` it reached (in flight: the depth the
node removed; staggered: the coating is removed where the pressure went beyond its yield). The worn profile is the
clearance of the next revolution.

>>> from bladecase.nsm import Damping
>>> from bladecase.nsm.massless.nodes import NodalSystem
>>> from bladecase.nsm.massless.wear import Abradable
>>> s = NodalSystem(np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2), np.diag([0.5, 0.5]),
...                 gap=[1.0, 1.0], casing=[4.0, 4.0])
>>> c = Abradable(thickness=1.0, yield_pressure=0.4, stiffness=4.0, cells=60, radius=30.0, width=1.0)
>>> w = wear_rub(s, c, speed=0.4, lobes=3, amplitude=1.2, angles=[0.0, 0.3], damping=Damping(zeta=0.05),
...              revolutions=4, areas=[1.0, 1.0])
>>> w.profile.lobes(), bool(w.removed[-1] > 0), bool(abs(w.profile.removed / w.profile.missing_volume - 1) < 1e-9)
(3, True, True)
>>> w.check.verdict, w.check.lobes, w.check.expected
('agree', 3, 3)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .coating_energy import CoatingEnergy, coating_balance
from .coating_flight import CoatingFlight
from .friction import friction_flight
from .nodes import NodalFlight, NodalSystem, Profile, Rub, simulate_nodes
from .wear import Abradable, WearProfile, pass_tip
from .wear_lobes import LobeCheck, dominant_ratio, lobe_check

__all__ = ["COUPLINGS", "WearRub", "vibration_ratio", "wear_rub"]

#: How the coating's removal meets the flight: ``"in_flight"``, the coating yields during the flight (each node a
#: Jenkins element, :mod:`~bladecase.nsm.massless.coating_flight`); ``"staggered"``, elastic within a revolution,
#: its removal taken at the revolution's end.
COUPLINGS = ("in_flight", "staggered")

#: Samples per coating cell of each node's path (at least), besides the switches.
SAMPLES_PER_CELL = 3

#: The last revolutions whose tip response gives the vibration frequency (:func:`vibration_ratio`).
TAIL = 4


@dataclass(frozen=True, eq=False)
class WearRub:
    """:func:`wear_rub`'s answer: the worn profile (with its ``history``: the profile after each revolution), per
    revolution the volume removed so far (m³), the peak tip normal displacement (m), the peak contact pressure on
    the coating (Pa) and the lobes of the profile; the dominant frequency of the last (up to 4) revolutions' mean
    tip normal displacement over the rotation frequency (:func:`vibration_ratio`); the phases flown (switches and
    profile steps); that mean tip displacement over each revolution (``tip``: ``(revolutions,
    samples_per_turn)``, m), the held-out check of the lobes worn over the last revolutions against the
    vibration's frequency over the same ones (``check``: :func:`~bladecase.nsm.massless.wear_lobes.lobe_check`),
    the coupling flown (:data:`COUPLINGS`) and, asked for (in flight), each revolution's energy balance (``energy``:
    :func:`~bladecase.nsm.massless.coating_energy.coating_balance`, else ``None``)."""

    profile: WearProfile
    removed: np.ndarray
    peak_displacement: np.ndarray
    peak_pressure: np.ndarray
    lobes: np.ndarray
    vibration_ratio: float
    phases: int
    tip: np.ndarray | None = None
    samples_per_turn: int = 0
    check: LobeCheck | None = None
    coupling: str = "staggered"
    energy: tuple[CoatingEnergy, ...] | None = None

    @property
    def depths(self) -> np.ndarray:
        """The profile after each revolution, ``(revolutions, cells)`` (m)."""
        return np.array(self.profile.history)


def vibration_ratio(signal, samples_per_turn: int) -> float:
    """The dominant frequency of ``signal`` (sampled ``samples_per_turn`` times a revolution over whole
    revolutions) over the rotation frequency: the strongest line of its Hann-windowed spectrum above half an engine
    order, its mean and trend taken out, refined by the parabola through it and its neighbours
    (:func:`~bladecase.nsm.massless.wear_lobes.dominant_ratio`).

    >>> t = np.arange(400) / 100                       # four revolutions, 100 samples each
    >>> round(vibration_ratio(np.cos(2 * np.pi * 7.9 * t), 100), 1)
    7.9
    """
    return dominant_ratio(signal, samples_per_turn)[0]


def wear_rub(system: NodalSystem, coating: Abradable, speed: float, lobes: int, amplitude: float, angles,
             damping=None, revolutions: int = 10, areas=None, friction=None,
             max_switches: int = 2_000_000, flight: NodalFlight | None = None,
             coupling: str | None = None, energy: bool = False) -> WearRub:
    """The coupled rub and wear of ``system`` at ``speed`` (rad/s) in a casing with ``lobes`` lobes of
    ``amplitude`` (m) lined with ``coating``, from rest over ``revolutions`` turns (module docstring). ``areas``:
    each node's tributary area (m²), for the pressure (``system.casing`` should be ``coating.stiffness × areas``);
    ``friction``: a :class:`~bladecase.nsm.massless.friction.Friction`, or ``None``; ``flight``: the flight to fly
    (its phases reused, e.g. the rub response's: of this system, damping, casing and friction; the staggered
    coupling's only); ``coupling``: one of :data:`COUPLINGS` (default ``"in_flight"``); ``energy``: keep each
    revolution's energy balance (:mod:`~bladecase.nsm.massless.coating_energy`; the in-flight coupling's only)."""
    if not isinstance(coating, Abradable):
        raise ValueError(f"coating must be an Abradable, got {type(coating).__name__}")
    if isinstance(revolutions, bool) or int(revolutions) != revolutions or revolutions < 1:
        raise ValueError(f"revolutions must be an integer >= 1, got {revolutions!r}")
    speed = float(speed)
    if not (np.isfinite(speed) and speed > 0):
        raise ValueError(f"speed must be a finite number > 0 (rad/s), got {speed!r}")
    if coupling is None:
        coupling = "in_flight"
    if coupling not in COUPLINGS:
        raise ValueError(f"coupling must be one of {COUPLINGS}, got {coupling!r}")
    if not isinstance(energy, (bool, np.bool_)):
        raise ValueError(f"energy must be True or False, got {energy!r}")
    if energy and coupling != "in_flight":
        raise ValueError(f"the energy balance of the wear rub needs the coupling 'in_flight', got {coupling!r}")
    areas = np.ones(system.m) if areas is None else np.asarray(areas, dtype=float)
    rub = Rub(lobes, amplitude, speed, angles)
    if coupling == "in_flight":
        want = coating.stiffness * areas
        if not np.allclose(system.casing, want, rtol=1e-6, atol=0.0):
            raise ValueError(f"the coating yielding in flight needs the system's casing stiffness at each node to be "
                             f"the coating's stiffness × the node's area, {want.tolist()} N/m, got "
                             f"{system.casing.tolist()}")
        fl = CoatingFlight(system, coating.yield_pressure * areas, damping, rub, friction)
    elif flight is not None:
        fl = flight
    else:
        fl = NodalFlight(system, damping, rub) if friction is None else friction_flight(system, friction, damping, rub)
    phi = np.asarray(rub.angles)
    turn = 2 * np.pi / speed
    per_turn = max(SAMPLES_PER_CELL * coating.cells, 48 * lobes,
                   int(np.ceil(24 * system.modes[0][-1] / speed)) if system.n else 0)
    grid = np.arange(per_turn) * (turn / per_turn)
    profile = WearProfile.new(coating)
    x, v = np.zeros(system.n), np.zeros(system.n)
    removed, peak_u, peak_p, count, tip, phases, balances = [], [], [], [], [], 0, []
    for _ in range(int(revolutions)):
        here = Profile(profile.depth, speed, phi)
        if coupling == "in_flight":
            tr = fl.simulate(x, v, turn, profile=here, max_switches=max_switches)
        else:
            tr = simulate_nodes(system, x, v, turn, flight=fl, max_switches=max_switches, profile=here)
        if not tr.complete:
            raise ValueError(f"the wear rub at {speed:.6g} rad/s needed more than {max_switches} switches in a "
                             "revolution")
        phases += int(tr.starts.size)
        if energy:
            balances.append(coating_balance(tr, 0.0, tr.t_end))
        t = np.unique(np.r_[grid, tr.starts, turn])
        if coupling == "in_flight":
            xs, _, lam, y = tr.sample(t)
            r = y - fl.gap(t)  # incursion beyond the unworn surface
        else:
            xs, _, lam = tr.sample(t)
            y = system.W.T @ xs - system.flexibility @ lam  # the nodes' own normal displacements
            r = y - fl._base_gap(t)
        for j in range(system.m):
            profile, _ = pass_tip(profile, phi[j] + speed * t, r[j])
        profile = WearProfile(coating, profile.depth, profile.removed, profile.history + (profile.depth.copy(),),
                              profile.worn_through)
        removed.append(profile.removed)
        peak_u.append(float(y.max()))
        peak_p.append(float((lam / areas[:, None]).max()))
        count.append(profile.lobes())
        tip.append((system.W.T @ xs[:, np.searchsorted(t, grid)]).mean(axis=0))
        x, v = tr.x_end, tr.v_end
    tip = np.array(tip)
    ratio = vibration_ratio(tip[-TAIL:].ravel(), per_turn)
    check = lobe_check(np.array(profile.history), tip, per_turn, window=TAIL)
    return WearRub(profile, np.array(removed), np.array(peak_u), np.array(peak_p), np.array(count), ratio, phases,
                   tip, per_turn, check, coupling, tuple(balances) if energy else None)
