"""Pseudo-arclength continuation of the solution curve of ``R(z) = 0``, generic over its residual.

A :class:`Curve` is ``R: ℝⁿ → ℝᵐ`` whose zero set is (locally) a curve — rank ``n - 1`` Jacobian; redundant
equations (``m >= n``) are allowed — given as callables: the residual, its EXACT Jacobian, and optional
predicates (``valid`` points, forbidden ``crossing`` between two points).  The driver knows nothing else:
the k-ipp families (:mod:`bladecase.nsm.newton.families`: impact times and period) and, e.g., the shooting equations of
a piecewise-linear contact model (switching instants and period) plug in the same way.

* :func:`tangent` — the unit null vector of the Jacobian (SVD), oriented along a previous one;
* :func:`correct` — Newton on ``[R(z) ; t·(z - z_p)] = 0`` (chord method when a Jacobian is given);
* :func:`follow` — points from ``z₀`` in one direction, adaptive step, until ``stop`` says so, the curve
  closes, or the corrector fails at the smallest step;
* :func:`trace` — both directions, joined into one polyline;
* :func:`bisect` — the point where a predicate on the curve (e.g. admissibility) changes, between two points;
* :class:`BatchCurve`, :class:`Followers`, :func:`follow_stack`, :func:`trace_stack` — the same algorithm on many
  curves at once (curves that evaluate many points in one call): every member makes one attempt per step, the
  residuals, exact Jacobians and least-squares steps of all of them computed together (:func:`lstsq_stack`,
  :func:`pinv_stack`, :func:`tangent_stack`, :func:`correct_stack`).

>>> import numpy as np
>>> circle = Curve(residual=lambda z: np.array([z @ z - 1.0]), jacobian=lambda z: 2 * z[None, :])
>>> pts, i0 = trace(circle, np.array([1.0, 0.0]), ds=0.1, max_points=200)
>>> bool(np.allclose([p @ p for p in pts], 1.0)), len(pts) > 60    # the whole circle, then it closes
(True, True)
>>> z_in, z_out, done = bisect(circle, pts[i0], np.array([0.0, 1.0]), lambda z: z[1] < 0.5,
...                            converged=lambda a, b: abs(a[1] - b[1]) < 1e-12)
>>> done, round(float(z_in[0]), 9)                      # where y crosses 1/2: x = √3/2
(True, 0.866025404)
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

Vector = np.ndarray

#: numpy's own least-squares driver (the LAPACK call of ``np.linalg.lstsq``), vectorised over a stack; private,
#: hence looked up defensively (:func:`lstsq_stack` falls back to one ``np.linalg.lstsq`` per matrix).
_LSTSQ = getattr(getattr(np.linalg, "_umath_linalg", None), "lstsq", None)


#: The machine epsilon, and ``4 ε`` of :func:`roundoff_floor`.
_EPS = float(np.finfo(float).eps)
_FOUR_EPS = 4 * _EPS


def _always(z) -> bool:
    return True


def _never(a, b) -> bool:
    return False


@dataclass(frozen=True)
class Curve:
    """The zero set of ``residual`` followed by the driver.

    Attributes
    ----------
    residual : callable ``z -> (m,) ndarray``
        ``R(z)``; non-finite values mark points where it is undefined (the corrector then fails).
    jacobian : callable ``z -> (m, n) ndarray``
        The exact ``∂R/∂z``.
    valid : callable ``z -> bool``
        Whether a corrected point is acceptable (domain of the problem: ordered times, finite impulses…).
    crossing : callable ``(z_a, z_b) -> bool``
        Whether the step ``z_a → z_b`` crosses something that ends the curve (a branch point): the step is
        then shortened, so the last point lands close to it.
    tol : float
        Largest ``max|R|`` of a converged point — or the residual's round-off floor there, if larger
        (:func:`roundoff_floor`).
    step_tol : float
        The corrector stops when its step is below this (max norm).
    """

    residual: Callable[[Vector], Vector]
    jacobian: Callable[[Vector], np.ndarray]
    valid: Callable[[Vector], bool] = _always
    crossing: Callable[[Vector, Vector], bool] = _never
    tol: float = 1e-10
    step_tol: float = 1e-11


def tangent(J: np.ndarray, previous: Vector | None = None) -> Vector:
    """Unit null vector of ``J`` (last right singular vector), oriented along ``previous``."""
    _, _, vt = np.linalg.svd(J)
    t = vt[-1]
    if previous is not None and t @ previous < 0:
        t = -t
    return t


def roundoff_floor(J: np.ndarray, z: np.ndarray) -> np.ndarray:
    """The smallest residual ``max|R|`` a point ``z`` can be expected to reach in floating point:
    ``4 ε max_i Σ_j |J_ij z_j|`` — what rounding ``z`` to the nearest doubles moves ``R`` by (``J`` the Jacobian
    ``∂R/∂z`` there; a stack ``(B, m, n)`` with ``z`` ``(B, n)`` gives one floor per row).

    The corrector accepts a converged point when ``max|R| < max(tol, floor)``: where the curve is stiff (near a
    resonance ``|J|`` reaches 1e6 and more) a fixed ``tol`` below the floor would accept or reject the same point
    by the last bits of ``z``, and a family would end by round-off.

    >>> J = np.array([[3e6, 1.0]])
    >>> float(roundoff_floor(J, np.array([1.0, 0.5]))) > 1e-10     # no residual below 1e-10 is representable
    True
    """
    return _FOUR_EPS * (np.abs(J) @ np.abs(z)[..., None])[..., 0].max(axis=-1)


def correct(curve: Curve, zp: Vector, direction: Vector, J: np.ndarray | None = None,
            maxiter: int = 10) -> tuple[Vector | None, int]:
    """Newton on ``[R(z) ; direction·(z - zp)] = 0`` from ``zp``; with ``J`` given, the chord method (that
    Jacobian kept for every iteration).  Converged: a step below ``step_tol``, then ``max|R|`` below ``tol`` or
    the round-off floor (:func:`roundoff_floor`).  Returns ``(z or None, iterations)``."""
    z = zp.copy()
    for it in range(maxiter):
        r = np.append(curve.residual(z), direction @ (z - zp))
        if not np.all(np.isfinite(r)):
            return None, it
        Jz = curve.jacobian(z) if J is None else J
        dz, *_ = np.linalg.lstsq(np.vstack([Jz, direction]), -r, rcond=None)
        z = z + dz
        if np.abs(dz).max() < curve.step_tol:
            res = np.abs(curve.residual(z)).max()
            return (z if res < max(curve.tol, float(roundoff_floor(Jz, z))) else None), it + 1
    return None, maxiter


def follow(curve: Curve, z0: Vector, direction: Vector, *, ds: float, ds_min: float | None = None,
           ds_max: float | None = None, max_points: int = 400, stop: Callable[[Vector], bool] | None = None,
           max_offset: float = 0.3) -> list[Vector]:
    """Points of the curve from ``z0`` (excluded) along ``direction``.

    Predictor ``z + h·t``, corrector :func:`correct` (chord method, else full Newton).  A corrected point
    is accepted when it is ``valid``, moved less than ``max_offset·h`` from the prediction (a larger move
    means the corrector jumped to another branch) and the step does not cross a ``crossing``; otherwise
    the step is halved.  The step ``h`` starts at ``ds`` and adapts between ``ds_min`` (default
    ``ds/1000``; below it the curve ends) and ``ds_max`` (default ``2·ds``) with the corrector's
    iteration count.  Following ends after a point for which ``stop(z)`` is true (that point included),
    when the curve closes on itself, or after ``max_points`` points.
    """
    ds_min = ds / 1000 if ds_min is None else ds_min
    ds_max = 2 * ds if ds_max is None else ds_max
    pts: list[Vector] = []
    J = curve.jacobian(z0)
    z, tan = z0, tangent(J, direction)
    travelled = 0.0
    for _ in range(max_points):
        step = ds
        while True:
            zp = z + step * tan
            zc, iters = correct(curve, zp, tan, J)
            if zc is None:  # chord method failed: full Newton (fresh Jacobian every iteration)
                zc, iters = correct(curve, zp, tan)
            if (zc is not None and curve.valid(zc) and np.linalg.norm(zc - zp) < max_offset * step
                    and not curve.crossing(z, zc)):
                break
            step /= 2
            if step < ds_min:
                return pts
        travelled += np.linalg.norm(zc - z)
        J = curve.jacobian(zc)
        tan = tangent(J, tan)
        z = zc
        pts.append(z)
        if travelled > 4 * ds_max and np.linalg.norm(z - z0) < step:
            return pts  # closed curve
        ds = min(ds_max, step * (1.5 if iters <= 6 else 0.7 if iters >= 9 else 1.0))
        if stop is not None and stop(z):
            return pts
    return pts


def trace(curve: Curve, z0: Vector, orientation: Vector | None = None, **options) -> tuple[list[Vector], int]:
    """The curve through ``z0`` in both directions of its tangent: ``(points, index of z0)``.

    The points run backwards, ``z0``, forwards; forwards is along ``orientation`` (e.g. increasing
    period) when given, else the arbitrary sign of the null vector.  ``options`` go to :func:`follow`
    (``ds`` required).
    """
    t0 = tangent(curve.jacobian(z0), orientation)
    fwd = follow(curve, z0, t0, **options)
    bwd = follow(curve, z0, -t0, **options)
    return bwd[::-1] + [z0] + fwd, len(bwd)


def bisect(curve: Curve, z_in: Vector, z_out: Vector, inside: Callable[[Vector], bool], *,
           converged: Callable[[Vector, Vector], bool],
           midpoint: Callable[[Vector, Vector], Vector | None] | None = None,
           maxiter: int = 80) -> tuple[Vector, Vector, bool]:
    """Bisection along the curve between ``z_in`` (``inside`` true) and ``z_out`` (false).

    The midpoint is ``midpoint(z_in, z_out)`` when given and not ``None`` (a problem-specific solve, e.g.
    at a fixed parameter), else the corrector from the chord's middle, orthogonal to the chord.  A
    midpoint that leaves the stretch between the two points is rejected and the bisection stops.
    Returns ``(z_in, z_out, converged(z_in, z_out))`` after the last accepted midpoint.
    """
    for _ in range(maxiter):
        if converged(z_in, z_out):
            return z_in, z_out, True
        zm = midpoint(z_in, z_out) if midpoint is not None else None
        if zm is None:
            chord = (z_out - z_in) / np.linalg.norm(z_out - z_in)
            zm, _ = correct(curve, 0.5 * (z_in + z_out), chord)
        if zm is None:
            break
        # stay on this stretch of the curve: between the two ends, near the chord
        span = z_out - z_in
        a = float((zm - z_in) @ span / (span @ span))
        if not 0 < a < 1 or np.linalg.norm(zm - z_in - a * span) > np.linalg.norm(span):
            break
        if inside(zm):
            z_in = zm
        else:
            z_out = zm
    return z_in, z_out, converged(z_in, z_out)


# -- many curves at once ------------------------------------------------------------------------------------


@dataclass(frozen=True)
class BatchCurve:
    """Many curves of one kind, evaluated together: the same algorithm as :func:`follow` on each, with the
    numerical work of all of them done in one vectorised call per iteration.

    Member ``i`` of a batch is curve ``idx[i]`` (e.g. the family it belongs to); every callable gets the
    points stacked as rows and the ``idx`` of each row.

    Attributes
    ----------
    evaluate : callable ``(Z, idx, jacobian: bool) -> (R, J or None)``
        Residuals ``(B, m)`` and, when asked, exact Jacobians ``(B, m, n)``; non-finite residuals mark
        points where the residual is undefined.
    valid : callable ``(Z, idx) -> (B,) bool``
    crossing : callable ``(Z_a, Z_b, idx) -> (B,) bool``
    tol, step_tol : float
        As in :class:`Curve`.
    """

    evaluate: Callable[[np.ndarray, np.ndarray, bool], tuple[np.ndarray, np.ndarray | None]]
    valid: Callable[[np.ndarray, np.ndarray], np.ndarray]
    crossing: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]
    tol: float = 1e-10
    step_tol: float = 1e-11

    @classmethod
    def of(cls, curves: list[Curve]) -> BatchCurve:
        """A batch of scalar :class:`Curve` s (member ``idx`` is ``curves[idx]``), evaluated one by one."""
        c0 = curves[0]

        def evaluate(Z, idx, jacobian):
            R = np.array([curves[i].residual(z) for z, i in zip(Z, idx)])
            return R, (np.array([curves[i].jacobian(z) for z, i in zip(Z, idx)]) if jacobian else None)

        return cls(evaluate, lambda Z, idx: np.array([curves[i].valid(z) for z, i in zip(Z, idx)], dtype=bool),
                   lambda A, B, idx: np.array([curves[i].crossing(a, b) for a, b, i in zip(A, B, idx)], dtype=bool),
                   c0.tol, c0.step_tol)


def lstsq_stack(A: np.ndarray, b: np.ndarray, rcond: float | None = None) -> np.ndarray:
    """``np.linalg.lstsq(A[i], b[i], rcond)[0]`` for every ``i`` of the float stacks ``A`` ``(B, M, N)``, ``b``
    ``(B, M)``: one call of numpy's own LAPACK driver over the whole stack when numpy exposes it (the same
    results), else one call per matrix.  Rows that LAPACK cannot solve (non-finite input) come back NaN.

    >>> A = np.array([[[1.0, 0.0], [0.0, 2.0], [0.0, 0.0]]] * 2)
    >>> lstsq_stack(A, np.array([[1.0, 2.0, 3.0], [2.0, 4.0, 0.0]])).tolist()
    [[1.0, 1.0], [2.0, 2.0]]
    """
    count, M, N = A.shape
    rcond = _EPS * max(M, N) if rcond is None else rcond
    if _LSTSQ is not None and count:
        try:
            with np.errstate(all="ignore"):
                return _LSTSQ(A, b[..., None], rcond, signature="ddd->ddid")[0][..., 0]
        except (TypeError, ValueError):
            pass  # another numpy's private signature: one call per matrix
    out = np.full((count, N), np.nan)
    for i in range(count):
        if np.all(np.isfinite(A[i])) and np.all(np.isfinite(b[i])):
            out[i] = np.linalg.lstsq(A[i], b[i], rcond=rcond)[0]
    return out


#: Stacks of at least this many 3×2 systems are solved in closed form (:func:`lstsq2_stack`): below it, numpy's
#: LAPACK loop is faster than the closed form's few dozen array operations (measured: equal at about 40 rows).
LSTSQ2_MIN_ROWS = 48


def lstsq2_stack(A: np.ndarray, b: np.ndarray, min_rows: int = LSTSQ2_MIN_ROWS) -> np.ndarray:
    """:func:`lstsq_stack` for two unknowns (``A`` ``(B, M, 2)``, ``M >= 2``): stacks of at least ``min_rows``
    by two Householder reflections in closed form, vectorised (backward stable, as LAPACK's QR), smaller ones by
    :func:`lstsq_stack` (faster there).  Rows rank deficient to within ``100 ε`` are left to :func:`lstsq_stack`
    (its rank cut-off); rows with non-finite entries come back NaN.

    >>> A = np.array([[[1.0, 0.0], [0.0, 2.0], [0.0, 0.0]], [[1.0, 1.0], [1.0, 1.0], [0.0, 0.0]]])
    >>> lstsq2_stack(A, np.array([[1.0, 2.0, 3.0], [2.0, 2.0, 0.0]]), min_rows=0).round(12).tolist()
    [[1.0, 1.0], [1.0, 1.0]]
    """
    if len(A) < min_rows:
        return lstsq_stack(A, b)
    a1, a2, y = A[:, :, 0], A[:, :, 1].copy(), np.array(b, dtype=float)
    with np.errstate(all="ignore"):
        n1 = np.sqrt(np.einsum("bi,bi->b", a1, a1))
        r11 = np.where(a1[:, 0] > 0, -n1, n1)  # the reflection of a1 onto r11·e1 (no cancellation)
        v = a1.copy()
        v[:, 0] -= r11
        vv = np.einsum("bi,bi->b", v, v)
        for x in (a2, y):  # H1 = I - 2vvᵀ/vᵀv
            x -= (2 * np.einsum("bi,bi->b", v, x) / vv)[:, None] * v
        u, w = a2[:, 1:], y[:, 1:]
        n2 = np.sqrt(np.einsum("bi,bi->b", u, u))
        r22 = np.where(u[:, 0] > 0, -n2, n2)
        u = u.copy()
        u[:, 0] -= r22
        uu = np.einsum("bi,bi->b", u, u)
        y2 = w[:, 0] - 2 * np.einsum("bi,bi->b", u, w) / uu * u[:, 0]
        x2 = np.where(uu > 0, y2, w[:, 0]) / r22
        x1 = (y[:, 0] - a2[:, 0] * x2) / r11
        out = np.stack([x1, x2], axis=1)
        weak = ~(np.abs(r22) > 100 * _EPS * np.maximum(np.abs(r11), np.abs(a2[:, 0])))
    finite = np.isfinite(A).all(axis=(1, 2)) & np.isfinite(b).all(axis=1)
    out[~finite] = np.nan  # as LAPACK leaves them
    weak = finite & (weak | ~np.isfinite(out).all(axis=1))
    if weak.any():
        out[weak] = lstsq_stack(A[weak], b[weak])
    return out


def tangent_stack(J: np.ndarray, previous: np.ndarray | None = None) -> np.ndarray:
    """:func:`tangent` of each matrix of the stack ``J`` ``(B, m, n)``, oriented along ``previous[i]``."""
    t = np.linalg.svd(J)[2][:, -1, :]
    if previous is not None:
        t = np.where(np.einsum("ij,ij->i", t, previous)[:, None] < 0, -t, t)
    return t


def pinv_stack(A: np.ndarray) -> np.ndarray:
    """Pseudo-inverses of the stack ``A`` ``(B, M, N)`` with the rank cut-off of :func:`lstsq_stack` (singular
    values at most ``ε·max(M, N)`` times the largest count as zero): ``pinv_stack(A)[i] @ b`` is
    ``lstsq_stack(A, b)[i]`` up to round-off.

    >>> A = np.array([[[1.0, 0.0], [0.0, 2.0], [0.0, 0.0]]])
    >>> (pinv_stack(A)[0] @ np.array([1.0, 2.0, 3.0])).tolist()
    [1.0, 1.0]
    """
    U, sv, Vt = np.linalg.svd(A, full_matrices=False)
    cut = _EPS * max(A.shape[1:]) * sv[:, :1]
    inv = np.divide(1.0, sv, out=np.zeros_like(sv), where=sv > cut)
    return np.swapaxes(Vt, 1, 2) @ (inv[:, :, None] * np.swapaxes(U, 1, 2))


def chord_pinv(J: np.ndarray, D: np.ndarray) -> np.ndarray:
    """The pseudo-inverses of the chord method's fixed matrices ``[J; D]`` (:func:`correct_stack`)."""
    return pinv_stack(np.concatenate([J, D[:, None, :]], axis=1))


def correct_stack(curve: BatchCurve, ZP: np.ndarray, D: np.ndarray, idx: np.ndarray, J: np.ndarray | None = None,
                  maxiter: int = 10, jacobians: bool = False, start: tuple | None = None,
                  P: np.ndarray | None = None) -> tuple:
    """:func:`correct` of every row of ``ZP`` (directions ``D``, chord Jacobians ``J`` or ``None`` for full
    Newton) at once.  Returns ``(Z, converged, iterations)``; rows that did not converge are left at ``ZP``
    with ``converged`` false.  The chord method's least-squares step uses the pseudo-inverse of its fixed
    matrix, computed once.  With ``jacobians`` also ``(Jacobians, known)``: the exact Jacobian at each converged
    point where the last evaluation (full Newton's residual test) computed it (``known`` true), NaN elsewhere.
    ``start``: ``curve.evaluate(ZP, idx, True)`` when already known (the first iteration's evaluation); ``P``: the
    chord method's pseudo-inverse (:func:`chord_pinv` of ``J`` and ``D``) when already known."""
    count = len(ZP)
    out, ok, iters = ZP.copy(), np.zeros(count, dtype=bool), np.full(count, maxiter)
    rows, Z, zp, d, ix = np.arange(count), ZP.copy(), ZP, D, idx
    if J is not None and P is None:
        P = chord_pinv(J, D)
    checking = np.zeros(count, dtype=bool)
    Jused = J  # the Jacobian of each row's last step (the round-off floor of its residual test)
    Jout, known = None, np.zeros(count, dtype=bool)
    for it in range(maxiter + 1):
        if it == maxiter:  # the last evaluation serves only the rows moved below step_tol: their residual test
            if it and checking.any():
                R = curve.evaluate(Z[checking], ix[checking], False)[0]
                done = rows[checking]
                floor = roundoff_floor(Jused[checking], Z[checking])
                ok[done] = np.abs(R).max(axis=1) < np.maximum(curve.tol, floor)
                iters[done] = it
                out[done] = Z[checking]
            break
        jacobian = P is None
        if it == 0 and start is not None:
            R, Jz = start[0], (start[1] if jacobian else None)
        else:
            R, Jz = curve.evaluate(Z, ix, jacobian)
        leave = checking if it and checking.any() else None  # the rows that stop here
        if leave is not None:  # moved less than step_tol at the last iteration: the residual test
            done = rows[checking]
            floor = roundoff_floor(Jused[checking], Z[checking])
            ok[done] = np.abs(R[checking]).max(axis=1) < np.maximum(curve.tol, floor)
            iters[done] = it
            out[done] = Z[checking]
            if jacobians and Jz is not None:
                if Jout is None:
                    Jout = np.full((count, *Jz.shape[1:]), np.nan)
                Jout[done], known[done] = Jz[checking], ok[done]
        r = np.concatenate([R, np.einsum("ij,ij->i", d, Z - zp)[:, None]], axis=1)
        undefined = ~np.isfinite(r).all(axis=1)  # undefined residual: no solution along this direction
        if undefined.any():
            if leave is not None:
                undefined &= ~leave
            iters[rows[undefined]] = it
            leave = undefined if leave is None else leave | undefined
        if leave is not None:
            keep = ~leave
            if not keep.any():
                break
            rows, Z, zp, d, ix, r = rows[keep], Z[keep], zp[keep], d[keep], ix[keep], r[keep]
            P = None if P is None else P[keep]
            Jz = None if Jz is None else Jz[keep]
            Jused = Jused[keep] if P is not None else Jused
        if P is None:
            Jused = Jz
        if P is not None:
            dz = -(P @ r[:, :, None])[:, :, 0]
        else:
            A = np.concatenate([Jz, d[:, None, :]], axis=1)
            dz = lstsq2_stack(A, -r) if A.shape[2] == 2 else lstsq_stack(A, -r)
        Z = Z + dz
        # a failed solve (non-finite step: its max is NaN or inf) is not checked: maxiter iterations, no convergence
        checking = np.abs(dz).max(axis=1) < curve.step_tol
    if jacobians:
        return out, ok, iters, Jout, known
    return out, ok, iters


class Followers:
    """:func:`follow` on many curves at once, members joining and leaving between steps.

    Each member (a start point and a direction on curve ``idx``) runs the algorithm of :func:`follow` — the
    same predictor, corrector, acceptance and step control; its points do not depend on the other members.
    One :meth:`step` makes one attempt (predictor + corrector, then acceptance) for every running member,
    with the numerical work of all of them done together.

    >>> circles = BatchCurve.of([Curve(residual=lambda z, r=r: np.array([z @ z - r * r]),
    ...                                jacobian=lambda z: 2 * z[None, :]) for r in (1.0, 2.0)])
    >>> run = Followers(circles, ds=0.1, max_points=10)
    >>> ids = run.add(np.array([[1.0, 0.0], [2.0, 0.0]]), np.array([[0.0, 1.0], [0.0, 1.0]]), np.array([0, 1]))
    >>> while run.running.size:
    ...     run.step()
    >>> [len(p) for p in run.points], [round(float(np.hypot(*p[-1])), 12) for p in run.points]
    ([10, 10], [1.0, 2.0])
    """

    def __init__(self, curve: BatchCurve, *, ds: float, ds_min: float | None = None, ds_max: float | None = None,
                 max_points: int = 400, stop: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
                 max_offset: float = 0.3):
        self.curve, self.ds, self.max_points = curve, float(ds), max_points
        self.stop, self.max_offset = stop, max_offset
        self.ds_min = ds / 1000 if ds_min is None else ds_min
        self.ds_max = 2 * ds if ds_max is None else ds_max
        self.points: list[list[Vector]] = []
        self._state: dict[str, np.ndarray] = {}

    def __len__(self) -> int:
        return len(self.points)

    @property
    def running(self) -> np.ndarray:
        """Ids of the members still being followed."""
        return np.flatnonzero(self._state["live"]) if self._state else np.zeros(0, dtype=int)

    def add(self, Z0: np.ndarray, directions: np.ndarray, idx: np.ndarray) -> np.ndarray:
        """New members from the rows of ``Z0`` along ``directions`` (curve ``idx`` each); their ids."""
        Z0 = np.asarray(Z0, dtype=float)
        count = len(Z0)
        if count == 0:
            return np.zeros(0, dtype=int)
        J = self.curve.evaluate(Z0, idx, True)[1]
        new = {"Z0": Z0, "Z": Z0.copy(), "tan": tangent_stack(J, directions), "J": J, "idx": np.asarray(idx),
               "travelled": np.zeros(count), "h": np.full(count, self.ds), "step": np.full(count, self.ds),
               "live": np.ones(count, dtype=bool), "points": np.zeros(count, dtype=int),
               "P": np.zeros((count, J.shape[2], J.shape[1] + 1)), "P_known": np.zeros(count, dtype=bool)}
        first = len(self.points)
        self._state = new if not self._state else {k: np.concatenate([self._state[k], v]) for k, v in new.items()}
        self.points.extend([] for _ in range(count))
        return np.arange(first, first + count)

    def add_traces(self, Z0: np.ndarray, orientation: np.ndarray, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Members for :func:`trace` through each row of ``Z0``: ids of the forward and of the backward ones."""
        Z0 = np.asarray(Z0, dtype=float)
        if len(Z0) == 0:
            return np.zeros(0, dtype=int), np.zeros(0, dtype=int)
        t0 = tangent_stack(self.curve.evaluate(Z0, idx, True)[1], np.broadcast_to(orientation, Z0.shape))
        ids = self.add(np.concatenate([Z0, Z0]), np.concatenate([t0, -t0]), np.concatenate([idx, idx]))
        return ids[: len(Z0)], ids[len(Z0):]

    def cancel(self, ids) -> None:
        """Stop following these members."""
        if self._state:
            self._state["live"][np.asarray(ids, dtype=int)] = False

    def step(self) -> None:
        """One attempt of every running member: a point accepted, or the step halved."""
        st, curve = self._state, self.curve
        rows = self.running
        if rows.size == 0:
            return
        Z, tan, step, idx = st["Z"], st["tan"], st["step"], st["idx"]
        ZP = Z[rows] + step[rows, None] * tan[rows]
        R0, J0 = curve.evaluate(ZP, idx[rows], True)  # the first iteration of both correctors
        new = rows[~st["P_known"][rows]]  # the chord's matrix changes with the point, not with the step
        st["P"][new], st["P_known"][new] = chord_pinv(st["J"][new], tan[new]), True
        ZC, ok, iters = correct_stack(curve, ZP, tan[rows], idx[rows], st["J"][rows], start=(R0, J0), P=st["P"][rows])
        retry = np.flatnonzero(~ok)  # chord method failed: full Newton
        known = np.zeros(rows.size, dtype=bool)  # the Jacobian at the corrected point known (full Newton's last)
        if retry.size:
            ZC[retry], ok[retry], iters[retry], Jr, known[retry] = correct_stack(
                curve, ZP[retry], tan[rows[retry]], idx[rows[retry]], jacobians=True, start=(R0[retry], J0[retry]))
        good = ok.copy()
        if good.any():
            good[good] = curve.valid(ZC[good], idx[rows[good]])
        with np.errstate(invalid="ignore"):
            good &= np.linalg.norm(ZC - ZP, axis=1) < self.max_offset * step[rows]
        if good.any():
            good[good] = ~curve.crossing(Z[rows[good]], ZC[good], idx[rows[good]])
        bad = rows[~good]
        step[bad] /= 2
        st["live"][bad[step[bad] < self.ds_min]] = False
        acc, ZC, iters = rows[good], ZC[good], iters[good]
        if acc.size == 0:
            return
        st["travelled"][acc] += np.linalg.norm(ZC - Z[acc], axis=1)
        if known[good].any():  # the Jacobians full Newton computed at its converged points; the others evaluated
            lookup = np.full(rows.size, -1)
            lookup[retry] = np.arange(retry.size)
            have = known[good]
            st["J"][acc[have]] = Jr[lookup[np.flatnonzero(good)[have]]]
            if not have.all():
                st["J"][acc[~have]] = curve.evaluate(ZC[~have], idx[acc[~have]], True)[1]
        else:
            st["J"][acc] = curve.evaluate(ZC, idx[acc], True)[1]
        tan[acc] = tangent_stack(st["J"][acc], tan[acc])
        st["P_known"][acc] = False
        Z[acc] = ZC
        for i, z in zip(acc.tolist(), ZC):
            self.points[i].append(z.copy())
        st["points"][acc] += 1
        closed = (st["travelled"][acc] > 4 * self.ds_max) & (np.linalg.norm(ZC - st["Z0"][acc], axis=1) < step[acc])
        factor = np.where(iters <= 6, 1.5, np.where(iters >= 9, 0.7, 1.0))
        st["h"][acc] = np.minimum(self.ds_max, step[acc] * factor)
        ended = closed | (st["points"][acc] >= self.max_points)
        if self.stop is not None:
            ended |= self.stop(ZC, idx[acc])
        st["live"][acc[ended]] = False
        step[acc] = st["h"][acc]


def follow_stack(curve: BatchCurve, Z0: np.ndarray, directions: np.ndarray, idx: np.ndarray, **options
                 ) -> list[list[Vector]]:
    """:func:`follow` from every row of ``Z0`` along ``directions`` at once (:class:`Followers`; ``stop(Z, idx)``
    vectorised): one list of points per row."""
    run = Followers(curve, **options)
    run.add(Z0, directions, idx)
    while run.running.size:
        run.step()
    return run.points


def trace_stack(curve: BatchCurve, Z0: np.ndarray, orientation: np.ndarray, idx: np.ndarray,
                **options) -> list[tuple[list[Vector], int]]:
    """:func:`trace` through every row of ``Z0`` (forwards along ``orientation``, one vector for all) at once;
    ``options`` go to :class:`Followers`."""
    run = Followers(curve, **options)
    fwd, bwd = run.add_traces(Z0, orientation, idx)
    while run.running.size:
        run.step()
    return [(run.points[b][::-1] + [np.asarray(Z0[i], dtype=float)] + run.points[f], len(run.points[b]))
            for i, (f, b) in enumerate(zip(fwd, bwd))]
