"""The modal kernel of periodic impulse responses, and the k-ipp equations built on it (theory §3–4).

For a non-resonant period ``T`` the ``T``-periodic response to the unit impulse train ``-w Σ_k δ(t - kT)``
is ``x = -G(t)``, with, for ``u ∈ [0, T]``,

    G(u) = Σ_j φ_j b_j cos(ω_j (u - T/2)) / (2 ω_j sin(ω_j T/2)),

and its contact scalars ``g = wᵀG`` and ``s = wᵀG' = g'``.  An orbit with impacts at ``0 < t₁ < … < t_k = T``
and impulses ``Λ`` satisfies ``ΠΛ = 0`` (impact law) and ``ΣΛ = d·1`` (at the obstacle at each impact), with
``Π_ij = s((t_i - t_j) mod T)`` (``Π_ii = 0``) and ``Σ_ij = -g((t_i - t_j) mod T)``.

:class:`ModalKernel` evaluates ``g``, ``s``, ``s'`` and their derivatives in ``T``; :func:`impact_matrices`,
:func:`kipp_residual`, :func:`newton_times` (Gauss–Newton with the exact Jacobian) and :func:`solve_times`
(Newton, else Levenberg–Marquardt) are the k-ipp pieces every solver of this package shares.

>>> from bladecase.nsm import chain
>>> kernel = ModalKernel.of(chain(2, k=1.0, m=0.5, gap=1.0), T=6.0)
>>> g, s = kernel.g_s([0.0, 3.0])
>>> bool(abs(s[1]) < 1e-12)   # s is odd about T/2
True
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .system import LinearSystem

#: ``T`` is resonant when ``|ω_j T - 2πm| <= RESONANCE_RTOL · ω_j T`` for an
#: integer ``m >= 1`` and a mode with ``b_j ≠ 0``: within the accuracy of the
#: computed ``ω_j`` (the response amplitude there exceeds ``~1e11 d``).
RESONANCE_RTOL = 1e-12

#: Two impacts closer than ``DISTINCT_RTOL·T`` are one: such a "solution" is
#: not a k-ipp orbit and is discarded.
DISTINCT_RTOL = 1e-7


def check_period(system: LinearSystem, T: float) -> float:
    """Return ``T`` as a float; raise ``ValueError`` if it is not a finite positive number or is resonant.

    >>> from bladecase.nsm import chain
    >>> check_period(chain(1, k=1.0, m=1.0, gap=1.0), 3.0)
    3.0
    """
    try:
        T = float(T)
    except (TypeError, ValueError):
        raise ValueError(f"period T must be a number, got {T!r}") from None
    if not np.isfinite(T) or T <= 0:
        raise ValueError(f"period T must be finite and > 0, got {T!r}")
    sp = system.spectrum
    omega = sp.omega[sp.active]
    r = omega * T / (2 * np.pi)
    m = np.rint(r)
    bad = np.flatnonzero((m >= 1) & (np.abs(r - m) <= RESONANCE_RTOL * r))
    if bad.size:
        j = int(np.flatnonzero(sp.active)[bad[0]])
        mm = int(m[bad[0]])
        raise ValueError(
            f"period T = {T!r} is resonant: ω_{j + 1} T = 2π·{mm} (mode {j + 1}, ω = {sp.omega[j]:.10g}, "
            f"linear period {2 * np.pi / sp.omega[j]:.10g}); nonsmooth orbits need ω_j T ∉ 2πℤ "
            f"(relative tolerance {RESONANCE_RTOL:g})"
        )
    return T


@dataclass(frozen=True)
class ModalKernel:
    """The periodic impulse response of a system at period ``T``, on the modes that see the contact.

    Attributes
    ----------
    omega, b : (m,) ndarray
        Angular frequencies and contact participations ``b_j = wᵀφ_j`` of the active modes.
    phi : (n, m) ndarray
        Their M-normalised shapes.
    sin_half : (m,) ndarray
        ``sin(ω_j T/2)`` (non-zero: ``T`` is not resonant).
    T : float
        Period.
    """

    omega: np.ndarray
    b: np.ndarray
    phi: np.ndarray
    sin_half: np.ndarray
    T: float

    @classmethod
    def of(cls, system: LinearSystem, T: float) -> ModalKernel:
        """The kernel of ``system`` at period ``T`` (no resonance check: see :func:`check_period`)."""
        omega, b, phi = system.spectrum.contact_modes
        return cls(omega=omega, b=b, phi=phi, sin_half=np.sin(omega * T / 2), T=T)

    def at(self, T: float) -> ModalKernel:
        """The same modes at another period ``T``."""
        return ModalKernel(self.omega, self.b, self.phi, np.sin(self.omega * T / 2), T)

    def _phase(self, u) -> np.ndarray:
        return np.multiply.outer(np.asarray(u, dtype=float) - self.T / 2, self.omega)

    @property
    def _c(self) -> np.ndarray:
        return self.b**2 / (2 * self.sin_half)

    def g_s(self, u) -> tuple[np.ndarray, np.ndarray]:
        """``g(u) = wᵀG(u)`` and ``s(u) = wᵀG'(u)`` for ``u`` in ``[0, T]`` (any shape)."""
        ph = self._phase(u)
        c = self._c
        return np.cos(ph) @ (c / self.omega), -(np.sin(ph) @ c)

    def ds(self, u) -> np.ndarray:
        """``s'(u) = wᵀG''(u)`` for ``u`` in ``(0, T)``."""
        return -(np.cos(self._phase(u)) @ (self.b**2 * self.omega / (2 * self.sin_half)))

    def dT(self, u) -> tuple[np.ndarray, np.ndarray]:
        """``∂g/∂T`` and ``∂s/∂T`` at fixed ``u`` (the kernel depends on ``T`` through ``T/2`` and ``sin(ωT/2)``)."""
        ph = self._phase(u)
        c = self._c
        cot = np.cos(self.omega * self.T / 2) / self.sin_half
        cs, sn = np.cos(ph), np.sin(ph)
        return (sn - cs * cot) @ (c / 2), (cs + sn * cot) @ (c * self.omega / 2)

    def matrices(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(Π, Σ)`` for impact times ``0 < t₁ < … < t_k = T`` (unchecked; see :func:`impact_matrices`)."""
        D = np.mod(times[:, None] - times[None, :], self.T)
        g, s = self.g_s(D)
        np.fill_diagonal(s, 0.0)
        return s, -g

    def start_state(self, times: np.ndarray, impulses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Active-mode coordinates ``(q, q̇)`` just after the impact at ``t = 0`` (``≡ T``) of the orbit."""
        theta = np.mod(-times, self.T) - self.T / 2
        ph = np.multiply.outer(self.omega, theta)
        scale = self.b / (2 * self.sin_half)
        return -(scale / self.omega) * (np.cos(ph) @ impulses), scale * (np.sin(ph) @ impulses)


def check_times(impact_times) -> np.ndarray:
    """``impact_times`` as a float array, checked to be ``0 < t₁ < … < t_k`` (finite, non-empty)."""
    times = np.asarray(impact_times, dtype=float).reshape(-1)
    if times.size == 0 or not np.all(np.isfinite(times)):
        raise ValueError("impact_times must be a non-empty sequence of finite times")
    if times[0] <= 0 or np.any(np.diff(times) <= 0):
        raise ValueError(f"impact_times must satisfy 0 < t1 < ... < tk = T, got {times.tolist()}")
    return times


def impact_matrices(system: LinearSystem, impact_times) -> tuple[np.ndarray, np.ndarray]:
    """The paper's matrices ``(Π, Σ)`` for impacts at ``0 < t₁ < … < t_k = T``.

    ``Π_ij = s((t_i - t_j) mod T)`` (``Π_ii = 0``; skew-symmetric) and
    ``Σ_ij = -g((t_i - t_j) mod T)`` (symmetric), with ``g = wᵀG`` and
    ``s = wᵀG'`` (theory §3–4).  A ``k``-ipp orbit has impulses ``Λ`` with
    ``ΠΛ = 0`` (elastic impact law at every impact) and ``ΣΛ = d·1`` (at the
    obstacle at every impact).

    >>> from bladecase.nsm import chain
    >>> Pi, Sigma = impact_matrices(chain(2, k=1.0, m=0.5, gap=1.0), [2.1, 5.3])
    >>> bool(Pi[0, 1] == -Pi[1, 0]), bool(Sigma[0, 1] == Sigma[1, 0])
    (True, True)
    """
    times = check_times(impact_times)
    T = check_period(system, times[-1])
    return ModalKernel.of(system, T).matrices(times)


def kipp_residual(kernel: ModalKernel, times: np.ndarray, impulses: np.ndarray, d: float) -> np.ndarray:
    """``[ΠΛ ; ΣΛ - d·1]`` (length ``2k``; ``ΛᵀΠΛ ≡ 0`` makes one component redundant)."""
    Pi, Sigma = kernel.matrices(times)
    return np.concatenate([Pi @ impulses, Sigma @ impulses - d])


def kipp_jacobian(kernel: ModalKernel, times: np.ndarray, impulses: np.ndarray) -> np.ndarray:
    """Exact Jacobian of :func:`kipp_residual` in ``(t₁ … t_{k-1}, Λ)`` at fixed ``T``: shape ``(2k, 2k-1)``."""
    return _residual_jacobian(kernel, times, impulses, 0.0)[1]


def _residual_jacobian(kernel: ModalKernel, times, lam, d: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`kipp_residual` and :func:`kipp_jacobian` from one evaluation of the kernel."""
    k = times.size
    D = np.mod(times[:, None] - times[None, :], kernel.T)
    g, s = kernel.g_s(D)
    np.fill_diagonal(s, 0.0)
    dsD = kernel.ds(D)
    np.fill_diagonal(dsD, 0.0)
    r = np.concatenate([s @ lam, -g @ lam - d])
    # d/dt_l of Σ_j X(D_ij) Λ_j, with dD_ij/dt_l = δ_il - δ_jl:
    #   row i: δ_il Σ_j X'(D_ij)Λ_j - X'(D_il)Λ_l
    A_pi = np.diag(dsD @ lam) - dsD * lam[None, :]
    A_sg = -(np.diag(s @ lam) - s * lam[None, :])
    return r, np.block([[A_pi[:, : k - 1], s], [A_sg[:, : k - 1], -g]])


def impulses_for(kernel: ModalKernel, times: np.ndarray, d: float) -> np.ndarray | None:
    """``Λ`` from ``ΣΛ = d·1`` (least squares), or ``None`` if ``Σ`` is singular."""
    _, Sigma = kernel.matrices(times)
    lam, *_ = np.linalg.lstsq(Sigma, np.full(times.size, d), rcond=1e-12)
    return lam if np.all(np.isfinite(lam)) else None


def _distinct(times: np.ndarray, T: float) -> bool:
    return not (times[0] <= DISTINCT_RTOL * T or np.any(np.diff(times) <= DISTINCT_RTOL * T))


def newton_times(kernel: ModalKernel, times: np.ndarray, lam: np.ndarray, d: float, maxiter: int = 12):
    """Gauss–Newton on ``[ΠΛ ; ΣΛ - d] = 0`` in ``(t₁…t_{k-1}, Λ)`` at fixed ``T``, with the exact
    Jacobian (:func:`kipp_jacobian`); ``(times, Λ)``, or ``None`` unless it converges to round-off
    with distinct impacts."""
    k, T = times.size, kernel.T
    times, lam = times.astype(float).copy(), lam.astype(float).copy()
    prev = np.inf
    for _ in range(maxiter):
        r, J = _residual_jacobian(kernel, times, lam, d)
        step, *_ = np.linalg.lstsq(J, -r, rcond=None)
        times[: k - 1] += step[: k - 1]
        lam += step[k - 1:]
        size = np.abs(step[: k - 1]).max(initial=0.0) / T + np.abs(step[k - 1:]).max() / max(np.abs(lam).max(), d)
        if not np.all(np.isfinite(step)) or size > 10 * prev:
            return None
        if size < 1e-14:
            break
        prev = size
    if not _distinct(times, T):
        return None  # impacts merged: not a k-ipp orbit
    r = kipp_residual(kernel, times, lam, d)
    scale = float(kernel.b @ kernel.b) / 2 * np.abs(lam).max()
    if np.abs(r[:k]).max() > 1e-9 * max(scale, d) or np.abs(r[k:]).max() > 1e-9 * d:
        return None
    return times, lam


def solve_times(kernel: ModalKernel, times0: np.ndarray, d: float) -> tuple[np.ndarray, np.ndarray] | None:
    """Solve for ``(t₁…t_{k-1}, Λ)`` at fixed ``T`` from impact times ``times0``: Newton with the exact
    Jacobian, else Levenberg–Marquardt (wider basin); ``None`` if neither converges."""
    from scipy.optimize import least_squares

    T, k = kernel.T, times0.size
    lam0 = impulses_for(kernel, times0, d)
    if lam0 is None:
        return None
    sol = newton_times(kernel, times0, lam0, d)
    if sol is not None:
        return sol
    lscale = max(np.abs(lam0).max(), d)

    def fun(u):
        return kipp_residual(kernel, np.append(u[: k - 1], T), u[k - 1:] * lscale, d) / d

    res = least_squares(fun, np.concatenate([times0[:-1], lam0 / lscale]), method="lm", xtol=1e-15, ftol=1e-15,
                        gtol=1e-15, max_nfev=200 * k)
    times = np.append(res.x[: k - 1], T)
    lam = res.x[k - 1:] * lscale
    if not np.all(np.isfinite(res.x)) or np.abs(res.fun).max() > 1e-9 or not _distinct(times, T):
        return None
    return times, lam
