"""Pseudo-arclength continuation of the solution curve of ``R(z) = 0``, generic over its residual.

A :class:`Curve` is ``R: ℝⁿ → ℝᵐ`` whose zero set is (locally) a curve — rank ``n - 1`` Jacobian; redundant
equations (``m >= n``) are allowed — given as callables: the residual, its EXACT Jacobian, and optional
predicates (``valid`` points, forbidden ``crossing`` between two points).  The driver knows nothing else:
the k-ipp families (:mod:`bladecase.nsm.families`: impact times and period) and, e.g., the shooting equations of
a piecewise-linear contact model (switching instants and period) plug in the same way.

* :func:`tangent` — the unit null vector of the Jacobian (SVD), oriented along a previous one;
* :func:`correct` — Newton on ``[R(z) ; t·(z - z_p)] = 0`` (chord method when a Jacobian is given);
* :func:`follow` — points from ``z₀`` in one direction, adaptive step, until ``stop`` says so, the curve
  closes, or the corrector fails at the smallest step;
* :func:`trace` — both directions, joined into one polyline;
* :func:`bisect` — the point where a predicate on the curve (e.g. admissibility) changes, between two points.

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
        Largest ``max|R|`` of a converged point.
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


def correct(curve: Curve, zp: Vector, direction: Vector, J: np.ndarray | None = None,
            maxiter: int = 10) -> tuple[Vector | None, int]:
    """Newton on ``[R(z) ; direction·(z - zp)] = 0`` from ``zp``; with ``J`` given, the chord method (that
    Jacobian kept for every iteration).  Returns ``(z or None, iterations)``."""
    z = zp.copy()
    for it in range(maxiter):
        r = np.append(curve.residual(z), direction @ (z - zp))
        if not np.all(np.isfinite(r)):
            return None, it
        A = np.vstack([curve.jacobian(z) if J is None else J, direction])
        dz, *_ = np.linalg.lstsq(A, -r, rcond=None)
        z = z + dz
        if np.abs(dz).max() < curve.step_tol:
            res = np.abs(curve.residual(z)).max()
            return (z if res < curve.tol else None), it + 1
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
