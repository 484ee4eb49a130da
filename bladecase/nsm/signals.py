"""Certified bounds and first roots of trigonometric sums.

Between two impacts, the contact distance of a linear structure is a sum
``f(τ) = c + Σ_m α_m cos(ω_m τ) + β_m sin(ω_m τ)`` (exact free flight in modal
coordinates).  Two questions are asked of it, both answered here with a
rigorous bound rather than by hoping a sampling grid is fine enough:

* :func:`certified_max` — is ``f <= tol`` on a whole interval?  (admissibility
  of a periodic orbit);
* :func:`first_upcrossing` — the FIRST ``τ > τ₀`` where ``f`` reaches 0
  (next impact of the event-driven simulator), missing no grazing contact.

Both use ``|f''| <= B₂ = Σ_m |(α_m, β_m)| ω_m²`` on a grid of step tied to the
highest frequency.  On an interval ``[a, b]`` of width ``h`` with values and
slopes at both ends, ``f`` is bounded above by the smallest of

* linear interpolation + ``B₂ h² / 8``,
* the Taylor bound from ``a``: ``max(f_a, f_a + f'_a h + B₂ h²/2)``,
* the Taylor bound from ``b``: ``max(f_b, f_b - f'_b h + B₂ h²/2)``,

and intervals whose bound is not conclusive are bisected (vectorised) until
it is.  Up to floating-point evaluation of ``f``, the results are proofs.
Grids are evaluated with the angle-addition formula so that ``P·Q`` points
cost ``(P + Q)·m`` trigonometric calls and two matrix products.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

#: Grid points per shortest period ``2π/ω_max`` used before refinement.
POINTS_PER_PERIOD = 4


def sincos(x) -> tuple[np.ndarray, np.ndarray]:
    """``(sin x, cos x)`` from one tangent of the half angle: with ``t = tan(x/2)``, ``sin x = 2t/(1 + t²)`` and
    ``cos x = (1 - t²)/(1 + t²)``.  Within about one ulp of ``np.sin``/``np.cos`` (absolute error ``<= 2.3e-16``,
    any argument), and several times faster: numpy's ``tan`` is vectorised where its ``sin`` and ``cos`` are not.

    >>> s, c = sincos(np.array([0.0, np.pi / 6, np.pi, 1e3]))
    >>> bool(np.allclose(s, np.sin([0.0, np.pi / 6, np.pi, 1e3]), rtol=0, atol=3e-16)), c[:2].round(12).tolist()
    (True, [1.0, 0.866025403784])
    """
    return sincos_half(0.5 * np.asarray(x, dtype=float))


def sincos_half(y) -> tuple[np.ndarray, np.ndarray]:
    """:func:`sincos` of ``x = 2y`` (``y`` a float array, overwritten): the same values, one pass fewer.

    >>> s, c = sincos_half(np.array([np.pi / 12]))
    >>> round(float(s[0]), 12), round(float(c[0]), 12)
    (0.5, 0.866025403784)
    """
    t = np.tan(y, out=y)
    u = t * t
    d = u + 1.0
    np.reciprocal(d, out=d)
    np.subtract(1.0, u, out=u)
    u *= d
    t *= d
    t *= 2.0
    return t, u


@dataclass(frozen=True)
class TrigSum:
    """``f(τ) = const + Σ α_m cos(ω_m τ) + β_m sin(ω_m τ)``."""

    alpha: np.ndarray
    beta: np.ndarray
    omega: np.ndarray
    const: float = 0.0

    @property
    def curvature_bound(self) -> float:
        """``B₂ >= max |f''|``."""
        return float(np.hypot(self.alpha, self.beta) @ (self.omega**2))

    @property
    def magnitude(self) -> float:
        """``Σ |(α_m, β_m)|``: scale of the floating-point error of ``f``."""
        return float(np.hypot(self.alpha, self.beta).sum())

    @property
    def step(self) -> float:
        """Base grid step ``2π / (POINTS_PER_PERIOD · ω_max)`` (refined where needed)."""
        return 2 * np.pi / (POINTS_PER_PERIOD * float(self.omega.max()))

    def __call__(self, tau) -> tuple[np.ndarray, np.ndarray]:
        """Values and first derivatives at the points ``tau`` (any shape)."""
        tau = np.asarray(tau, dtype=float)
        ph = np.multiply.outer(tau, self.omega)
        c, s = np.cos(ph), np.sin(ph)
        f = c @ self.alpha + s @ self.beta + self.const
        df = s @ (-self.omega * self.alpha) + c @ (self.omega * self.beta)
        return f, df

    def grid(self, start: float, h: float, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(τ, f, f')`` at ``τ = start + h·arange(count)``.

        Points are split as ``u_p + v_q`` (``P·Q >= count``); with
        ``c = α - iβ``, ``f = Re Σ c e^{iωu} e^{iωv}`` is one matrix
        product.  The exponentials are built by recurrence (``cumprod``), so
        only ``2m`` of them are evaluated; the recurrence error is about
        ``max(P, Q) ε Σ|c|``.
        """
        q = max(1, int(np.ceil(np.sqrt(count))))
        p = -(-count // q)
        w = self.omega
        Eu = np.empty((p, w.size), complex)
        Eu[0] = np.exp(1j * w * start)
        Eu[1:] = np.exp(1j * w * (h * q))
        np.cumprod(Eu, axis=0, out=Eu)
        Ev = np.empty((q, w.size), complex)
        Ev[0] = 1.0
        Ev[1:] = np.exp(1j * w * h)
        np.cumprod(Ev, axis=0, out=Ev)
        L = np.empty((2 * p, w.size), complex)
        np.multiply(Eu, self.alpha - 1j * self.beta, out=L[:p])
        np.multiply(L[:p], 1j * w, out=L[p:])
        # Only the real part is needed: Re(L Evᵀ) = [Re L, -Im L] [Re Ev, Im Ev]ᵀ,
        # one real product (half the work of the complex one).
        R = np.concatenate([L.real, -L.imag], axis=1) @ np.concatenate([Ev.real, Ev.imag], axis=1).T
        tau = start + h * np.arange(count)
        return tau, R[:p].ravel()[:count] + self.const, R[p:].ravel()[:count]


def interval_bound(fa, fb, da, db, h, B2):
    """Rigorous upper bound of ``f`` on intervals of width ``h`` (vectorised)."""
    h2 = B2 * h * h
    interp = np.maximum(fa, fb) + h2 / 8
    left = np.maximum(fa, fa + da * h + h2 / 2)
    right = np.maximum(fb, fb - db * h + h2 / 2)
    return np.minimum(interp, np.minimum(left, right))


@dataclass(frozen=True)
class MaxResult:
    """Outcome of :func:`certified_max`.

    ``value`` is the largest value of ``f`` found (a lower bound of the
    maximum, attained at ``where``); ``upper`` is a certified upper bound of
    the maximum; ``certified`` says whether ``upper <= tol`` was proved.
    """

    value: float
    where: float
    upper: float
    certified: bool


def certified_max(
    f: TrigSum,
    length: float,
    tol: float,
    ends_at_zero: bool = False,
    polish: bool = True,
    max_points: int = 2_000_000,
) -> MaxResult:
    """Prove ``f <= tol`` on ``[0, length]``, or find where it is violated.

    ``ends_at_zero`` states that ``f(0) = f(length) = 0`` exactly (a flight
    between two impacts): the computed end values, off by round-off, are
    replaced by 0.

    Intervals whose bound exceeds ``tol`` are bisected until the bound drops
    below ``tol`` or ``B₂h²/8 <= tol/2`` (then the bound is within ``tol/2`` of
    a sampled value).  When a sampled value exceeds ``tol`` the search stops
    certifying and (``polish=True``) refines the largest sampled maxima, so
    ``value`` is then the maximum to within the optimiser's tolerance.
    """
    B2 = f.curvature_bound
    count = max(2, int(np.ceil(length / f.step)) + 1)
    h = length / (count - 1)
    tau, F, D = f.grid(0.0, h, count)
    tau[-1] = length
    if ends_at_zero:
        F[0] = F[-1] = 0.0
    lo, hi = tau[:-1], tau[1:]
    fl, fr, dl, dr = F[:-1], F[1:], D[:-1], D[1:]
    best = int(np.argmax(F))
    best_val, best_t = float(F[best]), float(tau[best])
    used = count
    while True:
        width = hi - lo
        U = interval_bound(fl, fr, dl, dr, width, B2)
        if best_val > tol:
            if not polish:
                return MaxResult(best_val, best_t, float(U.max()), False)
            return _polish(f, length, tau, F, best_val, best_t, h, float(U.max()))
        open_ = (U > tol) & (B2 * width * width / 8 > tol / 2)
        if not open_.any() or used > max_points:
            upper = float(U.max())
            return MaxResult(best_val, best_t, upper, upper <= tol and not open_.any())
        keep = ~open_
        a, b = lo[open_], hi[open_]
        mid = 0.5 * (a + b)
        fm, dm = f(mid)
        used += mid.size
        j = int(np.argmax(fm))
        if fm[j] > best_val:
            best_val, best_t = float(fm[j]), float(mid[j])
        lo = np.concatenate([lo[keep], a, mid])
        hi = np.concatenate([hi[keep], mid, b])
        fl = np.concatenate([fl[keep], fl[open_], fm])
        fr = np.concatenate([fr[keep], fm, fr[open_]])
        dl = np.concatenate([dl[keep], dl[open_], dm])
        dr = np.concatenate([dr[keep], dm, dr[open_]])
        tau = np.concatenate([tau, mid])
        F = np.concatenate([F, fm])


def certified_max_stack(alpha: np.ndarray, beta: np.ndarray, omega: np.ndarray, const, length, tol,
                        ends_at_zero: bool = False, max_points: int = 2_000_000, chunk: int = 2_000_000
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`certified_max` with ``polish=False`` of many sums at once: row ``i`` is the sum
    ``TrigSum(alpha[i], beta[i], omega, const[i])`` on ``[0, length[i]]`` with tolerance ``tol[i]``.

    The same proof, interval by interval: the same grid (its angle-addition products batched over the rows
    that share a grid shape), the same bound and the same bisection of the intervals still open, for all rows
    together.  Returns ``(value, where, upper, certified)``, each ``(S,)``, as the fields of :class:`MaxResult`
    (``value`` a sampled lower bound of the maximum, ``upper`` a proved upper bound).  The grids are built for
    about ``chunk`` complex exponentials at a time (memory).

    >>> f = TrigSum(np.array([1.0, 0.5]), np.array([0.0, 0.2]), np.array([1.0, 3.0]), -1.6)
    >>> one = certified_max(f, 5.0, 1e-9, polish=False)
    >>> v, w, u, ok = certified_max_stack(np.array([f.alpha, -f.alpha]), np.array([f.beta, -f.beta]), f.omega,
    ...                                   [-1.6, -0.2], [5.0, 5.0], [1e-9, 1e-9])
    >>> bool(ok[0]) == one.certified, float(v[0]) == one.value, bool(ok[1]), bool(v[1] > 0)
    (True, True, False, True)
    """
    alpha, beta, omega, const, length, tol, B2, count, p, q = grid_plan(alpha, beta, omega, const, length, tol)
    S = len(alpha)
    if S == 0:
        return np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0, dtype=bool)
    value, where, upper = np.zeros(S), np.zeros(S), np.full(S, -np.inf)
    opened = []  # the grid intervals left open: (row, lo, hi, f_lo, f_hi, f'_lo, f'_hi)
    shapes = np.stack([p, q], axis=1)
    for pq in np.unique(shapes, axis=0):
        rows = np.flatnonzero((shapes == pq).all(axis=1))
        size = int(pq[0] + pq[1]) * max(omega.size, 1)  # the exponentials of one row (memory: chunk of them)
        for part in np.array_split(rows, -(-rows.size * size // chunk)):
            opened.append(_grid_stack(alpha[part], beta[part], omega, const[part], length[part], count[part],
                                      int(pq[0]), int(pq[1]), B2[part], tol[part], ends_at_zero, part,
                                      (value, where, upper)))
    certified = bisect_open(opened, alpha, beta, omega, const, tol, B2, count, max_points, (value, where, upper),
                            np.ones(S, dtype=bool))
    return value, where, upper, certified


def grid_plan(alpha, beta, omega, const, length, tol) -> tuple:
    """The inputs of a stacked proof as arrays, and its grid: ``(alpha, beta, omega, const, length, tol, B2,
    count, p, q)`` — ``B2 >= max|f''|`` per row, ``count`` grid points per row (``POINTS_PER_PERIOD`` per period of
    the highest frequency, at least 2), laid out as ``p × q`` angle-addition products."""
    alpha, beta = np.atleast_2d(np.asarray(alpha, dtype=float)), np.atleast_2d(np.asarray(beta, dtype=float))
    omega = np.asarray(omega, dtype=float)
    const, length, tol = (np.broadcast_to(np.asarray(x, dtype=float), (len(alpha),)) for x in (const, length, tol))
    B2 = np.hypot(alpha, beta) @ (omega**2)
    step = 2 * np.pi / (POINTS_PER_PERIOD * float(omega.max())) if omega.size else np.inf
    count = np.maximum(2, np.ceil(length / step).astype(int) + 1)
    q = np.maximum(1, np.ceil(np.sqrt(count)).astype(int))
    return alpha, beta, omega, const, length, tol, B2, count, -(-count // q), q


def bisect_open(opened: list, alpha, beta, omega, const, tol, B2, count, max_points: int, results: tuple,
                active: np.ndarray) -> np.ndarray:
    """The proof's last part for many sums at once: bisect the grid intervals left open until each ``active``
    row is violated (a sampled value above ``tol``), proved (every interval's bound within ``tol``) or out of
    points (``count`` + bisections ``> max_points``).

    ``opened``: tuples ``(row, lo, hi, f_lo, f_hi, f'_lo, f'_hi)`` of the open intervals; ``results``:
    ``(value, where, upper)``, raised in place (``upper`` is the proved bound of the finished rows); inactive rows
    are left as they are.  Returns ``certified`` ``(S,)``.
    """
    value, where, upper = results
    S = len(alpha)
    row, lo, hi, fl, fr, dl, dr = (np.concatenate(x) for x in zip(*opened))
    certified = np.zeros(S, dtype=bool)
    used = count.copy()
    active = active.copy()
    neg_wa, wb = -omega * alpha, omega * beta
    while True:
        # rows with a sampled violation, or no open interval left (or out of points), are finished
        width, b2, tol_row = hi - lo, B2[row], tol[row]
        U = interval_bound(fl, fr, dl, dr, width, b2)
        top = np.full(S, -np.inf)
        np.maximum.at(top, row, U)
        open_ = (U > tol_row) & (b2 * width**2 / 8 > tol_row / 2)
        any_open = np.bincount(row[open_], minlength=S) > 0
        violated = active & (value > tol)
        finish = violated | (active & (~any_open | (used > max_points)))
        upper[finish] = np.maximum(upper[finish], top[finish])
        certified[finish] = ~violated[finish] & ~any_open[finish] & (upper[finish] <= tol[finish])
        active &= ~finish
        # closed intervals of running rows are final: their bound counts, they are not looked at again
        closed = active[row] & ~open_
        np.maximum.at(upper, row[closed], U[closed])
        sel = active[row] & open_
        if not sel.any():
            return certified
        row, a, b = row[sel], lo[sel], hi[sel]
        mid = 0.5 * (a + b)
        s, c = sincos_half(np.multiply.outer(0.5 * mid, omega))  # sincos(mid·ω): the half angle, exactly
        fm = np.einsum("nm,nm->n", c, alpha[row]) + np.einsum("nm,nm->n", s, beta[row]) + const[row]
        dm = np.einsum("nm,nm->n", s, neg_wa[row]) + np.einsum("nm,nm->n", c, wb[row])
        used += np.bincount(row, minlength=S)
        _raise_best(row, fm, mid, value, where)
        lo, hi = np.concatenate([a, mid]), np.concatenate([mid, b])
        fl, fr = np.concatenate([fl[sel], fm]), np.concatenate([fm, fr[sel]])
        dl, dr = np.concatenate([dl[sel], dm]), np.concatenate([dm, dr[sel]])
        row = np.concatenate([row, row])


def _raise_best(row: np.ndarray, vals: np.ndarray, at: np.ndarray, value: np.ndarray, where: np.ndarray) -> None:
    """Per row, raise ``value`` (and its ``where``) to the largest of ``vals`` when that is larger."""
    better = vals > value[row]
    if not better.any():
        return
    r, v, t = row[better], vals[better], at[better]
    order = np.lexsort((-v, r))  # each row's largest value first
    first = np.concatenate([[True], r[order][1:] != r[order][:-1]])
    pick = order[first]
    value[r[pick]], where[r[pick]] = v[pick], t[pick]


def _grid_stack(alpha, beta, omega, const, length, count, p, q, B2, tol, ends_at_zero, rows, results):
    """The grid of :meth:`TrigSum.grid` (``P = p``, ``Q = q``) of the rows ``rows`` at once: the largest sampled
    values into ``results`` (``value``, ``where``, ``upper`` of the intervals), the intervals the bound leaves
    open returned as flat arrays."""
    value, where, upper = results
    G = len(rows)
    h = length / (count - 1)
    Eu = np.empty((G, p, omega.size), complex)
    Eu[:, 0] = 1.0
    Eu[:, 1:] = np.exp(1j * np.multiply.outer(h * q, omega))[:, None, :]
    np.cumprod(Eu, axis=1, out=Eu)
    Ev = np.empty((G, q, omega.size), complex)
    Ev[:, 0] = 1.0
    Ev[:, 1:] = np.exp(1j * np.multiply.outer(h, omega))[:, None, :]
    np.cumprod(Ev, axis=1, out=Ev)
    L = np.empty((G, 2 * p, omega.size), complex)
    np.multiply(Eu, (alpha - 1j * beta)[:, None, :], out=L[:, :p])
    np.multiply(L[:, :p], 1j * omega, out=L[:, p:])
    R = np.concatenate([L.real, -L.imag], axis=2) @ np.swapaxes(np.concatenate([Ev.real, Ev.imag], axis=2), 1, 2)
    n = p * q
    F = R[:, :p].reshape(G, n) + const[:, None]
    D = R[:, p:].reshape(G, n)
    tau = h[:, None] * np.arange(n)
    last = count - 1
    g = np.arange(G)
    tau[g, last] = length
    if ends_at_zero:
        F[:, 0] = 0.0
        F[g, last] = 0.0
    inside = np.arange(n)[None, :] <= last[:, None]
    Fm = np.where(inside, F, -np.inf)
    best = np.argmax(Fm, axis=1)
    value[rows], where[rows] = Fm[g, best], tau[g, best]
    ivl = inside[:, 1:]
    width = tau[:, 1:] - tau[:, :-1]
    U = np.where(ivl, interval_bound(F[:, :-1], F[:, 1:], D[:, :-1], D[:, 1:], width, B2[:, None]), -np.inf)
    open_ = ivl & (U > tol[:, None]) & (B2[:, None] * width**2 / 8 > tol[:, None] / 2)
    upper[rows] = np.where(open_, -np.inf, U).max(axis=1)
    gi, j = np.nonzero(open_)
    return rows[gi], tau[gi, j], tau[gi, j + 1], F[gi, j], F[gi, j + 1], D[gi, j], D[gi, j + 1]


def local_max(f: TrigSum, t0: float, lo: float, hi: float, iterations: int = 20) -> tuple[float, float]:
    """Local maximum of ``f`` reached by Newton's method on ``f'`` from ``t0``,
    kept in ``[lo, hi]``; returns ``(t, f(t))``."""
    w, a, b = f.omega, f.alpha, f.beta
    t = min(max(t0, lo), hi)
    for _ in range(iterations):
        c, s = np.cos(w * t), np.sin(w * t)
        d1 = (w * (b * c - a * s)).sum()
        d2 = -(w * w * (a * c + b * s)).sum()
        if d2 >= 0:  # not concave here: step uphill by the gradient sign
            t_new = min(max(t + np.sign(d1) * (hi - lo) / 64, lo), hi)
        else:
            t_new = min(max(t - d1 / d2, lo), hi)
        done = abs(t_new - t) <= 1e-15 * max(1.0, abs(t))
        t = t_new
        if done:
            break
    return float(t), float(f(t)[0])


def _polish(f: TrigSum, length, tau, F, best_val, best_t, h, upper) -> MaxResult:
    """Refine the largest sampled maxima of a violated bound (within ``[0, length]``)."""
    for t0 in tau[np.argsort(F)[::-1][:4]]:
        t, val = local_max(f, t0, max(0.0, t0 - h), min(length, t0 + h))
        if val > best_val:
            best_val, best_t = val, t
    return MaxResult(best_val, best_t, max(upper, best_val), False)


def first_upcrossing(f: TrigSum, start: float, stop: float, chunk: int = 512) -> float | None:
    """First ``τ`` in ``(start, stop]`` with ``f(τ) = 0``, given ``f(start) < 0``.

    Every interval not proved negative by :func:`interval_bound` is bisected,
    leftmost first, until it is proved negative, or a sign change is found on
    a sub-interval where ``f`` is provably increasing (unique root, refined by
    Brent's method to machine precision).  A local maximum is taken as a
    contact only if it reaches 0; a touch closer than ``B₂ h_min²/8`` (about
    ``1e-14`` of ``max|f|``) may be reported either way.  Returns ``None`` if
    ``f < 0`` on the whole interval.
    """
    B2 = f.curvature_bound
    if B2 == 0.0:
        return None
    scale = max(f.magnitude, abs(f.const), np.finfo(float).tiny)
    hmin = np.sqrt(8e-14 * scale / B2)
    h = f.step
    t = start
    while t < stop:
        count = min(chunk, int(np.ceil((stop - t) / h))) + 1
        hh = min(h, (stop - t) / (count - 1))
        tau, F, D = f.grid(t, hh, count)
        if F[0] >= 0 and t == start:
            raise ValueError("first_upcrossing needs f(start) < 0")
        U = interval_bound(F[:-1], F[1:], D[:-1], D[1:], hh, B2)
        for i in np.flatnonzero(U >= 0):
            root = _search(f, B2, hmin, tau[i], tau[i + 1], F[i], F[i + 1], D[i], D[i + 1])
            if root is not None:
                return root
        t = float(tau[-1])
    return None


def _brent(f: TrigSum, a: float, b: float) -> float:
    """Root of ``f`` in ``[a, b]`` to machine precision.  Grid values (angle
    addition) and direct values may differ in the last bits: when the direct
    values at the ends do not bracket a root, the end nearer to zero is it."""
    fa, fb = float(f(a)[0]), float(f(b)[0])
    if fa == 0 or fb == 0 or np.sign(fa) == np.sign(fb):
        return a if abs(fa) <= abs(fb) else b
    return brentq(lambda x: f(x)[0], a, b, xtol=1e-15 * max(1.0, abs(b)), rtol=4 * np.finfo(float).eps)


def _search(f, B2, hmin, a, b, fa, fb, da, db, polish=None):
    """The first root of ``f`` in ``[a, b]`` (``None`` when the interval is proved free of one): bisected, leftmost
    first, until a bracket where ``f`` provably rises is found, which ``polish(f, a, b, fa, fb, da, db)`` (default:
    Brent's method) refines."""
    if fb >= 0:
        if da - B2 * (b - a) > 0 or b - a < hmin:
            return _brent(f, a, b) if polish is None else polish(f, a, b, fa, fb, da, db)
    elif interval_bound(fa, fb, da, db, b - a, B2) < 0 or b - a < hmin:
        return None
    m = 0.5 * (a + b)
    fm, dm = (float(z) for z in f(m))
    if fm >= 0:
        return _search(f, B2, hmin, a, m, fa, fm, da, dm, polish)
    root = _search(f, B2, hmin, a, m, fa, fm, da, dm, polish)
    if root is not None:
        return root
    return _search(f, B2, hmin, m, b, fm, fb, dm, db, polish)


def all_roots(f: TrigSum, a: float, b: float, max_points: int = 2_000_000) -> np.ndarray:
    """Every root of ``f`` in ``(a, b)`` where ``f`` changes sign, sorted.

    Intervals are proved root-free with :func:`interval_bound` (applied to
    ``f`` and ``-f``) or bisected; an interval with a sign change on which
    ``f'`` provably keeps its sign holds exactly one root, refined by Brent's
    method.  Roots of even multiplicity (tangencies) are not reported.
    """
    B2 = f.curvature_bound
    count = max(2, int(np.ceil((b - a) / f.step)) + 1)
    h = (b - a) / (count - 1)
    tau, F, D = f.grid(a, h, count)
    tau[-1] = b
    scale = max(f.magnitude, abs(f.const), np.finfo(float).tiny)
    hmin = np.sqrt(8e-14 * scale / B2) if B2 > 0 else 0.0
    lo, hi, fl, fr, dl, dr = tau[:-1], tau[1:], F[:-1], F[1:], D[:-1], D[1:]
    roots = []
    used = count
    while lo.size and used <= max_points:
        w = hi - lo
        change = np.sign(fl) * np.sign(fr) < 0
        mono = change & (np.sign(dl) == np.sign(dr)) & (np.minimum(np.abs(dl), np.abs(dr)) > B2 * w)
        for x0, x1 in zip(lo[mono | (change & (w < hmin))], hi[mono | (change & (w < hmin))]):
            roots.append(_brent(f, x0, x1))
        pos = ~change & (fl > 0)
        neg = ~change & (fl < 0)
        cleared = (pos & (-interval_bound(-fl, -fr, -dl, -dr, w, B2) > 0)) | (
            neg & (interval_bound(fl, fr, dl, dr, w, B2) < 0)
        )
        split = ~(mono | cleared) & (w >= hmin)
        if not split.any():
            break
        x0, x1 = lo[split], hi[split]
        mid = 0.5 * (x0 + x1)
        fm, dm = f(mid)
        used += mid.size
        lo, hi = np.concatenate([x0, mid]), np.concatenate([mid, x1])
        fl, fr = np.concatenate([fl[split], fm]), np.concatenate([fm, fr[split]])
        dl, dr = np.concatenate([dl[split], dm]), np.concatenate([dm, dr[split]])
        exact = (fm == 0) & (mid > a) & (mid < b)
        roots.extend(mid[exact].tolist())
    return np.unique(np.array(roots, dtype=float))
