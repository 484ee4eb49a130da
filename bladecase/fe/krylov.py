"""Solving with a sequence of nearby symmetric matrices: one factorisation reused as the preconditioner of conjugate
gradients, refactorised only when they need too many iterations (modified Newton–Krylov).

Newton's iteration for the geometrically nonlinear static state (:mod:`~bladecase.fe.nonlinear_static`) solves with
tangents ``K_T(u) − Ω² M⊥`` that change little from one iteration to the next, and from one speed of a sweep to the
next; so do the matrices of the linear and second-order states (:func:`~bladecase.fe.rotation.spin`).  Factorising
each is most of the cost on a large blade (Rotor 37, 61k dofs, one core: a factorisation 9.7 s, a solve with it
0.1 s, a product with the matrix 0.01 s, the tangent's assembly 1.5 s).  :class:`ReusedFactor` keeps the
factorisation ``P`` of an earlier matrix and solves ``A x = b`` by the conjugate gradients preconditioned with
``P⁻¹`` (:func:`pcg`, from ``x₀ = P⁻¹ b``) to ``‖b − A x‖ <= rtol ‖b‖``.  When they would need more than
``max_iter`` iterations (judged from the rate of the first :data:`RATE_AFTER`), or meet a direction of non-positive
curvature (``A`` not positive definite), ``A`` is factorised (:func:`~bladecase.linalg.spd_factor`, else
:func:`~bladecase.linalg.symmetric_factor` for an indefinite ``A``) and solved directly; that factorisation then
preconditions the next solves.  Only a positive definite factorisation preconditions; with ``krylov=False`` every
solve factorises its matrix (the direct path).
"""

from __future__ import annotations

import math

import numpy as np

from ..linalg import Factor, SPDFactor, spd_factor, symmetric_factor

__all__ = ["MAX_KRYLOV", "RATE_AFTER", "ReusedFactor", "factor_symmetric", "pcg"]

#: Conjugate-gradient iterations a solve may take before the matrix is factorised instead (each costs a solve with
#: the factorisation and a product with the matrix: about 0.1 s on the 61k-dof blade, a factorisation 80 to 100 of
#: them).
MAX_KRYLOV = 60
#: After this many iterations the convergence rate so far predicts the count: past ``max_iter``, give up now.
RATE_AFTER = 8


def factor_symmetric(A, name: str) -> Factor:
    """``A``'s factorisation: :func:`~bladecase.linalg.spd_factor` (positive definite), else
    :func:`~bladecase.linalg.symmetric_factor` (indefinite: near buckling, or past a spin-softening critical speed);
    ``ValueError`` if singular.

    >>> import scipy.sparse as sp
    >>> type(factor_symmetric(sp.csr_array([[2.0, 1.0], [1.0, -2.0]]), "A")).__name__
    'Factor'
    """
    try:
        return spd_factor(A, name)
    except ValueError:
        return symmetric_factor(A, name)


def pcg(A, b: np.ndarray, factor: Factor, rtol: float, max_iter: int = MAX_KRYLOV) -> tuple[np.ndarray | None, int]:
    """Conjugate gradients on ``A x = b`` preconditioned by ``factor`` (the factorisation of a nearby symmetric
    positive definite matrix), from ``x₀ = factor.solve(b)``: ``(x, solves)`` with ``‖b − A x‖ <= rtol ‖b‖``, or
    ``(None, solves)`` when that takes more than ``max_iter`` iterations (predicted from the rate after
    :data:`RATE_AFTER`) or a direction has non-positive curvature.  ``solves`` counts the solves with ``factor``.

    >>> import scipy.sparse as sp
    >>> A = sp.diags_array([[-1.0] * 9, [2.0] * 10, [-1.0] * 9], offsets=[-1, 0, 1], format="csr")
    >>> near = spd_factor(sp.csr_array(A * 1.1))           # a 10 % stiffer matrix's factorisation
    >>> x, solves = pcg(A, np.ones(10), near, 1e-12)
    >>> bool(np.allclose(A @ x, 1.0, rtol=0, atol=1e-11)), solves
    (True, 2)
    """
    bnorm = float(np.linalg.norm(b))
    if bnorm == 0.0:
        return np.zeros_like(b), 0
    goal = rtol * bnorm
    x = factor.solve(b)
    r = b - A @ x
    rnorm = r0 = float(np.linalg.norm(r))
    solves = 1
    if rnorm <= goal:
        return x, solves
    z = factor.solve(r)
    solves += 1
    p, rz = z, float(r @ z)
    for k in range(1, max_iter + 1):
        Ap = A @ p
        curvature = float(p @ Ap)
        if not (curvature > 0.0 and rz > 0.0):  # A (or the preconditioner) not positive definite
            return None, solves
        alpha = rz / curvature
        x = x + alpha * p
        r = r - alpha * Ap
        rnorm = float(np.linalg.norm(r))
        if rnorm <= goal:
            return x, solves
        if k >= RATE_AFTER and k * math.log(goal / r0) / math.log(max(rnorm / r0, 1e-300)) > max_iter:
            return None, solves  # too slow: a factorisation is cheaper
        z = factor.solve(r)
        solves += 1
        rz_new = float(r @ z)
        p = z + (rz_new / rz) * p
        rz = rz_new
    return None, solves


class ReusedFactor:
    """Solves with a sequence of nearby symmetric matrices (module docstring): conjugate gradients preconditioned by
    the last factorisation, a new factorisation when they are too slow.

    Parameters
    ----------
    factor : Factor or None
        A factorisation to precondition with from the start (e.g. the previous speed's ``K(Ω)``); used only if it
        is positive definite (an :class:`~bladecase.linalg.SPDFactor`) and of the right size.
    krylov : bool
        ``False``: every :meth:`solve` factorises its matrix (the direct path).
    max_iter : int
        Iterations a preconditioned solve may take (:func:`pcg`).

    Attributes
    ----------
    factor : Factor or None
        The factorisation in use (the last made, or the one given).
    factorisations : int
        Factorisations made.
    iterations : int
        Solves with the preconditioner made by the conjugate gradients (whether or not they converged).

    >>> import scipy.sparse as sp
    >>> A = sp.diags_array([[-1.0] * 9, [2.0] * 10, [-1.0] * 9], offsets=[-1, 0, 1], format="csr")
    >>> solver = ReusedFactor()
    >>> x1 = solver.solve(A, np.ones(10), 1e-12)            # factorises A
    >>> x2 = solver.solve(sp.csr_array(A * 1.05), np.ones(10), 1e-12)   # preconditioned by A's factor
    >>> solver.factorisations, bool(np.allclose(x2, x1 / 1.05))
    (1, True)
    """

    def __init__(self, factor: Factor | None = None, *, krylov: bool = True, max_iter: int = MAX_KRYLOV):
        self.factor = factor
        self.krylov, self.max_iter = bool(krylov), int(max_iter)
        self.factorisations = self.iterations = 0

    def solve(self, A, b: np.ndarray, rtol: float, name: str = "A") -> np.ndarray:
        """``A⁻¹ b``: by the preconditioned conjugate gradients to ``rtol`` when they converge in ``max_iter``
        iterations, else by a new factorisation of ``A`` (named ``name`` in its errors: ``ValueError`` if
        singular), kept for the next solves."""
        f = self.factor
        if self.krylov and isinstance(f, SPDFactor) and f.n == A.shape[0]:
            x, solves = pcg(A, b, f, rtol, self.max_iter)
            self.iterations += solves
            if x is not None:
                return x
        self.factor = factor_symmetric(A, name)
        self.factorisations += 1
        return self.factor.solve(b)
