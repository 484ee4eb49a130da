"""A nonsmooth mode with friction: its amplitude-dependent frequency and damping ratio by the extended periodic
motion concept (Krack 2015): :func:`friction_mode`.

With friction (:mod:`~bladecase.nsm.massless.friction`) the free motion of a :class:`NodalSystem` against its
casing (constant clearances) is not periodic: the drag does work on the vibration. The extended periodic motion
concept adds the negative modal damping term ``−ξ M x'`` that makes it periodic again,

    M x'' + (C − ξM) x' + S x + (W − μT) λ = 0,

and solves for the orbit, its period ``T`` and ``ξ`` together at a given amplitude: ``ξ`` is the rate at which
the term puts back the energy that friction (and damping ``C``) take over a period, and the mode's damping ratio
is ``ζ = ξ / 2ω``, ``ω = 2π/T``. The unknowns are the start state in the open-phase modal coordinates (the
followed mode's coordinate at ``amplitude``, its velocity 0: the start is a turning point), ``T`` and ``ξ``; the
residual is the flow over ``T`` minus the start, solved by Powell's hybrid method with a finite-difference
Jacobian.

The flow is flown phase by phase in closed form (:class:`~bladecase.nsm.massless.friction.FrictionFlight`, whose
phases grow here: the term feeds them). A growing phase does not fit the certified switch search of the model
without it, so each phase's first switch is found on a grid of :data:`GRID_POINTS` points per fastest period of
the phase, then bracketed to machine precision: a switch narrower than a grid step could be missed. The answer is
checked independently by :func:`decay_ratio`: the free decay of the orbit's start state, without the term,
simulated by the certified simulator; its energy lost over the first period gives the damping ratio again.

>>> import numpy as np
>>> from bladecase.nsm.massless.nodes import NodalSystem
>>> from bladecase.nsm.massless.friction import Friction
>>> s = NodalSystem(np.eye(2), np.array([[1.0, 0.2], [0.2, 2.5]]), np.array([[1.0], [0.3]]), [[0.02]], gap=[1.0])
>>> f = Friction(0.15, T=np.array([[0.2], [1.0]]))
>>> m = friction_mode(s, f, amplitude=1.3)
>>> bool(m.converged), abs(m.zeta) < 1e-12, float(round(m.frequency / s.modes[0][0], 4))
(True, True, 1.1484)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq, root

from .friction import Friction, FrictionFlight
from .friction_energy import stored_energy
from .nodes import NodalSystem, simulate_nodes

__all__ = ["GRID_POINTS", "FrictionMode", "decay_ratio", "friction_mode", "harmonic_amplification",
           "start_ratio"]

#: Grid points per fastest period of a phase in the switch search of the EPMC flow.
GRID_POINTS = 64


class _GrowingFlight(FrictionFlight):
    """A :class:`FrictionFlight` with the extra modal damping ``−ξ`` (phases may grow)."""

    def __init__(self, system, friction, damping, xi: float):
        super().__init__(system, friction, damping)
        base = self.Cq if self.Cq is not None else np.zeros((self.n, self.n))
        self.Cq = base - xi * np.eye(self.n)
        self.allow_growth = True


def _first(sig, horizon: float, on: np.ndarray) -> tuple[float, int] | None:
    """The first root in ``(0, horizon]`` of the signals (grid of :data:`GRID_POINTS` per fastest period, then
    bracketed); signals ``on`` their surface are skipped until they have left it."""
    w = max(float(np.abs(sig.lam).max()), sig.nu, 1e-300)
    count = int(np.ceil(horizon * w * GRID_POINTS / (2 * np.pi))) + 1
    tau = np.linspace(0.0, horizon, max(count, 3))
    F = sig.values(tau)[0]
    left = np.ones_like(F, dtype=bool)
    if on.any():  # an on-surface signal counts once it has been positive
        left[:, on] = np.maximum.accumulate(F[:, on] > 0, axis=0)
    neg = (F[1:] < 0) & left[:-1]
    rows = np.flatnonzero(neg.any(axis=1))
    if rows.size == 0:
        return None
    i = int(rows[0])
    best = None
    for j in np.flatnonzero(neg[i]):
        r = brentq(lambda t, j=j: float(sig.values(t)[0][0, j]), tau[i], tau[i + 1], xtol=1e-15, rtol=1e-15)
        if best is None or r < best[0]:
            best = (r, int(j))
    return best


def _flow(fl: FrictionFlight, q, p, period: float, max_switches: int = 10_000):
    t, A, on = 0.0, fl.active_set(q, p, 0.0), np.zeros(fl.system.m, dtype=bool)
    for _ in range(max_switches):
        ph = fl.phase(A)
        a = ph.amplitudes(q, p, t)
        hit = _first(ph.signals(a, t), period - t, on)
        if hit is None:
            return ph.advance(a, t, period - t)
        tau, j = hit
        q, p = ph.advance(a, t, tau)
        t += tau
        on = np.zeros_like(on)
        on[j] = True
        A = A.copy()
        A[j] = not A[j]
    raise ValueError(f"the mode's flow needed more than {max_switches} switches in one period")


@dataclass(frozen=True, eq=False)
class FrictionMode:
    """:func:`friction_mode`'s answer: the start state (interior ``x0``, ``v0``), the period ``T`` (s), the
    frequency ``ω = 2π/T`` (rad/s), the extra damping ``ξ`` (1/s), the damping ratio ``ζ = ξ/2ω`` and the closing
    residual of the orbit relative to its amplitude."""

    x0: np.ndarray
    v0: np.ndarray
    period: float
    frequency: float
    xi: float
    zeta: float
    residual: float
    converged: bool


def checked_mode(system: NodalSystem, friction: Friction, amplitude: float, mode: int):
    """The arguments of an extended-periodic-motion mode checked (``ValueError`` naming the bad one); returns
    ``(n, ω, Φ, the other modes' indices)``."""
    if not isinstance(friction, Friction):
        raise ValueError(f"friction must be a Friction, got {type(friction).__name__}")
    friction.check(system)
    if not (np.isfinite(amplitude) and amplitude > 0):
        raise ValueError(f"amplitude must be a finite number > 0 (the mode's modal coordinate), got {amplitude!r}")
    n = system.n
    omega, phi = system.modes
    if not (isinstance(mode, (int, np.integer)) and 0 <= mode < n):
        raise ValueError(f"mode must be an integer in 0..{n - 1}, got {mode!r}")
    others = np.flatnonzero(np.arange(n) != mode)
    return n, omega, phi, others


def friction_mode(system: NodalSystem, friction: Friction, amplitude: float, mode: int = 0, damping=None,
                  guess: FrictionMode | None = None, tol: float = 1e-10) -> FrictionMode:
    """The periodic orbit of the extended periodic motion concept (module docstring) through the turning point
    where the open-phase mode ``mode``'s coordinate is ``amplitude``; ``guess``: a neighbouring answer to start
    from (default: the open-phase mode itself, ``ξ = 0``)."""
    n, omega, phi, others = checked_mode(system, friction, amplitude, mode)
    if guess is None:
        y0 = np.r_[np.zeros(2 * (n - 1)), 2 * np.pi / omega[mode], 0.0]
    else:
        q, p = phi.T @ (system.M @ guess.x0), phi.T @ (system.M @ guess.v0)
        y0 = np.r_[q[others] * amplitude / q[mode], p[others] * amplitude / q[mode], guess.period, guess.xi]
    scale = np.r_[np.full(2 * (n - 1), amplitude), y0[-2], 1.0 / y0[-2]]

    def start(y):
        q, p = np.zeros(n), np.zeros(n)
        q[mode], q[others], p[others] = amplitude, y[: n - 1], y[n - 1:2 * n - 2]
        return q, p

    def residual(z):
        y = z * scale
        q, p = start(y)
        fl = _GrowingFlight(system, friction, damping, y[-1])
        qT, pT = _flow(fl, q, p, y[-2])
        return np.r_[qT - q, pT - p] / amplitude

    sol = root(residual, y0 / scale, method="hybr", options={"xtol": tol})
    y = sol.x * scale
    res = float(np.abs(residual(sol.x)).max())
    q, p = start(y)
    T, xi = float(y[-2]), float(y[-1])
    w = 2 * np.pi / T
    return FrictionMode(phi @ q, phi @ p, T, w, xi, xi / (2 * w), res, bool(res < 1e3 * tol and T > 0))


def harmonic_amplification(omega, zeta, frequency: float, mode: int = 0,
                           harmonics: int = 12) -> list[tuple[int, int, float]]:
    """How strongly each other open-phase mode answers the harmonics of an orbit of ``mode`` at ``frequency``
    (rad/s): for each mode ``k`` above ``mode`` (angular frequencies ``omega``, damping ratios ``zeta``), its nearest
    harmonic ``h`` (1 to ``harmonics``) and the dynamic amplification ``1/√((1 − r²)² + (2ζ_k r)²)``,
    ``r = hΩ/ω_k``: ``[(k, h, gain), ...]``. A gain of tens says an internal resonance: the orbit's ``h``-th
    harmonic drives mode ``k`` near its resonance, and the orbit is not one nonlinear mode's alone.

    >>> out = harmonic_amplification([1.0, 4.01, 9.7], [0.005, 0.005, 0.005], 1.0)
    >>> [(k, h, round(g, 1)) for k, h, g in out]      # mode 1 answers the 4th harmonic, mode 2 the 10th
    [(1, 4, 89.7), (2, 10, 15.7)]
    """
    omega, zeta = np.asarray(omega, dtype=float), np.broadcast_to(np.asarray(zeta, dtype=float), np.shape(omega))
    out = []
    for k in range(mode + 1, omega.size):
        h = int(np.clip(np.round(omega[k] / frequency), 1, harmonics))
        r = h * frequency / omega[k]
        out.append((k, h, float(1 / np.sqrt((1 - r**2) ** 2 + (2 * zeta[k] * r) ** 2))))
    return out


def start_ratio(losses, kinetic, frequency: float) -> float:
    """The damping ratio at the start of a free decay from its first two periods: each period's energy loss
    ``W_k`` and kinetic integral ``K_k = ∫x'ᵀMx' dt``. A period's own ratio, ``W_k / 2ωK_k``, belongs to its
    middle, where the amplitude has already fallen by about ``πζ``; where the ratio changes with the amplitude
    (friction, contact) it is not the start's. With each period's middle amplitude ``A_k ∝ √K_k`` and the start's
    ``A_s = A_0 √(1 + W_0T/2K_0)`` (the energy ``K_0/T`` of the first period's middle plus half its loss), the loss
    is read at ``A_s`` on the power law ``W ∝ A^p`` through the two periods (exact for a viscous loss, ``p = 2``, and
    nearly so for a Jenkins element's, ``p ≈ 1``), and ``ζ = W(A_s) / 2ωK_s`` with ``K_s = K_0 A_s²/A_0²``. Where
    the amplitude falls by more than a fifth in a period (or the second period loses nothing: the decay has
    stuck), two periods do not make a law: the first period's own ratio is the answer.

    >>> import numpy as np
    >>> z = 0.01                                       # a linear oscillator (ω = 1): its energy falls e^(−4πζ) a period
    >>> W = np.array([1.0, np.exp(-4 * np.pi * z)]) * (1 - np.exp(-4 * np.pi * z))
    >>> round(start_ratio(W, W / (2 * z), 1.0) / z, 6)
    1.0
    """
    W = np.asarray(losses, dtype=float)
    K = np.asarray(kinetic, dtype=float)
    T = 2 * np.pi / frequency
    A = np.sqrt(K)
    grow = np.sqrt(1 + W[0] * T / (2 * K[0]))  # A_s / A_0
    if not (W[0] > 0 and W[1] > 0 and 0.8 * A[0] <= A[1] < A[0]):
        return float(W[0] / (2 * frequency * K[0]))
    p = np.log(W[0] / W[1]) / np.log(A[0] / A[1])
    return float(W[0] * grow ** (p - 2) / (2 * frequency * K[0]))


def decay_ratio(system: NodalSystem, friction: Friction, mode: FrictionMode, damping=None,
                samples: int = 4001) -> float:
    """The damping ratio at ``mode``'s amplitude of the free decay from its start state, without the extra term:
    over each period ``T`` of the certified simulation, the energy lost, ``−ΔE``, over what the term ``ξ`` would
    put back in the extended concept, ``ξ∫x'ᵀMx' dt`` (Simpson's rule on ``samples`` points), read at the start's
    amplitude from the first two periods (:func:`start_ratio`). Without friction it agrees with ``mode.zeta`` to
    first order in the damping; with it, within a few per cent: the decaying orbit is not reversible and friction
    does work on it, while the extended concept's orbit is balanced.

    >>> import numpy as np
    >>> from bladecase.nsm import Damping
    >>> from bladecase.nsm.massless.nodes import NodalSystem
    >>> s = NodalSystem(np.eye(2), np.array([[1.0, 0.2], [0.2, 2.5]]), np.array([[1.0], [0.3]]), [[0.02]],
    ...                 gap=[1.0])
    >>> f = Friction(0.15, T=np.array([[0.2], [1.0]]))
    >>> m = friction_mode(s, f, amplitude=1.3, damping=Damping(zeta=0.01))
    >>> round(float(decay_ratio(s, f, m, Damping(zeta=0.01)) / m.zeta), 3)   # friction works on the decay
    0.978
    """
    from scipy.integrate import simpson

    from .friction import friction_flight

    fl = friction_flight(system, friction, damping)
    T = mode.period
    tr = simulate_nodes(system, mode.x0, mode.v0, 2 * T, flight=fl)
    E = stored_energy(tr, [0.0, T, 2 * T])
    kinetic = []
    for k in range(2):
        t = np.linspace(k * T, (k + 1) * T, samples)
        _, v = tr.state(t)
        kinetic.append(simpson(np.einsum("it,ij,jt->t", v, system.M, v), x=t))
    return start_ratio(-np.diff(E), kinetic, mode.frequency)
