"""The energy balance of the coating yielding in flight (:mod:`~bladecase.nsm.massless.coating_flight`): what the
casing puts in, what friction does, what damping takes, what the coating's removal takes and what the worn
surface's steps put in, per span or per revolution (:func:`coating_balance`, :func:`per_revolution`).

Over ``[t0, t1]``:

    E(t1) − E(t0) = W_casing + W_friction − D − W_plastic + W_steps,
    E = ½x'ᵀMx' + ½xᵀSx + ½λᵀH_Eλ,   H_E = H − μ(C_nt + C_ntᵀ) + μ²C_tt,
    W_casing = −∫ λᵀg' dt,   W_friction = ∫ μλᵀz' dt,   D = ∫ x'ᵀCx' dt,   W_plastic = ∫ Σ_j λ_y,j w_j' dt,

``g`` the clearances without wear (the lobes moving), ``z'`` the nodes' tangential vibration velocity (the rotation
model of :mod:`~bladecase.nsm.massless.friction`; ``μ = 0`` without friction), ``w_j' = y_j' − g_j'`` the removal
rate of a plastic node (the sum over the plastic nodes). ``E`` holds the interior's kinetic and strain energy, the
contact nodes' own strain energy and the coating's springs (``H = H_s + diag(1/k)``), a plastic node's spring at
its yield force. Within a phase each touching node keeps ``(Wᵀx − H_μλ)_j = g_j + w_j`` (an elastic node's surface
held, a plastic node's receding with ``λ_j = λ_y,j``), so ``λᵀWᵀx' = λᵀH_μλ' + λᵀ(g' + w')`` and the balance is
:mod:`~bladecase.nsm.massless.friction_energy`'s with the plastic flow's work taken out. ``x`` and ``x'`` are
continuous everywhere; ``λ`` is continuous at every switch but jumps where the surfaces jump — a node entering a
cell of another depth, or pressed beyond its yield there and removing the excess at once —: there the stored
energy jumps, ``W_steps = Σ (E(t⁺) − E(t⁻))`` over those instants in ``(t0, t1]`` (:func:`surface_steps`). The
integrals are taken as :mod:`~bladecase.nsm.massless.friction_energy` takes them (Gauss–Legendre on each phase, cut
into pieces a quarter of its own fastest period long, at two orders: their difference is the stated error); the
stored energy is read in closed form.

>>> from bladecase.nsm.massless.coating_flight import simulate_coating
>>> from bladecase.nsm.massless.nodes import NodalSystem
>>> s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), [[0.0]], gap=[1.0], casing=[100.0])
>>> tr = simulate_coating(s, [10.0], [0.0], [10.0], 3.0)      # into a coating of yield 10 at speed 10
>>> e = coating_balance(tr, 0.0, 3.0)
>>> round(e.plastic, 8), round(10.0 * float(tr.removed()[0]), 8)   # λ_y × the depth removed
(37.66068747, 37.66068747)
>>> bool(abs(e.stored_change + e.plastic) < 1e-12 * e.plastic), bool(abs(e.relative) < 1e-13)
(True, True)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .coating_flight import PLASTIC, CoatingTrajectory
from .friction_energy import ORDERS, gauss_points, revolution_spans

__all__ = ["STEP_RTOL", "CoatingEnergy", "coating_balance", "per_revolution", "stored_energy", "surface_steps"]

#: Relative size (to the largest clearance or surface) beyond which a node's surface jumps at a phase's start.
STEP_RTOL = 1e-9


@dataclass(frozen=True)
class CoatingEnergy:
    """The energy balance over ``[t0, t1]`` (J): ``stored_change = casing + friction − damping − plastic + steps``
    up to ``residual``; ``relative``: ``residual`` over the largest term; ``quadrature_error``: the two quadratures'
    largest difference (module docstring)."""

    t0: float
    t1: float
    casing: float
    friction: float
    damping: float
    plastic: float
    steps: float
    stored_change: float
    residual: float
    relative: float
    quadrature_error: float


def _check(tr) -> None:
    if not isinstance(tr, CoatingTrajectory):
        raise ValueError(f"the coating's energy balance needs a CoatingTrajectory (simulate_coating), got "
                         f"{type(tr).__name__}")


def _terms(fl):
    """``(μ, T_q, C_nt, C_tt, H_E)`` of the flight (``μ = 0``, ``None`` and ``H`` without friction)."""
    fr, s = fl.friction, fl.system
    if fr is None:
        return 0.0, None, None, None, s.H
    return fr.mu, fl.phi.T @ fr.T, fr.C_nt, fr.C_tt, fr.stored(s)


def _grouped(tr: CoatingTrajectory, k: np.ndarray, t: np.ndarray):
    """The order that groups the times ``t`` by code set and, in that order, the modal ``q``, ``p``, ``λ``, ``λ'``,
    the nodes' ``y'``, ``g'`` and the plastic mask ``(m, k)`` at those times, each from the phase ``k`` (a phase's
    closed form, read before its start too: the state before a jump).

    The phases of one set of node codes share their modes and force maps (only their surfaces, hence their
    equilibria, differ): the times are taken a code set at a time, each phase's own amplitudes and equilibrium
    gathered per time; the caller puts them back in order (:func:`_fields`) or sums over them."""
    fl = tr.flight
    n, m = fl.n, fl.m
    _, first, code = np.unique(tr.codes, axis=0, return_index=True, return_inverse=True)
    code = code.reshape(-1)
    order = np.argsort(code[k], kind="stable")  # the times grouped by code set: one contiguous block each
    ks, ts = k[order], t[order]
    tau = ts - tr.starts[ks]
    Q, P = np.empty((n, t.size)), np.empty((n, t.size))
    lam, dlam = np.empty((m, t.size)), np.empty((m, t.size))
    g = fl.gap(ts) + tr.surfaces[ks].T
    gdot = np.zeros((m, t.size)) if fl.D is None else np.multiply.outer(1j * fl.nu * fl.D,
                                                                         np.exp(1j * fl.nu * ts)).real
    wave = np.exp(1j * fl.nu * ts) if fl.nu > 0 else None
    q_eq = np.array([tr._phase(int(i)).q_eq for i in range(tr.starts.size)])
    bounds = np.searchsorted(code[ks], np.arange(first.size + 1))
    for u in np.flatnonzero(np.diff(bounds)):
        a, b = bounds[u], bounds[u + 1]
        ph = tr._phase(int(first[u]))
        e = np.exp(ph.lam[:, None] * tau[a:b]) * tr.amplitudes[ks[a:b]].T
        q, p = q_eq[ks[a:b]].T + (ph.Vx @ e).real, (ph.Vv @ e).real
        if wave is not None:
            x = ph.X[:, None] * wave[a:b]
            q, p = q + x.real, p + (1j * fl.nu * x).real
        Q[:, a:b], P[:, a:b] = q, p
        lam[:, a:b], dlam[:, a:b] = ph.lam_c[:, None], 0.0
        ia = ph.idx  # the elastic nodes: the only rows (and columns of the clearances) the force maps have
        if ia.size:
            Lg = ph.Lg_lam[np.ix_(ia, ia)]
            lam[ia, a:b] += ph.Lq_lam[ia] @ q + Lg @ g[ia, a:b]
            dlam[ia, a:b] = ph.Lq_lam[ia] @ p + Lg @ gdot[ia, a:b]
    dy = fl.Wq.T @ P - fl.Hy @ dlam
    return order, (Q, P, lam, dlam, dy, gdot, tr.codes[ks].T == PLASTIC)


def _fields(tr: CoatingTrajectory, k: np.ndarray, t: np.ndarray):
    """:func:`_grouped`'s fields in the order of ``t``."""
    order, fields = _grouped(tr, k, t)
    back = np.empty_like(order)
    back[order] = np.arange(order.size)
    return tuple(A[:, back] for A in fields)


def _holding(tr: CoatingTrajectory, t: np.ndarray) -> np.ndarray:
    """The phase holding each time (the one starting there, at a start)."""
    return np.clip(np.searchsorted(tr.starts, t, side="right") - 1, 0, tr.starts.size - 1)


def _energy(fl, Q, P, lam) -> np.ndarray:
    H_E = _terms(fl)[4]
    return 0.5 * (P * P).sum(0) + 0.5 * ((fl.omega[:, None] ** 2) * Q * Q).sum(0) + 0.5 * (lam * (H_E @ lam)).sum(0)


def stored_energy(tr: CoatingTrajectory, t) -> np.ndarray:
    """``E(t)`` (module docstring, J) at the times ``t``, in closed form; at a jump of the surfaces, after it.

    >>> from bladecase.nsm.massless.coating_flight import simulate_coating
    >>> from bladecase.nsm.massless.nodes import NodalSystem
    >>> s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), [[0.0]], gap=[1.0], casing=[100.0])
    >>> tr = simulate_coating(s, [1e9], [0.0], [10.0], 3.0)     # a yield never reached: E is conserved
    >>> float(np.ptp(stored_energy(tr, [0.0, 0.5, 2.9])).round(11))
    0.0
    """
    _check(tr)
    t = np.atleast_1d(np.asarray(t, dtype=float))
    Q, P, lam, *_ = _fields(tr, _holding(tr, t), t)
    return _energy(tr.flight, Q, P, lam)


def _at_starts(tr: CoatingTrajectory, k: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each node's surface ``(m, len(t))`` in the phase ``k`` at ``t`` (its own receding one if plastic) and the
    stored energy there."""
    fl = tr.flight
    Q, P, lam, *_ = _fields(tr, k, t)
    out = tr.surfaces[k].T.copy()
    y = fl.Wq.T @ Q - fl.Hy @ lam
    own = y - fl.gap(t) - (fl.yield_force / fl.system.casing)[:, None]
    plastic = tr.codes[k].T == PLASTIC
    out[plastic] = own[plastic]
    return out, _energy(fl, Q, P, lam)


def _starts(tr: CoatingTrajectory) -> tuple[np.ndarray, np.ndarray]:
    """The starts after the first where the surfaces jump (:func:`surface_steps`) and the stored energy's jump
    ``E(t⁺) − E(t⁻)`` at each."""
    if tr.starts.size < 2:
        return np.zeros(0, dtype=np.int64), np.zeros(0)
    i = np.arange(1, tr.starts.size)
    t = tr.starts[i]
    surfaces, energies = _at_starts(tr, np.r_[i - 1, i], np.r_[t, t])  # before each start, after it
    before, after = surfaces[:, :i.size], surfaces[:, i.size:]
    e_before, e_after = energies[:i.size], energies[i.size:]
    scale = max(float(np.abs(tr.flight.system.gap).max()), float(np.abs(tr.surfaces).max()))
    jump = (np.abs(after - before) > STEP_RTOL * scale).any(axis=0)
    return i[jump], (e_after - e_before)[jump]


def surface_steps(tr: CoatingTrajectory) -> np.ndarray:
    """The phase starts (indices into ``tr.starts``, after the first) where some node's surface jumps: its surface
    after the start (its receding one if plastic) differs from the one before by more than :data:`STEP_RTOL` of the
    largest clearance or surface. At every other start ``λ`` is continuous (a switch).

    >>> from bladecase.nsm.massless.coating_flight import simulate_coating
    >>> from bladecase.nsm.massless.nodes import NodalSystem, Profile
    >>> s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), [[0.0]], gap=[1.0], casing=[100.0])
    >>> prof = Profile([0.0, 0.5], speed=1.0, angles=[0.0])           # a step at t = π
    >>> tr = simulate_coating(s, [1e9], [0.0], [10.0], 4.0, profile=prof)
    >>> tr.starts[surface_steps(tr)].round(9).tolist()
    [3.141592654]
    """
    _check(tr)
    return _starts(tr)[0]


def _integrals(tr: CoatingTrajectory, t: np.ndarray, weights: tuple) -> tuple:
    """The casing's, friction's, damping's and the plastic flow's work ``(4,)`` of each set of quadrature
    ``weights`` at the points ``t`` (the points of every set end to end)."""
    fl = tr.flight
    mu, Tq, C_nt, C_tt, _ = _terms(fl)
    order, (Q, P, lam, dlam, dy, gdot, plastic) = _grouped(tr, _holding(tr, t), t)
    casing = -(lam * gdot).sum(0)
    fric = np.zeros(t.size) if Tq is None else mu * (lam * (Tq.T @ P - C_nt.T @ dlam + mu * (C_tt @ dlam))).sum(0)
    damp = (P * (fl.Cq @ P)).sum(0) if fl.Cq is not None else np.zeros(t.size)
    flow = np.where(plastic, fl.yield_force[:, None] * (dy - gdot), 0.0).sum(0)
    powers = np.vstack([casing, fric, damp, flow])
    cuts = np.cumsum([0] + [w.size for w in weights])
    return tuple(powers @ np.r_[np.zeros(a), w, np.zeros(t.size - b)][order] for w, a, b in
                 zip(weights, cuts[:-1], cuts[1:]))


def _fastest(tr: CoatingTrajectory) -> np.ndarray:
    """Each phase's fastest rate (rad/s): its modes' or the casing's."""
    _, first, code = np.unique(tr.codes, axis=0, return_index=True, return_inverse=True)
    w = np.array([float(np.abs(tr._phase(int(i)).lam).max()) for i in first])
    return np.maximum(w[code.reshape(-1)], max(tr.flight.nu, 1e-300))


def coating_balance(tr: CoatingTrajectory, t0: float, t1: float) -> CoatingEnergy:
    """The energy balance of the coating's flight ``tr`` over ``[t0, t1]`` (module docstring), with or without
    friction, lobes, damping or a worn profile."""
    _check(tr)
    return _balance(tr, t0, t1, _fastest(tr), _starts(tr))


def _balance(tr: CoatingTrajectory, t0: float, t1: float, fast: np.ndarray, starts) -> CoatingEnergy:
    """:func:`coating_balance` with each phase's fastest rate (:func:`_fastest`) and the jumps at the starts
    (:func:`_starts`) computed."""
    if not (0 <= t0 < t1 <= tr.t_end * (1 + 1e-12)):
        raise ValueError(f"[t0, t1] = [{t0!r}, {t1!r}] must lie in the trajectory's [0, {tr.t_end!r}] with t0 < t1")
    (ta, wa), (tb, wb) = (gauss_points(tr.starts, t0, t1, fast, n) for n in ORDERS)
    low, high = _integrals(tr, np.r_[ta, tb], (wa, wb))  # both orders in one pass
    casing, fric, damp, plastic = high
    E = stored_energy(tr, [t0, t1])
    change = float(E[1] - E[0])
    idx, jumps = starts
    here = (tr.starts[idx] > t0) & (tr.starts[idx] <= t1)
    steps = float(jumps[here].sum())
    residual = change - (casing + fric - damp - plastic + steps)
    scale = max(abs(casing), abs(fric), abs(damp), abs(plastic), abs(steps), abs(change), float(np.abs(E).max()),
                np.finfo(float).tiny)
    return CoatingEnergy(float(t0), float(t1), float(casing), float(fric), float(damp), float(plastic), steps, change,
                         float(residual), float(residual / scale), float(np.abs(high - low).max()))


def per_revolution(tr: CoatingTrajectory, speed: float, first: int = 0) -> list[CoatingEnergy]:
    """:func:`coating_balance` over each whole revolution ``2π/speed`` of ``tr`` from revolution ``first``.

    >>> from bladecase.nsm.massless.coating_flight import simulate_coating
    >>> from bladecase.nsm.massless.nodes import NodalSystem
    >>> s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), [[0.0]], gap=[1.0], casing=[100.0])
    >>> tr = simulate_coating(s, [10.0], [0.0], [10.0], 3.0)
    >>> [round(e.t1, 6) for e in per_revolution(tr, speed=2 * np.pi)]     # three revolutions of a second
    [1.0, 2.0, 3.0]
    """
    _check(tr)
    fast, starts = _fastest(tr), _starts(tr)
    return [_balance(tr, a, b, fast, starts) for a, b in revolution_spans(tr.t_end, speed, first)]
