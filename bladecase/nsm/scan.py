"""Backbones: orbits over a range of periods and their admissible intervals.

:func:`backbone` evaluates the k-ipp orbit at every period of a scan, keeps
the frequency–energy data, and refines the maximal admissible intervals of
``T`` by bisection on the admissibility predicate.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from .orbits import PeriodicOrbit, orbit_1ipp
from .system import LinearSystem

#: Relative precision in ``T`` of the refined ends of admissible intervals.
BISECTION_RTOL = 1e-9


@dataclass(frozen=True)
class Interval:
    """A maximal admissible interval ``[T_lo, T_hi]`` of the period.

    ``refined_lo``/``refined_hi`` tell whether the end was refined by
    bisection (False when the interval reaches the end of the scan, where
    admissibility beyond the scan is unknown).
    """

    T_lo: float
    T_hi: float
    refined_lo: bool
    refined_hi: bool

    def to_dict(self) -> dict:
        return {"T_lo": self.T_lo, "T_hi": self.T_hi, "refined_lo": self.refined_lo, "refined_hi": self.refined_hi}


@dataclass(frozen=True, eq=False)
class Backbone:
    """Orbits of one family type (``ipp`` impacts per period) over a period scan.

    Attributes
    ----------
    periods : (N,) ndarray
        Scanned periods.
    orbits : list of PeriodicOrbit or None
        ``None`` where the period is resonant (or no orbit exists).
    intervals : list of Interval
        Maximal admissible intervals, ends refined to ``BISECTION_RTOL``.
    linear_frequencies : (m,) ndarray
        ``ω_j / 2π`` of the modes that see the contact.
    """

    system: LinearSystem = field(repr=False)
    ipp: int
    periods: np.ndarray
    orbits: list = field(repr=False)
    intervals: list
    linear_frequencies: np.ndarray = field(repr=False)

    def _column(self, get, default=np.nan) -> np.ndarray:
        return np.array([default if o is None else get(o) for o in self.orbits])

    @property
    def frequencies(self) -> np.ndarray:
        """``1 / T`` for every scanned period."""
        return 1.0 / self.periods

    @property
    def energy(self) -> np.ndarray:
        return self._column(lambda o: o.energy)

    @property
    def admissible(self) -> np.ndarray:
        return self._column(lambda o: o.admissible, False).astype(bool)

    @property
    def max_violation(self) -> np.ndarray:
        return self._column(lambda o: o.max_violation)

    @property
    def impulses(self) -> np.ndarray:
        """``(N, ipp)`` impulses (NaN rows where no orbit)."""
        return np.array([np.full(self.ipp, np.nan) if o is None else o.impulses for o in self.orbits])

    def table(self) -> str:
        """Human-readable table of the scan followed by the admissible intervals."""
        lines = [f"{'T':>14} {'1/T':>12} {'energy':>12} {'impulses':>24} admissible"]
        for T, o in zip(self.periods, self.orbits):
            if o is None:
                lines.append(f"{T:14.8g} {1 / T:12.6g} {'resonant':>12}")
                continue
            imp = " ".join(f"{x:.5g}" for x in o.impulses)
            lines.append(f"{T:14.8g} {1 / T:12.6g} {o.energy:12.6g} {imp:>24} {'yes' if o.admissible else 'no'}")
        lines.append("")
        if self.intervals:
            lines.append(f"admissible intervals of T ({self.ipp} impact(s) per period):")
            for iv in self.intervals:
                lines.append(f"  [{iv.T_lo:.12g}, {iv.T_hi:.12g}]   1/T in [{1 / iv.T_hi:.8g}, {1 / iv.T_lo:.8g}]")
        else:
            lines.append(f"no admissible {self.ipp}-ipp orbit in the scanned range")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """Plain data (JSON-ready): system summary, scan, intervals."""
        return {
            "ipp": self.ipp,
            "system": {"n": self.system.n, "gap": self.system.gap},
            "linear_frequencies": self.linear_frequencies.tolist(),
            "linear_periods": (1.0 / self.linear_frequencies).tolist(),
            "orbits": [
                {"T": float(T), "frequency": float(1 / T), "resonant": True} if o is None else o.to_dict()
                for T, o in zip(self.periods, self.orbits)
            ],
            "intervals": [iv.to_dict() for iv in self.intervals],
        }

    def plot(self, ax=None, **kwargs):
        """Frequency–energy plot (see :func:`bladecase.post.plots.frequency_energy`)."""
        from ..post.plots import frequency_energy

        return frequency_energy([self], ax=ax, **kwargs)


def _solver(ipp: int) -> Callable[[LinearSystem, float], PeriodicOrbit]:
    if ipp == 1:
        return orbit_1ipp
    raise ValueError(
        f"backbone scans 1-ipp orbits (ipp = 1), got ipp = {ipp!r}: for k >= 2 impacts per period the "
        "orbits exist only on curves of impact times, use bladecase.nonsmooth_mode(system, k, T_range) "
        "(or orbits_kipp(system, T, k) at one period)"
    )


def _try(solve, system, T) -> PeriodicOrbit | None:
    try:
        return solve(system, T)
    except ValueError:
        return None


def _check(solve, system, T, probe) -> tuple[bool, float | None]:
    """Fast admissibility predicate: ``(admissible, time of a violation or None)``."""
    try:
        o = solve(system, T, polish=False, probe=probe)
    except ValueError:
        return False, probe
    return o.admissible, (None if o.admissible else o.max_violation_time / o.T)


def _bisect(solve, system, T_in: float, T_out: float, probe: float | None) -> float:
    """Boundary of admissibility between an admissible ``T_in`` and a non-admissible ``T_out``.

    Returns the admissible end of a bracket of relative width
    ``BISECTION_RTOL``.  The predicate is the certified admissibility; the
    phase ``probe`` where the non-admissible side violates the constraint is
    checked first, so most rejections are cheap.  (A root-finder on a
    continuous violation measure does not pay here: between two scan points
    of a large model lie thousands of high-mode resonances.)
    """
    tol = BISECTION_RTOL * abs(T_in)
    while abs(T_out - T_in) > tol:
        mid = 0.5 * (T_in + T_out)
        ok, where = _check(solve, system, mid, None if probe is None else probe * mid)
        if ok:
            T_in = mid
        else:
            T_out, probe = mid, where if where is not None else probe
    return T_in


def _first_resonance(omega: np.ndarray, T_a: float, T_b: float, last: bool = False) -> float | None:
    """Smallest (``last``: largest) resonant period ``2πm/ω_j`` in ``(T_a, T_b)``, or ``None``."""
    if last:
        m = np.ceil(omega * T_b / (2 * np.pi)) - 1
        r = 2 * np.pi * m / omega
        r = r[(m >= 1) & (r > T_a) & (r < T_b)]
        return float(r.max()) if r.size else None
    m = np.floor(omega * T_a / (2 * np.pi)) + 1
    r = 2 * np.pi * m / omega
    r = r[(r > T_a) & (r < T_b)]
    return float(r.min()) if r.size else None


def _phase(orbit: PeriodicOrbit | None) -> float | None:
    return None if orbit is None else orbit.max_violation_time / orbit.T


def backbone(
    system: LinearSystem,
    periods: Sequence[float] | np.ndarray,
    ipp: int = 1,
    progress: bool = False,
) -> Backbone:
    """Orbits with ``ipp`` impacts per period at each of ``periods``.

    Parameters
    ----------
    system : LinearSystem
    periods : array_like
        Periods to scan (> 0); sorted internally.  Resonant periods get no
        orbit (``None``) rather than an error.
    ipp : int
        Impacts per period.
    progress : bool
        Show a progress bar (tqdm) on standard error.

    Returns
    -------
    Backbone
        Orbits, frequency–energy data and the maximal admissible intervals of
        ``T``, whose ends are refined by bisection to ``BISECTION_RTOL``.
        An interval never contains a resonant period ``2πm/ω_j`` of a mode
        that sees the contact (the impulse changes sign there): two
        admissible scan points with a resonance between them give two
        intervals, whose ends are refined towards the resonance (an end next
        to a resonance converges to the excluded resonant period).
        Admissible stretches between two resonances that fall between the
        same two scan points are not found: scan finer.
    """
    solve = _solver(ipp)
    P = np.asarray(periods, dtype=float).reshape(-1)
    if P.size == 0:
        raise ValueError("periods is empty: give at least one period")
    if not np.all(np.isfinite(P)) or np.any(P <= 0):
        raise ValueError(f"periods must be finite and > 0, got e.g. {P[~(np.isfinite(P) & (P > 0))][0]!r}")
    P = np.unique(P)
    it = P
    if progress:
        from tqdm.auto import tqdm

        it = tqdm(P, desc=f"{ipp}-ipp orbits", unit="T", leave=False)
    orbits = [_try(solve, system, T) for T in it]
    adm = np.array([o is not None and o.admissible for o in orbits])
    omega = system.spectrum.contact_modes[0]
    # Nearest resonances 2πm/ω_j strictly inside each gap between scan points:
    # an admissible interval never contains one (Λ = -d/g(0) changes sign there).
    first_res = [_first_resonance(omega, P[g], P[g + 1]) for g in range(P.size - 1)]
    last_res = [_first_resonance(omega, P[g], P[g + 1], last=True) for g in range(P.size - 1)]
    intervals = []
    i = 0
    while i < P.size:
        if not adm[i]:
            i += 1
            continue
        j = i
        while j + 1 < P.size and adm[j + 1] and first_res[j] is None:
            j += 1
        lo = hi = None
        if i > 0:
            out = last_res[i - 1]
            lo = _bisect(solve, system, P[i], P[i - 1] if out is None else out,
                         _phase(orbits[i - 1]) if out is None else None)
        if j + 1 < P.size:
            out = first_res[j]
            hi = _bisect(solve, system, P[j], P[j + 1] if out is None else out,
                         _phase(orbits[j + 1]) if out is None else None)
        intervals.append(Interval(float(P[i] if lo is None else lo), float(P[j] if hi is None else hi),
                                  lo is not None, hi is not None))
        i = j + 1
    sp = system.spectrum
    return Backbone(
        system=system, ipp=ipp, periods=P, orbits=orbits, intervals=intervals,
        linear_frequencies=sp.frequencies[sp.active],
    )
