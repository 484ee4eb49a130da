"""Forcing-period sweep of the forced, damped impact oscillator (seed paper Sec. 2.5, Figs. 9–10).

For each forcing period ``T = 2π/Ω`` the system is integrated over ``n_periods`` periods
(:func:`~bladecase.nsm.newton.forced.simulate_forced`, exact flights, certified contact search) and the end of
the run is classified by :func:`forced_point`:

* **periodic steady state** — the stroboscopic map (the state sampled once per forcing period) returns
  to itself after ``p`` forcing periods, for the smallest ``p`` in ``1..max_p``: the relative distance
  ``‖z(s) - z(s - pT)‖ / ‖z(s)‖`` (energy norm ``‖(x, v)‖² = xᵀKx + vᵀMv``) is at most ``tol`` for the
  last two returns (``s``, ``s - pT`` and ``s - 2pT``).  The section phase is put in the middle of the
  widest impact-free gap of the last periods, so that round-off in an impact time never flips a sample
  between its pre- and post-impact state.  The orbit is then "``k`` impacts per ``p`` forcing periods"
  (``k`` counted over the last cycle), e.g. the paper's 1 impact per ``T``, 2 per ``T`` or ``2T``, 3 per
  ``2T``.  Without impacts in the compared window the motion is linear and only ``p = 1`` is accepted (a
  decaying free oscillation can return after ``p > 1`` periods by near-commensurability alone);
* **not periodic** (within ``tol`` after ``n_periods``): reported as such (``periodic = False``), like the
  paper's "it is not known whether they could eventually reach the periodic regime" — unless the motion is
  proved never to impact again (:func:`settles_linear`, label ``"linear"``: it converges to the linear
  steady state, only too slowly for ``tol``; the paper's ``C = αK`` damps the lowest mode very little);
  runs stopped by chattering (``restitution < 1``) have ``complete = False``.

**Energy.** The paper plots "the energy" of the forced periodic motions next to the (constant) energy
of the nonsmooth modes without defining it; here ``energy`` is the MAXIMUM over the last cycle of the
mechanical energy ``E(t) = ½vᵀMv + ½xᵀKx`` (kinetic + strain; the damping and forcing terms are not
included), sampled at 64 points per shortest period and refined around the largest sample;
``mean_energy`` is its time average over the cycle.

**Massless contact model** (:class:`~bladecase.nsm.massless.model.MasslessSystem`): the runs are
:func:`~bladecase.nsm.massless.forced.simulate_forced_massless`; "impacts" are then the contact phases (their
closing switches: ``k`` contact phases per ``p`` forcing periods), ``impulses`` the momentum ``∫λ dt`` each
phase transmits, the energy ``½vᵀMv + ½xᵀSx + ½k_c max(0, y - d)²`` and the return norm ``xᵀSx + vᵀMv``.

:func:`forced_sweep` visits the periods in the sweep direction, each run starting from the end state of
the previous one (sweep ``"up"`` in forcing FREQUENCY = decreasing ``T``; ``"down"`` = increasing ``T``),
with a progress bar; with ``continuation=False`` every period starts from the same state and the pure
:func:`forced_point` is mapped by an executor (``executor.map(fn, items)``,
:mod:`bladecase.study.executor`).
"""

from __future__ import annotations

import functools
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize_scalar

from ..progress import progress_bar
from .damping import Damping, _real
from .massless.forced import MasslessForcedTrajectory, simulate_forced_massless
from .massless.model import MasslessSystem
from .newton.forced import ForcedTrajectory, simulate_forced
from .system import LinearSystem

__all__ = ["SWEEP_TOL", "SweepPoint", "forced_point", "forced_sweep", "rate_max", "settles_linear"]

#: Default relative tolerance of the stroboscopic return of a periodic steady state.
SWEEP_TOL = 1e-6

#: Samples of the energy per shortest period (``2π / max(ω_max, Ω)``) before refinement.
ENERGY_SAMPLES = 64


@dataclass(frozen=True)
class SweepPoint:
    """The steady state reached at one forcing period (see the module docstring).

    Attributes
    ----------
    T : float
        Forcing period.
    periodic : bool
        Whether a periodic steady state was detected (within ``tol``).
    p, k : int or None
        Its period in forcing periods and its impacts per cycle (``None`` when not periodic).
    energy, mean_energy : float
        Maximum and time average of ``½vᵀMv + ½xᵀKx`` over the last cycle (``p`` forcing periods, or
        ``max_p`` when not periodic).
    residual : float
        Relative stroboscopic mismatch after ``p`` periods (the smallest over ``1..max_p`` when not
        periodic).
    complete : bool
        False when the run stopped early (chattering).
    linear : bool
        Proved never to reach the obstacle again (:func:`settles_linear`): the motion converges to the
        non-impacting linear steady state, however slowly its transient decays.
    impact_phases, impulses : ndarray
        Impact times of the last cycle as forcing phases ``(t mod pT)/T`` in ``[0, p)`` (the forcing is
        ``cos(2πt/T)``), in the order they occur, and their impulses.
    x_end, v_end : ndarray
        State at the end of the run (the next period of a sweep starts there).
    """

    T: float
    periodic: bool
    p: int | None
    k: int | None
    energy: float
    mean_energy: float
    residual: float
    complete: bool
    impact_phases: np.ndarray = field(repr=False)
    impulses: np.ndarray = field(repr=False)
    x_end: np.ndarray = field(repr=False)
    v_end: np.ndarray = field(repr=False)
    n_periods: int = field(repr=False, default=0)
    linear: bool = False

    @property
    def label(self) -> str:
        """``"k/p"`` (``k`` impacts per ``p`` forcing periods), ``"linear"`` (not yet periodic within ``tol``
        but proved never to impact again), ``"non-periodic"`` or ``"incomplete"``."""
        if not self.complete:
            return "incomplete"
        if self.periodic:
            return f"{self.k}/{self.p}"
        return "linear" if self.linear else "non-periodic"


def _section_phase(tr: ForcedTrajectory, T: float, since: float) -> float:
    """Phase in ``[0, 1)`` (of the forcing period) in the middle of the widest impact-free gap."""
    t = tr.impact_times[tr.impact_times >= since]
    if t.size == 0:
        return 0.5
    ph = np.unique(np.mod(t / T, 1.0))
    gaps = np.diff(np.append(ph, ph[0] + 1.0))
    i = int(np.argmax(gaps))
    return float(np.mod(ph[i] + 0.5 * gaps[i], 1.0))


def _cycle_energy(tr: ForcedTrajectory, a: float, b: float) -> tuple[float, float]:
    """``(max, mean)`` of the mechanical energy on ``[a, b]``: the largest of the samples, of the
    pre-impact energies (``E`` has a corner at an impact; with ``e < 1`` its left limit is the supremum)
    and of the largest sample refined by Brent's bounded search inside its own flight (where ``E`` is
    smooth)."""
    fl = tr.flight
    h = 2 * np.pi / (ENERGY_SAMPLES * rate_max(tr))
    n = max(2, int(np.ceil((b - a) / h)) + 1)
    t = np.linspace(a, b, n)
    E = tr.energy_at(t)
    i = int(np.argmax(E))
    hits = tr.impact_times[(tr.impact_times > a) & (tr.impact_times <= b)]
    before, after = hits[hits <= t[i]], hits[hits > t[i]]
    lo = max(t[max(i - 1, 0)], before[-1] if before.size else a)
    hi = min(t[min(i + 1, n - 1)], after[0] if after.size else b)
    best = float(E[i])
    if hi > lo:
        res = minimize_scalar(lambda s: -float(tr.energy_at(s)[0]), bounds=(lo, hi), method="bounded",
                              options={"xatol": 1e-12 * max(1.0, b)})
        best = max(best, -float(res.fun))
    if hits.size and isinstance(tr, ForcedTrajectory):  # the massless model's E has no corner
        k = np.searchsorted(tr.impact_times, hits)
        p_pre = tr._p[:, k] + fl.b[:, None] * tr.impulses[k][None, :]
        best = max(best, float(fl.energy(tr._q[:, k], p_pre).max()))
    return best, float(np.trapezoid(E, t) / (b - a))


def rate_max(tr: ForcedTrajectory | MasslessForcedTrajectory) -> float:
    """Highest angular rate of a forced run's flights (sets the sampling steps)."""
    return tr.flight.rate_max if isinstance(tr, MasslessForcedTrajectory) else tr.flight.modes.rate_max


def settles_linear(tr: ForcedTrajectory | MasslessForcedTrajectory) -> bool:
    """Whether the motion after the end of ``tr`` provably never reaches the obstacle again.

    Every mode damped (``σ_j > 0``): ``wᵀx = Σ b_j q_j`` is the steady state ``Re(P e^{iΩt})`` plus the
    homogeneous deviation, whose mode-wise amplitude ``√(q_h'² + ω²q_h²)/ω`` never grows; so
    ``wᵀx(t) <= |P| + Σ |b_j| R_j/ω_j`` for all later ``t``, and if that is below ``d`` there is no further
    impact: the motion converges to the linear (non-impacting) steady state.  The massless model likewise in
    its open-phase modes (``y = ŵᵀx + gF₀cos Ωt``: the contact load's term joins the steady state).
    """
    fl = tr.flight
    massless = isinstance(tr, MasslessForcedTrajectory)
    m = fl.open.modes if massless else fl.modes
    if not np.all(m.sigma > 0):
        return False
    q, p = fl.encode(tr.x_end, tr.v_end)
    qp, pp = m.particular(tr.t_end)
    amp = abs(complex(fl.b @ np.where(m.split, m.amplitude, 0j)) + (fl.g if massless else 0.0))
    drift = float(np.abs(fl.b) @ (np.hypot(p - pp, m.omega * (q - qp)) / m.omega))
    return amp + drift < fl.gap


def _returns(tr: ForcedTrajectory, s0: float, T: float, max_p: int) -> np.ndarray:
    """Relative distances ``r_p``, ``p = 1..max_p``, of the stroboscopic samples (energy norm)."""
    s = s0 - T * np.arange(2 * max_p + 1)
    q, p = tr.modal_state(s)
    Z = np.vstack([tr.flight.omega[:, None] * q, p])
    scale = max(float(np.linalg.norm(Z[:, 0])), np.finfo(float).tiny)
    r = [max(np.linalg.norm(Z[:, 0] - Z[:, k]), np.linalg.norm(Z[:, k] - Z[:, 2 * k])) / scale
         for k in range(1, max_p + 1)]
    return np.array(r)


def _run(system, T: float, n_periods: int, x0, v0, kw: dict, restitution: float, contact_load: float):
    """The forced run of ``n_periods`` periods of either contact model."""
    if isinstance(system, MasslessSystem):
        if restitution != 1.0:
            raise ValueError(f"restitution applies to Newton's contact model only; the massless model has no "
                             f"impact law (got restitution={restitution!r})")
        return simulate_forced_massless(system, x0, v0, n_periods * T, period=T, contact_load=contact_load, **kw)
    if contact_load != 0.0:
        raise ValueError(f"contact_load is for the massless contact model only, got {contact_load!r}")
    return simulate_forced(system, x0, v0, n_periods * T, period=T, restitution=restitution, **kw)


def _check_system(system, what: str) -> None:
    if not isinstance(system, (LinearSystem, MasslessSystem)):
        raise ValueError(f"{what}: system must be a LinearSystem (Newton's contact) or a MasslessSystem (massless "
                         f"contact), got {type(system).__name__}")


def forced_point(system: LinearSystem | MasslessSystem, T: float, *, damping: Damping | None = None,
                 amplitude: float = 1.0, load=None, n_periods: int = 500, x0=None, v0=None, restitution: float = 1.0,
                 tol: float = SWEEP_TOL, max_p: int = 4, contact_load: float = 0.0) -> SweepPoint:
    """Integrate ``n_periods`` forcing periods from ``(x0, v0)`` (default: rest) and classify the end.

    A pure function of its arguments (a study executor may map it over periods).  A
    :class:`~bladecase.nsm.massless.model.MasslessSystem` is run by
    :func:`~bladecase.nsm.massless.forced.simulate_forced_massless` (``contact_load``: its ``g``; module
    docstring: contact phases are counted instead of impacts).

    The paper's 2-dof chain forced at ``T = 4.5`` settles on one impact per forcing period; its energy peaks
    at the impact:

    >>> from bladecase.nsm import chain
    >>> s = chain(2, k=1.0, m=0.5, gap=1.0)
    >>> pt = forced_point(s, 4.5, damping=Damping(alpha=0.05), amplitude=0.6, n_periods=150)
    >>> pt.label, round(pt.energy, 6), pt.impact_phases.round(6).tolist(), pt.residual < 1e-10
    ('1/1', 7.890714, [0.067096], True)
    """
    _check_system(system, "forced_point")
    T = _real("forcing period T", T)
    if not np.isfinite(T) or T <= 0:
        raise ValueError(f"forcing period T must be finite and > 0, got {T!r}")
    if isinstance(max_p, bool) or not isinstance(max_p, (int, np.integer)) or max_p < 1:
        raise ValueError(f"max_p must be an integer >= 1, got {max_p!r}")
    if isinstance(n_periods, bool) or not isinstance(n_periods, (int, np.integer)) or n_periods < 2 * max_p + 1:
        raise ValueError(f"n_periods must be an integer >= 2*max_p + 1 = {2 * max_p + 1}, got {n_periods!r}")
    if not (np.isfinite(_real("tol", tol)) and tol > 0):
        raise ValueError(f"tol must be finite and > 0, got {tol!r}")
    amplitude, restitution, contact_load = (_real(name, v) for name, v in (
        ("amplitude", amplitude), ("restitution", restitution), ("contact_load", contact_load)))
    x0 = np.zeros(system.n) if x0 is None else x0
    v0 = np.zeros(system.n) if v0 is None else v0
    empty = np.zeros(0)
    stopped = SweepPoint(T, False, None, None, np.nan, np.nan, np.nan, False, empty, empty,
                         np.asarray(x0, float), np.asarray(v0, float), n_periods)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="simulate stopped", category=RuntimeWarning)
        try:
            tr = _run(system, T, n_periods, x0, v0, dict(amplitude=amplitude, damping=damping, load=load),
                      restitution, contact_load)
        except RuntimeError:  # the event loop's "would slide along the obstacle": the end of chattering
            return stopped
    if not tr.complete:
        return stopped
    theta = _section_phase(tr, T, (n_periods - 2 * max_p - 1) * T)
    s0 = (n_periods - 1 + theta) * T
    r = _returns(tr, s0, T, max_p)
    if not np.any(tr.impact_times > s0 - 2 * max_p * T):
        # no impact: the motion is linear and its only steady state is T-periodic; a return after p > 1
        # periods is a decaying free oscillation whose frequency happens to be near-commensurate with pT
        r[1:] = np.inf
    ok = np.flatnonzero(r <= tol)
    periodic = ok.size > 0
    p = int(ok[0]) + 1 if periodic else max_p
    start = s0 - p * T
    sel = (tr.impact_times > start) & (tr.impact_times <= s0)
    Emax, Emean = _cycle_energy(tr, start, s0)
    return SweepPoint(T, periodic, p if periodic else None, int(sel.sum()) if periodic else None, Emax, Emean,
                      float(r[p - 1] if periodic else r.min()), True, np.mod(tr.impact_times[sel], p * T) / T,
                      tr.impulses[sel], tr.x_end, tr.v_end, n_periods, settles_linear(tr))


def forced_sweep(system: LinearSystem | MasslessSystem, periods, damping: Damping | None = None,
                 amplitude: float = 1.0, load=None, n_periods: int = 500, direction: str = "up", tol: float = SWEEP_TOL,
                 max_p: int = 4, restitution: float = 1.0, x0=None, v0=None, continuation: bool = True,
                 executor=None, progress: bool = False, contact_load: float = 0.0) -> list[SweepPoint]:
    """Steady states of the forced response over forcing ``periods`` (seed paper Figs. 9–10).

    Parameters
    ----------
    system : LinearSystem or MasslessSystem
        Either contact model (:func:`forced_point`).
    periods : sequence of float
        Forcing periods ``T = 2π/Ω`` (any order; visited in the sweep direction).
    damping, amplitude, load, restitution, contact_load
        As :func:`~bladecase.nsm.newton.forced.simulate_forced` (``amplitude`` is ``F₀``; ``restitution``: Newton's
        model only) and :func:`~bladecase.nsm.massless.forced.simulate_forced_massless` (``contact_load``).
    n_periods : int
        Forcing periods integrated at each ``T`` (the paper: 500).
    direction : {"up", "down"}
        Sweep in forcing frequency: ``"up"`` visits decreasing ``T``, ``"down"`` increasing ``T``.
    tol, max_p
        Periodicity test (module docstring).
    x0, v0 : array_like or None
        Initial state of the first period (default: rest); of every period when ``continuation=False``.
    continuation : bool
        Start each period from the end state of the previous one (serial).  ``False``: independent
        runs, mapped by ``executor`` (anything with ``map(fn, items, desc=, progress=)``, e.g.
        :class:`bladecase.study.executor.SerialExecutor`; default: one after the other here).
    progress : bool
        Progress bar over the periods (:func:`bladecase.progress.progress_bar`).

    Returns
    -------
    list of SweepPoint
        In the order visited.

    Examples
    --------
    >>> from bladecase.nsm import chain
    >>> pts = forced_sweep(chain(2, k=1.0, m=0.5, gap=1.0), [4.5, 4.6], damping=Damping(alpha=0.05),
    ...                    amplitude=0.6, n_periods=150, progress=False)
    >>> [(pt.T, pt.label, round(pt.energy, 4)) for pt in pts]
    [(4.6, '1/1', 6.7433), (4.5, '1/1', 7.8907)]
    """
    _check_system(system, "forced_sweep")
    if not isinstance(direction, str) or direction not in ("up", "down"):
        raise ValueError(f"direction must be 'up' (increasing forcing frequency) or 'down', got {direction!r}")
    try:
        if periods is None or isinstance(periods, (str, bytes)):
            raise TypeError
        order = np.sort(np.asarray(periods, dtype=float).reshape(-1))
    except (TypeError, ValueError):
        raise ValueError(f"periods must be a sequence of forcing periods (numbers > 0), got {periods!r}") from None
    if order.size == 0:
        raise ValueError("periods is empty: give at least one forcing period")
    if not np.all(np.isfinite(order) & (order > 0)):
        bad = order[~(np.isfinite(order) & (order > 0))][0]
        raise ValueError(f"periods must be finite forcing periods > 0, got {float(bad)!r} among them")
    for name, flag in (("continuation", continuation), ("progress", progress)):
        if not isinstance(flag, (bool, np.bool_)):
            raise ValueError(f"{name} must be True or False, got {flag!r}")
    if executor is not None and not callable(getattr(executor, "map", None)):
        raise ValueError(f"executor must have a map(fn, items, desc=, progress=) method (e.g. make_executor(...)) "
                         f"or be None, got {executor!r}")
    if direction == "up":
        order = order[::-1]
    run = functools.partial(forced_point, system, damping=damping, amplitude=amplitude, load=load,
                            n_periods=n_periods, restitution=restitution, tol=tol, max_p=max_p,
                            contact_load=contact_load)
    if not continuation:
        task = functools.partial(run, x0=x0, v0=v0)
        if executor is None:
            return [task(T) for T in progress_bar(order.tolist(), "forced sweep", enabled=progress, unit="T")]
        return executor.map(task, order.tolist(), desc="forced sweep", progress=progress)
    points = []
    x, v = x0, v0
    for T in progress_bar(order.tolist(), "forced sweep", enabled=progress, unit="T"):
        pt = run(T, x0=x, v0=v)
        points.append(pt)
        if pt.complete:
            x, v = pt.x_end, pt.v_end
    return points
