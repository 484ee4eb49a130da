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
from functools import cache, cached_property

import numpy as np

from ..continuation import lstsq_stack
from ..signals import sincos_half
from ..system import LinearSystem

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
    with np.errstate(over="ignore"):
        r = omega * T / (2 * np.pi)
    if r.size and r.max() >= 0.5 / RESONANCE_RTOL:  # every T is then within the tolerance of a resonance
        j = int(np.flatnonzero(sp.active)[int(np.argmax(r))])
        raise ValueError(
            f"period T = {T:.6g} is too long: it spans {r.max():.6g} periods of mode {j + 1} (linear period "
            f"{2 * np.pi / sp.omega[j]:.6g}); beyond {0.5 / RESONANCE_RTOL:.6g} periods every T is within the "
            f"resonance tolerance {RESONANCE_RTOL:g} of a resonance: valid periods are below "
            f"{0.5 / RESONANCE_RTOL * 2 * np.pi / sp.omega[j]:.6g}"
        )
    m = np.rint(r)
    bad = np.flatnonzero((m >= 1) & (np.abs(r - m) <= RESONANCE_RTOL * r))
    if bad.size:
        j = int(np.flatnonzero(sp.active)[bad[0]])
        mm = int(m[bad[0]])
        raise ValueError(
            f"period T = {T:.10g} is resonant: ω_{j + 1} T = 2π·{mm} (mode {j + 1}, ω = {sp.omega[j]:.10g}, "
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

    @cached_property
    def _c(self) -> np.ndarray:
        return self.b**2 / (2 * self.sin_half)

    @cached_property
    def _weights(self) -> tuple[np.ndarray, np.ndarray]:
        return self._c / self.omega, self.b**2 * self.omega / (2 * self.sin_half)

    def g_s(self, u) -> tuple[np.ndarray, np.ndarray]:
        """``g(u) = wᵀG(u)`` and ``s(u) = wᵀG'(u)`` for ``u`` in ``[0, T]`` (any shape)."""
        ph = self._phase(u)
        return np.cos(ph) @ self._weights[0], -(np.sin(ph) @ self._c)

    def ds(self, u) -> np.ndarray:
        """``s'(u) = wᵀG''(u)`` for ``u`` in ``(0, T)``."""
        return -(np.cos(self._phase(u)) @ self._weights[1])

    def g_s_ds(self, u) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`g_s` and :meth:`ds` together (one evaluation of the trigonometric terms)."""
        ph = self._phase(u)
        cs = np.cos(ph)
        return cs @ self._weights[0], -(np.sin(ph) @ self._c), -(cs @ self._weights[1])

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
    g, s, dsD = kernel.g_s_ds(D)
    np.fill_diagonal(s, 0.0)
    np.fill_diagonal(dsD, 0.0)
    r = np.concatenate([s @ lam, -g @ lam - d])
    # d/dt_l of Σ_j X(D_ij) Λ_j, with dD_ij/dt_l = δ_il - δ_jl:
    #   row i: δ_il Σ_j X'(D_ij)Λ_j - X'(D_il)Λ_l
    A_pi = np.diag(dsD @ lam) - dsD * lam[None, :]
    A_sg = -(np.diag(s @ lam) - s * lam[None, :])
    return r, np.concatenate([np.concatenate([A_pi[:, : k - 1], s], axis=1),
                              np.concatenate([A_sg[:, : k - 1], -g], axis=1)])


def impulses_for(kernel: ModalKernel, times: np.ndarray, d: float) -> np.ndarray | None:
    """``Λ`` from ``ΣΛ = d·1`` (least squares), or ``None`` if ``Σ`` is singular."""
    _, Sigma = kernel.matrices(times)
    lam = lstsq_stack(Sigma[None], np.full((1, times.size), d), rcond=1e-12)[0]
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
        step = lstsq_stack(J[None], -r[None])[0]
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
    Jacobian, else Levenberg–Marquardt (wider basin); ``None`` if neither converges.  For ``k = 2`` the
    scalar equation ``s(t₁) = 0`` is tried first (:func:`solve_pairs`)."""
    if times0.size == 2:
        sol = solve_pairs(kernel.omega, kernel.b, np.array([kernel.T]), times0[None, :1], d)
        if np.isfinite(sol[0][0, 0]):
            return sol[0][0], sol[1][0]
    lam0 = impulses_for(kernel, times0, d)
    if lam0 is None:
        return None
    sol = newton_times(kernel, times0, lam0, d)
    if sol is not None:
        return sol
    return _levenberg_marquardt(kernel, times0, lam0, d)


def half_period_terms(omega: np.ndarray, b: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(c, sin, cos)`` of ``ωT/2`` for periods ``T`` ``(B,)``, each ``(B, m)``, ``c = b²/(2 sin(ωT/2))``: the
    period-dependent factors of the kernel sums ``g``, ``s`` (:class:`ModalKernel`), half-angle sines."""
    sh, ch = sincos_half(np.multiply.outer(np.asarray(T, dtype=float) / 4, omega))
    return b**2 / (2 * sh), sh, ch


def delay_terms(omega: np.ndarray, T: np.ndarray, D: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(sin, cos)`` of ``ω(D - T/2)`` ``(B, m)`` at delays ``D`` ``(B,)``: ``s(D) = -Σ c sin``,
    ``g(D) = Σ (c/ω) cos``, ``s'(D) = -Σ cω cos``."""
    return sincos_half(np.multiply.outer((D - T / 2) / 2, omega))


def solve_pairs(omega: np.ndarray, b: np.ndarray, T: np.ndarray, t1: np.ndarray, d: float,
                maxiter: int = 12) -> tuple[np.ndarray, np.ndarray]:
    """2-ipp orbits at fixed periods, many at once: ``(times, Λ)``, each ``(B, 2)``, NaN rows where Newton fails.

    For ``k = 2`` the fixed-period equations reduce to one scalar equation (theory §4; the paper's Eq. 15):
    ``ΠΛ = 0`` is ``s(t₁) = 0`` and ``ΣΛ = d·1`` gives ``Λ₁ = Λ₂ = -d/(g(0) + g(t₁))``.  Newton on ``s`` from
    ``t1`` (``(B,)`` or ``(B, 1)``, periods ``T`` ``(B,)``) with the exact ``s'``, stopped as
    :func:`newton_times` is (a step below ``1e-14·T``; a failure when a step grows tenfold), and accepted as it
    is: distinct impacts and the residual ``[ΠΛ ; ΣΛ - d]`` within ``1e-9`` of its scale.  Where it fails,
    :func:`solve_times` falls back on Gauss–Newton in ``(t₁, Λ)`` and Levenberg–Marquardt (wider basins).

    >>> from bladecase.nsm import chain
    >>> s2 = chain(2, k=1.0, m=0.5, gap=1.0)
    >>> omega, b, _ = s2.spectrum.contact_modes
    >>> times, lam = solve_pairs(omega, b, np.array([13.5, 13.5]), np.array([6.0, 6.7]), 1.0)
    >>> times[:, 0].round(4).tolist(), bool(np.allclose(lam[:, 0], lam[:, 1]))
    ([6.0829, 6.75], True)
    """
    T = np.asarray(T, dtype=float)
    u = np.asarray(t1, dtype=float).reshape(-1).copy()
    c, _, ch = half_period_terms(omega, b, T)  # (B, m)
    cw = c * omega
    prev = np.full(u.size, np.inf)
    live = np.ones(u.size, dtype=bool)
    failed = np.zeros(u.size, dtype=bool)
    rows, Tr, cr, cwr = np.arange(u.size), T, c, cw  # the rows still iterating, and their terms
    with np.errstate(divide="ignore", invalid="ignore"):
        for _ in range(maxiter):
            if rows.size == 0:
                break
            sn, cs = delay_terms(omega, Tr, u[rows])
            step = -np.einsum("bm,bm->b", sn, cr) / np.einsum("bm,bm->b", cs, cwr)  # -s/s'
            u[rows] += step
            size = np.abs(step) / Tr
            bad = ~np.isfinite(step) | (size > 10 * prev[rows])
            failed[rows[bad]] = True
            stop = bad | (size < 1e-14)
            live[rows[stop]] = False
            prev[rows] = size
            if stop.any():
                rows, Tr, cr, cwr = rows[~stop], Tr[~stop], cr[~stop], cwr[~stop]
    failed |= live  # not converged within maxiter
    with np.errstate(invalid="ignore"):
        failed |= ~((u > DISTINCT_RTOL * T) & (T - u > DISTINCT_RTOL * T))
    sn, cs = delay_terms(omega, T, u)
    w = c / omega
    s_u = -np.einsum("bm,bm->b", sn, c)
    with np.errstate(divide="ignore", invalid="ignore"):
        sigma = np.einsum("bm,bm->b", ch + cs, w)  # g(0) + g(t₁)
        lam = -d / sigma
        scale = float(b @ b) / 2 * np.abs(lam)
        ok = (~failed & np.isfinite(lam) & (np.abs(s_u * lam) <= 1e-9 * np.maximum(scale, d))
              & (np.abs(-sigma * lam - d) <= 1e-9 * d))
    times = np.where(ok[:, None], np.stack([u, T], axis=1), np.nan)
    return times, np.where(ok[:, None], lam[:, None] * np.ones(2), np.nan)


def _levenberg_marquardt(kernel: ModalKernel, times0: np.ndarray, lam0: np.ndarray, d: float):
    """The wide-basin fallback of :func:`solve_times`: Levenberg–Marquardt on the scaled residual."""
    from scipy.optimize import least_squares

    T, k = kernel.T, times0.size
    lscale = max(np.abs(lam0).max(), d)
    scale = np.concatenate([np.ones(k - 1), np.full(k, lscale)]) / d
    last: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}

    def both(u):  # residual and its exact Jacobian in u = (t₁…t_{k-1}, Λ/lscale), from one kernel evaluation
        key = u.tobytes()
        if key not in last:
            last.clear()
            r, J = _residual_jacobian(kernel, np.append(u[: k - 1], T), u[k - 1:] * lscale, d)
            last[key] = (r / d, J * scale)
        return last[key]

    res = least_squares(lambda u: both(u)[0], np.concatenate([times0[:-1], lam0 / lscale]),
                        jac=lambda u: both(u)[1], method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=200 * k)
    times = np.append(res.x[: k - 1], T)
    lam = res.x[k - 1:] * lscale
    if not np.all(np.isfinite(res.x)) or np.abs(res.fun).max() > 1e-9 or not _distinct(times, T):
        return None
    return times, lam


# -- many periods at once ----------------------------------------------------------------------------------


@cache
def _upper_pairs(k: int) -> tuple[np.ndarray, np.ndarray]:
    """``np.triu_indices(k, 1)``, made once per ``k`` (read-only)."""
    iu, ju = np.triu_indices(k, 1)
    iu.flags.writeable = ju.flags.writeable = False
    return iu, ju


def impact_kernels(omega: np.ndarray, b: np.ndarray, times: np.ndarray, derivatives: bool = False,
                   T: np.ndarray | None = None, which: str = "all"):
    """The kernel sums at the delays ``D_ij = (t_i - t_j) mod T`` of many impact patterns at once.

    ``times`` ``(B, k)``: rows ``0 < t₁ < … < t_k = T`` (periods ``T`` ``(B,)``: default the last column).
    Returns ``(g, s)`` at ``D`` — with ``derivatives``
    also ``(s', ∂g/∂T, ∂s/∂T)`` — each ``(B, k, k)`` (the sums of :meth:`ModalKernel.g_s`, :meth:`ModalKernel.ds`,
    :meth:`ModalKernel.dT`; ``s`` with its diagonal ``s(0)``, not zeroed).  The trigonometric terms are evaluated
    at the ``k(k-1)/2`` delays ``i < j`` only: ``D_ji = T - D_ij`` and ``D_ii = 0`` follow by symmetry about
    ``T/2`` (``g``, ``s'`` even, ``s`` odd).  ``which = "g"``: ``(g, None)`` only; ``which = "times"`` (with
    ``derivatives``): ``(g, s, s')`` only, the derivatives in the impact times (the same values, the rest not
    computed).

    >>> from bladecase.nsm import chain
    >>> s2 = chain(2, k=1.0, m=0.5, gap=1.0)
    >>> omega, b, _ = s2.spectrum.contact_modes
    >>> g, s = impact_kernels(omega, b, np.array([[2.1, 7.0], [3.3, 6.0]]))
    >>> Pi, Sigma = ModalKernel.of(s2, 6.0).matrices(np.array([3.3, 6.0]))
    >>> bool(np.allclose(-g[1], Sigma, rtol=1e-13)), bool(np.allclose(s[1] - np.diag(np.diag(s[1])), Pi, rtol=1e-13))
    (True, True)
    """
    count, k = times.shape
    T = times[:, -1] if T is None else T
    half = np.multiply.outer(T / 2, omega)
    sh, ch = np.sin(half), np.cos(half)
    c = b**2 / (2 * sh)  # (B, m)
    iu, ju = _upper_pairs(k)
    D = np.mod(times[:, iu] - times[:, ju], T[:, None])  # (B, P): the delays above the diagonal
    ph = (D - (T / 2)[:, None])[:, :, None] * omega
    cp = np.cos(ph)
    dg = np.arange(k)

    def dot(x, w):
        return (x @ w[:, :, None])[..., 0]

    def full(upper, lower, diag):
        out = np.empty((count, k, k))
        out[:, iu, ju], out[:, ju, iu], out[:, dg, dg] = upper, lower, diag[:, None]
        return out

    w = c / omega
    g_p = dot(cp, w)
    g = full(g_p, g_p, np.einsum("bm,bm->b", ch, w))
    if which == "g":
        return g, None
    sp = np.sin(ph)
    s_p = -dot(sp, c)
    s = full(s_p, -s_p, np.einsum("bm,bm->b", sh, c))
    if not derivatives:
        return g, s
    cw = c * omega
    ds_p = -dot(cp, cw)
    dsD = full(ds_p, ds_p, -np.einsum("bm,bm->b", ch, cw))
    if which == "times":
        return g, s, dsD
    cot = ch / sh
    a1, a2 = dot(sp, c / 2), dot(cp, c * cot / 2)
    b1, b2 = dot(cp, cw / 2), dot(sp, cw * cot / 2)
    return (g, s, dsD, full(a1 - a2, -a1 - a2, np.einsum("bm,bm->b", -sh - ch * cot, c / 2)),
            full(b1 + b2, b1 - b2, np.einsum("bm,bm->b", ch - sh * cot, cw / 2)))


def solve_stack(A: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """``np.linalg.solve`` of each matrix of the stack ``A`` ``(B, k, k)`` with the vectors ``rhs`` ``(B, k)``
    (or matrices ``(B, k, p)``); rows whose matrix is singular come back NaN instead of raising."""
    vector = rhs.ndim == 2
    b = rhs[..., None] if vector else rhs
    try:
        x = np.linalg.solve(A, b)
    except np.linalg.LinAlgError:
        x = np.full(b.shape, np.nan)
        for i in range(len(A)):
            try:
                x[i] = np.linalg.solve(A[i], b[i])
            except np.linalg.LinAlgError:
                pass
    return x[..., 0] if vector else x


def _residual_jacobian_stack(omega, b, T, times, lam, d, jacobian=True):
    """:func:`_residual_jacobian` at many periods: residuals ``(B, 2k)`` and Jacobians ``(B, 2k, 2k-1)``."""
    k = times.shape[1]
    off = ~np.eye(k, dtype=bool)
    sums = impact_kernels(omega, b, times, derivatives=jacobian, T=T, which="times")
    g, s = sums[0], np.where(off, sums[1], 0.0)
    r = np.concatenate([np.einsum("bij,bj->bi", s, lam), -np.einsum("bij,bj->bi", g, lam) - d], axis=1)
    if not jacobian:
        return r, None
    dsD = np.where(off, sums[2], 0.0)
    eye = np.eye(k)
    A_pi = np.einsum("bij,bj->bi", dsD, lam)[:, :, None] * eye - dsD * lam[:, None, :]
    A_sg = -(np.einsum("bij,bj->bi", s, lam)[:, :, None] * eye - s * lam[:, None, :])
    top = np.concatenate([A_pi[:, :, : k - 1], s], axis=2)
    bottom = np.concatenate([A_sg[:, :, : k - 1], -g], axis=2)
    return r, np.concatenate([top, bottom], axis=1)


def solve_times_stack(system: LinearSystem, T: np.ndarray, times0: np.ndarray,
                      d: float, pairs: bool = True) -> list[tuple[np.ndarray, np.ndarray] | None]:
    """:func:`solve_times` for many periods ``T`` ``(B,)`` and starting impact times ``times0`` ``(B, k)``:
    the Newton iterations of all of them vectorised, Levenberg–Marquardt one by one where Newton fails.  For
    ``k = 2`` (unless ``pairs`` is false) the scalar equation of :func:`solve_pairs` first, the rest where it fails.

    >>> from bladecase.nsm import chain
    >>> s2 = chain(2, k=1.0, m=0.5, gap=1.0)
    >>> sols = solve_times_stack(s2, np.array([13.5, 13.5]), np.array([[6.0, 13.5], [6.7, 13.5]]), 1.0)
    >>> [round(float(t[0]), 4) for t, _ in sols]
    [6.0829, 6.75]
    """
    omega, b, _ = system.spectrum.contact_modes
    T = np.asarray(T, dtype=float)
    times0 = np.asarray(times0, dtype=float)
    count, k = times0.shape
    out: list[tuple[np.ndarray, np.ndarray] | None] = [None] * count
    if count == 0:
        return out
    if k == 2 and pairs:  # the scalar equation first, the general solve where it fails
        pt, pl = solve_pairs(omega, b, T, times0[:, 0], d)
        good = np.isfinite(pt[:, 0])
        rest = np.flatnonzero(~good)
        for i in np.flatnonzero(good):
            out[i] = (pt[i], pl[i])
        for i, sol in zip(rest, solve_times_stack(system, T[rest], times0[rest], d, pairs=False) if rest.size else []):
            out[i] = sol
        return out
    Sigma = -impact_kernels(omega, b, times0, T=T, which="g")[0]
    lam0 = lstsq_stack(Sigma, np.full((count, k), d), rcond=1e-12)
    start = np.flatnonzero(np.all(np.isfinite(lam0), axis=1))
    times, lam, ok = _newton_stack(omega, b, T[start], times0[start], lam0[start], d)
    for j, i in enumerate(start):
        if ok[j]:
            out[i] = (times[j], lam[j])
            continue
        try:
            out[i] = _levenberg_marquardt(ModalKernel.of(system, T[i]), times0[i], lam0[i], d)
        except ValueError:
            pass  # the residual is not finite at the start: no solution from there
    return out


def _newton_stack(omega, b, T, times, lam, d, maxiter: int = 12):
    """:func:`newton_times` vectorised over many periods: ``(times, Λ, converged)``."""
    count, k = times.shape
    times, lam = times.copy(), lam.copy()
    prev = np.full(count, np.inf)
    live = np.ones(count, dtype=bool)
    failed = np.zeros(count, dtype=bool)
    for _ in range(maxiter):
        rows = np.flatnonzero(live)
        if rows.size == 0:
            break
        r, J = _residual_jacobian_stack(omega, b, T[rows], times[rows], lam[rows], d)
        step = lstsq_stack(J, -r)
        times[rows, : k - 1] += step[:, : k - 1]
        lam[rows] += step[:, k - 1:]
        size = (np.abs(step[:, : k - 1]).max(axis=1, initial=0.0) / T[rows]
                + np.abs(step[:, k - 1:]).max(axis=1) / np.maximum(np.abs(lam[rows]).max(axis=1), d))
        bad = ~np.all(np.isfinite(step), axis=1) | (size > 10 * prev[rows])
        failed[rows[bad]] = True
        live[rows[bad | (size < 1e-14)]] = False
        prev[rows] = size
    gaps = np.diff(np.concatenate([np.zeros((count, 1)), times], axis=1), axis=1)
    ok = ~failed & np.all(gaps > DISTINCT_RTOL * T[:, None], axis=1)
    rows = np.flatnonzero(ok)
    if rows.size:
        r = _residual_jacobian_stack(omega, b, T[rows], times[rows], lam[rows], d, jacobian=False)[0]
        scale = float(b @ b) / 2 * np.abs(lam[rows]).max(axis=1)
        ok[rows] = ((np.abs(r[:, :k]).max(axis=1) <= 1e-9 * np.maximum(scale, d))
                    & (np.abs(r[:, k:]).max(axis=1) <= 1e-9 * d))
    return times, lam, ok
