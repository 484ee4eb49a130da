"""Nonsmooth modes: families of k-ipp periodic orbits followed in the period.

A k-ipp orbit is a zero of ``R(t₁…t_{k-1}, T, Λ) = [ΠΛ ; ΣΛ - d·1]``: ``2k``
equations in ``2k`` unknowns, one of them redundant (``ΛᵀΠΛ ≡ 0``), so the
solutions form curves — the nonsmooth modes (theory §4).  They are followed
by pseudo-arclength continuation (tangent from the SVD of the Jacobian,
Gauss–Newton corrector on ``R = 0`` plus the arclength condition), so turning
points in ``T`` do not stop them.  Starting points come from
:func:`bladecase.orbits_kipp` on a scan of periods.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .orbits import (
    REPEAT_RTOL,
    PeriodicOrbit,
    _matrices,
    _Modal,
    _solve_times,
    canonical_rotation,
    check_period,
    make_orbit,
    orbits_kipp,
)
from .system import LinearSystem

#: Relative precision in ``T`` of the refined ends of admissible arcs.
ARC_RTOL = 1e-9

#: A family is not followed past two impacts closer than ``MERGE_RTOL·T``
#: (it then tends to an orbit with fewer impacts).
MERGE_RTOL = 1e-4


@dataclass(frozen=True)
class Arc:
    """An admissible arc of a family: points ``start..stop`` (inclusive) and its
    period range ``[T_lo, T_hi]``.

    ``refined_lo``/``refined_hi`` say whether that end is where admissibility
    is lost (refined by bisection along the curve); otherwise the arc ends
    where the family itself ends (period range, resonance, impacts merging,
    branch point with a repeated orbit).  Along a curve with a turning point
    ``T`` is not monotone: ``T_lo``/``T_hi`` are the extreme periods of the arc.
    """

    start: int
    stop: int
    T_lo: float
    T_hi: float
    refined_lo: bool = True
    refined_hi: bool = True

    def to_dict(self) -> dict:
        return {"start": int(self.start), "stop": int(self.stop), "T_lo": float(self.T_lo),
                "T_hi": float(self.T_hi), "refined_lo": bool(self.refined_lo), "refined_hi": bool(self.refined_hi)}


@dataclass(frozen=True, eq=False)
class Family:
    """A nonsmooth mode: a one-parameter family of k-ipp periodic orbits.

    Attributes
    ----------
    k : int
        Impacts per period.
    orbits : list of PeriodicOrbit
        The orbits along the curve, in continuation order (``T`` need not be
        monotone: turning points are followed).
    arcs : list of Arc
        Maximal admissible stretches, with ends refined by bisection along the
        curve.
    """

    system: LinearSystem = field(repr=False)
    k: int
    orbits: list = field(repr=False)
    arcs: list

    @property
    def T(self) -> np.ndarray:
        return np.array([o.T for o in self.orbits])

    @property
    def frequencies(self) -> np.ndarray:
        return 1.0 / self.T

    @property
    def energy(self) -> np.ndarray:
        return np.array([o.energy for o in self.orbits])

    @property
    def admissible(self) -> np.ndarray:
        return np.array([o.admissible for o in self.orbits], dtype=bool)

    @property
    def impact_times(self) -> np.ndarray:
        """``(N, k)`` impact times."""
        return np.array([o.impact_times for o in self.orbits])

    @property
    def impulses(self) -> np.ndarray:
        return np.array([o.impulses for o in self.orbits])

    @property
    def ipp(self) -> int:
        return self.k

    @property
    def intervals(self) -> list:
        """Admissible arcs as :class:`bladecase.Interval` (for plots shared with backbones)."""
        from .scan import Interval

        return [Interval(a.T_lo, a.T_hi, a.refined_lo, a.refined_hi) for a in self.arcs]

    @property
    def linear_frequencies(self) -> np.ndarray:
        sp = self.system.spectrum
        return sp.frequencies[sp.active]

    def orbit_at(self, T: float) -> list[PeriodicOrbit]:
        """The family's orbits of period ``T`` (one per crossing of ``T`` by the curve),
        each re-solved exactly from the interpolated neighbours."""
        out = []
        Ts = self.T
        d = self.system.gap
        T = check_period(self.system, T)
        for i in range(len(Ts) - 1):
            lo, hi = sorted((Ts[i], Ts[i + 1]))
            if not lo <= T <= hi or hi == lo:
                continue
            a = (T - Ts[i]) / (Ts[i + 1] - Ts[i])
            guess = (1 - a) * self.orbits[i].impact_times / Ts[i] + a * self.orbits[i + 1].impact_times / Ts[i + 1]
            sol = _solve_times(_Modal.of(self.system, T), guess * T, d)
            if sol is not None:
                out.append(make_orbit(self.system, T, *sol))
        return out

    def manifold(self, n_orbits: int = 40, n_times: int = 200, admissible_only: bool = True):
        """Sample the family's 2-D invariant manifold ``(T, t) ↦ (x, v)``.

        Picks ``n_orbits`` orbits evenly along the curve (by index, over the
        admissible arcs when ``admissible_only``) and ``n_times`` instants
        ``t = θT``, ``θ ∈ [0, 1)``, on each.

        Returns
        -------
        T : (n_orbits,) periods;  theta : (n_times,) phases;
        x, v : (n, n_orbits, n_times) positions and velocities.
        """
        idx = np.arange(len(self.orbits))
        if admissible_only:
            idx = idx[self.admissible]
            if idx.size == 0:
                raise ValueError("the family has no admissible orbit (use admissible_only=False)")
        pick = idx[np.unique(np.linspace(0, idx.size - 1, n_orbits).round().astype(int))]
        theta = np.arange(n_times) / n_times
        xs, vs = [], []
        for i in pick:
            o = self.orbits[i]
            x, v = o.state(theta * o.T)
            xs.append(x)
            vs.append(v)
        return self.T[pick], theta, np.stack(xs, axis=1), np.stack(vs, axis=1)

    def to_dict(self) -> dict:
        return {
            "ipp": self.k,
            "arcs": [a.to_dict() for a in self.arcs],
            "orbits": [o.to_dict() for o in self.orbits],
        }

    def table(self) -> str:
        lines = [f"{self.k}-ipp family, {len(self.orbits)} orbits, T in [{self.T.min():.8g}, {self.T.max():.8g}]"]
        for a in self.arcs:
            lines.append(f"  admissible arc: T in [{a.T_lo:.10g}, {a.T_hi:.10g}]  (points {a.start}..{a.stop})")
        if not self.arcs:
            lines.append("  no admissible arc")
        return "\n".join(lines)


# ---------------------------------------------------------------------------


class _Curve:
    """The k-ipp equations with the impulses eliminated, in the scaled
    unknowns ``z = (t₁/T₀ … t_{k-1}/T₀, T/T₀)``.

    ``Λ = d Σ⁻¹ 1`` satisfies the position conditions; the residual is the
    impact-law condition ``Π n`` with the direction ``n = Σ⁻¹1 / |Σ⁻¹1|``,
    scaled by ``wᵀM⁻¹w / 2`` (``k`` equations, one redundant since
    ``nᵀΠn ≡ 0``).  For k = 2 this is the paper's Eq. 15, ``s(t₁) = 0``, and
    the curve lives in the ``(t₁, T)`` plane of its Fig. 2.
    """

    def __init__(self, system: LinearSystem, k: int, T0: float, lam0: float):
        self.system, self.k, self.T0, self.lam0 = system, k, T0, lam0
        self.d = system.gap
        b = system.spectrum.contact_modes[1]
        self.scale = float(b @ b) / 2

    def times(self, z) -> tuple[float, np.ndarray]:
        T = z[-1] * self.T0
        return T, np.append(z[:-1] * self.T0, T)

    def split(self, z):
        """``(T, times, Λ)`` at ``z``."""
        T, times = self.times(z)
        _, Sigma = _matrices(_Modal.of(self.system, T), times)
        lam = self.d * np.linalg.solve(Sigma, np.ones(self.k))
        return T, times, lam

    def join(self, times, lam=None):
        return times / self.T0

    def residual(self, z):
        T, times = self.times(z)
        Pi, Sigma = _matrices(_Modal.of(self.system, T), times)
        try:
            n = np.linalg.solve(Sigma, np.ones(self.k))
        except np.linalg.LinAlgError:
            return np.full(self.k, np.nan)
        return Pi @ (n / np.linalg.norm(n)) / self.scale

    def jacobian(self, z, h=1e-7):
        n = z.size
        J = np.empty((self.k, n))
        for j in range(n):
            e = np.zeros(n)
            e[j] = h
            J[:, j] = (self.residual(z + e) - self.residual(z - e)) / (2 * h)
        return J

    def tangent(self, z, previous=None, J=None):
        """Unit null vector of the Jacobian, oriented along ``previous``."""
        _, _, vt = np.linalg.svd(self.jacobian(z) if J is None else J)
        t = vt[-1]
        if previous is not None and t @ previous < 0:
            t = -t
        return t

    def valid(self, z) -> bool:
        """Ordered impacts, no two closer than ``MERGE_RTOL·T``, finite impulses,
        and not within ``MERGE_RTOL`` of a repeated orbit (period ``T/j``)."""
        T, times = self.times(z)
        gaps = np.diff(np.concatenate([[0.0], times]))
        if not (np.all(np.isfinite(z)) and T > 0 and gaps.min() > MERGE_RTOL * T):
            return False
        try:
            T, times, lam = self.split(z)
        except np.linalg.LinAlgError:
            return False
        if not np.all(np.isfinite(lam)) or np.abs(lam).max() > 1e8 * self.lam0:
            return False
        return _distance_to_repetition(times, lam, T) > MERGE_RTOL

    def correct(self, zp, tangent, J=None, tol=1e-10, maxiter=10):
        """Newton on ``[R(z) ; tangent·(z - zp)] = 0``; with ``J`` given, the chord
        method (that Jacobian kept for every iteration)."""
        z = zp.copy()
        for it in range(maxiter):
            r = np.append(self.residual(z), tangent @ (z - zp))
            if not np.all(np.isfinite(r)):
                return None, it
            A = np.vstack([self.jacobian(z) if J is None else J, tangent])
            dz, *_ = np.linalg.lstsq(A, -r, rcond=None)
            z = z + dz
            if np.abs(dz).max() < 1e-11:
                res = np.abs(self.residual(z)).max()
                return (z if res < tol else None), it + 1
        return None, maxiter


def _repetition_offsets(times, T) -> list[np.ndarray]:
    """For each ``j > 1`` dividing ``k``: the offsets of the impact pattern from
    one repeating every ``T/j`` (all zero at a repeated orbit)."""
    k = times.size
    return [np.mod(np.roll(times, -(k // j)) - times, T) - T / j for j in range(2, k + 1) if k % j == 0]


def _crosses_repetition(curve: _Curve, z_a, z_b) -> bool:
    """Does the segment ``z_a → z_b`` cross a repeated orbit (all offsets flip sign)?"""
    for da, db in zip(_repetition_offsets(*curve.times(z_a)[::-1]), _repetition_offsets(*curve.times(z_b)[::-1])):
        if np.all(np.sign(da) * np.sign(db) < 0):
            return True
    return False


def _distance_to_repetition(times, lam, T) -> float:
    """How far (relative) the impact pattern is from repeating every ``T/j``, ``j | k``."""
    k = times.size
    scale = max(np.abs(lam).max(), np.finfo(float).tiny)
    best = np.inf
    for j in range(2, k + 1):
        if k % j:
            continue
        shift = k // j
        dt = np.mod(np.roll(times, -shift) - times, T)
        dist = max(np.abs(dt - T / j).max() / T, np.abs(np.roll(lam, -shift) - lam).max() / scale)
        best = min(best, dist)
    return best


def _follow(curve: _Curve, z0, direction, T_range, ds, ds_min, ds_max, max_points):
    """Points of the curve from ``z0`` along ``direction`` until it leaves
    ``T_range``, two impacts merge, it reaches a repeated orbit (a branch
    point with the family of period-``T/j`` orbits), the impulses blow up
    (resonance), the curve closes on itself, or the corrector fails at the
    smallest step."""
    pts = []
    J = curve.jacobian(z0)
    z, tan = z0, curve.tangent(z0, direction, J)
    travelled = 0.0
    for _ in range(max_points):
        step = ds
        while True:
            zp = z + step * tan
            zc, iters = curve.correct(zp, tan, J)
            if zc is None:  # chord method failed: full Newton (fresh Jacobian every iteration)
                zc, iters = curve.correct(zp, tan)
            # The corrector moves across the curve; a large move means it jumped
            # to another branch: take a smaller step instead.
            # Crossing a repeated (period T/j) orbit is a branch point: the family
            # ends there; smaller steps bring its last point close to it.
            if (zc is not None and curve.valid(zc) and np.linalg.norm(zc - zp) < 0.3 * step
                    and not _crosses_repetition(curve, z, zc)):
                break
            step /= 2
            if step < ds_min:
                return pts
        travelled += np.linalg.norm(zc - z)
        J = curve.jacobian(zc)
        tan = curve.tangent(zc, tan, J)
        z = zc
        pts.append(z)
        if travelled > 4 * ds_max and np.linalg.norm(z - z0) < step:
            return pts  # closed curve
        ds = min(ds_max, step * (1.5 if iters <= 6 else 0.7 if iters >= 9 else 1.0))
        T = z[curve.k - 1] * curve.T0
        if not T_range[0] <= T <= T_range[1]:
            return pts
    return pts


def nonsmooth_mode(
    system: LinearSystem,
    k: int,
    T_range: tuple[float, float],
    scan: int = 24,
    step: float = 0.01,
    max_points: int = 400,
    refine: bool = True,
    progress: bool = False,
    resolution: int | None = None,
) -> list[Family]:
    """Follow every k-ipp family (nonsmooth mode) found in ``T_range``.

    Parameters
    ----------
    system : LinearSystem
    k : int
        Impacts per period (>= 1).
    T_range : (T_min, T_max)
        Periods of interest; the curves are followed until they leave it.
    scan : int
        Number of periods (evenly spaced in ``T_range``, resonant ones
        skipped) where :func:`orbits_kipp` looks for starting orbits.
        Orbits that are repetitions of shorter-period orbits (``repeats >
        1``) are not followed: they are not new modes.
    step : float
        Initial arclength step in scaled unknowns (times / ``T``, impulses /
        their scale); it adapts between ``step/1000`` and ``2·step``.
    max_points : int
        Cap on points per direction of each family.
    refine : bool
        Refine the ends of the admissible arcs by bisection along the curve
        (relative precision ``ARC_RTOL`` in ``T``).
    progress : bool
        Progress bar over the starting periods.
    resolution : int or None
        Grid points per impact time of the k >= 3 multistart search at each
        starting period (:func:`orbits_kipp`); ``None`` for its default.

    Returns
    -------
    list of Family
        Each family's orbits in curve order (all within ``T_range``), certified,
        with admissible arcs.
        A family crossing a later scan period is not started again there.
    """
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
        raise ValueError(f"k (impacts per period) must be an integer >= 1, got {k!r}")
    T_lo, T_hi = (float(x) for x in T_range)
    if not (np.isfinite(T_lo) and np.isfinite(T_hi)) or not 0 < T_lo < T_hi:
        raise ValueError(f"T_range must be (T_min, T_max) with 0 < T_min < T_max, got {T_range!r}")
    if k == 1:
        return _one_ipp_families(system, (T_lo, T_hi), scan, refine)
    periods = np.linspace(T_lo, T_hi, scan)
    it = periods
    if progress:
        from tqdm.auto import tqdm

        it = tqdm(periods, desc=f"{k}-ipp starts", unit="T", leave=False)
    starts = []
    for T in it:
        try:
            sols = orbits_kipp(system, T, k, resolution=resolution)
        except ValueError:
            continue
        starts.extend((T, o) for o in sols if o.repeats == 1)
    families: list[Family] = []
    covered = [False] * len(starts)
    for n, (T, o) in enumerate(starts):
        if covered[n]:
            continue
        lam0 = max(np.abs(o.impulses).max(), system.gap)
        curve = _Curve(system, k, T, lam0)
        z0 = curve.join(o.impact_times)
        t0 = curve.tangent(z0)
        fwd = _follow(curve, z0, t0, (T_lo, T_hi), step, step / 1000, 2 * step, max_points)
        bwd = _follow(curve, z0, -t0, (T_lo, T_hi), step, step / 1000, 2 * step, max_points)
        zs = bwd[::-1] + [z0] + fwd
        orbits = []
        for z in zs:
            if not T_lo <= z[k - 1] * curve.T0 <= T_hi:
                continue  # the step that left the period range: not part of the family
            try:
                orbits.append(_polished_orbit(curve, z))
            except (ValueError, np.linalg.LinAlgError):
                continue
        for m in range(n + 1, len(starts)):
            if not covered[m] and _passes(curve, zs, starts[m]):
                covered[m] = True
        arcs = _arcs(curve, [curve.join(o.impact_times) for o in orbits], orbits, refine)
        families.append(Family(system=system, k=k, orbits=orbits, arcs=arcs))
    return families


def _polished_orbit(curve: _Curve, z) -> PeriodicOrbit:
    """The orbit at curve point ``z``, its impact times re-solved at fixed ``T``
    to machine precision (Newton on ``(t, Λ)``).  Admissibility is certified;
    for a non-admissible orbit ``max_violation`` is the largest sampled
    violation (not polished)."""
    T, times, lam = curve.split(z)
    sol = _solve_times(_Modal.of(curve.system, T), times, curve.d)
    if sol is not None and np.abs(sol[0] - times).max() < 1e-6 * T:
        times, lam = sol
    return make_orbit(curve.system, T, times, lam, polish=False)


#: A start orbit is only re-solved from a crossing segment of a followed curve
#: when the interpolated impact times lie within ``PASS_GATE·T`` of its own
#: (under every re-anchoring); farther crossings are other orbits of that period.
PASS_GATE = 0.05


def _phase_distance(times: np.ndarray, reference: np.ndarray, T: float) -> float:
    """``min`` over re-anchorings of ``times`` (shift by each ``t_r``) of the largest
    distance to ``reference`` (both sets of ``k`` impact times in ``(0, T]``)."""
    shifted = np.mod(times[None, :] - times[:, None], T)  # row r: re-anchored at impact r
    shifted[shifted == 0] = T
    shifted.sort(axis=1)
    return float(np.abs(shifted - np.sort(reference)[None, :]).max(axis=1).min())


def _passes(curve: _Curve, zs, start) -> bool:
    """Does the polyline ``zs`` cross the start orbit (same period, same impacts)?"""
    T_s, o = start
    k = curve.k
    Ts = np.array([z[k - 1] for z in zs]) * curve.T0
    lo, hi = np.minimum(Ts[:-1], Ts[1:]), np.maximum(Ts[:-1], Ts[1:])
    segments = np.flatnonzero((lo <= T_s) & (T_s <= hi) & (hi > lo))
    if segments.size == 0:
        return False
    md = _Modal.of(curve.system, T_s)
    for i in segments:
        a = (T_s - Ts[i]) / (Ts[i + 1] - Ts[i])
        ta, tb = curve.times(zs[i])[1], curve.times(zs[i + 1])[1]
        guess = ((1 - a) * ta / Ts[i] + a * tb / Ts[i + 1]) * T_s
        if _phase_distance(guess, o.impact_times, T_s) > PASS_GATE * T_s:
            continue  # the interpolated impacts are far from the start's: no need to solve
        sol = _solve_times(md, guess, curve.d)
        if sol is None:
            continue
        times, _ = canonical_rotation(sol[0], sol[1], T_s)
        if np.abs(times - o.impact_times).max() <= 1e3 * REPEAT_RTOL * T_s:
            return True
    return False


def _arcs(curve: _Curve, zs, orbits, refine: bool) -> list[Arc]:
    adm = np.array([o.admissible for o in orbits], dtype=bool)
    arcs = []
    i = 0
    while i < adm.size:
        if not adm[i]:
            i += 1
            continue
        j = i
        while j + 1 < adm.size and adm[j + 1]:
            j += 1
        ref_a, ref_b = refine and i > 0, refine and j + 1 < adm.size
        T_a, T_b = orbits[i].T, orbits[j].T
        if ref_a:
            T_a, ref_a = _bisect_curve(curve, zs[i], zs[i - 1])
        if ref_b:
            T_b, ref_b = _bisect_curve(curve, zs[j], zs[j + 1])
        Ts = [o.T for o in orbits[i:j + 1]] + [T_a, T_b]
        lo, hi = min(Ts), max(Ts)
        arcs.append(Arc(i, j, float(lo), float(hi), refined_lo=bool((lo == T_a and ref_a) or (lo == T_b and ref_b)),
                        refined_hi=bool((hi == T_a and ref_a) or (hi == T_b and ref_b))))
        i = j + 1
    return arcs


def _bisect_curve(curve: _Curve, z_in, z_out, maxiter: int = 80) -> tuple[float, bool]:
    """Period where admissibility is lost between curve points ``z_in``
    (admissible) and ``z_out``: bisection along the curve.

    The midpoint is solved at fixed ``T = (T_in + T_out)/2`` by Newton from
    the interpolated impact times (robust near resonances, where the
    eliminated-impulse residual is stiff), else by the arclength corrector
    orthogonal to the chord (turning points); a midpoint that leaves the
    bracket is rejected.  Returns the admissible end and whether the bracket
    was narrowed to ``ARC_RTOL``.
    """
    k = curve.k
    for _ in range(maxiter):
        T_in, T_out = z_in[k - 1] * curve.T0, z_out[k - 1] * curve.T0
        if abs(T_out - T_in) <= ARC_RTOL * abs(T_in):
            return float(T_in), True
        zm = None
        Tm = 0.5 * (T_in + T_out)
        if T_in != T_out:
            try:
                md = _Modal.of(curve.system, check_period(curve.system, Tm))
                guess = 0.5 * (curve.times(z_in)[1] / T_in + curve.times(z_out)[1] / T_out) * Tm
                sol = _solve_times(md, guess, curve.d)
            except ValueError:
                sol = None
            if sol is not None:
                zm = curve.join(sol[0])
        if zm is None:
            chord = (z_out - z_in) / np.linalg.norm(z_out - z_in)
            zm, _ = curve.correct(0.5 * (z_in + z_out), chord)
        if zm is None:
            break
        # stay on this stretch of the curve: between the two ends, near the chord
        span = z_out - z_in
        a = float((zm - z_in) @ span / (span @ span))
        if not 0 < a < 1 or np.linalg.norm(zm - z_in - a * span) > np.linalg.norm(span):
            break
        Tm, times, lam = curve.split(zm)
        try:
            ok = make_orbit(curve.system, Tm, times, lam, polish=False).admissible
        except ValueError:
            ok = False
        if ok:
            z_in = zm
        else:
            z_out = zm
    return float(z_in[k - 1] * curve.T0), False


def _one_ipp_families(system, T_range, scan, refine) -> list[Family]:
    """k = 1: the family is the 1-ipp backbone (one family; its admissible arcs never span a resonance)."""
    from .scan import backbone

    bb = backbone(system, np.linspace(T_range[0], T_range[1], max(scan, 200)))
    orbits = [o for o in bb.orbits if o is not None]
    adm = np.array([o.admissible for o in orbits], dtype=bool)
    arcs = []
    for iv in bb.intervals:
        idx = [n for n, o in enumerate(orbits) if iv.T_lo <= o.T <= iv.T_hi]
        if idx:
            arcs.append(Arc(idx[0], idx[-1], iv.T_lo, iv.T_hi, iv.refined_lo, iv.refined_hi))
    del adm
    return [Family(system=system, k=1, orbits=orbits, arcs=arcs)]
