"""The certified search for the first switch of a phase of :class:`~bladecase.nsm.massless.nodes.NodalFlight`.

A phase of the every-node contact model ends at the first root of any of its ``m`` switching signals (``λ_j`` of a
closed contact, ``s_j`` of an open one), each ``f_j(τ) = const_j + Re(Σ_k C_jk e^{λ_kτ} + E_j e^{iντ})``
(:class:`_Signals`). :func:`first_switch` finds it with no switch missed: a grid set by the signals'
amplitude-weighted frequency, every interval certified by a bound on the second derivative or bisected, the
roots polished by a bracketed Newton method.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..signals import POINTS_PER_PERIOD, _search, interval_bound

__all__ = ["first_switch", "leave_flat"]


@dataclass(frozen=True, eq=False)
class _Signals:
    """``f_j(τ) = const_j + Re(Σ_k C_jk e^{λ_kτ} + E_j e^{iντ})``, ``j = 1..m`` (``Re λ_k <= 0``)."""

    lam: np.ndarray
    C: np.ndarray
    E: np.ndarray
    nu: float
    const: np.ndarray
    lam2: np.ndarray

    def at(self, tau: float, js: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(f, f')`` of the signals ``js`` at one point ``tau``."""
        e = np.exp(tau * self.lam)
        C = self.C[js]
        f = (C @ e).real + self.const[js]
        df = (C @ (self.lam * e)).real
        if self.nu > 0:
            z = np.exp(1j * self.nu * tau) * self.E[js]
            f, df = f + z.real, df - self.nu * z.imag
        return f, df

    def values(self, tau) -> tuple[np.ndarray, np.ndarray]:
        """``(f, f')`` at the points ``tau``: ``(len(tau), m)``."""
        tau = np.atleast_1d(np.asarray(tau, dtype=float))
        e = np.exp(np.multiply.outer(tau, self.lam))
        f = (e @ self.C.T).real + self.const
        df = (e @ (self.C * self.lam).T).real
        if self.nu > 0:
            z = np.multiply.outer(np.exp(1j * self.nu * tau), self.E)
            f, df = f + z.real, df - self.nu * z.imag
        return f, df

    def value(self, tau: np.ndarray) -> np.ndarray:
        """``f`` alone at the points ``tau`` (1-D), ``(len(tau), m)``: :meth:`values`' first array, computed the same
        way, without the derivatives (the maximum searches of the orbits' peaks read only the values)."""
        f = (np.exp(np.multiply.outer(tau, self.lam)) @ self.C.T).real + self.const
        if self.nu > 0:
            f = f + np.multiply.outer(np.exp(1j * self.nu * tau), self.E).real
        return f

    @cached_property
    def bound(self) -> np.ndarray:
        """``B₂ >= max|f_j''|`` of each signal."""
        return np.abs(self.C) @ self.lam2 + np.abs(self.E) * self.nu**2

    @cached_property
    def magnitude(self) -> np.ndarray:
        return np.abs(self.C).sum(axis=1) + np.abs(self.E) + np.abs(self.const)

    @property
    def step(self) -> float:
        """The first grid's step: ``2π / (POINTS_PER_PERIOD · ω_eff)`` with ``ω_eff² = max_j B₂_j / Σ|terms_j|``,
        the signals' amplitude-weighted frequency (a component of negligible amplitude does not shorten the grid;
        the certification does not depend on it: an inconclusive interval is bisected)."""
        amp = np.abs(self.C).sum(axis=1) + np.abs(self.E)
        live = amp > 0
        if not live.any():
            return np.inf
        w2 = float(np.max(self.bound[live] / amp[live]))
        return 2 * np.pi / (POINTS_PER_PERIOD * max(np.sqrt(w2), self.nu, 1e-300))

    def row(self, j: int) -> _Row:
        return _Row(self, j)


class _Row:
    """One signal of :class:`_Signals`, NEGATED (its upcrossings are the switches), for the scalar search."""

    def __init__(self, sig: _Signals, j: int):
        self.lam, self.c, self.E, self.nu, self.const = sig.lam, sig.C[j], complex(sig.E[j]), sig.nu, sig.const[j]
        self.cl = self.c * self.lam

    def __call__(self, tau):
        t = np.asarray(tau, dtype=float)
        e = np.exp(np.multiply.outer(t, self.lam))
        f, df = (e @ self.c).real + self.const, (e @ self.cl).real
        if self.nu > 0:
            z = self.E * np.exp(1j * self.nu * t)
            f, df = f + z.real, df - self.nu * z.imag
        return -f, -df


def _newton(row: _Row, a: float, b: float, fa: float, fb: float, da: float, db: float) -> float:
    """The root of the (negated) signal in ``[a, b]`` where it rises through 0 and its slope provably stays
    positive: Newton's method from the secant point, kept in the bracket (bisection when a step leaves it), to
    machine precision — 2 to 4 evaluations where Brent's method takes 6 to 8."""
    x = a - fa * (b - a) / (fb - fa) if fb != fa else 0.5 * (a + b)
    for _ in range(40):
        f, d = row(x)
        f, d = float(f), float(d)
        if f == 0.0:
            return x
        if f < 0:
            a = x
        else:
            b = x
        step = f / d if d > 0 else np.inf
        new = x - step
        if not a < new < b:
            new = 0.5 * (a + b)
        if abs(new - x) <= 4 * np.finfo(float).eps * max(1.0, abs(x)) or b - a <= 4 * np.finfo(float).eps * max(
                1.0, abs(b)):
            return new
        x = new
    return x


def _leave(f0: float, d0: float, B2: float, horizon: float, row: _Row) -> float:
    """A ``τ > 0`` before which the negated signal ``-f`` (starting at ``-f0`` ≈ 0 rising as ``-d0``) stays < 0."""
    if -f0 < 0 and d0 <= 0:  # away from the surface already: the search starts at 0
        return 0.0
    if d0 <= 0:
        raise ValueError("grazing switch: a contact signal does not leave its switching surface "
                         f"(value {f0:.3g}, rate {d0:.3g})")
    tau = min(d0 / max(B2, 1e-300), horizon)
    while tau > 1e-300 and float(row(tau)[0]) >= 0:
        tau /= 2
    return tau


def leave_flat(row: _Row, horizon: float, step: float, band: float, points: int = 16) -> float | None:
    """A first flight ``τ`` over which the signal of ``row`` (negated), starting on its surface with a zero slope,
    is positive at ``points`` points: from ``min(horizon, step)``, halved until it is; ``None`` if it never is.

    A flight shorter than ``step`` (cut short by an event: a cell's edge, the end) is taken whole when the signal
    stays above ``−band`` over it: it could not leave its surface's band (``band``: the tolerance that admitted its
    start, e.g. a start ``1e-14`` of its size below it curving up by less than that before the event) and the
    decision at the event takes it from there.

    >>> sig = _Signals(np.array([0.0]), np.array([[0.0]]), np.array([0.0]), 0.0, np.array([0.0]), np.array([0.0]))
    >>> leave_flat(sig.row(0), 1.0, 0.5, 1e-9) is None          # a zero signal never leaves its surface
    True
    >>> leave_flat(sig.row(0), 1e-3, 0.5, 1e-9)                 # unless the flight ends first, within its band
    0.001
    """
    tau = min(horizon, step)
    grid = np.arange(1, points + 1) / points
    f = -row(tau * grid)[0]
    if tau == horizon and np.all(f >= -band):
        return float(tau)
    for _ in range(200):
        if np.all(f > 0):
            return float(tau)
        tau /= 2
        f = -row(tau * grid)[0]
    return None


def first_switch(sig: _Signals, horizon: float, on: np.ndarray, chunk: int = 256) -> tuple[float, int] | None:
    """The first ``τ`` in ``(0, horizon]`` where one of the signals reaches 0, and which; ``None`` if none does.

    Every signal starts ``>= 0``; those flagged ``on`` start ON their surface (a switch just happened) and must
    be rising. The signals are evaluated together on one grid; each grid interval not proved positive for a
    signal by the bound on its second derivative is bisected (:func:`bladecase.nsm.signals.first_upcrossing`'s
    certified search), earliest interval first.
    """
    f0, d0 = sig.values(0.0)
    f0, d0 = f0[0], d0[0]
    B2 = sig.bound
    scale = np.maximum(sig.magnitude, np.finfo(float).tiny)
    hmin = np.sqrt(8e-14 * scale / np.maximum(B2, 1e-300))
    starts = np.zeros(sig.C.shape[0])
    for j in np.flatnonzero(on | (f0 <= 0)):
        starts[j] = _leave(float(f0[j]), float(d0[j]), float(B2[j]), horizon, sig.row(j))
    # a signal whose constant exceeds the sum of its oscillating terms' moduli (|e^{λτ}| <= 1) never reaches 0
    live = (B2 > 0) & (sig.const - np.abs(sig.C).sum(axis=1) - np.abs(sig.E) <= 0)
    if not live.any():
        return None
    step = min(sig.step, horizon)
    # the first grid step from the nearest linear estimate of a switch (f/|f'| of a falling signal): most flights
    # are a small fraction of the base step, and a first interval that holds the switch is bisected less;
    # the step then doubles up to the base step (the certification holds at any step)
    falling = live & (d0 < 0) & (f0 > 0)
    h = step if not falling.any() else min(step, max(2 * float(np.min(f0[falling] / -d0[falling])), step / 1024))
    t, size = 0.0, 8
    while t < horizon:
        count = min(size, int(np.ceil((horizon - t) / h))) + 1
        size = min(2 * size, chunk)
        hh = min(h, (horizon - t) / (count - 1))
        h = min(2 * h, step)
        tau = t + hh * np.arange(count)
        F, D = sig.values(tau)
        F, D = -F, -D
        U = interval_bound(F[:-1], F[1:], D[:-1], D[1:], hh, B2[None, :]) >= 0
        U &= live[None, :]
        U &= (tau[1:, None] > starts[None, :])
        for i in np.flatnonzero(U.any(axis=1)):
            js = np.flatnonzero(U[i])
            a = float(tau[i])
            late = starts[js] > a  # the interval holding a signal's start: searched from there
            best = None  # the earliest root among them (several signals may start on their surfaces at once)
            for j in js[late]:
                row = sig.row(j)
                fs, ds = (float(v) for v in row(float(starts[j])))
                root = _search(row, float(B2[j]), float(hmin[j]), float(starts[j]), float(tau[i + 1]), fs,
                               float(F[i + 1, j]), ds, float(D[i + 1, j]), _newton)
                if root is not None and (best is None or root < best[0]):
                    best = (float(root), int(j))
            if best is not None:
                early = _earliest(sig, B2, hmin, a, best[0], js[~late])
                return early if early is not None else best
            js = js[~late]
            if js.size:
                hit = _many(sig, B2, hmin, a, float(tau[i + 1]), js, F[i, js], F[i + 1, js], D[i, js], D[i + 1, js])
                if hit is not None:
                    return hit
        t = float(tau[-1])
    return None


def _earliest(sig: _Signals, B2, hmin, a: float, b: float, js: np.ndarray) -> tuple[float, int] | None:
    """The first switch among the signals ``js`` in ``[a, b]``, if any (values computed afresh)."""
    if not js.size or b <= a:
        return None
    F, D = sig.values(np.array([a, b]))
    return _many(sig, B2, hmin, a, b, js, -F[0, js], -F[1, js], -D[0, js], -D[1, js])


def _many(sig: _Signals, B2, hmin, a: float, b: float, js, Fa, Fb, Da, Db) -> tuple[float, int] | None:
    """The first upcrossing in ``[a, b]`` of the NEGATED signals ``js`` (values and slopes at the ends given):
    bisected together while several may cross, then :func:`~bladecase.nsm.signals.first_upcrossing`'s certified
    scalar search on the last one."""
    keep = interval_bound(Fa, Fb, Da, Db, b - a, B2[js]) >= 0
    js, Fa, Fb, Da, Db = js[keep], Fa[keep], Fb[keep], Da[keep], Db[keep]
    if js.size == 0:
        return None
    if js.size == 1 or b - a < hmin[js].min():
        best = None
        for k, j in enumerate(js):
            root = _search(sig.row(j), float(B2[j]), float(hmin[j]), a, b, float(Fa[k]), float(Fb[k]), float(Da[k]),
                           float(Db[k]), _newton)
            if root is not None and (best is None or root < best[0]):
                best = (float(root), int(j))
        return best
    m = 0.5 * (a + b)
    Fm, Dm = sig.at(m, js)
    Fm, Dm = -Fm, -Dm
    hit = _many(sig, B2, hmin, a, m, js, Fa, Fm, Da, Dm)
    return hit if hit is not None else _many(sig, B2, hmin, m, b, js, Fm, Fb, Dm, Db)
