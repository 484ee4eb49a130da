"""The rub response of a blade turning inside an out-of-round casing, at one speed or over a range of speeds.

The blade (a :class:`~bladecase.nsm.massless.nodes.NodalSystem`: one massless contact per tip node) turns at
``Ω`` inside a casing with ``n`` lobes of amplitude ``a``: node ``j``, at the angle ``φ_j`` about the engine axis,
sees the clearance ``g_j(t) = d_j − a cos(n(Ωt + φ_j))``. Starting at rest, the response is simulated exactly
(:func:`~bladecase.nsm.massless.nodes.simulate_nodes`: closed-form flights, certified switches) over
``revolutions`` turns; the last ``window`` turns give the figures an engineer reads — the peak normal
displacement of each node (m, outwards), the peak contact force on each node (N), the fraction of the
revolution each node spends in contact, the casing's peak penetration at each node (compliant casing, m), the
nodes that touch, the peak of the total force ``Σ_j λ_j`` and the nodes' forces at that instant, and — given the
nodes' tributary areas — the largest area in contact — and whether the response has settled (the window's peaks
against the previous window's).

A sweep in speed (:func:`rub_sweep`) runs the speeds through an executor (each speed on its own).

>>> import numpy as np
>>> from bladecase.nsm import Damping
>>> from bladecase.nsm.massless.nodes import NodalSystem
>>> s = NodalSystem(np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2), np.diag([0.5, 0.5]),
...                 gap=[1.0, 1.0], casing=[4.0, 4.0])
>>> r = rub_response(s, speed=0.4, lobes=3, amplitude=1.2, angles=[0.0, 0.3], damping=Damping(zeta=0.05),
...                  revolutions=30, window=5)
>>> r.touching, bool(r.peak_force.max() > 0), r.settled
((0, 1), True, True)
>>> bool(r.peak_force.max() <= r.total_force <= r.peak_force.sum()), bool(r.total_force == r.force_at_peak.sum())
(True, True)
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from .nodes import NodalFlight, NodalSystem, Rub, simulate_nodes

__all__ = ["RubResponse", "rub_response", "rub_sweep"]

#: Relative change of the window's peaks against the previous window's below which the response has settled.
SETTLED_RTOL = 0.02

#: Samples per revolution and per period of the highest mode of interest used for the peaks.
SAMPLES_PER_PERIOD = 24


@dataclass(frozen=True)
class RubResponse:
    """The rub response at one speed (module docstring); per-node arrays follow ``system.nodes``."""

    speed: float
    lobes: int
    amplitude: float
    revolutions: int
    window: int
    nodes: tuple
    peak_displacement: np.ndarray
    peak_force: np.ndarray
    contact_fraction: np.ndarray
    penetration: np.ndarray
    switches: int
    settled: bool
    change: float
    total_force: float = 0.0
    force_at_peak: np.ndarray | None = None
    loaded_area: float | None = None

    @property
    def touching(self) -> tuple:
        """The nodes that touch the casing in the window (their labels)."""
        return tuple(k for k, f in zip(self.nodes, self.contact_fraction) if f > 0)

    @property
    def tip_displacement(self) -> float:
        """The largest peak normal displacement over the nodes (m)."""
        return float(self.peak_displacement.max())

    def as_dict(self) -> dict:
        """Plain numbers and lists (for JSON)."""
        d = asdict(self)
        return {k: (v.tolist() if isinstance(v, np.ndarray) else list(v) if isinstance(v, tuple) else v)
                for k, v in d.items()}


def _peaks(tr, flight: NodalFlight, t0: float, t1: float, samples: int) -> tuple[np.ndarray, ...]:
    """Per node over ``[t0, t1]`` (sampled, the switches included): peak normal displacement, force and casing
    yield; then the nodes' forces at the sample of the largest total force."""
    s = flight.system
    t = np.unique(np.r_[np.linspace(t0, t1, samples), tr.starts[(tr.starts >= t0) & (tr.starts <= t1)]])
    x, _, lam = tr.sample(t)
    u = s.W.T @ x - s.flexibility @ lam  # the nodes' own normal displacements
    pen = lam / s.casing[:, None]
    return u.max(axis=1), lam.max(axis=1), pen.max(axis=1), lam[:, int(np.argmax(lam.sum(axis=0)))]


def _loaded_area(tr, areas: np.ndarray, t0: float, t1: float) -> float:
    """The largest ``Σ_{j closed} A_j`` over the phases that overlap ``[t0, t1]`` (exact: from the phases)."""
    ends = np.r_[tr.starts[1:], tr.t_end]
    live = (ends > t0) & (tr.starts < t1)
    return float((tr.active[live] @ areas).max(initial=0.0))


def rub_response(system: NodalSystem, speed: float, lobes: int, amplitude: float, angles, damping=None,
                 revolutions: int = 40, window: int = 10, max_switches: int = 2_000_000,
                 areas=None) -> RubResponse:
    """The rub response at ``speed`` (rad/s) from rest, over ``revolutions`` turns, read on the last ``window``
    (module docstring). ``angles``: each contact node's angle about the engine axis (rad); ``damping``: a
    :class:`~bladecase.nsm.damping.Damping` of the open-phase modes (``None``: undamped); ``areas``: each node's
    tributary area (m², ``(m,)``) for the largest loaded area (``loaded_area``; ``None`` without)."""
    if isinstance(revolutions, bool) or int(revolutions) != revolutions or revolutions < 2:
        raise ValueError(f"revolutions must be an integer >= 2, got {revolutions!r}")
    if isinstance(window, bool) or int(window) != window or not 1 <= window <= revolutions // 2:
        raise ValueError(f"window must be an integer in 1..revolutions/2 = {revolutions // 2}, got {window!r}")
    speed = float(speed)
    if not (np.isfinite(speed) and speed > 0):
        raise ValueError(f"speed must be a finite number > 0 (rad/s), got {speed!r}")
    rub = Rub(lobes, amplitude, speed, angles)
    fl = NodalFlight(system, damping, rub)
    turn = 2 * np.pi / speed
    tr = simulate_nodes(system, np.zeros(system.n), np.zeros(system.n), revolutions * turn, flight=fl,
                        max_switches=max_switches)
    if not tr.complete:
        raise ValueError(f"the rub response at {speed:.6g} rad/s needed more than {max_switches} switches in "
                         f"{revolutions} revolutions")
    omega = system.modes[0]
    per_turn = max(SAMPLES_PER_PERIOD * lobes, int(np.ceil(SAMPLES_PER_PERIOD * omega[0] / speed)) * 4)
    end = tr.t_end
    now = _peaks(tr, fl, end - window * turn, end, per_turn * window)
    before = _peaks(tr, fl, end - 2 * window * turn, end - window * turn, per_turn * window)
    fraction = tr.contact_time(end - window * turn, end) / (window * turn)
    scale = max(float(np.abs(now[0]).max()), float(system.gap.max()))
    change = float(max(np.abs(now[0] - before[0]).max() / scale,
                       np.abs(now[1] - before[1]).max() / max(float(now[1].max()), 1e-300)))
    loaded = None
    if areas is not None:
        areas = np.asarray(areas, dtype=float)
        if areas.shape != (system.m,):
            raise ValueError(f"areas must hold one value per contact node ({system.m}), got shape {areas.shape}")
        loaded = _loaded_area(tr, areas, end - window * turn, end)
    return RubResponse(speed, int(lobes), float(amplitude), int(revolutions), int(window), system.nodes, now[0],
                       now[1], fraction, now[2], int(tr.switch_times.size), change <= SETTLED_RTOL, change,
                       float(now[3].sum()), now[3], loaded)


def _one(args) -> RubResponse:
    system, speed, lobes, amplitude, angles, damping, revolutions, window = args
    return rub_response(system, speed, lobes, amplitude, angles, damping, revolutions, window)


def rub_sweep(system: NodalSystem, speeds, lobes: int, amplitude: float, angles, damping=None,
              revolutions: int = 40, window: int = 10, executor=None, progress=None) -> list[RubResponse]:
    """:func:`rub_response` at every speed of ``speeds`` (rad/s), through ``executor`` (anything with a ``map``
    of a function over a list, e.g. the study's executors; default: in turn)."""
    speeds = np.asarray(speeds, dtype=float).reshape(-1)
    if speeds.size == 0 or not np.all(np.isfinite(speeds)) or np.any(speeds <= 0):
        raise ValueError(f"speeds must be finite numbers > 0 (rad/s), got {speeds.tolist()}")
    jobs = [(system, float(w), lobes, amplitude, tuple(np.asarray(angles, dtype=float).tolist()), damping,
             revolutions, window) for w in speeds]
    if executor is None:
        out = []
        for job in jobs:
            out.append(_one(job))
            if progress is not None:
                progress()
        return out
    return list(executor.map(_one, jobs))
