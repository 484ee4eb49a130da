"""Least squares over stacks of small matrices: the corrector's linear algebra of :mod:`~bladecase.nsm.continuation`.

* :func:`lstsq_stack` — ``np.linalg.lstsq`` of every matrix of a stack, in one LAPACK call;
* :func:`lstsq2_stack` — the same for two unknowns, in closed form for big stacks;
* :func:`pinv_stack` — pseudo-inverses with the same rank cut-off;
* :func:`tangent_stack` — unit null vectors (the curves' tangents), oriented.

>>> A = np.array([[[1.0, 0.0], [0.0, 2.0], [0.0, 0.0]]])
>>> lstsq_stack(A, np.array([[1.0, 2.0, 3.0]])).tolist(), (pinv_stack(A)[0] @ [1.0, 2.0, 3.0]).tolist()
([[1.0, 1.0]], [1.0, 1.0])
"""

from __future__ import annotations

import numpy as np

#: The machine epsilon.
_EPS = float(np.finfo(float).eps)

#: numpy's own least-squares driver (the LAPACK call of ``np.linalg.lstsq``), vectorised over a stack; private,
#: hence looked up defensively (:func:`lstsq_stack` falls back to one ``np.linalg.lstsq`` per matrix).
_LSTSQ = getattr(getattr(np.linalg, "_umath_linalg", None), "lstsq", None)


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
    """The unit null vector (last right singular vector) of each matrix of the stack ``J`` ``(B, m, n)``, oriented
    along ``previous[i]`` (:func:`bladecase.nsm.continuation.tangent` of each).

    >>> tangent_stack(np.array([[[1.0, 1.0]]]), np.array([[-1.0, 0.0]])).round(12).tolist()
    [[-0.707106781187, 0.707106781187]]
    """
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


