"""A nonsmooth mode with stick–slip friction: its amplitude-dependent frequency and damping ratio by the extended
periodic motion concept (Krack 2015), :func:`coulomb_mode`, checked by the free decay (:func:`coulomb_decay_ratio`)
and, for a tangential contact at constant normal load, by the closed form of a Jenkins element
(:func:`jenkins_dissipation`, :func:`equivalent_ratio`).

With the stick–slip model (:mod:`~bladecase.nsm.massless.friction_coulomb`) and a casing at rest or slow, friction
truly dissipates: a node that sticks and slips on the casing traces a hysteresis loop. The extended concept adds the
negative modal damping term ``−ξ M x'``; it only changes the damping of the phases, ``C → C − ξM`` (the open-phase
modal damping less ``ξ``), so each phase stays linear and is flown in closed form, growing. The unknowns are the
start state at a turning point (the followed mode's coordinate at ``amplitude``, its velocity 0; the other modes'
coordinates and velocities), the period ``T`` and ``ξ``; the mode's damping ratio is ``ζ = ξ / 2ω``, ``ω = 2π/T``.

The start also needs each touching node's tangential state (its force ``τ_j`` within the cone ``|τ_j| <= μλ_j``):
it is taken as a fraction ``r_j = τ_j / μλ_j`` of the cone, first ``r_j = −sign`` of the node's tangential motion
into the turning point (the node arrives sliding), then the end state's own fraction, until they agree (the
orbit's ``tangential_residual``). Switches of the growing phases are found on a grid of
:data:`~bladecase.nsm.massless.friction_modes.GRID_POINTS` points per fastest period, then bracketed.

**Closed form.** A mass ``m`` on a spring ``k`` with a Jenkins element (a spring ``k_t`` in series with a Coulomb
slider of slip force ``F_s = μN`` at a constant normal load ``N``), moving between ``±a``, dissipates per cycle the
area of its hysteresis loop, ``W_d = 4F_s(a − F_s/k_t)`` for ``a > F_s/k_t`` (0 below: it sticks). The equivalent
viscous ratio is ``ζ_eq = W_d / (2π · 2E_max)`` with ``E_max = ½mω²a²`` (the energy a viscous damper ``2ζmω``
dissipates over a harmonic cycle, ``2πζmω²a²``, set equal to ``W_d``); for a rigid node (``k_t → ∞``) it is
``ζ_eq = 2μN / (π k a)``.

>>> import numpy as np
>>> from bladecase.nsm.massless.nodes import NodalSystem
>>> from bladecase.nsm.massless.friction import Friction
>>> # a tangential dof (k = 1) with a Jenkins contact (k_t = 2, slip force 0.4 * 1) at a constant normal load
>>> s = NodalSystem(np.eye(2), np.diag([1.0, 4.0]), np.array([[0.0], [1.0]]), [[1e-3]], gap=[0.1])
>>> f = Friction(0.4, T=[[1.0], [0.0]], C_tt=[[0.5]], model="coulomb")
>>> m = coulomb_mode(s, f, amplitude=1.0, load=[0.0, 4 * 0.1 + 1.0 * (1 + 4e-3)])
>>> bool(m.converged), round(float(m.zeta), 4), round(float(jenkins_dissipation(1.0, 0.4, 2.0)), 4)
(True, 0.1623, 1.28)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import root

from .friction import Friction
from .friction_coulomb import CoulombFlight, CoulombTrajectory
from .friction_coulomb_phase import OPEN, STICK
from .friction_coulomb_rub import _stored
from .friction_modes import _first, checked_mode, start_ratio
from .nodes import SURFACE_RTOL, NodalSystem, lcp

__all__ = ["CoulombMode", "coulomb_decay_ratio", "coulomb_mode", "equivalent_ratio", "jenkins_dissipation",
           "orbit_kinetic"]

#: Outer iterations on the start's tangential state (the cone fractions) at most.
TANGENTIAL_ITERATIONS = 8


class _EPMCFlight(CoulombFlight):
    """A :class:`CoulombFlight` with the extra modal damping ``−ξ`` (phases may grow)."""

    def __init__(self, system, friction, damping, sliding, load, xi: float):
        super().__init__(system, friction, damping, None, sliding, load)
        base = self.Cq if self.Cq is not None else np.zeros((self.n, self.n))
        self.Cq = base - xi * np.eye(self.n)
        self.allow_growth = True
        self.xi = float(xi)


class _Anchored(CoulombFlight):
    """A :class:`CoulombFlight` whose start takes given sticking anchors (the certified simulator from a state
    whose sticking nodes already carry a tangential force)."""

    def __init__(self, *args, anchors: np.ndarray):
        super().__init__(*args)
        self._given = np.asarray(anchors, dtype=float)

    def _stick_anchors(self, codes, q, t: float) -> np.ndarray:
        return self._given.copy()


def _admissible(fl: CoulombFlight, codes, anchors, q, p) -> tuple[np.ndarray, np.ndarray]:
    """The start codes made admissible: a node whose sticking would leave the cone slides that way."""
    codes, anchors = codes.copy(), anchors.copy()
    for _ in range(4 * fl.m + 4):
        cand, bad = fl._violations(codes, anchors, q, p, 0.0)
        if not bad:
            return codes, anchors
        i, kind = cand.meta[bad[0]]
        codes[i] = fl._options(cand, i, kind, codes, p, 0.0)[0]
        if codes[i] == STICK:
            anchors[i] = fl._anchor(cand, i, q, 0.0, anchors)
    raise ValueError("no admissible start state of the contact nodes (a grazing start): change the amplitude")


def _start(fl: CoulombFlight, q, p, ratio: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Codes and anchors at ``(q, p)``: each closed node sticks with ``τ_j = r_j μ λ_j`` (then made admissible)."""
    codes, _ = fl.initial(q, p)
    closed = codes > OPEN
    codes = np.where(closed, STICK, OPEN).astype(np.int8)
    anchors = np.zeros(fl.m)
    S = np.flatnonzero(closed)
    if S.size:
        ph = fl.phase(codes)
        G = ph.Pt - (fl.mu * ratio)[:, None] * ph.El  # τ − rμλ in the phase's unknowns
        u0 = ph.Uq @ q + ph.Ur @ ph.rho(fl, 0.0, anchors)
        A = (G @ ph.Ur[:, fl.m:])[np.ix_(S, S)]
        anchors[S] = np.linalg.solve(A, -(G @ u0)[S])
    try:
        return _admissible(fl, codes, anchors, q, p)
    except ValueError:  # no admissible state from these fractions (a trial state of the solve): free of force
        return _admissible(fl, *fl.initial(q, p), q, p)


def _flow(fl: CoulombFlight, q, p, codes, anchors, period: float, max_switches: int = 20_000) -> CoulombTrajectory:
    """The flight of ``period`` from ``(q, p)`` with the node state ``(codes, anchors)``: its phases as a
    :class:`CoulombTrajectory` (switches on a grid, then bracketed: the phases may grow)."""
    t, still = 0.0, 0
    starts, cl, al, qs, ps, amps = [], [], [], [], [], []
    for _ in range(max_switches):
        ph = fl.phase(codes)
        amp = ph.amplitudes(q, p, t, anchors)
        starts.append(t), cl.append(codes), al.append(anchors), qs.append(q), ps.append(p), amps.append(amp)
        sig = ph.signals(fl, amp, t, anchors, period - t)
        f0 = sig.values(0.0)[0][0]
        on = np.abs(f0) <= SURFACE_RTOL * np.maximum(sig.magnitude, np.finfo(float).tiny)
        hit = _first(sig, period - t, on)
        if hit is None:
            break
        tau, k = hit
        q, p = ph.advance(amp, t, tau, anchors)
        t += tau
        new, anchors = fl._switch(ph, k, codes, anchors, q, p, t)
        # a switch that changes no node and finds its signal again at once would repeat forever
        still = still + 1 if np.array_equal(new, codes) and tau <= 1e-12 * period else 0
        if still > 2 * fl.m + 2:
            node, kind = ph.meta[k]
            raise ValueError(f"the mode's flow is stuck at t = {t:.12g} s: contact node {fl.system.nodes[node]}'s "
                             f"{kind} signal reaches 0 again at once and no node changes (a degenerate switch)")
        codes = new
    else:
        raise ValueError(f"the mode's flow needed more than {max_switches} switches in one period")
    return CoulombTrajectory(fl, np.array(starts), np.array(cl), np.array(al), np.array(qs).T, np.array(ps).T,
                             np.array(amps), float(period), True)


def _ratio(tr: CoulombTrajectory, t: float) -> np.ndarray:
    """Each node's ``τ_j / μλ_j`` at ``t`` (0 for an open node)."""
    _, _, lam, tau, _, _ = tr.sample(t)
    lam, tau = lam[:, 0], tau[:, 0]
    mu = tr.flight.mu
    return np.where(lam > 0, np.clip(tau / np.where(lam > 0, mu * lam, 1.0), -1.0, 1.0), 0.0)


@dataclass(frozen=True, eq=False)
class CoulombMode:
    """:func:`coulomb_mode`'s answer: the start state (interior ``x0``, ``v0``; the nodes' ``codes`` and sticking
    ``anchors``), the period ``T`` (s), ``ω = 2π/T`` (rad/s), the extra damping ``ξ`` (1/s), ``ζ = ξ/2ω``, the
    orbit's closing residual relative to its amplitude, the tangential start state's (cone fractions), and the
    orbit over one period (:class:`~bladecase.nsm.massless.friction_coulomb.CoulombTrajectory`, ``−ξ`` in its
    damping)."""

    x0: np.ndarray
    v0: np.ndarray
    codes: np.ndarray
    anchors: np.ndarray
    period: float
    frequency: float
    xi: float
    zeta: float
    residual: float
    tangential_residual: float
    converged: bool
    orbit: CoulombTrajectory


def _guess(system, friction, damping, sliding, load, amplitude, mode, others, n):
    """A start for the solve: the other modes at the load's static deflection (its contacts closed as they
    hold), the open-phase period, and ``ξ``
    from the energy of the followed mode lost over that period without the term."""
    omega, phi = system.modes
    fq = phi.T @ np.asarray(load if load is not None else np.zeros(n), dtype=float)
    Wq = phi.T @ system.W
    lam = lcp(system.gap - Wq.T @ (fq / omega**2), system.H + Wq.T @ (Wq / omega[:, None] ** 2))
    q = (fq - Wq @ lam) / omega**2  # the static state with its contacts
    q[mode] = amplitude
    p = np.zeros(n)
    T = 2 * np.pi / omega[mode]
    fl = _EPMCFlight(system, friction, damping, sliding, load, 0.0)
    ratio = -np.sign(fl.Tq[mode]) * np.sign(amplitude)
    codes, anchors = _start(fl, q, p, ratio)
    tr = _flow(fl, q, p, codes, anchors, T)
    qT, pT = tr.state(T)
    qT, pT = phi.T @ (system.M @ qT[:, 0]), phi.T @ (system.M @ pT[:, 0])
    e0 = 0.5 * omega[mode] ** 2 * amplitude**2
    e1 = 0.5 * (pT[mode] ** 2 + omega[mode] ** 2 * qT[mode] ** 2)
    xi = max(-np.log(max(e1, 1e-300) / e0) / T, 0.0) if e1 > 0 else 0.0
    return np.r_[q[others], p[others], T, xi], ratio


def coulomb_mode(system: NodalSystem, friction: Friction, amplitude: float, mode: int = 0, damping=None,
                 load=None, sliding=0.0, guess: CoulombMode | None = None, tol: float = 1e-10) -> CoulombMode:
    """The periodic orbit of the extended periodic motion concept with stick–slip friction (module docstring)
    through the turning point where the open-phase mode ``mode``'s coordinate is ``amplitude``: ``load``, a constant
    force on the interior (the normal preload); ``sliding``, the casing's speed under each node (m/s, default 0: at
    rest); ``guess``, a neighbouring answer to start from.

    >>> import numpy as np
    >>> s = NodalSystem(np.eye(2), np.diag([1.0, 4.0]), np.array([[0.0], [1.0]]), [[1e-3]], gap=[0.1])
    >>> f = Friction(0.4, T=[[1.0], [0.0]], C_tt=[[0.5]], model="coulomb")
    >>> m = coulomb_mode(s, f, amplitude=2.0, load=[0.0, 1.404])
    >>> round(m.frequency, 4), round(m.zeta, 4)          # stiffer and damped by the stick–slip contact
    (1.0493, 0.106)
    """
    n, omega, phi, others = checked_mode(system, friction, amplitude, mode)
    if guess is None:
        y0, ratio = _guess(system, friction, damping, sliding, load, amplitude, mode, others, n)
    else:
        q, p = phi.T @ (system.M @ guess.x0), phi.T @ (system.M @ guess.v0)
        y0 = np.r_[q[others], p[others], guess.period, guess.xi]
        ratio = _ratio(guess.orbit, 0.0)
    scale = np.r_[np.full(2 * (n - 1), amplitude), y0[-2], max(abs(y0[-1]), 1e-3 / y0[-2])]

    def state(y):
        q, p = np.zeros(n), np.zeros(n)
        q[mode], q[others], p[others] = amplitude, y[: n - 1], y[n - 1:2 * n - 2]
        return q, p

    def orbit(z, ratio):
        y = z * scale
        q, p = state(y)
        fl = _EPMCFlight(system, friction, damping, sliding, load, y[-1])
        codes, anchors = _start(fl, q, p, ratio)
        return _flow(fl, q, p, codes, anchors, y[-2]), q, p

    def residual(z, ratio):
        tr, q, p = orbit(z, ratio)
        qT, pT = tr.state(tr.t_end)
        qT = phi.T @ (system.M @ qT[:, 0])
        pT = phi.T @ (system.M @ pT[:, 0])
        return np.r_[qT - q, pT - p] / amplitude

    z = y0 / scale
    gap = np.inf
    for _ in range(TANGENTIAL_ITERATIONS):
        sol = root(residual, z, args=(ratio,), method="hybr", options={"xtol": tol})
        z = sol.x
        tr, _, _ = orbit(z, ratio)
        new = _ratio(tr, tr.t_end)
        gap = float(np.abs(new - ratio).max())
        ratio = new
        if gap < 1e-8:
            break
    tr, q, p = orbit(z, ratio)
    res = float(np.abs(residual(z, ratio)).max())
    y = z * scale
    T, xi = float(y[-2]), float(y[-1])
    w = 2 * np.pi / T
    return CoulombMode(phi @ q, phi @ p, tr.codes[0], tr.anchors[0], T, w, xi, xi / (2 * w), res, gap,
                       bool(res < 1e3 * tol and gap < 1e-6 and 0 < T < 4 * np.pi / omega.min()), tr)


def orbit_kinetic(tr: CoulombTrajectory, t0: float, t1: float, order: int = 20) -> float:
    """``∫ x'ᵀMx' dt`` over ``[t0, t1]`` of a stick–slip trajectory (Gauss–Legendre of ``order`` on each phase
    piece, cut at most a tenth of the open-phase fastest period long).

    >>> import numpy as np
    >>> s = NodalSystem(np.eye(2), np.diag([1.0, 4.0]), np.array([[0.0], [1.0]]), [[1e-3]], gap=[0.1])
    >>> f = Friction(0.4, T=[[1.0], [0.0]], C_tt=[[0.5]], model="coulomb")
    >>> m = coulomb_mode(s, f, amplitude=2.0, load=[0.0, 1.404])
    >>> round(m.xi * orbit_kinetic(m.orbit, 0.0, m.period), 6)     # = the Jenkins loop 4·0.4·(2 − 0.2)
    2.88
    """
    s = tr.system
    step = 0.1 * 2 * np.pi / float(s.modes[0].max())
    cuts = np.r_[t0, tr.starts[(tr.starts > t0) & (tr.starts < t1)], t1]
    edges = np.unique(np.concatenate([np.linspace(a, b, int(np.ceil((b - a) / step)) + 1)
                                      for a, b in zip(cuts[:-1], cuts[1:])]))
    mid, half = 0.5 * (edges[1:] + edges[:-1]), 0.5 * np.diff(edges)
    g, w = np.polynomial.legendre.leggauss(order)
    _, v = tr.state((mid[:, None] + half[:, None] * g).ravel())
    return float(np.einsum("it,ij,jt->t", v, s.M, v) @ (half[:, None] * w).ravel())


def coulomb_decay_ratio(system: NodalSystem, friction: Friction, mode: CoulombMode, damping=None, load=None,
                        sliding=0.0) -> float:
    """The damping ratio at ``mode``'s amplitude of the free decay from its start state (its nodes' codes and
    anchors too), without the extra term, by the certified stick–slip simulator. Over each period ``T`` the energy
    lost, ``−ΔE``, over what the term ``ξ`` would put back, ``ξ∫x'ᵀMx' dt``, is that period's ratio
    ``ζ_k = −ΔE_k / (2ω ∫x'ᵀMx' dt)``; it belongs to the period's middle, where the amplitude has already fallen by
    about ``πζ``. Friction's share of the ratio grows steeply with the amplitude just above the grazing one (seven
    times as fast, relatively, on the demo blade's tip), so the ratio at the start's amplitude is read from the
    first two periods, half a period back: :func:`~bladecase.nsm.massless.friction_modes.start_ratio`.

    >>> import numpy as np
    >>> from bladecase.nsm.massless.nodes import NodalSystem
    >>> s = NodalSystem(np.eye(2), np.diag([1.0, 4.0]), np.array([[0.0], [1.0]]), [[1e-3]], gap=[0.1])
    >>> f = Friction(0.4, T=[[1.0], [0.0]], C_tt=[[0.5]], model="coulomb")
    >>> load = [0.0, 0.4 + 1.004]
    >>> m = coulomb_mode(s, f, amplitude=10.0, load=load)
    >>> round(float(m.zeta), 4), round(float(coulomb_decay_ratio(s, f, m, load=load) / m.zeta), 3)
    (0.0248, 1.002)
    """
    fl = _Anchored(system, friction, damping, None, sliding, load, anchors=mode.anchors)
    T = mode.period
    tr = fl.simulate(mode.x0, mode.v0, 2 * T, codes=mode.codes)
    E = _stored(tr, [0.0, T, 2 * T])
    kinetic = [orbit_kinetic(tr, 0.0, T), orbit_kinetic(tr, T, 2 * T)]
    return start_ratio(-np.diff(E), kinetic, mode.frequency)


def jenkins_dissipation(amplitude, slip_force: float, contact_stiffness: float):
    """The energy a Jenkins element (a spring ``k_t`` in series with a slider of slip force ``F_s``) dissipates
    over a cycle between ``±a``: ``4F_s(a − F_s/k_t)``, 0 while it sticks (``a <= F_s/k_t``).

    >>> float(jenkins_dissipation(1.0, 0.5, 10.0))
    1.9
    """
    a = np.asarray(amplitude, dtype=float)
    if not (slip_force >= 0 and contact_stiffness > 0):
        raise ValueError(f"slip_force must be >= 0 and contact_stiffness > 0, got {slip_force!r}, "
                         f"{contact_stiffness!r}")
    return 4 * slip_force * np.maximum(a - slip_force / contact_stiffness, 0.0)


def equivalent_ratio(dissipation, amplitude, omega, mass: float = 1.0):
    """The equivalent viscous damping ratio of a cycle between ``±a`` at ``ω`` dissipating ``W_d``:
    ``W_d / (2π · 2E_max)``, ``E_max = ½mω²a²``.

    >>> round(float(equivalent_ratio(4 * 0.1, 1.0, 1.0)), 6)        # rigid node: 2μN/(πka), μN = 0.1, k = 1
    0.063662
    """
    return np.asarray(dissipation, dtype=float) / (2 * np.pi * mass * np.asarray(omega, float) ** 2
                                                    * np.asarray(amplitude, float) ** 2)
