"""Exact damped, harmonically forced modal flight and its contact signal with a certified curvature bound.

Between two impacts every mode ``j`` of ``M x'' + C x' + K x = F₀ cos(Ωt) f`` with a modal damping
(``ΦᵀCΦ = diag(2σ_j)``, ``σ_j = ζ_j ω_j``; Rayleigh ``C = αK + βM`` gives ``σ_j = (αω_j² + β)/2``) obeys

    q_j'' + 2σ_j q_j' + ω_j² q_j = F_j cos(Ωt),        F_j = F₀ φ_jᵀ f,

solved here in closed form (:class:`DampedModes`), in every regime and without cancellation:

* **homogeneous part** ``e^{-στ}(h₀(C + σS) + h₁S)`` with ``C = cos ω_dτ``, ``S = τ·sinc(ω_dτ)``,
  ``ω_d = √((ω-σ)(ω+σ))`` (underdamped, and critical damping ``ω_d = 0``: ``C = 1``, ``S = τ``), or for
  overdamped modes (``σ > ω``, ``γ = √((σ-ω)(σ+ω))``) the two real exponentials
  ``e^{-στ}C = (e^{-(σ-γ)τ} + e^{-(σ+γ)τ})/2``, ``e^{-στ}S = e^{-(σ-γ)τ}(1 - e^{-2γτ})/(2γ)``
  (with ``σ - γ = ω²/(σ+γ)``: no overflow, no cancellation near critical damping);
* **damped modes** (``σ > 0``): steady-state particular ``Re(A e^{iΩt})``, ``A = F/(ω² - Ω² + 2iσΩ)``,
  plus the homogeneous flight of the initial deviation from it;
* **undamped modes** (``σ = 0``): the Duhamel response from rest written with ``a = (ω+Ω)/2``,
  ``b = (ω-Ω)/2`` and ``sinc``, e.g. ``(cos Ωτ - cos ωτ)/(ω² - Ω²) = τ sin(aτ) sinc(bτ)/(2a)``, which is
  exact and free of the ``1/(ω - Ω)`` cancellation for near-resonant forcing and gives the secular
  ``τ sin(ωτ)/(2ω)`` at exact resonance ``Ω = ω``.

The contact signal of a flight, ``f(τ) = wᵀx(τ) - d = Σ b_j q_j(τ) - d`` (:class:`DampedSignal`), is a
sum of exponentially damped sinusoids plus a harmonic.  It offers what
:func:`bladecase.nsm.signals.first_upcrossing` needs (values and slopes, grid, ``curvature_bound``,
``step``, ``magnitude``), so the event loop finds the FIRST contact with the same certified bisection as
for undamped sums.  The **certified curvature bound** holds on the whole flight ``[0, H]``
(``H`` = the horizon: the end of the simulation) and rests on two energy estimates per mode, with
``E = ½(q'² + ω²q²)`` and ``|q''| = |ω·ωq + 2σ·q' - F cos| ≤ √(ω² + 4σ²)·√(2E) + |F|``:

* *growth bound*: ``d√(2E)/dt = q'(F cos Ωt - 2σq')/√(2E) ≤ |F|``, so on ``[0, H]``
  ``√(2E) ≤ R₀ + |F|H`` (``R₀ = √(p₀² + ω²q₀²)``) and ``|q''| ≤ √(ω²+4σ²)(R₀ + |F|H) + |F|``;
* *split bound* (unless ``σ = 0`` and ``Ω = ω``): the homogeneous part's energy never grows
  (``dE_h/dt = -2σq_h'² ≤ 0``) and the particular part has ``|q_p''| = |A|Ω²``, so for all ``τ >= 0``
  ``|q''| ≤ √(ω²+4σ²)·R_h + |A|Ω²`` with ``R_h`` the homogeneous amplitude at the start.

Each mode takes the smaller of the two; ``B₂ = Σ_j |b_j| min(...) >= max |f''|`` on the flight.  With
no damping and no forcing this is exactly :class:`~bladecase.nsm.signals.TrigSum`'s bound
``Σ |b_j| ω_j √(ω_j²q_j² + p_j²)``.  A gap between samples is then proved free of contact by
:func:`~bladecase.nsm.signals.interval_bound` (the smallest of linear interpolation + ``B₂h²/8`` and the
two Taylor bounds), else bisected; a sign change on a provably increasing piece is refined by Brent's
method to machine precision.

>>> import numpy as np
>>> modes = DampedModes(omega=np.array([1.0]), sigma=np.array([0.0]), force=np.array([1.0]), Omega=1.0)
>>> q, p = modes.flight(np.zeros(1), np.zeros(1), 0.0, 2.0)      # exact resonance from rest: τ sin(ωτ)/(2ω)
>>> bool(np.isclose(q[0], np.sin(2.0))), bool(np.isclose(p[0], np.sin(2.0) / 2 + np.cos(2.0)))
(True, True)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .signals import POINTS_PER_PERIOD

__all__ = ["DampedModes", "DampedSignal"]


def _sinc(x):
    """``sin(x)/x`` (1 at 0)."""
    return np.sinc(np.asarray(x) / np.pi)


@dataclass(frozen=True, eq=False)
class DampedModes:
    """Modes ``q'' + 2σq' + ω²q = F cos(Ωt)``, one entry per mode; exact flight from any state.

    Attributes
    ----------
    omega : (m,) ndarray
        Undamped angular frequencies ``ω_j > 0``.
    sigma : (m,) ndarray
        Decay rates ``σ_j = ζ_j ω_j >= 0``.
    force : (m,) ndarray
        Modal force amplitudes ``F_j`` (``F₀ φ_jᵀ f``).
    Omega : float
        Forcing angular frequency ``Ω >= 0``.
    """

    omega: np.ndarray
    sigma: np.ndarray
    force: np.ndarray
    Omega: float

    def __post_init__(self) -> None:
        for name in ("omega", "sigma", "force"):
            object.__setattr__(self, name, np.asarray(getattr(self, name), dtype=float).reshape(-1))
        m = self.omega.size
        if self.sigma.shape != (m,) or self.force.shape != (m,):
            raise ValueError(f"omega, sigma and force must have the same length, got {self.omega.size}, "
                             f"{self.sigma.size}, {self.force.size}")
        if not (np.all(self.omega > 0) and np.all(np.isfinite(self.omega))):
            raise ValueError("every modal frequency omega must be finite and > 0")
        if not (np.all(self.sigma >= 0) and np.all(np.isfinite(self.sigma))):
            raise ValueError("every decay rate sigma must be finite and >= 0")
        if not np.all(np.isfinite(self.force)):
            raise ValueError("modal forces must be finite")
        if not (np.isfinite(self.Omega) and self.Omega >= 0):
            raise ValueError(f"Omega must be finite and >= 0, got {self.Omega!r}")

    # --- per-mode constants ----------------------------------------------------------

    @cached_property
    def overdamped(self) -> np.ndarray:
        """Modes with ``σ > ω`` (two real exponentials)."""
        return self.sigma > self.omega

    @cached_property
    def _rates(self) -> tuple[np.ndarray, np.ndarray]:
        """``ω_d`` (oscillatory modes, 0 for the others) and ``γ`` (overdamped modes, 0 for the others)."""
        w, s = self.omega, self.sigma
        prod = (w - s) * (w + s)
        return np.sqrt(np.maximum(prod, 0.0)), np.sqrt(np.maximum(-prod, 0.0))

    @cached_property
    def beat(self) -> np.ndarray:
        """Forced undamped modes, flown with the Duhamel (beat) formula."""
        return (self.sigma == 0) & (self.force != 0)

    @cached_property
    def split(self) -> np.ndarray:
        """Forced damped modes, flown as steady state + homogeneous deviation."""
        return (self.sigma > 0) & (self.force != 0)

    @cached_property
    def amplitude(self) -> np.ndarray:
        """Complex steady-state amplitude ``A_j = F_j / (ω² - Ω² + 2iσΩ)`` (``inf`` when undamped and
        exactly resonant: then there is no bounded steady state)."""
        den = self.omega**2 - self.Omega**2 + 2j * self.sigma * self.Omega
        with np.errstate(divide="ignore", invalid="ignore"):
            A = np.where(self.force == 0, 0j, self.force / np.where(den == 0, 1.0, den))
        return np.where((den == 0) & (self.force != 0), np.inf + 0j, A)

    @property
    def rate_max(self) -> float:
        """Highest angular rate of the flight: ``max(ω_max, Ω)`` (sets the base sampling step)."""
        return float(max(self.omega.max(), self.Omega))

    # --- the flight -------------------------------------------------------------------

    def particular(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Steady state ``(Re(A e^{iΩt}), Re(iΩA e^{iΩt}))`` of the damped modes (zero elsewhere), shape
        ``(m,) + shape(t)``."""
        t = np.asarray(t, dtype=float)
        A = np.where(self.split, self.amplitude, 0j).reshape((-1,) + (1,) * t.ndim)
        c, s = np.cos(self.Omega * t), np.sin(self.Omega * t)
        return A.real * c - A.imag * s, -self.Omega * (A.real * s + A.imag * c)

    @cached_property
    def _fast(self) -> tuple[bool, np.ndarray, np.ndarray, bool]:
        """``(simple, 1/ω_d, -σ, damped)``: ``simple`` when every mode is strictly underdamped or undamped
        (``ω_d > 0``), the common case evaluated with the fewest operations."""
        wd = self._rates[0]
        simple = bool(np.all(wd > 0))
        with np.errstate(divide="ignore"):
            inv = np.where(wd > 0, 1.0 / np.where(wd > 0, wd, 1.0), 0.0)
        return simple, inv, -self.sigma[:, None], bool(self.sigma.any())

    def _decay(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(e^{-στ}C(τ), e^{-στ}S(τ))`` per mode, shape ``(m, N)`` for ``tau`` of shape ``(N,)``."""
        simple, inv, neg_s, damped = self._fast
        wd, g = self._rates
        t = tau[None, :]
        if simple:
            ph = wd[:, None] * t
            EC, ES = np.cos(ph), np.sin(ph) * inv[:, None]
            if damped:
                e = np.exp(neg_s * t)
                EC *= e
                ES *= e
            return EC, ES
        w, s = self.omega[:, None], self.sigma[:, None]
        wd, g = wd[:, None], g[:, None]
        over = self.overdamped
        EC = np.empty((w.shape[0], tau.size))
        ES = np.empty_like(EC)
        osc = ~over
        if osc.any():
            e = np.exp(-s[osc] * t)
            EC[osc] = e * np.cos(wd[osc] * t)
            ES[osc] = e * t * _sinc(wd[osc] * t)
        if over.any():
            slow = w[over] ** 2 / (s[over] + g[over])
            e1 = np.exp(-slow * t)
            EC[over] = 0.5 * (e1 + np.exp(-(s[over] + g[over]) * t))
            ES[over] = e1 * (-np.expm1(-2 * g[over] * t)) / (2 * g[over])
        return EC, ES

    def _beat(self, t0: np.ndarray, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Duhamel response from rest of the forced undamped modes, rows of ``self.beat``."""
        idx = self.beat
        w, F, W = self.omega[idx, None], self.force[idx, None], self.Omega
        a, b = (w + W) / 2, (w - W) / 2
        t = tau[None, :]
        sa, ca, sn = np.sin(a * t), np.cos(a * t), _sinc(b * t)
        U = t * sa * sn / (2 * a)
        V = -t * ca * sn / (2 * a) + np.sin(w * t) / (2 * a * w)
        dU = w * t * ca * sn / (2 * a) + np.sin(W * t) / (2 * a)
        c0, s0 = np.cos(W * t0)[None, :], np.sin(W * t0)[None, :]
        return F * (c0 * U - s0 * V), F * (c0 * dU - s0 * W * U)

    def flight(self, q0, p0, t0, tau) -> tuple[np.ndarray, np.ndarray]:
        """State ``(q, p)`` after a flight of duration ``tau`` started from ``(q0, p0)`` at time ``t0``.

        ``q0``, ``p0`` of shape ``(m,)`` or ``(m, N)`` (one flight per column); ``tau`` and ``t0`` scalars
        or shape ``(N,)``.  The result has shape ``(m,)`` for one state and a scalar ``tau``, else
        ``(m, N)``.
        """
        q0, p0 = np.asarray(q0, dtype=float), np.asarray(p0, dtype=float)
        one = q0.ndim == 1 and np.ndim(tau) == 0
        tau = np.atleast_1d(np.asarray(tau, dtype=float))
        N = max(tau.size, q0.shape[1] if q0.ndim == 2 else 1, np.size(t0))
        tau = np.broadcast_to(tau, (N,))
        t0 = np.broadcast_to(np.asarray(t0, dtype=float), (N,))
        q0 = np.broadcast_to(q0 if q0.ndim == 2 else q0[:, None], (self.omega.size, N))
        p0 = np.broadcast_to(p0 if p0.ndim == 2 else p0[:, None], (self.omega.size, N))
        h0, h1 = q0, p0
        if self.split.any():
            qp0, pp0 = self.particular(t0)
            h0, h1 = q0 - qp0, p0 - pp0
        EC, ES = self._decay(tau)
        s, w2 = self.sigma[:, None], self.omega[:, None] ** 2
        q = EC * h0 + ES * (h1 + s * h0)
        p = EC * h1 - ES * (w2 * h0 + s * h1)
        if self.split.any():
            qp, pp = self.particular(t0 + tau)
            q, p = q + qp, p + pp
        if self.beat.any():
            dq, dp = self._beat(t0, tau)
            q[self.beat] += dq
            p[self.beat] += dp
        return (q[:, 0], p[:, 0]) if one else (q, p)

    def energy_growth(self, q0, p0, t0, horizon: float) -> tuple[np.ndarray, np.ndarray]:
        """Per-mode certified ``(bound of |q''|, bound of |q|)`` on a flight of length ``horizon`` from
        ``(q0, p0)`` at ``t0`` (see the module docstring: the smaller of the growth and split bounds)."""
        w, s, F = self.omega, self.sigma, np.abs(self.force)
        k = np.sqrt(w**2 + 4 * s**2)
        R0 = np.hypot(np.asarray(p0, float), w * np.asarray(q0, float))
        with np.errstate(invalid="ignore", over="ignore"):
            Rg = R0 + (F * horizon if np.isfinite(horizon) else np.where(F == 0, 0.0, np.inf))
            curv_g, mag_g = k * Rg + F, Rg / w
            A = np.abs(self.amplitude)
            qp, pp = self.particular(t0) if self.split.any() else (0.0, 0.0)
            qp0 = np.where(self.split, qp, np.where(self.beat, self.amplitude.real * np.cos(self.Omega * t0), 0.0))
            pp0 = np.where(self.split, pp, np.where(self.beat, -self.Omega * self.amplitude.real
                                                    * np.sin(self.Omega * t0), 0.0))
            Rh = np.hypot(np.asarray(p0, float) - pp0, w * (np.asarray(q0, float) - qp0))
            curv_s, mag_s = k * Rh + A * self.Omega**2, Rh / w + A
        curv_s = np.where(np.isfinite(A), curv_s, np.inf)
        mag_s = np.where(np.isfinite(A), mag_s, np.inf)
        return np.minimum(curv_g, curv_s), np.minimum(mag_g, mag_s)


@dataclass(frozen=True, eq=False)
class DampedSignal:
    """Contact signal ``f(τ) = const + Σ b_j q_j(τ)`` of the flight from ``(q0, p0)`` at time ``t0``,
    valid (with its certified bound) on ``[0, horizon]``.

    Drop-in for :class:`~bladecase.nsm.signals.TrigSum` in
    :func:`~bladecase.nsm.signals.first_upcrossing`: ``f(τ) -> (values, slopes)``, :meth:`grid`,
    :attr:`curvature_bound`, :attr:`magnitude`, :attr:`step`, :attr:`omega`, :attr:`const`.

    >>> import numpy as np
    >>> from bladecase.nsm.signals import first_upcrossing
    >>> modes = DampedModes(np.array([1.0]), np.array([0.1]), np.array([0.5]), Omega=1.0)
    >>> f = DampedSignal(modes, b=np.array([1.0]), q0=np.zeros(1), p0=np.zeros(1), t0=0.0, const=-1.0,
    ...                  horizon=100.0)
    >>> tau = first_upcrossing(f, 0.0, 100.0)        # the resonant build-up reaches the obstacle
    >>> round(tau, 6), abs(float(f(tau)[0])) < 1e-14
    (7.152437, True)
    """

    modes: DampedModes
    b: np.ndarray
    q0: np.ndarray
    p0: np.ndarray
    t0: float
    const: float
    horizon: float = np.inf

    @cached_property
    def _coef(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, complex, float, float]:
        """Coefficients of ``f(τ) = f(0) + α·(EC - 1) + β·ES + Re(P(e^{iΩτ} - 1)) (+ beat terms)`` and of
        ``f'`` likewise, and ``(f(0), f'(0))`` computed exactly as ``bᵀq₀ + const``, ``bᵀp₀`` (so that the
        signal at 0 agrees to the last bit with the event loop's gap and normal velocity)."""
        m, b = self.modes, self.b
        h0, h1, P = self.q0, self.p0, 0j
        if m.split.any():
            qp, pp = m.particular(self.t0)
            h0, h1 = h0 - qp, h1 - pp
            P = complex(np.exp(1j * m.Omega * self.t0) * (b[m.split] @ m.amplitude[m.split]))
        s, w2 = m.sigma, m.omega**2
        f0, d0 = float(b @ self.q0) + self.const, float(b @ self.p0)
        return b * h0, b * (h1 + s * h0), b * h1, -b * (w2 * h0 + s * h1), P, f0, d0

    def _scalar(self, t: float) -> tuple[float, float]:
        """``(f(t), f'(t))`` at one point, for strictly underdamped or undamped modes without beat terms
        (the many single evaluations of bisection and Brent's method, with the fewest operations)."""
        m = self.modes
        a_f, b_f, a_d, b_d, P, f0, d0 = self._coef
        _, inv, neg_s, damped = m._fast
        ph = m._rates[0] * t
        c, s = np.cos(ph), np.sin(ph) * inv
        if damped:
            e = np.exp(neg_s[:, 0] * t)
            c *= e
            s *= e
        c -= 1.0
        f, df = f0 + float(a_f @ c) + float(b_f @ s), d0 + float(a_d @ c) + float(b_d @ s)
        if P:
            th = m.Omega * t
            sh = math.sin(0.5 * th)
            e = P * complex(-2.0 * sh * sh, math.sin(th))
            f, df = f + e.real, df - m.Omega * e.imag
        return f, df

    def __call__(self, tau) -> tuple[np.ndarray, np.ndarray]:
        """Values and first derivatives at the points ``tau`` (any shape)."""
        m = self.modes
        if np.ndim(tau) == 0 and m._fast[0] and not m.beat.any():
            f, df = self._scalar(float(tau))
            return np.array(f), np.array(df)
        tau = np.asarray(tau, dtype=float)
        t = tau.reshape(-1)
        a_f, b_f, a_d, b_d, P, f0, d0 = self._coef
        EC, ES = m._decay(t)
        EC -= 1.0
        f = a_f @ EC + b_f @ ES + f0
        df = a_d @ EC + b_d @ ES + d0
        if P:
            th = m.Omega * t
            e = P * (-2 * np.sin(th / 2) ** 2 + 1j * np.sin(th))      # P (e^{iΩτ} - 1)
            f += e.real
            df -= m.Omega * e.imag
        if m.beat.any():
            dq, dp = m._beat(np.full(t.size, self.t0), t)
            bb = self.b[m.beat]
            f += bb @ dq
            df += bb @ dp
        return f.reshape(tau.shape), df.reshape(tau.shape)

    def grid(self, start: float, h: float, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(τ, f, f')`` at ``τ = start + h·arange(count)``."""
        tau = start + h * np.arange(count)
        f, df = self(tau)
        return tau, f, df

    @cached_property
    def _bounds(self) -> tuple[float, float]:
        curv, mag = self.modes.energy_growth(self.q0, self.p0, self.t0, self.horizon)
        ab = np.abs(self.b)
        used = ab > 0
        B2, scale = float(ab[used] @ curv[used]), float(ab[used] @ mag[used])
        if not np.isfinite(B2):
            raise ValueError("an undamped mode forced exactly at resonance needs a finite horizon "
                             f"(got horizon={self.horizon!r}) for a certified bound")
        return B2, scale

    @property
    def curvature_bound(self) -> float:
        """``B₂ >= max |f''|`` on ``[0, horizon]`` (module docstring)."""
        return self._bounds[0]

    @property
    def magnitude(self) -> float:
        """A bound of ``Σ |b_j q_j|`` on the flight: the scale of the floating-point error of ``f``."""
        return self._bounds[1]

    @property
    def omega(self) -> np.ndarray:
        """Angular rates of the flight: the ``ω_j`` and ``Ω``."""
        return np.append(self.modes.omega, self.modes.Omega)

    @property
    def step(self) -> float:
        """Base grid step ``2π / (POINTS_PER_PERIOD · max(ω_max, Ω))`` (refined where needed)."""
        return 2 * np.pi / (POINTS_PER_PERIOD * self.modes.rate_max)
