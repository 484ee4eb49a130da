"""Block shift-invert Lanczos: the lowest eigenpairs of ``K φ = λ M φ`` from one factorisation of ``K``.

:func:`block_lanczos` builds an ``M``-orthonormal basis ``V = [V₁ V₂ …]`` of the block Krylov space of
``S = K⁻¹M`` from a random start block (two passes of block Gram–Schmidt in the ``M`` inner product, then a
Cholesky QR), and the Rayleigh quotient ``H = VᵀM S M V = VᵀM W`` (``W = S V``, one block solve per block).
The Ritz pairs ``(θ, V z)`` of ``H`` give ``λ = 1/θ``; the residual of each pair is ``‖S φ - θ φ‖_M =
‖R z_last‖`` (``R`` the triangular factor of the next block, ``z_last`` the last block rows of ``z``), so
convergence is checked without forming a residual.  It stops when every wanted pair has
``‖S φ - θ φ‖_M ≤ tol · θ``.

Why blocks: a supernodal Cholesky factor (CHOLMOD) solves 8 right-hand sides in about twice the time of one
(110k dofs: 0.165 s vs 0.082 s), so 14 block solves of 8 vectors replace ARPACK's 53 single solves for 20
modes: 2.7 s vs 3.7 to 7.5 s (``bladecase.linalg.lowest_modes`` chooses; SuperLU solves column by column,
and ARPACK stays its choice).

>>> import numpy as np, scipy.sparse as sp, scipy.sparse.linalg as spla
>>> n = 400
>>> K = sp.diags_array([[-1.0] * (n - 1), [2.0] * n, [-1.0] * (n - 1)], offsets=[-1, 0, 1], format="csc")
>>> lam, phi = block_lanczos(K, sp.eye_array(n, format="csr"), spla.splu(K).solve, 3, block=4)
>>> exact = 2 - 2 * np.cos(np.arange(1, 4) * np.pi / (n + 1))
>>> bool(np.allclose(lam, exact, rtol=1e-10, atol=0))
True
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.linalg as sla

__all__ = ["BLOCK_SIZE", "BLOCK_TOL", "block_lanczos"]

#: Default block size (right-hand sides per solve).
BLOCK_SIZE = 8

#: Default convergence tolerance ``‖S φ - θ φ‖_M / θ`` of every wanted Ritz pair: 1e-10 gives residuals
#: ``‖K φ - λ M φ‖ / ‖K φ‖`` near 1e-8 (as ARPACK's) and frequencies within ~1e-11 of ARPACK's.
BLOCK_TOL = 1e-10


def _m_orthonormalise(Y: np.ndarray, V: np.ndarray, MV: np.ndarray, M,
                      C: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``Y`` made ``M``-orthogonal to the columns of ``V`` (two passes) then ``M``-orthonormal (Cholesky QR).

    ``C``: the first pass's coefficients ``(MV)ᵀY`` if already computed.  Returns ``(Q, MQ, R)`` with
    ``Y_⊥ = Q R``; raises ``np.linalg.LinAlgError`` if ``Y_⊥`` is rank deficient.
    """
    if V.shape[1]:
        Y = Y - V @ (MV.T @ Y if C is None else C)
        Y = Y - V @ (MV.T @ Y)
    MY = M @ Y
    G = Y.T @ MY
    R = np.linalg.cholesky(0.5 * (G + G.T)).T
    if np.min(np.abs(np.diag(R))) <= 1e-10 * np.max(np.abs(np.diag(R))):
        raise np.linalg.LinAlgError("rank-deficient block")
    Q = sla.solve_triangular(R, Y.T, trans="T", check_finite=False).T
    MQ = sla.solve_triangular(R, MY.T, trans="T", check_finite=False).T
    return Q, MQ, R


def block_lanczos(K, M, solve: Callable[[np.ndarray], np.ndarray], count: int, *, block: int = BLOCK_SIZE,
                  tol: float = BLOCK_TOL, max_dim: int | None = None, seed: int = 0,
                  space: list | None = None) -> tuple[np.ndarray, np.ndarray] | None:
    """The ``count`` lowest eigenpairs of ``K φ = λ M φ`` by block shift-invert Lanczos (module docstring).

    Parameters
    ----------
    K, M : (n, n) scipy sparse (symmetric, ``K`` positive definite, ``M`` positive semi-definite)
    solve : callable
        ``b ↦ K⁻¹b`` for a block ``b`` of shape ``(n, block)`` (``SPDFactor.solve``).
    count : int
        Number of eigenpairs, ``1 <= count`` and ``count + block <= max_dim``.
    block : int
        Vectors per block (solves per step).
    tol : float
        Convergence: every wanted pair with ``‖S φ - θ φ‖_M <= tol · θ`` (``S = K⁻¹M``, ``θ = 1/λ``).
    max_dim : int or None
        Largest basis (columns); default ``min(n, max(4 count, count + 20 block))``.
    seed : int
        Seed of the random start block (the result is reproducible).
    space : list or None
        On convergence, the Ritz vectors of the whole Krylov basis beyond the ``count`` returned (``M``-orthonormal,
        ``(n, m - count)``, lowest eigenvalue first) are appended to it: directions a richer model can reuse
        without another solve (:func:`bladecase.reduction.krylov_extension`).

    Returns
    -------
    (lam, phi) or None
        Eigenvalues ascending and ``M``-orthonormal modes ``(n, count)``; ``None`` if the basis reached
        ``max_dim`` (or an invariant subspace) before every wanted pair converged — the caller then uses
        another solver.

    Raises
    ------
    ValueError
        ``block`` < 1 or a basis too small for ``count + block`` vectors.
    """
    n = K.shape[0]
    if block < 1:
        raise ValueError(f"block must be an integer >= 1, got {block!r}")
    max_dim = min(n, max(4 * count, count + 20 * block)) if max_dim is None else int(max_dim)
    if count + block > max_dim:
        raise ValueError(f"max_dim = {max_dim} is too small for count = {count} and block = {block} "
                         f"(needs count + block <= max_dim <= n = {n})")
    V = np.empty((n, max_dim), order="F")
    MV = np.empty((n, max_dim), order="F")
    H = np.zeros((max_dim, max_dim))
    start = np.random.default_rng(seed).standard_normal((n, block))
    try:
        Q, MQ, _ = _m_orthonormalise(solve(start), V[:, :0], MV[:, :0], M)
        m = 0
        while m + block <= max_dim:
            V[:, m:m + block], MV[:, m:m + block] = Q, MQ
            W = solve(MQ)  # S Q = K⁻¹ M Q
            m += block
            C = MV[:, :m].T @ W  # (m, block): the new columns of H = VᵀM S M V
            H[:m, m - block:m] = C
            H[m - block:m, :m - block] = C[:m - block].T
            theta_all, Z_all = np.linalg.eigh(0.5 * (H[:m, :m] + H[:m, :m].T))
            theta, Z = theta_all[::-1][:count], Z_all[:, ::-1][:, :count]
            Q, MQ, R = _m_orthonormalise(W, V[:, :m], MV[:, :m], M, C)
            if m >= count and np.all(np.linalg.norm(R @ Z[m - block:m], axis=0) <= tol * theta):
                if space is not None:
                    space.append(V[:, :m] @ Z_all[:, ::-1][:, count:])
                return 1.0 / theta, V[:, :m] @ Z
    except np.linalg.LinAlgError:  # an invariant subspace (or a breakdown) before convergence
        return None
    return None
