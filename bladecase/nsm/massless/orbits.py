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

from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np
import scipy.linalg as sla

from ... import log
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
        closed, open_ = s.closed.flight(x1, v1), s.open.flight(x2, v2)
        X, V = np.empty((s.n, t.size)), np.empty((s.n, t.size))
        for j, tj in enumerate(t):
            X[:, j], V[:, j] = closed(tj) if tj < 2 * self.beta else open_(tj - 2 * self.beta)
        return X, V

    @cached_property
    def proofs(self):
        """Certified ``max(y - d)`` over the open phase and ``max(d - y)`` over the closed phase.

        Both phases end where the contact switches, at ``y = d + r`` (``r``: the orbit's closing residual, at most
        ``1e-8 d`` from the solvers; next to grazing against a soft casing it is the rounding of ``α``, up to a few
        ``1e-9 d``): on the side it lies, each proof is of ``y`` against ``d + r`` (``r`` capped at ``1e-8 d``) with
        the tolerance :data:`ADMISSIBILITY_RTOL`, so the solver's residual at the switch is not read as a
        violation; the values reported are still of ``y - d`` and ``d - y``."""
        s = self._bound()
        d = s.gap
        tol = ADMISSIBILITY_RTOL * d
        x1, v1 = self.closing_state()
        r = min(max(float(s.w @ x1) - d, -1e-8 * d), 1e-8 * d)

        def proof(f: TrigSum, length: float, shift: float):
            out = certified_max(TrigSum(f.alpha, f.beta, f.omega, f.const - shift), length, tol)
            return replace(out, value=out.value + shift, upper=out.upper + shift) if shift else out

        y = s.open.contact(self.x_mid_open, np.zeros(s.n))
        open_ = proof(TrigSum(y.alpha, y.beta, y.omega, y.const - d), self.alpha, max(r, 0.0))
        xm, vm = s.closed.advance(x1, v1, self.beta)
        y = s.closed.contact(xm, vm)
        closed = proof(TrigSum(-y.alpha, -y.beta, y.omega, d - y.const), self.beta, max(-r, 0.0))
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


def _correct(system: MasslessSystem, z: np.ndarray, scale: float = 1.0, narrow: bool = False
             ) -> tuple[np.ndarray, bool, int]:
    """Newton on ``r = 0`` with steps along ``∇r`` (orthogonal to the tangent); ``scale``: the time scale of ``z``.

    ``narrow``: the valley of ``r`` is narrower than the step criterion (a contact that stiffens the mode by a small
    ``κ``: ``r`` goes from ``-d`` to its pole within ``κβ``), so a step below it with ``|r|`` still above its
    tolerance goes on to round-off instead of failing (which halved the continuation's step down to nothing)."""
    for it in range(10):
        _, r, g = closing_residual(system, *z, True)
        dz = -r * g / (g @ g)
        z = z + dz
        step = np.hypot(*dz)
        if step <= 1e-11 * (scale + np.hypot(*z)):
            if abs(r) <= 1e-8 * system.gap or not narrow or step <= 1e-15 * np.hypot(*z):
                return z, abs(r) <= 1e-8 * system.gap, it
    return z, False, 10


def contact_share(system: MasslessSystem, mode: int = 0) -> float:
    """``κ = k b_j² / ω_j²``: the contact's spring (``system.kc``) seen by open-phase mode ``mode``, as a fraction
    of the mode's own stiffness — how much the contact phase stiffens it (its frequency rises by about ``κ/2``
    when ``κ`` is small).

    Next to grazing (contact half-time ``β``, ``δ = α - π/ω_j``) the closing residual is, to leading order,
    ``r/d = κβ / (δ + β(1 + κ)) - 1``: its root at ``δ = -β`` (``T = 2π/ω_j``), its pole (``L`` singular) at
    ``δ = -β(1 + κ)``; the two are ``κβ`` apart whatever the other modes (measured on FE strips within 3e-4 κβ
    up to ``βω = 0.03``)."""
    o = system.open
    return float(system.kc * o.b[mode] ** 2 / o.omega[mode] ** 2)


#: The grazing root of the closing residual is resolved to ``|r| <= 1e-8 d`` once ``κβω`` is at least this (its
#: distance from the pole, ``κβ``, against the rounding of ``α``: measured ``|r|/d ≈ 2e-16 / (κβω)``; 10× margin).
GRAZING_RESOLUTION = 2e-7
#: Longest contact half-time ``βω`` the first point of a branch may take when grazing is not resolved closer (the
#: contact then lasts ``βω/π`` of the period: 3 %).
GRAZING_BETA_MAX = 0.1


def _grazing_root(system: MasslessSystem, mode: int, beta: float) -> np.ndarray | None:
    """``(α, β)`` on the branch grown from grazing of ``mode`` at contact half-time ``beta``, or ``None``.

    The root is bracketed from the closed-form structure (:func:`contact_share`): with ``m = min(κ, 1)``,
    ``r = +d`` at ``δ = -β(1 + m/2)`` (between the pole and the root) and ``r = -d/2`` at ``δ = -β(1 - m)`` (beyond
    the root); if higher-order terms move the pole (fast closed-phase modes with ``βω_c`` not small), points on both
    sides of ``δ = -β`` (within ``2^-20 mβ``), towards the pole and away from it are scanned."""
    from scipy.optimize import brentq

    w = system.open.omega[mode]
    half, d = np.pi / w, system.gap
    m = min(contact_share(system, mode), 1.0)
    if not m > 0:
        return None

    def r(u: float) -> float:  # α = π/ω - β + u m β: the root at u ≈ 0, the pole at u ≈ -κ/m <= -1
        value = closing_residual(system, half - beta + u * m * beta, beta)[1]
        return value if np.isfinite(value) else np.nan

    brackets = [(-0.5, 1.0)]
    ends = {u: r(u) for u in brackets[0]}
    if not ends[-0.5] > 0 > ends[1.0]:  # beyond leading order (the pole moved more than the root): scan both
        near = 0.5 ** np.arange(1, 21)  # sides of the root's place u = 0, and towards the pole and away from it
        grid = np.concatenate([-(1 - near[:6]), -near, [0.0], near[::-1], 4.0 ** np.arange(5)])
        ends.update({u: r(u) for u in grid if u not in ends})
        u = np.array(sorted(ends))
        v = np.array([ends[x] for x in u])
        brackets = [(u[i], u[i + 1]) for i in np.flatnonzero(np.isfinite(v[:-1]) & np.isfinite(v[1:])
                                                            & (np.sign(v[:-1]) != np.sign(v[1:])))]
    for lo, hi in brackets:
        try:
            u = brentq(r, lo, hi, xtol=1e-14, rtol=4 * np.finfo(float).eps)
        except ValueError:
            continue
        alpha = half - beta + u * m * beta
        if abs(closing_residual(system, alpha, beta)[1]) <= 1e-8 * d:
            return np.array([alpha, beta])
    return None


def _is_grazing_root(system: MasslessSystem, mode: int, z: np.ndarray) -> bool:
    """Whether the root ``z = (α, β)`` is the one grown from grazing of ``mode``: nearer ``δ = -β`` than half way
    to the pole (a root beside another pole of ``r`` — another mode's — is not)."""
    w = system.open.omega[mode]
    m = min(contact_share(system, mode), 1.0)
    return bool(m > 0 and 0 < z[1] and abs(z[0] + z[1] - np.pi / w) <= 0.5 * m * z[1])


def _grazing_start(system: MasslessSystem, mode: int) -> np.ndarray:
    """The first point ``(α, β)`` of the branch grown from grazing of ``mode``, bracketed beside its pole.

    The root lies ``κβ`` from the pole (:func:`contact_share`): a soft casing puts it within ``1e-7`` of ``π/ω`` at
    ``βω = 1e-6`` (``1e7`` N/m on a stiff plate), beyond double precision for ``κβω`` below
    :data:`GRAZING_RESOLUTION`. The contact half-time ``βω`` starts at ``1e-6`` (as Newton does), or at the
    shortest that resolves the root, and grows tenfold up to :data:`GRAZING_BETA_MAX`; ``ValueError`` saying why
    (computed from the system) if none does."""
    w = system.open.omega[mode]
    kappa = contact_share(system, mode)
    shortest = max(1e-6, GRAZING_RESOLUTION / kappa) if kappa > 0 else np.inf
    tried = [shortest * 10.0 ** i for i in range(6) if shortest * 10.0 ** i <= GRAZING_BETA_MAX * (1 + 1e-12)]
    if tried and tried[-1] < GRAZING_BETA_MAX / 2:
        tried.append(GRAZING_BETA_MAX)
    for bw in tried:
        z = _grazing_root(system, mode, bw / w)
        if z is not None:
            if bw > 1e-6:
                log.info("massless branch of open mode %d: the contact stiffens it by κ = %.3g of its stiffness; its "
                         "orbits are resolved from a contact phase of %.2g %% of the period on (closer to grazing the "
                         "closing residual's root is within rounding of its pole)", mode + 1, kappa, 100 * bw / np.pi)
            return z
    raise ValueError(_no_grazing_reason(system, mode, tried))


def _no_grazing_reason(system: MasslessSystem, mode: int, tried: list[float]) -> str:
    """Why no orbit grows from grazing of ``mode``, in the system's numbers."""
    o = system.open
    w, b = o.omega[mode], float(o.b[mode])
    f = w / (2 * np.pi)
    kappa = contact_share(system, mode)
    shares = system.kc * o.b**2 / o.omega**2
    best = int(np.argmax(shares))
    head = f"no grazing orbit found from open-phase mode {mode + 1} ({f:.6g} Hz): "
    seen = (f"the contact sees mode {best + 1} ({o.omega[best] / (2 * np.pi):.6g} Hz) most, b = {o.b[best]:.3g}, "
            f"κ = {shares[best]:.3g}")
    if not tried:
        energy = 0.5 * w**2 * (system.gap / b) ** 2 if b else np.inf
        return (head + f"the contact hardly sees it — its contact participation b = {b:.3g} is "
                f"{abs(b) / np.abs(o.b).max():.1e} of the largest, so the contact's spring ({system.kc:.4g}) adds "
                f"only κ = k b²/ω² = {kappa:.2e} to the mode's stiffness (its frequency by {50 * kappa:.1e} %) and "
                f"grazing takes the energy {energy:.3g}. Its one-phase orbits are the linear mode to within κ: the "
                f"closing residual's root lies κβ from its pole, below double precision for any contact shorter than "
                f"{100 * GRAZING_BETA_MAX / np.pi:.0f} % of the period (resolving it needs κ >= "
                f"{GRAZING_RESOLUTION / GRAZING_BETA_MAX:.0e}). Put the contact where this mode moves it, or search "
                f"near a mode the contact sees ({seen})")
    ratio = o.omega / w
    near = [i for i in range(system.n) if i != mode and ratio[i] > 1.5 and abs(ratio[i] - np.rint(ratio[i])) <= 0.02]
    resonance = "".join(f"; open-phase mode {i + 1} ({o.omega[i] / (2 * np.pi):.6g} Hz) is "
                        f"{ratio[i]:.4f} × its frequency (an internal resonance at grazing)" for i in near)
    return (head + f"the closing residual has no root beside its pole at contact half-times βω = "
            f"{tried[0]:.2g} … {tried[-1]:.2g} (κ = k b²/ω² = {kappa:.3g}, b = {b:.3g}{resonance}); {seen}")


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
    narrow = False
    if not (abs(r) <= 1e-8 * system.gap and _is_grazing_root(system, mode, z)):
        z = _grazing_start(system, mode)  # Newton missed the root beside the pole (a soft casing): bracket it
        narrow = z[1] * w > 1.5e-6  # resolved beyond Newton's contact half-time: the valley of r is narrow
    out: list[SymmetricOrbit] = []
    tangent, h, ds_max = None, ds * L, ds_max * L
    while len(out) < max_points:
        a, _, g = closing_residual(system, *z, True)
        out.append(SymmetricOrbit(system, z[0], z[1], a))
        t = np.array([-g[1], g[0]]) / np.hypot(*g)
        t = t if (t[1] > 0 if tangent is None else t @ tangent > 0) else -t
        tangent = t
        while True:
            zp, ok, it = _correct(system, z + h * tangent, L, narrow)
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
