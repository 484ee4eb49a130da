"""Periodic orbits of the massless contact model with one contact phase per period, and their branches.

A symmetric orbit (time-reversible system) has ``v = 0`` at the middle of its open phase and at the middle of its
closed phase. From the mid-open state ``(Φ_o a, 0)``: open flight for ``α``, closing (``y = d``), closed flight for
``β``, ``v = 0`` — so ``T = 2(α + β)`` and the contact lasts ``2β``. In closed-phase modal coordinates the closing
state is ``p = P diag(cos ω_o α) a - q_eq``, ``p' = -P diag(ω_o sin ω_o α) a`` (``P = Φ_cᵀMΦ_o``), and
``v = 0`` after ``β`` is the linear system ``L(α, β) a = -ω_c sin(ω_c β) q_eq`` with

    L = -diag(ω_c sin ω_c β) P diag(cos ω_o α) - diag(cos ω_c β) P diag(ω_o sin ω_o α).

The closing condition leaves ONE scalar equation ``r(α, β) = b_oᵀ diag(cos ω_o α) a - d = 0``: a curve in the
``(α, β)`` plane — the nonsmooth mode — followed by pseudo-arclength continuation with the exact gradient of ``r``
(derivatives of ``L`` in closed form), so folds in ``T`` are passed on the same branch. Admissibility
(``y <= d`` over the open phase, ``λ >= 0`` over the closed one) is proved with certified bounds.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import scipy.linalg as sla

from ..signals import TrigSum, certified_max
from ..system import LinearSystem
from .model import BoundOrbit, MasslessSystem

#: Relative tolerance (of the clearance) of the admissibility proofs.
ADMISSIBILITY_RTOL = 1e-9


def check_massless_system(system, what: str) -> MasslessSystem:
    """``system`` if it is a :class:`MasslessSystem`, else ``ValueError`` naming ``what``."""
    if isinstance(system, MasslessSystem):
        return system
    hint = (": a LinearSystem has Newton's contact; its modes come from nonsmooth_mode(system, k, T_range)"
            if isinstance(system, LinearSystem) else "")
    raise ValueError(f"{what} solves the massless contact model: system must be a MasslessSystem (bar(..., "
                     f"contact='massless'), condense(...) or a massless reduced model's .system), got "
                     f"{type(system).__name__}{hint}")


def _number(name: str, value, low: float = 0.0, strict: bool = True) -> float:
    """``float(value)`` if it is a finite number ``> low`` (``>= low`` unless ``strict``), else ``ValueError``."""
    try:
        if isinstance(value, (bool, np.bool_, str, bytes)):
            raise TypeError
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a finite number {'>' if strict else '>='} {low:g}, got {value!r}") from None
    if not np.isfinite(x) or (x <= low if strict else x < low):
        raise ValueError(f"{name} must be a finite number {'>' if strict else '>='} {low:g}, got {value!r}")
    return x


def _mode(system: MasslessSystem, mode) -> int:
    if isinstance(mode, (bool, np.bool_)) or not isinstance(mode, (int, np.integer)) or not 0 <= mode < system.n:
        raise ValueError(f"mode must be an open-phase mode index, an integer in [0, {system.n}), got {mode!r}")
    return int(mode)


@dataclass(frozen=True, eq=False)
class SymmetricOrbit(BoundOrbit):
    """A symmetric periodic orbit with one contact phase: open ``2α``, closed ``2β``, mid-open state ``(Φ_o a, 0)``.

    Time origin: the contact closes at ``t = 0`` (``≡ T``) and opens at ``t = 2β``. The record reads like a
    :class:`~bladecase.nsm.PeriodicOrbit` for branches, plots and reports: ``impact_times = [T]`` (the closing
    instant), ``impulses = [∫λ dt]`` (the momentum the casing transfers during the contact phase),
    ``max_violation`` (the largest ``y - d`` over the open phase, ``<= 0`` when admissible). Pickles without its
    system (:meth:`bind` re-attaches one).
    """

    system: MasslessSystem | None = field(repr=False)
    alpha: float
    beta: float
    a: np.ndarray = field(repr=False)

    k = 1
    repeats = 1
    stable = None
    multipliers = None
    contact_model = "massless"


    @property
    def impact_times(self) -> np.ndarray:
        """``[T]``: the contact closes at ``t = 0 ≡ T`` (the convention of the Newton orbits' last impact)."""
        return np.array([self.T])

    @cached_property
    def impulses(self) -> np.ndarray:
        """``[∫λ dt]`` over the closed phase (exact: ``λ = k_c (y - d)`` is a trigonometric sum)."""
        from .phases import PhasedOrbit

        return PhasedOrbit(self._bound(), "open", [self.alpha, self.beta], self.a).impulses

    @property
    def max_violation(self) -> float:
        """Largest ``y - d`` found over the open phase (``<= 0`` up to the tolerance when admissible)."""
        return float(self.proofs[0].value)

    def to_dict(self) -> dict:
        """Plain-data record (JSON-ready); :meth:`from_dict` reads it back."""
        return {"T": self.T, "frequency": self.frequency, "ipp": 1, "contact_model": "massless",
                "alpha": self.alpha, "beta": self.beta, "a": self.a.tolist(), "contact_time": self.contact_time,
                "impact_times": self.impact_times.tolist(), "impulses": self.impulses.tolist(),
                "energy": self.energy, "admissible": self.admissible, "max_violation": self.max_violation,
                "repeats": 1, "stable": None, "multipliers": None}

    @classmethod
    def from_dict(cls, system: MasslessSystem | None, data: dict) -> SymmetricOrbit:
        """The orbit back from :meth:`to_dict` (its state is exact: it is re-flown from ``α, β, a``)."""
        return cls(system, float(data["alpha"]), float(data["beta"]), np.asarray(data["a"], dtype=float))

    @property
    def T(self) -> float:
        """Period."""
        return 2.0 * (self.alpha + self.beta)

    @property
    def frequency(self) -> float:
        return 1.0 / self.T

    @property
    def contact_time(self) -> float:
        """Duration of the closed phase."""
        return 2.0 * self.beta

    def monodromy(self) -> np.ndarray:
        """``(2n, 2n)`` monodromy of ``(x, v)`` over one period (see :meth:`PhasedOrbit.monodromy`)."""
        from .phases import PhasedOrbit

        return PhasedOrbit(self._bound(), "open", [self.alpha, self.beta], self.a).monodromy()

    @property
    def contact_intervals(self) -> list[tuple[float, float]]:
        """``[(0, 2β)]``: the one contact phase (closing at ``t = 0``)."""
        return [(0.0, 2.0 * self.beta)]

    @property
    def mid_open_time(self) -> float:
        """The middle of the open phase (``v = 0``)."""
        return 2.0 * self.beta + self.alpha

    def in_contact(self, t) -> np.ndarray:
        """Whether the contact is closed at times ``t``."""
        return np.mod(np.atleast_1d(np.asarray(t, float)), self.T) <= 2.0 * self.beta

    @property
    def x_mid_open(self) -> np.ndarray:
        return self.system.open.phi @ self.a

    @cached_property
    def energy(self) -> float:
        return self._bound().energy(self.x_mid_open, np.zeros(self.system.n))

    def band_energy(self, modes: int) -> float:
        """Energy held by the lowest ``modes`` open-phase modes (at mid-open, where ``v = 0`` and ``λ = 0``).

        ``E = ½ Σ ω_j² a_j²`` over all modes is the total energy; the band-limited part is the measure that
        converges under mesh refinement when the total does not (mesh-scale modes carry the rest).
        """
        if isinstance(modes, bool) or int(modes) < 1:
            raise ValueError(f"modes must be an integer >= 1, got {modes!r}")
        om, a = self.system.open.omega[: int(modes)], self.a[: int(modes)]
        return float(0.5 * np.sum(om**2 * a**2))

    def closing_state(self) -> tuple[np.ndarray, np.ndarray]:
        """State when the contact closes (``t = α`` from mid-open)."""
        return self.system.open.advance(self.x_mid_open, np.zeros(self.system.n), self.alpha)

    def state(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Interior ``(x, v)`` at times ``t`` (``t = 0``: closing), each ``(n, len(t))``."""
        s = self.system
        t = np.mod(np.atleast_1d(np.asarray(t, float)), self.T)
        x1, v1 = self.closing_state()
        x2, v2 = s.closed.advance(x1, v1, 2 * self.beta)
        X, V = np.empty((s.n, t.size)), np.empty((s.n, t.size))
        for j, tj in enumerate(t):
            X[:, j], V[:, j] = s.closed.advance(x1, v1, tj) if tj < 2 * self.beta else \
                s.open.advance(x2, v2, tj - 2 * self.beta)
        return X, V

    @cached_property
    def proofs(self):
        """Certified ``max(y - d)`` over the open phase and ``max(d - y)`` over the closed phase."""
        s = self._bound()
        d = s.gap
        tol = ADMISSIBILITY_RTOL * d
        y = s.open.contact(self.x_mid_open, np.zeros(s.n))
        open_ = certified_max(TrigSum(y.alpha, y.beta, y.omega, y.const - d), self.alpha, tol)
        x1, v1 = self.closing_state()
        xm, vm = s.closed.advance(x1, v1, self.beta)
        y = s.closed.contact(xm, vm)
        closed = certified_max(TrigSum(-y.alpha, -y.beta, y.omega, d - y.const), self.beta, tol)
        return open_, closed

    @property
    def admissible(self) -> bool:
        """``y <= d`` throughout the open phase and ``λ >= 0`` throughout the closed phase (proved)."""
        o, c = self.proofs
        return bool(o.certified and c.certified)


def closing_residual(system: MasslessSystem, alpha: float, beta: float, gradient: bool = False):
    """``(a, r)`` or ``(a, r, ∇r)``: mid-open amplitudes and the closing residual ``r(α, β)`` (exact gradient)."""
    o, c, P = system.open, system.closed, system.transfer
    co, so = np.cos(o.omega * alpha), np.sin(o.omega * alpha)
    cc, sc = np.cos(c.omega * beta), np.sin(c.omega * beta)
    q_eq = c.phi.T @ (system.M @ c.x_eq)
    L = -(sc * c.omega)[:, None] * (P * co) - cc[:, None] * (P * (o.omega * so))
    lu = sla.lu_factor(L, check_finite=False)
    a = sla.lu_solve(lu, -(c.omega * sc) * q_eq)
    r = float(o.b @ (co * a)) - system.gap
    if not gradient:
        return a, r
    L_a = (sc * c.omega)[:, None] * (P * (o.omega * so)) - cc[:, None] * (P * (o.omega**2 * co))
    L_b = -(cc * c.omega**2)[:, None] * (P * co) + (c.omega * sc)[:, None] * (P * (o.omega * so))
    a_a = sla.lu_solve(lu, -L_a @ a)
    a_b = sla.lu_solve(lu, -(c.omega**2 * cc) * q_eq - L_b @ a)
    return a, r, np.array([float(o.b @ (-o.omega * so * a + co * a_a)), float(o.b @ (co * a_b))])


def orbit_at_period(system: MasslessSystem, T: float, beta0: float, maxiter: int = 60) -> SymmetricOrbit | None:
    """The symmetric one-phase orbit of period ``T`` reached by Newton from contact half-time ``beta0``."""
    check_massless_system(system, "orbit_at_period")
    T = _number("T", T)
    b, prev = _number("beta0", beta0), np.inf
    for _ in range(maxiter):
        _, r, g = closing_residual(system, T / 2 - b, b, True)
        step = r / (g[1] - g[0])
        b -= step
        if not 0 < b < T / 2:
            return None
        # converged, or stagnating at round-off (next to grazing the steps cycle at ~1e-16 s)
        stalled = abs(step) <= 1e-10 * T and abs(step) >= 0.5 * abs(prev) and abs(r) <= 1e-9 * system.gap
        if abs(step) <= 1e-14 * T or stalled:
            a, _ = closing_residual(system, T / 2 - b, b)
            return SymmetricOrbit(system, T / 2 - b, b, a)
        prev = step
    return None


def _correct(system: MasslessSystem, z: np.ndarray, scale: float = 1.0) -> tuple[np.ndarray, bool, int]:
    """Newton on ``r = 0`` with steps along ``∇r`` (orthogonal to the tangent); ``scale``: the time scale of ``z``."""
    for it in range(10):
        _, r, g = closing_residual(system, *z, True)
        dz = -r * g / (g @ g)
        z = z + dz
        if np.hypot(*dz) <= 1e-11 * (scale + np.hypot(*z)):
            return z, abs(r) <= 1e-8 * system.gap, it
    return z, False, 10


def _grazing_start(system: MasslessSystem, w: float) -> np.ndarray:
    """The first point ``(α, β₀)`` of the branch by bracketing: ``r(α, β₀)`` has a pole at about half the linear
    period and its root beside it, closer the softer the contact's spring (a soft casing: within 1e-7 of ``π/ω``
    at 1e7 N/m on a stiff plate, where Newton from ``π/ω`` goes astray). ``α`` approaches the pole from each side
    geometrically, a sign change with ``|r|`` small at the refined root is the start; ``β₀`` grows tenfold while
    none is found."""
    from scipy.optimize import brentq

    o, c, P = system.open, system.closed, system.transfer

    def det(alpha: float, beta: float) -> float:  # the mid-open amplitudes' matrix (closing_residual's L)
        co, so = np.cos(o.omega * alpha), np.sin(o.omega * alpha)
        cc, sc = np.cos(c.omega * beta), np.sin(c.omega * beta)
        L = -(sc * c.omega)[:, None] * (P * co) - cc[:, None] * (P * (o.omega * so))
        sign, logdet = np.linalg.slogdet(L)
        return float(sign)

    half = np.pi / w
    for beta in np.array([1e-6, 1e-5, 1e-4, 1e-3]) / w:
        lo, hi = 0.9 * half, 1.1 * half  # the pole: where L is singular, beside half the linear period
        grid = np.linspace(lo, hi, 401)
        s = np.array([det(x, beta) for x in grid])
        flips = np.flatnonzero(s[:-1] != s[1:])
        if not flips.size:
            continue
        k = flips[np.argmin(np.abs(grid[flips] - half))]
        a0, a1 = grid[k], grid[k + 1]
        for _ in range(200):  # bisection on the determinant's sign to the last bit
            m = 0.5 * (a0 + a1)
            if m in (a0, a1):
                break
            a0, a1 = (m, a1) if det(m, beta) == s[k] else (a0, m)
        pole = 0.5 * (a0 + a1)
        eps = pole * np.logspace(-2, -15, 261)
        for side in (-1.0, 1.0):
            a = pole + side * eps
            r = np.array([closing_residual(system, x, beta)[1] for x in a])
            for k in np.flatnonzero(np.isfinite(r[:-1]) & np.isfinite(r[1:]) & (np.sign(r[:-1]) != np.sign(r[1:]))):
                root = brentq(lambda x, b=beta: closing_residual(system, x, b)[1], min(a[k], a[k + 1]),
                              max(a[k], a[k + 1]), xtol=1e-15 * pole, rtol=4 * np.finfo(float).eps)
                if abs(closing_residual(system, root, beta)[1]) <= 1e-8 * system.gap:
                    return np.array([root, beta])
    raise ValueError("no grazing orbit found from the linear mode: the closing residual has no root beside its "
                     "pole at half the linear period (the contact does not see this mode?)")


def follow_from_grazing(system: MasslessSystem, T_min: float, mode: int = 0, ds: float = 1e-3,
                        ds_max: float = 0.02, max_points: int = 2000) -> list[SymmetricOrbit]:
    """The branch grown from the linear open-phase mode ``mode`` at grazing, followed while ``T >= T_min``.

    Pseudo-arclength in ``(α, β)``: tangent ``⊥ ∇r`` oriented by the previous one (so turning points in ``T``
    are passed on the same branch), step accepted only if the corrected point is within twice the step and
    ahead; adaptive step between ``1e-10`` and ``ds_max``. Steps are relative to a quarter of the mode's linear
    period ``π/(2ω)``, so the same ``ds`` serves a bar in units of ``L/c`` and a blade in seconds.
    """
    check_massless_system(system, "follow_from_grazing")
    T_min = _number("T_min", T_min, strict=False)
    mode = _mode(system, mode)
    ds, ds_max = _number("ds", ds), _number("ds_max", ds_max)
    if isinstance(max_points, (bool, np.bool_)) or not isinstance(max_points, (int, np.integer)) or max_points < 1:
        raise ValueError(f"max_points must be an integer >= 1, got {max_points!r}")
    w = system.open.omega[mode]
    L = np.pi / (2 * w)
    z = np.array([np.pi / w, 1e-6 / w])
    for _ in range(100):  # first point: r(α, β₀) = 0 in α near half the linear period
        _, r, g = closing_residual(system, *z, True)
        step = r / g[0]
        if abs(step) <= 1e-14 * z[0]:
            break
        # r has a pole next to its root near grazing (the mid-open amplitudes' matrix is singular at grazing):
        # a full Newton step can land beyond it (e.g. the bilinear oscillator with k2 <= k1), so backtrack until
        # |r| decreases
        lam = 1.0
        while lam > 1e-12 and abs(closing_residual(system, z[0] - lam * step, z[1])[1]) >= abs(r):
            lam /= 2
        z[0] -= lam * step
    r = closing_residual(system, *z)[1]
    if not (abs(r) <= 1e-8 * system.gap and 0.5 * np.pi / w < z[0] < 1.5 * np.pi / w):
        z = _grazing_start(system, w)  # Newton missed the root beside the pole (a soft casing): bracket it
    out: list[SymmetricOrbit] = []
    tangent, h, ds_max = None, ds * L, ds_max * L
    while len(out) < max_points:
        a, _, g = closing_residual(system, *z, True)
        out.append(SymmetricOrbit(system, z[0], z[1], a))
        t = np.array([-g[1], g[0]]) / np.hypot(*g)
        t = t if (t[1] > 0 if tangent is None else t @ tangent > 0) else -t
        tangent = t
        while True:
            zp, ok, it = _correct(system, z + h * tangent, L)
            if ok and np.hypot(*(zp - z)) < 2 * h and (zp - z) @ tangent > 0:
                h = min(h * (1.5 if it <= 3 else 1.0), ds_max)
                break
            h /= 2
            if h < 1e-10 * L:
                return out
        z = zp
        if 2 * (z[0] + z[1]) < T_min or min(z) <= 0:
            return out
    return out


def orbits_at_period(system: MasslessSystem, T: float, samples: int | None = None) -> list[SymmetricOrbit]:
    """Every symmetric one-phase orbit of period ``T`` found from sign changes of ``r`` on a grid of contact
    half-times ``β ∈ (0, T/2)`` (``samples`` points, default ``20 n``), each refined by Brent's method.

    Sign changes across a pole of ``r`` (``L`` singular) are discarded. Co-existing orbits are the rule for
    fine models: their number grows with the number of dofs (internal resonances with the discrete spectrum).
    """
    from scipy.optimize import brentq

    check_massless_system(system, "orbits_at_period")
    T = _number("T", T)
    if samples is not None and (isinstance(samples, (bool, np.bool_)) or not isinstance(samples, (int, np.integer))
                                or samples < 3):
        raise ValueError(f"samples must be None or an integer >= 3, got {samples!r}")
    count = int(samples) if samples is not None else 20 * system.n
    betas = np.linspace(0.0, T / 2, count + 2)[1:-1]
    r = np.array([closing_residual(system, T / 2 - b, b)[1] for b in betas])
    out = []
    for i in np.flatnonzero(np.sign(r[1:]) != np.sign(r[:-1])):
        b = brentq(lambda x: closing_residual(system, T / 2 - x, x)[1], betas[i], betas[i + 1], xtol=1e-15)
        a, res = closing_residual(system, T / 2 - b, b)
        if abs(res) <= 1e-8 * system.gap:
            out.append(SymmetricOrbit(system, T / 2 - b, b, a))
    return out


def smoothest(orbits: list[SymmetricOrbit], modes: int = 10) -> SymmetricOrbit | None:
    """The orbit with the least energy outside the lowest ``modes`` open-phase modes (``None`` for no orbit).

    Among co-existing orbits at one period, the one a continuum would recognise: its band-limited energy
    converges under mesh refinement (``docs/massless.md``).
    """
    return min(orbits, key=lambda o: o.energy - o.band_energy(modes), default=None)
