"""The admissibility proofs of many flights at once, as the k-ipp search runs them.

:func:`certify_flights` is :func:`bladecase.nsm.signals.certified_max_stack` (the same grid, bound and bisection
of the intervals left open, the same arithmetic: the same values, bit for bit) for what
:func:`~bladecase.nsm.newton.orbits.make_orbits` asks of it — the largest sampled value, where, and whether
``f <= tol`` was proved — organised for the search's many flights:

* the grid's complex powers (``np.cumprod``'s products, in its order) are computed for a batch of flights of
  all shapes at once, and they and the real matrices of the grid's products are built in a scratch space reused
  from call to call (fresh temporaries of that size would cost more in page faults than in arithmetic); the
  matrix products are left as they are (one ``(2p × 2m)·(2m × q)`` product per flight, the operands in the same
  layout: BLAS's sums depend on the shapes);
* a flight whose grid already shows a violation is finished there: the intervals its grid leaves open are not
  extracted, bounded or bisected (its proof would stop at their first look; only the upper bound
  ``certified_max_stack`` also returns, which nothing here uses, would differ).

The bisection of the intervals left open is :func:`bladecase.nsm.signals.bisect_open`, shared with
``certified_max_stack``.
"""

from __future__ import annotations

import threading

import numpy as np

from ..signals import bisect_open, grid_plan, interval_bound

__all__ = ["certify_flights"]

#: Complex exponentials per grid batch (a bound on the scratch space: about ``8×`` this many floats).
CHUNK = 200_000

#: The reused scratch space grows to at most this many floats (larger needs get a temporary array).
SCRATCH_MAX = 4_000_000

_LOCAL = threading.local()


def _scratch(size: int, which: int = 0) -> np.ndarray:
    """``size`` floats of this thread's scratch space ``which`` (a temporary array beyond ``SCRATCH_MAX``)."""
    if size > SCRATCH_MAX:
        return np.empty(size)
    name = f"buf{which}"
    buf = getattr(_LOCAL, name, None)
    if buf is None or buf.size < size:
        buf = np.empty(min(SCRATCH_MAX, max(size, 2 * (0 if buf is None else buf.size))))
        setattr(_LOCAL, name, buf)
    return buf[:size]


def certify_flights(alpha: np.ndarray, beta: np.ndarray, omega: np.ndarray, const, length, tol,
                    ends_at_zero: bool = False, max_points: int = 2_000_000
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(value, where, certified)`` of :func:`bladecase.nsm.signals.certified_max_stack` (the same values): row
    ``i`` is the sum ``α_i·cos(ωτ) + β_i·sin(ωτ) + const_i`` on ``[0, length_i]`` with tolerance ``tol_i``;
    ``value`` its largest sampled value (at ``where``), ``certified`` whether ``value <= tol`` was proved on
    the whole interval.

    >>> from bladecase.nsm.signals import certified_max_stack
    >>> rng = np.random.default_rng(1)
    >>> alpha, beta, omega = rng.normal(size=(40, 6)), rng.normal(size=(40, 6)), np.linspace(1.0, 9.0, 6)
    >>> const, length, tol = -np.abs(alpha).sum(axis=1) * rng.uniform(0.9, 1.1, 40), rng.uniform(1, 9, 40), 1e-9
    >>> mine, theirs = certify_flights(alpha, beta, omega, const, length, tol), certified_max_stack(
    ...     alpha, beta, omega, const, length, tol)
    >>> all(np.array_equal(a, b) for a, b in zip(mine, (theirs[0], theirs[1], theirs[3]))), int(mine[2].sum())
    (True, 14)
    """
    alpha, beta, omega, const, length, tol, B2, count, p, q = grid_plan(alpha, beta, omega, const, length, tol)
    S = len(alpha)
    if S == 0:
        return np.zeros(0), np.zeros(0), np.zeros(0, dtype=bool)
    value, where, upper = np.zeros(S), np.zeros(S), np.full(S, -np.inf)
    opened = []  # the grid intervals left open of the flights not violated: (row, lo, hi, f_lo, f_hi, f'_lo, f'_hi)
    key = p * (int(q.max()) + 1) + q  # the grid shapes (p, q), in the order of np.unique(axis=0)
    order = np.argsort(key, kind="stable")
    per = max(1, CHUNK // (int((p + q).max()) * max(omega.size, 1)))  # rows per batch of powers
    for first in range(0, S, per):  # the rows in shape order, a batch at a time: the powers of all its rows
        part = order[first:first + per]
        h = length[part] / (count[part] - 1)
        U, V = _powers(h, q[part], omega, int(p[part].max()), int(q[part].max()))
        cuts = np.flatnonzero(np.diff(key[part])) + 1
        for a, b in zip([0, *cuts], [*cuts, part.size]):  # then each grid shape's products
            rows = part[a:b]
            pp, qq = int(p[rows[0]]), int(q[rows[0]])
            F, D, tau = _grid(alpha[rows], beta[rows], omega, const[rows], length[rows], count[rows], h[a:b],
                              U[:pp, a:b], V[a:b, :qq], ends_at_zero)
            opened.append(_intervals(F, D, tau, count[rows], B2[rows], tol[rows], rows, (value, where, upper)))
    certified = bisect_open(opened, alpha, beta, omega, const, tol, B2, count, max_points, (value, where, upper),
                            ~(value > tol))  # the flights violated on their grid are finished
    return value, where, certified


def _powers(h, q, omega, P: int, Q: int) -> tuple[np.ndarray, np.ndarray]:
    """The grids' complex powers of rows with steps ``h`` and shapes ``(p <= P, q <= Q)``, as ``np.cumprod``
    computes them (``z_j = z_{j-1}·e``: ``(a_r e_r - a_i e_i, a_r e_i + a_i e_r)``, from ``z_0 = 1``):
    ``U`` ``(P, G, m)`` complex, ``e^{iω·h·q·j}``, and ``V`` ``(G, Q, 2m)``, ``[Re, Im] e^{iω·h·j}`` (the
    layout of the grid's matrix products), in the scratch space."""
    G, m = len(h), omega.size
    n = max(P, Q)
    nu, nv, nz = G * P * m, G * Q * 2 * m, n * 2 * G * m
    work = _scratch(2 * nu + nv + 2 * nz + 6 * G * m)
    U = work[:2 * nu].view(complex).reshape(P, G, m)
    V = work[2 * nu:2 * nu + nv].reshape(G, Q, 2 * m)
    zr, zi = work[2 * nu + nv:2 * nu + nv + 2 * nz].reshape(2, n, 2, G, m)  # the powers of both factors
    er, ei, t = work[2 * nu + nv + 2 * nz:].reshape(3, 2, G, m)
    E = np.exp(1j * np.multiply.outer(np.stack([h * q, h]), omega))  # the two steps' factors (2, G, m)
    np.copyto(er, E.real)
    np.copyto(ei, E.imag)
    zr[0], zi[0] = 1.0, 0.0
    for j in range(1, n):
        np.multiply(zr[j - 1], er, out=zr[j])
        np.multiply(zi[j - 1], ei, out=t)
        zr[j] -= t
        np.multiply(zr[j - 1], ei, out=zi[j])
        np.multiply(zi[j - 1], er, out=t)
        zi[j] += t
    U.real, U.imag = zr[:P, 0], zi[:P, 0]
    V[:, :, :m] = zr[:Q, 1].transpose(1, 0, 2)
    V[:, :, m:] = zi[:Q, 1].transpose(1, 0, 2)
    return U, V


def _grid(alpha, beta, omega, const, length, count, h, U, V, ends_at_zero: bool):
    """``(F, f', τ)`` ``(G, p·q)`` on the grids of :meth:`bladecase.nsm.signals.TrigSum.grid` (``P = p``,
    ``Q = q``) of rows of one shape, as ``certified_max_stack`` computes them: ``f = Re Σ c e^{iωu} e^{iωv}``
    with the powers ``U`` ``(p, G, m)`` (overwritten) and ``V`` ``(G, q, 2m)`` of :func:`_powers`, one real
    matrix product per row."""
    p, G, m = U.shape
    q = V.shape[1]
    A1 = _scratch(G * 2 * p * 2 * m, 1).reshape(G, 2 * p, 2 * m)  # [Re, -Im] of c·e^{iωu}, then of c·iω·e^{iωu}
    L = np.multiply(U, alpha - 1j * beta, out=U)  # numpy's complex product, as the grid's
    A1[:, :p, :m] = L.real.transpose(1, 0, 2)
    np.negative(L.imag.transpose(1, 0, 2), out=A1[:, :p, m:])
    np.multiply(A1[:, :p, m:], omega, out=A1[:, p:, :m])  # c·e^{iωu}·iω = (-Im·ω, Re·ω), exactly
    np.multiply(A1[:, :p, :m], -omega, out=A1[:, p:, m:])
    R = A1 @ np.swapaxes(V, 1, 2)
    n = p * q
    F = R[:, :p].reshape(G, n)
    F += const[:, None]
    tau = h[:, None] * np.arange(n)
    g = np.arange(G)
    tau[g, count - 1] = length
    if ends_at_zero:
        F[:, 0] = 0.0
        F[g, count - 1] = 0.0
    return F, R[:, p:].reshape(G, n), tau


def _intervals(F, D, tau, count, B2, tol, rows, results) -> tuple:
    """The grids ``F``, ``D``, ``τ`` of the rows ``rows``: the largest sampled values into ``results``
    (``value``, ``where``; ``upper``: the bound of the intervals closed, for the rows not violated), and the
    intervals left open of the rows not violated, as flat arrays."""
    value, where, upper = results
    G, n = F.shape
    g = np.arange(G)
    inside = np.arange(n)[None, :] <= (count - 1)[:, None]
    Fm = np.where(inside, F, -np.inf)
    best = np.argmax(Fm, axis=1)
    value[rows], where[rows] = Fm[g, best], tau[g, best]
    live = np.flatnonzero(~(value[rows] > tol))
    F, D, tau, ivl, rows, B2, tol = F[live], D[live], tau[live], inside[live, 1:], rows[live], B2[live], tol[live]
    width = tau[:, 1:] - tau[:, :-1]
    U = np.where(ivl, interval_bound(F[:, :-1], F[:, 1:], D[:, :-1], D[:, 1:], width, B2[:, None]), -np.inf)
    open_ = ivl & (U > tol[:, None]) & (B2[:, None] * width**2 / 8 > tol[:, None] / 2)
    upper[rows] = np.where(open_, -np.inf, U).max(axis=1, initial=-np.inf)
    gi, j = np.nonzero(open_)
    return rows[gi], tau[gi, j], tau[gi, j + 1], F[gi, j], F[gi, j + 1], D[gi, j], D[gi, j + 1]
