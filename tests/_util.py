"""Independent references for the tests: numpy/scipy only (no bladecase internals).

* exact free flight through the matrix exponential of the first-order system;
* closed-form data of the seed paper's 2-dof example;
* the random non-diagonal SPD system used across the suite;
* a re-simulation helper and a finite-difference monodromy (Floquet multipliers).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

import bladecase as bc


def dense(a) -> np.ndarray:
    return a.toarray() if sp.issparse(a) else np.asarray(a, dtype=float)


def random_spd_system(n: int = 6, seed: int = 1234, gap: float = 0.7) -> bc.LinearSystem:
    """Dense non-diagonal SPD ``M``, ``K`` (well conditioned) and a generic ``w`` (not a unit vector)."""
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    M = (A @ A.T + n * np.eye(n)) / n
    B = rng.standard_normal((n, n))
    K = B @ B.T + n * np.eye(n)
    w = 0.8 * rng.standard_normal(n) + 0.3
    return bc.LinearSystem(M, K, w, gap)


def flow(system: bc.LinearSystem, x, v, tau: float) -> tuple[np.ndarray, np.ndarray]:
    """Free flight ``M x'' + K x = 0`` over ``tau`` by ``expm`` of the first-order system."""
    M, K = dense(system.M), dense(system.K)
    n = M.shape[0]
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -np.linalg.solve(M, K)
    z = sla.expm(A * tau) @ np.concatenate([x, v])
    return z[:n], z[n:]


def two_dof_exact():
    """``(ω, b²)`` of ``chain(2, k=1, m=1/2)`` in closed form (ascending ω).

    ``M⁻¹K = 2 [[2, -1], [-1, 1]]``; the eigenvalues of ``[[2,-1],[-1,1]]`` are
    ``μ = (3 ∓ √5)/2`` with eigenvectors ``(1, 2 - μ)``; ``ω² = 2μ``; with the
    M-norm ``½(1 + (2-μ)²)``, ``b² = (2-μ)² / (½(1 + (2-μ)²))``.
    """
    mu = np.array([(3 - np.sqrt(5)) / 2, (3 + np.sqrt(5)) / 2])
    omega = np.sqrt(2 * mu)
    b2 = (2 - mu) ** 2 / (0.5 * (1 + (2 - mu) ** 2))
    return omega, b2


def stacked(x, v) -> np.ndarray:
    return np.concatenate([np.ravel(x), np.ravel(v)])


def resimulate(system: bc.LinearSystem, orbit: bc.PeriodicOrbit, periods: int):
    """Simulate from the orbit's post-impact state ``state(0.0)`` up to ``(periods + ½) T``.

    Returns ``(trajectory, z0, errors)`` with ``errors[k-1]`` the relative distance
    between the post-impact state at the k-th impact and ``z0``.
    """
    x0, v0 = orbit.state(0.0)
    x0, v0 = x0[:, 0], v0[:, 0]
    tr = bc.simulate(system, x0, v0, (periods + 0.5) * orbit.T)
    z0 = stacked(x0, v0)
    Z = np.vstack([tr.x, tr.v])
    errors = np.linalg.norm(Z - z0[:, None], axis=0) / np.linalg.norm(z0)
    return tr, z0, errors


def fd_flow_map(system: bc.LinearSystem, z: np.ndarray, T: float, impacts: int, eps: float = 1e-6) -> np.ndarray:
    """Central-difference Jacobian of the time-``T`` map of :func:`bladecase.simulate` at the state ``z = (x, v)``
    (every perturbed run must make ``impacts`` impacts)."""
    n = system.n
    h = eps * np.abs(z).max()

    def period_map(z):
        tr = bc.simulate(system, z[:n], z[n:], T)
        assert tr.impact_times.size == impacts
        return stacked(tr.x_end, tr.v_end)

    J = np.empty((2 * n, 2 * n))
    for i in range(2 * n):
        dz = np.zeros(2 * n)
        dz[i] = h
        J[:, i] = (period_map(z + dz) - period_map(z - dz)) / (2 * h)
    return J


def floquet_multipliers(system: bc.LinearSystem, orbit: bc.PeriodicOrbit, eps: float = 1e-6) -> np.ndarray:
    """Eigenvalues of the one-period flow map, by central differences of :func:`bladecase.simulate`.

    The map starts at mid-flight ``t = T/2`` (away from the obstacle, so every
    perturbation is admissible) and runs for one period (one impact).
    """
    x, v = orbit.state(orbit.T / 2)
    return np.linalg.eigvals(fd_flow_map(system, stacked(x, v), orbit.T, 1, eps))
