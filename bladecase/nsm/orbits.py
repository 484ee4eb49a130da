"""Periodic orbits with impacts: the core of the nonsmooth-mode solver.

Formulation (theory §3–4).  For a non-resonant period ``T``, the ``T``-periodic
response to the unit impulse train ``-w Σ_k δ(t - kT)`` is ``x = -G(t)`` with

    G(t)  = Σ_j φ_j b_j cos(ω_j (t - T/2)) / (2 ω_j sin(ω_j T/2)),   t ∈ [0, T)

and an orbit with impacts at ``0 < t₁ < … < t_k = T`` and impulses ``Λ_i`` is
``x(t) = -Σ_i Λ_i G((t - t_i) mod T)``.  One impact per period (k = 1) gives
``Λ = -d / g(0)``, ``g = wᵀG``.  Everything is evaluated in the modal
coordinates of the modes that see the contact (``b_j ≠ 0``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from .signals import TrigSum, certified_max
from .system import LinearSystem

#: ``T`` is resonant when ``|ω_j T - 2πm| <= RESONANCE_RTOL · ω_j T`` for an
#: integer ``m >= 1`` and a mode with ``b_j ≠ 0``: within the accuracy of the
#: computed ``ω_j`` (the response amplitude there exceeds ``~1e11 d``).
RESONANCE_RTOL = 1e-12

#: An orbit is admissible when its impulses are >= 0 and
#: ``wᵀx(t) - d <= ADMISSIBILITY_RTOL · d`` is PROVED for every ``t`` of the
#: period (see :mod:`bladecase.trigsum`); the tolerance is raised to
#: ``10⁴ ε Σ|coefficients|`` when round-off in evaluating ``wᵀx`` is larger.
ADMISSIBILITY_RTOL = 1e-9


def check_period(system: LinearSystem, T: float) -> float:
    """Return ``T`` as a float; raise ``ValueError`` if it is invalid or resonant."""
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
class _Modal:
    """Active-mode data of a system at period ``T``."""

    omega: np.ndarray
    b: np.ndarray
    phi: np.ndarray
    sin_half: np.ndarray  # sin(ω T / 2)
    T: float

    @classmethod
    def of(cls, system: LinearSystem, T: float) -> _Modal:
        omega, b, phi = system.spectrum.contact_modes
        return cls(omega=omega, b=b, phi=phi, sin_half=np.sin(omega * T / 2), T=T)

    def g_s(self, u) -> tuple[np.ndarray, np.ndarray]:
        """``g(u) = wᵀG(u)`` and ``s(u) = wᵀG'(u)`` for ``u`` in ``[0, T]`` (any shape)."""
        ph = np.multiply.outer(np.asarray(u, dtype=float) - self.T / 2, self.omega)
        c = self.b**2 / (2 * self.sin_half)
        return np.cos(ph) @ (c / self.omega), -(np.sin(ph) @ c)

    def ds(self, u) -> np.ndarray:
        """``s'(u) = wᵀG''(u)`` for ``u`` in ``(0, T)``."""
        ph = np.multiply.outer(np.asarray(u, dtype=float) - self.T / 2, self.omega)
        return -(np.cos(ph) @ (self.b**2 * self.omega / (2 * self.sin_half)))


@dataclass(frozen=True, eq=False)
class PeriodicOrbit:
    """A periodic orbit with ``k`` impacts per period.

    Attributes
    ----------
    system : LinearSystem
    T : float
        Period.
    impact_times : (k,) ndarray
        ``0 < t₁ < … < t_k = T``; the orbit is at the obstacle at ``t = 0``.
    impulses : (k,) ndarray
        Impulses ``Λ_i`` (``M Δv = -w Λ``); admissible orbits have ``Λ_i >= 0``.
    energy : float
        ``½vᵀMv + ½xᵀKx`` (constant along the orbit).
    admissible : bool
        ``Λ_i >= 0`` and ``wᵀx(t) <= d(1 + ADMISSIBILITY_RTOL)`` proved on the
        whole period (:func:`bladecase.nsm.signals.certified_max`).
    max_violation : float
        Largest ``wᵀx - d`` over the period (``0`` at the impacts, so it is
        ``>= 0``; ``<= ADMISSIBILITY_RTOL·d`` when admissible).
    max_violation_time : float
        Where it occurs.
    repeats : int
        ``j > 1`` when the orbit is an orbit of period ``T/j`` counted ``j``
        times (its impacts and impulses are invariant under a shift by
        ``T/j``): not a new nonsmooth mode.  ``1`` otherwise.
    """

    system: LinearSystem = field(repr=False)
    T: float
    impact_times: np.ndarray
    impulses: np.ndarray
    energy: float
    admissible: bool
    max_violation: float
    max_violation_time: float = field(repr=False)
    repeats: int = 1

    @property
    def k(self) -> int:
        """Impacts per period."""
        return int(self.impact_times.size)

    @property
    def frequency(self) -> float:
        """``1 / T``."""
        return 1.0 / self.T

    @cached_property
    def _modal(self) -> _Modal:
        return _Modal.of(self.system, self.T)

    def modal_state(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Active-mode coordinates ``(q, q̇)``, each of shape ``(m_active, len(t))``."""
        md = self._modal
        t = np.atleast_1d(np.asarray(t, dtype=float))
        T = self.T
        q = np.zeros((md.omega.size, t.size))
        qd = np.zeros_like(q)
        for ti, lam in zip(self.impact_times, self.impulses):
            tau = np.mod(t - ti, T) - T / 2
            ph = np.multiply.outer(md.omega, tau)
            q -= lam * np.cos(ph)
            qd += lam * np.sin(ph)
        scale = md.b / (2 * md.sin_half)
        q *= (scale / md.omega)[:, None]
        qd *= scale[:, None]
        return q, qd

    def state(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Positions and velocities ``(x, v)``, each of shape ``(n, len(t))``.

        Vectorised over ``t`` (any real times; the orbit is periodic).  At an
        impact instant the post-impact velocity is returned, so ``state(0.0)``
        is the post-impact state at the obstacle.
        """
        q, qd = self.modal_state(t)
        phi = self._modal.phi
        return phi @ q, phi @ qd

    def contact(self, t) -> np.ndarray:
        """``wᵀx(t)`` at the times ``t`` (cheap: no mode shapes involved)."""
        q, _ = self.modal_state(t)
        return self._modal.b @ q

    def segment(self, i: int) -> TrigSum:
        """``wᵀx(t_{i-1} + τ) - d`` on flight ``i`` (``t₀ = 0``) as a trigonometric sum in ``τ``."""
        return _segment_sum(self._modal, self.T, self.impact_times, self.impulses, i, self.system.gap)

    def to_dict(self) -> dict:
        """Plain-data summary (JSON-ready)."""
        return {
            "T": self.T,
            "frequency": self.frequency,
            "ipp": self.k,
            "impact_times": self.impact_times.tolist(),
            "impulses": self.impulses.tolist(),
            "energy": self.energy,
            "admissible": bool(self.admissible),
            "max_violation": self.max_violation,
            "repeats": self.repeats,
        }


def _segment_sum(md: _Modal, T: float, times: np.ndarray, impulses: np.ndarray, i: int, d: float) -> TrigSum:
    start = 0.0 if i == 0 else times[i - 1]
    theta = np.mod(start - times, T) - T / 2  # phase of each impulse at the segment start
    ph = np.multiply.outer(md.omega, theta)
    c = -md.b**2 / (2 * md.omega * md.sin_half)
    alpha = c * (np.cos(ph) @ impulses)
    beta = -c * (np.sin(ph) @ impulses)
    return TrigSum(alpha=alpha, beta=beta, omega=md.omega, const=-d)


def make_orbit(
    system: LinearSystem,
    T: float,
    impact_times,
    impulses,
    _md: _Modal | None = None,
    polish: bool = True,
    probe: float | None = None,
    certify: bool = True,
) -> PeriodicOrbit:
    """Build a :class:`PeriodicOrbit` from its impact data, computing energy and admissibility.

    ``polish=False`` skips refining the location of a violation once one is
    found (``max_violation`` is then only a sampled lower bound): for
    predicates such as bisection on admissibility.  ``probe`` is a time where
    a violation is suspected (e.g. where a neighbouring orbit violated the
    constraint): it is checked first, so a violated orbit is rejected cheaply.
    ``certify=False`` skips the admissibility check altogether (the orbit is
    then marked non-admissible with a NaN ``max_violation``).
    """
    times = np.asarray(impact_times, dtype=float)
    lam = np.asarray(impulses, dtype=float)
    md = _md if _md is not None else _Modal.of(system, T)
    d = system.gap
    # Energy from the post-impact modal state at t = 0.
    theta = np.mod(-times, T) - T / 2
    ph = np.multiply.outer(md.omega, theta)
    scale = md.b / (2 * md.sin_half)
    q = -(scale / md.omega) * (np.cos(ph) @ lam)
    qd = scale * (np.sin(ph) @ lam)
    energy = 0.5 * float(qd @ qd + (md.omega * q) @ (md.omega * q))
    # Admissibility, flight by flight.
    starts = np.concatenate([[0.0], times[:-1]])
    segments = [_segment_sum(md, T, times, lam, i, d) for i in range(times.size)]
    tols = [max(ADMISSIBILITY_RTOL * d, 1e4 * np.finfo(float).eps * f.magnitude) for f in segments]
    worst, worst_t, certified = 0.0, 0.0, True
    quick = not polish
    if not certify:
        worst, certified, segments = np.nan, False, []
    elif quick and np.any(lam < 0):
        certified, segments = False, []
    elif quick and probe is not None:
        i = min(int(np.searchsorted(times, np.mod(probe, T), side="right")), times.size - 1)
        f = segments[i]
        tau = np.clip(np.mod(probe, T) - starts[i] + f.step * np.linspace(-2, 2, 9), 0, times[i] - starts[i])
        vals = f(tau)[0]
        if vals.max() > tols[i]:
            worst, worst_t = float(vals.max()), float(starts[i] + tau[np.argmax(vals)])
            certified, segments = False, []
    for i, f in enumerate(segments):
        res = certified_max(f, times[i] - starts[i], tols[i], ends_at_zero=True, polish=polish)
        certified &= res.certified
        if res.value > worst:
            worst, worst_t = res.value, starts[i] + res.where
        if quick and not certified:
            break
    admissible = bool(certified and np.all(lam >= 0))
    return PeriodicOrbit(
        system=system, T=T, impact_times=times, impulses=lam, energy=energy,
        admissible=admissible, max_violation=float(worst), max_violation_time=float(worst_t),
        repeats=repetitions(times, lam, T),
    )


#: Relative tolerance (of ``T`` for times, of ``max|Λ|`` for impulses) of the
#: repeated-orbit test.
REPEAT_RTOL = 1e-7

#: Two impacts closer than ``DISTINCT_RTOL·T`` are one: such a "solution" is
#: not a k-ipp orbit and is discarded.
DISTINCT_RTOL = 1e-7


def repetitions(times: np.ndarray, impulses: np.ndarray, T: float) -> int:
    """Largest ``j`` dividing ``k`` such that the impact pattern repeats every ``T/j``."""
    k = times.size
    scale = max(np.abs(impulses).max(), np.finfo(float).tiny)
    for j in range(k, 1, -1):
        if k % j:
            continue
        shift = k // j
        dt = np.mod(np.roll(times, -shift) - times, T)
        if np.all(np.abs(dt - T / j) <= REPEAT_RTOL * T) and np.all(
            np.abs(np.roll(impulses, -shift) - impulses) <= REPEAT_RTOL * scale
        ):
            return j
    return 1


def orbit_1ipp(system: LinearSystem, T: float, **options) -> PeriodicOrbit:
    """The periodic orbit of period ``T`` with one impact per period.

    ``x(t) = -Λ G(t)`` with ``Λ = -d / g(0)``,
    ``g(0) = Σ_j b_j² cot(ω_j T/2) / (2 ω_j)`` (theory §4, k = 1).  The orbit
    always exists for a non-resonant ``T`` with ``g(0) ≠ 0``; whether it is a
    motion of the impacting system is :attr:`PeriodicOrbit.admissible`
    (``Λ >= 0`` and ``wᵀx <= d`` certified on the whole period).

    Raises
    ------
    ValueError
        ``T`` not a positive finite number, resonant (some ``ω_j T ∈ 2πℤ`` with
        ``b_j ≠ 0``), or ``g(0) = 0`` (no impulse brings the orbit to the obstacle).

    ``options`` are passed to :func:`make_orbit` (``polish``, ``probe``, ``certify``).
    """
    T = check_period(system, T)
    md = _Modal.of(system, T)
    g0 = float(np.sum(md.b**2 * np.cos(md.omega * T / 2) / (2 * md.omega * md.sin_half)))
    if g0 == 0.0 or not np.isfinite(g0):
        raise ValueError(f"no 1-ipp orbit at T = {T!r}: the impulse response does not reach the obstacle (g(0) = {g0})")
    lam = -system.gap / g0
    return make_orbit(system, T, [T], [lam], md, **options)


# ---------------------------------------------------------------------------
# k impacts per period
# ---------------------------------------------------------------------------


def _check_times(impact_times) -> np.ndarray:
    times = np.asarray(impact_times, dtype=float).reshape(-1)
    if times.size == 0 or not np.all(np.isfinite(times)):
        raise ValueError("impact_times must be a non-empty sequence of finite times")
    if times[0] <= 0 or np.any(np.diff(times) <= 0):
        raise ValueError(f"impact_times must satisfy 0 < t1 < ... < tk = T, got {times.tolist()}")
    return times


def _matrices(md: _Modal, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    D = np.mod(times[:, None] - times[None, :], md.T)
    g, s = md.g_s(D)
    np.fill_diagonal(s, 0.0)
    return s, -g


def impact_matrices(system: LinearSystem, impact_times) -> tuple[np.ndarray, np.ndarray]:
    """The paper's matrices ``(Π, Σ)`` for impacts at ``0 < t₁ < … < t_k = T``.

    ``Π_ij = s((t_i - t_j) mod T)`` (``Π_ii = 0``; skew-symmetric) and
    ``Σ_ij = -g((t_i - t_j) mod T)`` (symmetric), with ``g = wᵀG`` and
    ``s = wᵀG'`` (theory §3–4).  A ``k``-ipp orbit has impulses ``Λ`` with
    ``ΠΛ = 0`` (elastic impact law at every impact) and ``ΣΛ = d·1`` (at the
    obstacle at every impact).
    """
    times = _check_times(impact_times)
    T = check_period(system, times[-1])
    return _matrices(_Modal.of(system, T), times)


def kipp_residual(md: _Modal, times: np.ndarray, impulses: np.ndarray, d: float) -> np.ndarray:
    """``[ΠΛ ; ΣΛ - d·1]`` (length ``2k``; ``ΛᵀΠΛ ≡ 0`` makes one component redundant)."""
    Pi, Sigma = _matrices(md, times)
    return np.concatenate([Pi @ impulses, Sigma @ impulses - d])


def _impulses(md: _Modal, times: np.ndarray, d: float) -> np.ndarray | None:
    """``Λ`` from ``ΣΛ = d·1`` (least squares), or ``None`` if ``Σ`` is singular."""
    _, Sigma = _matrices(md, times)
    lam, *_ = np.linalg.lstsq(Sigma, np.full(times.size, d), rcond=1e-12)
    return lam if np.all(np.isfinite(lam)) else None


def newton_times(md: _Modal, times: np.ndarray, lam: np.ndarray, d: float, maxiter: int = 12):
    """Gauss–Newton on ``[ΠΛ ; ΣΛ - d] = 0`` in ``(t₁…t_{k-1}, Λ)`` at fixed ``T``,
    with the analytic Jacobian; ``None`` unless it converges to round-off."""
    k, T = times.size, md.T
    times, lam = times.astype(float).copy(), lam.astype(float).copy()
    prev = np.inf
    for _ in range(maxiter):
        D = np.mod(times[:, None] - times[None, :], T)
        g, s = md.g_s(D)
        np.fill_diagonal(s, 0.0)
        r = np.concatenate([s @ lam, -g @ lam - d])
        dsD = md.ds(D)
        np.fill_diagonal(dsD, 0.0)
        # d/dt_l of Σ_j X(D_ij) Λ_j, with dD_ij/dt_l = δ_il - δ_jl:
        #   row i: δ_il Σ_j X'(D_ij)Λ_j - X'(D_il)Λ_l
        A_pi = np.diag(dsD @ lam) - dsD * lam[None, :]
        A_sg = -(np.diag(s @ lam) - s * lam[None, :])
        J = np.block([[A_pi[:, : k - 1], s], [A_sg[:, : k - 1], -g]])
        step, *_ = np.linalg.lstsq(J, -r, rcond=None)
        times[: k - 1] += step[: k - 1]
        lam += step[k - 1:]
        size = np.abs(step[: k - 1]).max(initial=0.0) / T + np.abs(step[k - 1:]).max() / max(np.abs(lam).max(), d)
        if not np.all(np.isfinite(step)) or size > 10 * prev:
            return None
        if size < 1e-14:
            break
        prev = size
    if times[0] <= DISTINCT_RTOL * T or np.any(np.diff(times) <= DISTINCT_RTOL * T):
        return None  # impacts merged: not a k-ipp orbit
    r = kipp_residual(md, times, lam, d)
    scale = float(md.b @ md.b) / 2 * np.abs(lam).max()
    if np.abs(r[:k]).max() > 1e-9 * max(scale, d) or np.abs(r[k:]).max() > 1e-9 * d:
        return None
    return times, lam


def _solve_times(md: _Modal, times0: np.ndarray, d: float) -> tuple[np.ndarray, np.ndarray] | None:
    """Solve for ``(t₁…t_{k-1}, Λ)`` at fixed ``T`` from impact times ``times0``:
    Newton with the analytic Jacobian, else Levenberg–Marquardt (wider basin)."""
    from scipy.optimize import least_squares

    T, k = md.T, times0.size
    lam0 = _impulses(md, times0, d)
    if lam0 is None:
        return None
    sol = newton_times(md, times0, lam0, d)
    if sol is not None:
        return sol
    lscale = max(np.abs(lam0).max(), d)

    def fun(u):
        times = np.append(u[: k - 1], T)
        return kipp_residual(md, times, u[k - 1:] * lscale, d) / d

    res = least_squares(fun, np.concatenate([times0[:-1], lam0 / lscale]), method="lm", xtol=1e-15, ftol=1e-15,
                        gtol=1e-15, max_nfev=200 * k)
    times = np.append(res.x[: k - 1], T)
    lam = res.x[k - 1:] * lscale
    if not np.all(np.isfinite(res.x)) or np.abs(res.fun).max() > 1e-9:
        return None
    if times[0] <= DISTINCT_RTOL * T or np.any(np.diff(times) <= DISTINCT_RTOL * T):
        return None
    return times, lam


def orbits_kipp(system: LinearSystem, T: float, k: int, resolution: int | None = None) -> list[PeriodicOrbit]:
    """Every periodic orbit of period ``T`` with ``k`` impacts per period.

    Solves ``Π(t)Λ = 0``, ``Σ(t)Λ = d·1`` for ``0 < t₁ < … < t_k = T``
    (theory §4).  k = 1: :func:`orbit_1ipp`.  k = 2: the condition is the
    scalar ``s(t₁) = 0`` (the paper's Eq. 15, ``Pf(Π) = Π₁₂``); all its sign
    changes on ``(0, T)`` are found with certified root exclusion
    (:func:`bladecase.nsm.signals.all_roots`), then ``Λ = Σ⁻¹ d·1``.  k >= 3
    (``Pf(Π) = 0`` and a two-dimensional null space for even k, the null
    vector of ``Π`` for odd k): Newton on ``(t₁…t_{k-1}, Λ)`` started from
    every cell of a grid on the ordered times, ``resolution`` points per time
    (default: 4 per period of the highest contact mode, between 16 and 48),
    from the equally spaced and repeated lower-order patterns, and
    Levenberg–Marquardt from the most promising cells; solutions closer than
    ``1e-7 T`` are merged.  For k >= 3 completeness is up to that resolution.
    Solutions that differ only by which impact is placed at ``t = 0`` (a time
    shift) are the same orbit and are returned once
    (:func:`canonical_rotation`).

    Each solution is a :class:`PeriodicOrbit` with certified admissibility;
    orbits with a negative impulse are never admissible.  Solutions that are
    an orbit of period ``T/j`` counted ``j`` times (e.g. k = 2 with
    ``t₁ = T/2``, a 1-ipp orbit of period ``T/2``) have ``repeats = j``.

    Returns
    -------
    list of PeriodicOrbit, sorted by ``t₁``.
    """
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
        raise ValueError(f"k (impacts per period) must be an integer >= 1, got {k!r}")
    if k == 1:
        return [orbit_1ipp(system, T)]
    T = check_period(system, T)
    md = _Modal.of(system, T)
    d = system.gap
    solutions: list[tuple[np.ndarray, np.ndarray]] = []
    if k == 2:
        for t1 in _k2_roots(md):
            times = np.array([t1, T])
            lam = _impulses(md, times, d)
            if lam is not None:
                solutions.append((times, lam))
    else:
        solutions = _multistart(md, k, d, resolution)
    unique: list[tuple[np.ndarray, np.ndarray]] = []
    for times, lam in solutions:
        times, lam = canonical_rotation(times, lam, T)
        if not any(np.abs(times - t).max() <= REPEAT_RTOL * T for t, _ in unique):
            unique.append((times, lam))
    orbits = [make_orbit(system, T, times, lam, md) for times, lam in unique]
    return sorted(orbits, key=lambda o: tuple(o.impact_times))


def canonical_rotation(times: np.ndarray, impulses: np.ndarray, T: float) -> tuple[np.ndarray, np.ndarray]:
    """The same orbit re-anchored at the impact that makes ``(t₁, …, t_k)`` smallest
    lexicographically (times closer than ``REPEAT_RTOL·T`` count as equal, so
    that round-off cannot pick different representatives of one orbit).
    Re-anchoring at impact ``r`` (a time shift by ``t_r``) gives the same
    physical orbit; this picks one representative."""
    tol = REPEAT_RTOL * T
    best = None
    for r in range(times.size):
        shifted = np.mod(times - times[r], T)
        shifted[(shifted <= tol) | (shifted >= T - tol)] = T
        order = np.argsort(shifted)
        cand = (shifted[order], impulses[order])
        if best is None:
            best = cand
            continue
        diff = cand[0] - best[0]
        first = np.flatnonzero(np.abs(diff) > tol)
        if first.size and diff[first[0]] < 0:
            best = cand
    best[0][-1] = T
    return best


def _multistart(md: _Modal, k: int, d: float, resolution: int | None) -> list[tuple[np.ndarray, np.ndarray]]:
    """Solutions for k >= 3: Levenberg–Marquardt from the equally spaced
    pattern, from every repeated lower-order solution (period ``T/j``,
    ``j | k``) and from the grid cells of ordered impact times whose screening
    residual is a local minimum (non-strict) or among the lowest 5 %; Newton
    from every grid cell."""
    from itertools import combinations

    T = md.T
    if resolution is None:
        resolution = int(np.clip(np.ceil(4 * T * md.omega.max() / (2 * np.pi)), 16, 48))
    grid = T * (np.arange(1, resolution) / resolution)
    idx = np.array(list(combinations(range(grid.size), k - 1)))
    starts = np.column_stack([grid[idx], np.full(len(idx), T)])
    # Screening residual: ||Π n|| / ||n|| with n = Σ⁻¹1 (scale-free).
    S = float(md.b @ md.b) / 2
    score = np.full(len(starts), np.inf)
    for i, times in enumerate(starts):
        Pi, Sigma = _matrices(md, times)
        try:
            n = np.linalg.solve(Sigma, np.ones(k))
        except np.linalg.LinAlgError:
            continue
        score[i] = np.linalg.norm(Pi @ n) / (np.linalg.norm(n) * S)
    pos = {tuple(row): i for i, row in enumerate(idx)}
    finite = np.isfinite(score)
    low = set(np.flatnonzero(finite & (score <= np.quantile(score[finite], 0.05)))) if finite.any() else set()
    candidates = []
    for i, row in enumerate(idx):
        if not finite[i]:
            continue
        best = i in low
        if not best:
            best = True
            for delta in np.ndindex(*(3,) * (k - 1)):
                j = pos.get(tuple(row + np.array(delta) - 1))
                if j is not None and j != i and score[j] < score[i]:
                    best = False
                    break
        if best:
            candidates.append(starts[i])
    # Patterns that always solve or nearly solve: equally spaced impacts, and
    # repetitions of the solutions with k/j impacts at period T/j.
    seeds = [T * np.arange(1, k + 1) / k]
    for j in range(2, k):
        if k % j == 0:
            sub = _Modal(omega=md.omega, b=md.b, phi=md.phi, sin_half=np.sin(md.omega * T / (2 * j)), T=T / j)
            base = [np.array([T / j])] if k // j == 1 else (
                [t for t, _ in _multistart(sub, k // j, d, resolution)] if k // j >= 3 else
                [np.array([t1, T / j]) for t1 in _k2_roots(sub)])
            for t in base:
                seeds.append(np.concatenate([t + m * T / j for m in range(j)]))
    found: list[tuple[np.ndarray, np.ndarray]] = []

    def keep(sol):
        if sol is not None and not any(np.abs(sol[0] - t).max() <= REPEAT_RTOL * T for t, _ in found):
            found.append(sol)

    # Newton (analytic Jacobian, cheap) from every cell: the screening score is
    # a poor guide to Newton's basins; Levenberg–Marquardt (wider basin,
    # costlier) from the seeds and the promising cells.
    for times0 in seeds + candidates:
        keep(_solve_times(md, np.asarray(times0, dtype=float), d))
    for times0 in starts:
        lam0 = _impulses(md, times0, d)
        if lam0 is not None:
            keep(newton_times(md, times0, lam0, d))
    return found


def _k2_roots(md: _Modal) -> np.ndarray:
    """Every ``t₁`` in ``(0, T)`` with ``s(t₁) = 0`` (the k = 2 condition)."""
    from .signals import all_roots

    T = md.T
    c = md.b**2 / 2
    s_sum = TrigSum(alpha=c, beta=-c * np.cos(md.omega * T / 2) / md.sin_half, omega=md.omega)
    return np.array([t for t in all_roots(s_sum, 0.0, T) if 0 < t < T])
