"""The energy balance of a trajectory with friction (:mod:`~bladecase.nsm.massless.friction`): what the casing puts
in, what friction does, what damping takes, what is stored — per span or per revolution; the rub with friction.

Over ``[t0, t1]`` (theory §8 with the friction terms of :mod:`~bladecase.nsm.massless.friction`):

    E(t1) − E(t0) = W_casing + W_friction − D,
    E = ½x'ᵀMx' + ½xᵀSx + ½λᵀ(H − μ(C_nt + C_ntᵀ) + μ²C_tt)λ,
    W_casing = −∫ λᵀg' dt,   W_friction = ∫ μλᵀz' dt,   D = ∫ x'ᵀCx' dt,

``z' = Tᵀx' − C_ntᵀλ' + μC_ttλ'`` the nodes' tangential vibration velocity. ``E`` holds the interior's kinetic and
strain energy, the contact nodes' strain energy under their normal and tangential forces, and the casing's springs.
``W_friction`` is the work of friction on the vibration (the heat ``μλΩR`` the rotor's drive pays is not in it).
The integrals are taken by Gauss–Legendre quadrature on each contact phase (every integrand is a smooth sum of
exponentials there), each phase cut into pieces a quarter of its fastest period long, at two orders (10 and 20
points): their difference is the stated quadrature error. The stored energy is read in closed form at the ends.

>>> import numpy as np
>>> from bladecase.nsm import Damping
>>> from bladecase.nsm.massless.nodes import NodalSystem
>>> from bladecase.nsm.massless.friction import Friction, simulate_friction
>>> s = NodalSystem(np.eye(2), np.diag([1.0, 2.0]), np.array([[1.0], [0.0]]), np.array([[0.05]]), gap=[1.0])
>>> f = Friction(0.15, T=np.array([[0.0], [1.0]]))
>>> tr = simulate_friction(s, f, [2.0, 0.0], [0.0, 0.3], 30.0, damping=Damping(zeta=0.01))
>>> e = energy_balance(tr, 0.0, 30.0)
>>> bool(abs(e.relative) < 1e-12), bool(e.friction != 0), bool(e.damping > 0)
(True, True, True)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .nodes import NodalTrajectory

__all__ = ["FrictionEnergy", "energy_balance", "gauss_points", "per_revolution", "revolution_spans", "stored_energy",
           "tangential_rates"]

#: Gauss–Legendre orders of the two quadratures (their difference: the stated error).
ORDERS = (10, 20)

#: Pieces per fastest period of a phase.
PIECES_PER_PERIOD = 4


@dataclass(frozen=True)
class FrictionEnergy:
    """The energy balance over ``[t0, t1]`` (J): ``stored_change = casing + friction − damping`` up to ``residual``;
    ``relative``: ``residual`` over the largest term; ``quadrature_error``: the two quadratures' difference."""

    t0: float
    t1: float
    casing: float
    friction: float
    damping: float
    stored_change: float
    residual: float
    relative: float
    quadrature_error: float


def _rates(tr: NodalTrajectory, t: np.ndarray):
    """Modal ``q``, ``p``, ``λ``, ``λ'`` and ``g'`` at the times ``t`` (each from the phase holding it)."""
    fl = tr.flight
    t = np.atleast_1d(np.asarray(t, dtype=float))
    k = np.clip(np.searchsorted(tr.starts, t, side="right") - 1, 0, tr.starts.size - 1)
    n, m = fl.n, tr.system.m
    Q, P = np.empty((n, t.size)), np.empty((n, t.size))
    lam, dlam = np.zeros((m, t.size)), np.zeros((m, t.size))
    gdot = np.zeros((m, t.size)) if fl.D is None else np.multiply.outer(1j * fl.nu * fl.D,
                                                                         np.exp(1j * fl.nu * t)).real
    order = np.argsort(k, kind="stable")
    bounds = np.searchsorted(k[order], np.arange(tr.starts.size + 1))
    for i in np.flatnonzero(np.diff(bounds)):
        sel = order[bounds[i]:bounds[i + 1]]
        ph = fl.phase(tr.active[i], tr.starts[i])
        a = tr.amplitudes[i]
        Q[:, sel], P[:, sel] = ph.advance(a, tr.starts[i], t[sel] - tr.starts[i])
        if ph.idx.size:
            lam[np.ix_(ph.idx, sel)] = ph.GWt @ Q[:, sel] - ph.G @ fl.gap(t[sel])[ph.idx]
            dlam[np.ix_(ph.idx, sel)] = ph.GWt @ P[:, sel] - ph.G @ gdot[np.ix_(ph.idx, sel)]
    return Q, P, lam, dlam, gdot


def _friction_terms(fl):
    fr = getattr(fl, "friction", None)
    s = fl.system
    if fr is None:
        return 0.0, None, None, None, s.H
    return fr.mu, fl.Tq, fr.C_nt, fr.C_tt, fr.stored(s)


def tangential_rates(tr: NodalTrajectory, t) -> np.ndarray:
    """The nodes' tangential vibration velocities ``z'`` (``(m, k)``) at the times ``t`` (zero without friction
    data).

    >>> from bladecase.nsm.massless.nodes import NodalSystem
    >>> from bladecase.nsm.massless.friction import Friction, simulate_friction
    >>> s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), np.array([[0.05]]), gap=[2.0])
    >>> tr = simulate_friction(s, Friction(0.2, T=[[0.5]]), [1.0], [0.0], 1.0)
    >>> float(tangential_rates(tr, np.pi / 2)[0, 0].round(12))      # free flight: z' = 0.5 x' = −0.5
    -0.5
    """
    mu, Tq, C_nt, C_tt, _ = _friction_terms(tr.flight)
    Q, P, lam, dlam, _ = _rates(tr, t)
    if Tq is None:
        return np.zeros_like(lam)
    return Tq.T @ P - C_nt.T @ dlam + mu * (C_tt @ dlam)


def stored_energy(tr: NodalTrajectory, t) -> np.ndarray:
    """``E(t)`` (module docstring) at the times ``t`` (J), in closed form.

    >>> from bladecase.nsm.massless.nodes import NodalSystem, simulate_nodes
    >>> s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), np.array([[0.05]]), gap=[1.0])
    >>> tr = simulate_nodes(s, [2.0], [0.0], 10.0)
    >>> float(np.ptp(stored_energy(tr, [0.0, 7.3])).round(12)) == 0.0
    True
    """
    fl = tr.flight
    _, _, _, _, Hst = _friction_terms(fl)
    Q, P, lam, _, _ = _rates(tr, t)
    return 0.5 * (P * P).sum(0) + 0.5 * ((fl.omega[:, None] ** 2) * Q * Q).sum(0) + 0.5 * (lam * (Hst @ lam)).sum(0)


def _powers(tr: NodalTrajectory, t: np.ndarray) -> np.ndarray:
    """``(3, k)``: the casing's, friction's and damping's powers at ``t``."""
    fl = tr.flight
    mu, Tq, C_nt, C_tt, _ = _friction_terms(fl)
    Q, P, lam, dlam, gdot = _rates(tr, t)
    casing = -(lam * gdot).sum(0)
    if Tq is None:
        fric = np.zeros(t.size)
    else:
        fric = mu * (lam * (Tq.T @ P - C_nt.T @ dlam + mu * (C_tt @ dlam))).sum(0)
    damp = (P * (fl.Cq @ P)).sum(0) if fl.Cq is not None else np.zeros(t.size)
    return np.vstack([casing, fric, damp])


def _fastest(tr: NodalTrajectory) -> float:
    fl = tr.flight
    w = max(float(np.abs(fl.phase(A).lam).max()) for A in np.unique(tr.active, axis=0))
    return max(w, fl.nu, 1e-300)


def gauss_points(starts: np.ndarray, t0: float, t1: float, fastest, order: int):
    """The Gauss–Legendre points and weights of ``order`` over ``[t0, t1]``, cut at the phase ``starts`` inside it
    and each phase cut into pieces a :data:`PIECES_PER_PERIOD`-th of the period ``2π/fastest`` long (``fastest``:
    one rate (rad/s), or one a phase).

    >>> t, w = gauss_points(np.array([0.0, 1.0]), 0.0, 2.0, np.pi, 3)     # two phases of a 2 s period's half each
    >>> t.size, round(float(w.sum()), 12), round(float(w @ t**5), 12)    # ∫₀² t⁵ dt = 64/6, exact
    (12, 2.0, 10.666666666667)
    """
    cuts = np.r_[t0, starts[(starts > t0) & (starts < t1)], t1]
    h = 2 * np.pi / (PIECES_PER_PERIOD * fastest)
    x, w = np.polynomial.legendre.leggauss(order)
    a, b = cuts[:-1], cuts[1:]
    if np.ndim(h):  # each span's phase: the one starting at its left end
        h = h[np.clip(np.searchsorted(starts, a, side="right") - 1, 0, None)]
    k = np.maximum(1, np.ceil((b - a) / h).astype(np.int64))  # pieces of each span, its edges as np.linspace's
    step = (b - a) / k
    span = np.repeat(np.arange(a.size), k)
    j = (np.arange(span.size) - np.repeat(np.cumsum(k) - k, k)).astype(float)
    left = j * step[span] + a[span]
    right = np.where(j + 1 == k[span], b[span], (j + 1) * step[span] + a[span])
    mid, half = 0.5 * (right + left), 0.5 * (right - left)
    return (mid[:, None] + half[:, None] * x).ravel(), (half[:, None] * w).ravel()


def _integrals(tr: NodalTrajectory, t0: float, t1: float, order: int) -> np.ndarray:
    t, wt = gauss_points(tr.starts, t0, t1, _fastest(tr), order)
    return _powers(tr, t) @ wt


def energy_balance(tr: NodalTrajectory, t0: float, t1: float) -> FrictionEnergy:
    """The energy balance of ``tr`` over ``[t0, t1]`` (module docstring), with or without friction."""
    if not (0 <= t0 < t1 <= tr.t_end * (1 + 1e-12)):
        raise ValueError(f"[t0, t1] = [{t0!r}, {t1!r}] must lie in the trajectory's [0, {tr.t_end!r}] with t0 < t1")
    low, high = (_integrals(tr, t0, t1, n) for n in ORDERS)
    casing, fric, damp = high
    E = stored_energy(tr, [t0, t1])
    change = float(E[1] - E[0])
    residual = change - (casing + fric - damp)
    scale = max(abs(casing), abs(fric), abs(damp), abs(change), float(np.abs(E).max()), np.finfo(float).tiny)
    return FrictionEnergy(float(t0), float(t1), float(casing), float(fric), float(damp), change, float(residual),
                          float(residual / scale), float(np.abs(high - low).max()))


def per_revolution(tr: NodalTrajectory, speed: float, first: int = 0) -> list[FrictionEnergy]:
    """:func:`energy_balance` over each whole revolution ``2π/speed`` of ``tr`` from revolution ``first``."""
    return [energy_balance(tr, a, b) for a, b in revolution_spans(tr.t_end, speed, first)]


def revolution_spans(t_end: float, speed: float, first: int = 0) -> list[tuple[float, float]]:
    """The whole revolutions ``2π/speed`` in ``[0, t_end]`` from revolution ``first``: ``(start, end)`` each.

    >>> revolution_spans(2.0 * np.pi, 2.0)          # two revolutions of π s
    [(0.0, 3.141592653589793), (3.141592653589793, 6.283185307179586)]
    """
    turn = 2 * np.pi / speed
    count = int(np.floor(t_end / turn * (1 + 1e-12)))
    return [(k * turn, min((k + 1) * turn, t_end)) for k in range(first, count)]
