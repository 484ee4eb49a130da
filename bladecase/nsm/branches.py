"""Branches of periodic orbits — the nonsmooth modes — and how they are found.

One type, :class:`Branch`, holds a sequence of k-ipp orbits with its admissible :class:`Arc` s, whether it came
from a scan of periods (:func:`bladecase.nsm.newton.scan.backbone`, 1 impact per period: one orbit per requested
period, ``None`` at resonant ones) or from continuation along the solution curve (:func:`nonsmooth_mode`, any
``k``; the curve is followed through turning points in ``T`` by :mod:`bladecase.nsm.continuation`).
``Family``, ``Backbone`` and ``Interval`` are the former names of :class:`Branch` and :class:`Arc`.

Serialisation lives here only: :meth:`Branch.to_dict` and :meth:`Branch.from_dict`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .newton.families import ARC_RTOL, MERGE_RTOL
from .newton.kipp import check_k
from .newton.modal import ModalKernel, check_period, solve_times
from .newton.orbits import PeriodicOrbit, make_orbit
from .system import LinearSystem

__all__ = ["ARC_RTOL", "MERGE_RTOL", "Arc", "Backbone", "Branch", "Family", "Interval"]  # nonsmooth_mode: .modes

SPACINGS = ("index", "state", "period")



@dataclass(frozen=True)
class Arc:
    """An admissible arc of a branch: points ``start..stop`` (inclusive) and its
    period range ``[T_lo, T_hi]``.

    ``refined_lo``/``refined_hi`` say whether that end is where admissibility
    is lost (refined by bisection, along the curve or in ``T``); otherwise the
    arc ends where the branch itself ends (period range or scan end, resonance,
    impacts merging, branch point with a repeated orbit).  Along a curve with a
    turning point ``T`` is not monotone: ``T_lo``/``T_hi`` are the extreme
    periods of the arc.

    Examples
    --------
    The admissible arcs of a 1-ipp scan of the two-mass chain: the first starts where the scan
    starts (``T = 4``, not refined), both other ends are where admissibility is lost, found by bisection:

    >>> from bladecase.nsm import backbone, chain
    >>> branch = backbone(chain(2, k=1.0, m=0.5, gap=1.0), np.linspace(4.0, 12.0, 9))
    >>> [(a.start, a.stop, round(a.T_lo, 6), round(a.T_hi, 6), a.refined_lo) for a in branch.arcs]
    [(0, 1, 4.0, 5.491705, False), (2, 3, 5.650149, 7.188736, True)]
    >>> Arc.from_dict(branch.arcs[1].to_dict()) == branch.arcs[1]
    True
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

    @classmethod
    def from_dict(cls, data: dict) -> Arc:
        return cls(int(data["start"]), int(data["stop"]), float(data["T_lo"]), float(data["T_hi"]),
                   bool(data["refined_lo"]), bool(data["refined_hi"]))


@dataclass(frozen=True, eq=False)
class Branch:
    """A branch of k-ipp periodic orbits (a nonsmooth mode, or a 1-ipp backbone scan).

    Attributes
    ----------
    system : LinearSystem or None
        ``None`` once unpickled (:meth:`bind` re-attaches one).
    k : int
        Impacts per period (also :attr:`ipp`).
    orbits : list of PeriodicOrbit (or None)
        The points: in continuation order along a curve (``T`` need not be
        monotone), or one per scanned period (``None`` where it is resonant).
    arcs : list of Arc
        Maximal admissible stretches (also :attr:`intervals`).
    periods : ndarray or None
        The scanned periods (a scan); ``None`` for a curve (the orbits' periods).
    source : str
        ``"scan"`` (periods given) or ``"curve"``.

    Examples
    --------
    A scan of 1-ipp orbits of the two-mass chain (one orbit per period; :func:`~bladecase.nsm.newton.scan.backbone`):

    >>> from bladecase.nsm import backbone, chain
    >>> system = chain(2, k=1.0, m=0.5, gap=1.0)
    >>> branch = backbone(system, np.linspace(4.0, 12.0, 9))
    >>> branch.k, branch.source, branch.T.tolist()
    (1, 'scan', [4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0])
    >>> branch.energy.round(6)[:4].tolist(), branch.admissible.tolist()
    ([14.800367, 0.854346, 0.602841, 0.265441], [True, True, True, True, False, False, False, False, False])
    >>> [(round(a.T_lo, 6), round(a.T_hi, 6)) for a in branch.arcs]   # admissible period ranges
    [(4.0, 5.491705), (5.650149, 7.188736)]
    >>> [(o.T, o.admissible) for o in branch.orbit_at(5.2)]           # re-solved between scanned points
    [(5.2, True)]
    >>> again = Branch.from_dict(system, branch.to_dict())            # plain data (JSON) and back
    >>> again.arcs == branch.arcs, again.energy.tolist() == branch.energy.tolist()
    (True, True)
    """

    system: LinearSystem | None = field(repr=False)
    k: int
    orbits: list = field(repr=False)
    arcs: list
    periods: np.ndarray | None = field(default=None, repr=False)
    source: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "k", check_k(self.k))
        object.__setattr__(self, "orbits", list(self.orbits))
        object.__setattr__(self, "arcs", list(self.arcs))
        if self.periods is not None:
            P = np.asarray(self.periods, dtype=float).reshape(-1)
            if P.size != len(self.orbits):
                raise ValueError(f"periods has {P.size} entries for {len(self.orbits)} orbits")
            object.__setattr__(self, "periods", P)
        elif any(o is None for o in self.orbits):
            raise ValueError("a branch with missing orbits (None) needs the periods of its points")
        source = self.source or ("scan" if self.periods is not None else "curve")
        if source not in ("scan", "curve"):
            raise ValueError(f"source must be 'scan' or 'curve', got {self.source!r}")
        object.__setattr__(self, "source", source)

    # -- columns ---------------------------------------------------------------------------------

    def _column(self, get, default=np.nan) -> np.ndarray:
        return np.array([default if o is None else get(o) for o in self.orbits])

    @property
    def ipp(self) -> int:
        """Impacts per period (``k``)."""
        return self.k

    @property
    def T(self) -> np.ndarray:
        """``(N,)`` period of every point."""
        return self.periods if self.periods is not None else np.array([o.T for o in self.orbits], dtype=float)

    @property
    def frequencies(self) -> np.ndarray:
        """``1 / T`` of every point."""
        return 1.0 / self.T

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
    def impact_times(self) -> np.ndarray:
        """``(N, k)`` impact times (NaN rows where no orbit; rows padded with NaN when the orbits' counts differ,
        as along a massless mode whose number of contact phases changes)."""
        rows = [np.full(self.k, np.nan) if o is None else np.asarray(o.impact_times, float) for o in self.orbits]
        width = max([self.k] + [r.size for r in rows])
        return np.array([np.pad(r, (0, width - r.size), constant_values=np.nan) for r in rows])

    @property
    def impulses(self) -> np.ndarray:
        """``(N, k)`` impulses (NaN rows where no orbit)."""
        return np.array([np.full(self.k, np.nan) if o is None else o.impulses for o in self.orbits])

    @property
    def stable(self) -> np.ndarray:
        """Per-point Floquet stability (object array: ``True``/``False``, ``None`` where not computed)."""
        return np.array([None if o is None else o.stable for o in self.orbits], dtype=object)

    @property
    def intervals(self) -> list[Arc]:
        """The admissible arcs (former name, from the backbone scans)."""
        return self.arcs

    @property
    def linear_frequencies(self) -> np.ndarray:
        """``ω_j / 2π`` of the modes that see the contact."""
        sp = self._bound().spectrum
        return sp.frequencies[sp.active]

    # -- binding and pickling ----------------------------------------------------------------------

    def _bound(self) -> LinearSystem:
        if self.system is None:
            raise ValueError("this Branch is not bound to a system (it was unpickled): call branch.bind(system)")
        return self.system

    def __getstate__(self) -> dict:
        return {"k": self.k, "orbits": self.orbits, "arcs": self.arcs, "periods": self.periods,
                "source": self.source, "system": None}

    def __setstate__(self, state: dict) -> None:
        for name, value in state.items():
            object.__setattr__(self, name, value)

    def bind(self, system: LinearSystem) -> Branch:
        """This branch (and its orbits) attached to ``system``."""
        orbits = [None if o is None else o.bind(system) for o in self.orbits]
        return Branch(system, self.k, orbits, self.arcs, self.periods, self.source)

    def compact(self) -> Branch:
        """The same orbits without the missing (resonant) points, as a curve; arcs re-indexed."""
        keep = [i for i, o in enumerate(self.orbits) if o is not None]
        new = {old: n for n, old in enumerate(keep)}
        arcs = [Arc(new[a.start], new[a.stop], a.T_lo, a.T_hi, a.refined_lo, a.refined_hi) for a in self.arcs]
        return Branch(self.system, self.k, [self.orbits[i] for i in keep], arcs)

    # -- orbits anywhere on the branch ---------------------------------------------------------------

    def orbit_at(self, T: float) -> list[PeriodicOrbit]:
        """The branch's orbits of period ``T`` (one per crossing of ``T`` by the curve),
        each re-solved exactly from the interpolated neighbours; ``[]`` where the branch does not reach ``T``.

        Newton's contact: the impact times interpolated, then Newton at ``T``.  The massless contact model
        (a branch of :func:`~bladecase.nsm.massless.branches.massless_modes` or
        :func:`~bladecase.nsm.massless.branches.massless_mode`): the contact half-time or the half-phase
        durations interpolated, then Newton at ``T``, through changes of the number of contact phases
        (:func:`~bladecase.nsm.massless.branches.massless_orbit_at`).  ``T`` on a computed point gives that
        orbit once.

        >>> from bladecase.nsm import chain, nonsmooth_mode
        >>> families = nonsmooth_mode(chain(2, k=1.0, m=0.5, gap=1.0), 2, (13.2, 13.75), scan=2)
        >>> (mode,) = [f for f in families if f.arcs]
        >>> [(o.T, round(float(o.impact_times[0]), 6), o.admissible) for o in mode.orbit_at(13.5)]
        [(13.5, 6.082917, True)]
        """
        system = self._bound()
        if getattr(system, "contact_model", "newton") == "massless":
            from .massless.orbit_at import massless_orbit_at

            return massless_orbit_at(system, self.orbits, T)
        out = []
        Ts = self.T
        T = check_period(system, T)
        for i in range(len(Ts) - 1):
            a_orb, b_orb = self.orbits[i], self.orbits[i + 1]
            lo, hi = sorted((Ts[i], Ts[i + 1]))
            if a_orb is None or b_orb is None or not lo <= T <= hi or hi == lo:
                continue
            a = (T - Ts[i]) / (Ts[i + 1] - Ts[i])
            guess = (1 - a) * a_orb.impact_times / Ts[i] + a * b_orb.impact_times / Ts[i + 1]
            sol = solve_times(ModalKernel.of(system, T), guess * T, system.gap)
            if sol is None:
                continue
            orbit = make_orbit(system, T, *sol)
            if not any(o.impact_times.shape == orbit.impact_times.shape and
                       np.allclose(orbit.impact_times, o.impact_times, rtol=0, atol=1e-9 * T) for o in out):
                out.append(orbit)  # T on a computed point: the pairs on both sides give it
        return out

    def _arc_through(self, at: float | None) -> Arc | None:
        """The arc whose period range holds ``at``, else the widest arc (``None`` if there is none)."""
        arcs = [a for a in self.arcs if at is not None and a.T_lo <= at <= a.T_hi]
        arcs = arcs or sorted(self.arcs, key=lambda a: a.T_lo - a.T_hi)[:1]
        return arcs[0] if arcs else None

    def sample(self, count: int, *, at: float | None = None, spacing: str = "index",
               admissible_only: bool = True) -> list[PeriodicOrbit]:
        """``count`` orbits spread over the branch (or over the admissible arc through period ``at``).

        ``spacing``: ``"index"`` — evenly by index among the computed orbits; ``"state"`` — evenly in the
        cumulative RMS distance between consecutive orbits' states (64 phases each), so fast-changing
        stretches are not crowded; ``"period"`` — re-solved (:meth:`orbit_at`) at evenly spaced periods
        over the arc through ``at`` (the widest arc when ``at`` is None or in no arc), keeping at each
        period the admissible orbit closest in impact phases to the previous one.  The first two pick
        admissible orbits only when ``admissible_only``; fewer orbits come back where fewer exist.
        """
        if spacing not in SPACINGS:
            raise ValueError(f"spacing must be one of {SPACINGS}, got {spacing!r}")
        if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
            raise ValueError(f"count must be an integer >= 1, got {count!r}")
        if spacing == "period":
            return self._sample_periods(count, at)
        idx = np.array([i for i, o in enumerate(self.orbits) if o is not None], dtype=int)
        if at is not None:
            arc = self._arc_through(at)
            idx = idx[(idx >= arc.start) & (idx <= arc.stop)] if arc is not None else idx[:0]
        if admissible_only:
            idx = idx[self.admissible[idx]]
            if idx.size == 0:
                raise ValueError("the branch has no admissible orbit (use admissible_only=False)")
        if spacing == "index":
            pick = idx[np.unique(np.linspace(0, idx.size - 1, count).round().astype(int))]
        else:
            theta = np.arange(64) / 64
            states = np.array([np.concatenate(self.orbits[i].state(theta * self.orbits[i].T)).ravel() for i in idx])
            dist = np.concatenate([[0.0], np.cumsum(np.sqrt(np.mean(np.diff(states, axis=0) ** 2, axis=1)))])
            pick = idx[np.unique([int(np.argmin(np.abs(dist - s))) for s in np.linspace(0.0, dist[-1], count)])]
        return [self.orbits[i] for i in pick]

    def _sample_periods(self, count: int, at: float | None) -> list[PeriodicOrbit]:
        arc = self._arc_through(at)
        if arc is None:
            return []
        pad = 1e-6 * (arc.T_hi - arc.T_lo)
        out: list[PeriodicOrbit] = []
        for Tj in np.linspace(arc.T_lo + pad, arc.T_hi - pad, count):
            try:
                cands = [o for o in self.orbit_at(Tj) if o.admissible]
            except ValueError:  # a resonant period
                continue
            if not cands:
                continue
            if out:
                ref = out[-1].impact_times / out[-1].T
                cands.sort(key=lambda o: np.abs(o.impact_times / o.T - ref).max())
            out.append(cands[0])
        return out

    def manifold(self, n_orbits: int = 40, n_times: int = 200, admissible_only: bool = True, *,
                 at: float | None = None, spacing: str = "index"):
        """Sample the branch's 2-D invariant manifold ``(T, t) ↦ (x, v)``.

        ``n_orbits`` orbits picked by :meth:`sample` (default: evenly by index over the admissible
        arcs when ``admissible_only``) and ``n_times`` instants ``t = θT``, ``θ ∈ [0, 1)``, on each.

        Returns
        -------
        T : (m,) periods (``m <= n_orbits``);  theta : (n_times,) phases;
        x, v : (n, m, n_times) positions and velocities.
        """
        orbits = self.sample(n_orbits, at=at, spacing=spacing, admissible_only=admissible_only)
        if not orbits:
            raise ValueError("no orbit to sample on the branch")
        theta = np.arange(n_times) / n_times
        states = [o.state(theta * o.T) for o in orbits]
        return (np.array([o.T for o in orbits]), theta, np.stack([s[0] for s in states], axis=1),
                np.stack([s[1] for s in states], axis=1))

    # -- plain data ----------------------------------------------------------------------------------

    def to_dict(self) -> dict:
        """Plain data (JSON-ready); :meth:`from_dict` reads it back.

        Keys: ``ipp``, ``source``, ``orbits`` (records; ``{"T", "frequency", "resonant": true}`` at a
        resonant scan period), ``arcs`` (with point indices), ``intervals`` (their period ranges), and,
        when bound, ``system`` (``n``, ``gap``), ``linear_frequencies``, ``linear_periods``.
        """
        out: dict = {"ipp": self.k, "source": self.source}
        if self.system is not None:
            lf = self.linear_frequencies
            out.update(system={"n": self.system.n, "gap": self.system.gap}, linear_frequencies=lf.tolist(),
                       linear_periods=(1.0 / lf).tolist())
        out["orbits"] = [{"T": float(T), "frequency": float(1 / T), "resonant": True} if o is None else o.to_dict()
                         for T, o in zip(self.T, self.orbits)]
        out["arcs"] = [a.to_dict() for a in self.arcs]
        out["intervals"] = [{"T_lo": a.T_lo, "T_hi": a.T_hi, "refined_lo": a.refined_lo, "refined_hi": a.refined_hi}
                            for a in self.arcs]
        return out

    @classmethod
    def from_dict(cls, system: LinearSystem | None, data: dict) -> Branch:
        """A branch back from :meth:`to_dict` (orbits as stored: not re-solved, not re-certified).

        Also reads the documents written before the branch types were merged: a family's
        (``ipp``, ``arcs``, ``orbits``) and a backbone's (``intervals`` without point indices).
        """
        try:
            k = check_k(int(data["ipp"]))
            n = (data.get("system") or {}).get("n")
            if system is not None and n is not None and int(n) != system.n:
                raise ValueError(f"the branch was computed on a system of {n} dofs, this one has {system.n}")
            orbits, periods = [], []
            for rec in data["orbits"]:
                orbit = None if rec.get("resonant") else _orbit_from_dict(system, rec)
                orbits.append(orbit)
                periods.append(float(rec["T"]))
            if "arcs" in data:
                arcs = [Arc.from_dict(a) for a in data["arcs"]]
            else:
                arcs = [_interval_arc(iv, periods, orbits) for iv in data["intervals"]]
            source = data.get("source") or ("curve" if "arcs" in data else "scan")
        except (KeyError, TypeError, AttributeError) as exc:
            raise ValueError(f"not a branch document (as written by Branch.to_dict): missing or bad {exc}") from None
        return cls(system, k, orbits, arcs, periods if source == "scan" else None, source)

    def table(self, points: bool | None = None) -> str:
        """Human-readable summary: a header line, one row per point (``points``; default: for scans),
        then the admissible arcs.

        Newton's contact speaks of impacts (times and impulses); the massless contact model of contact phases
        (the instants the contact closes, ``∫λ dt`` over each phase, the number of phases per period).
        """
        massless = getattr(self.system, "contact_model", None) == "massless" or any(
            getattr(o, "contact_model", None) == "massless" for o in self.orbits if o is not None)
        k, T = self.k, self.T
        span = f"{len(self.orbits)} orbits ({self.source}), T in [{T.min():.8g}, {T.max():.8g}]"
        lines = [f"nonsmooth mode (massless contact), {span}, {_phases(self.orbits)} per period" if massless
                 else f"{k}-ipp family, {span}"]
        if points if points is not None else self.source == "scan":
            lines.append(f"{'T':>14} {'1/T':>12} {'energy':>12} " + (f"{'phases':>6} " if massless else "")
                         + (f"{'contact closes at':>36} {'∫λ dt per phase':>30}" if massless
                            else f"{'impact times':>36} {'impulses':>30}") + " admissible")
            for Tp, o in zip(T, self.orbits):
                if o is None:
                    lines.append(f"{Tp:14.8g} {1 / Tp:12.6g} {'resonant':>12}")
                    continue
                times = " ".join(f"{t:.6g}" for t in o.impact_times)
                imp = " ".join(f"{x:.5g}" for x in o.impulses)
                lines.append(f"{Tp:14.8g} {1 / Tp:12.6g} {o.energy:12.6g} " + (f"{o.k:>6} " if massless else "")
                             + f"{times:>36} {imp:>30} {'yes' if o.admissible else 'no'}")
        lines.append("")
        if self.arcs:
            lines.append("admissible intervals of T:" if massless else
                         f"admissible intervals of T ({k} impact(s) per period):")
            for a in self.arcs:
                lines.append(f"  admissible arc: T in [{a.T_lo:.12g}, {a.T_hi:.12g}]   "
                             f"1/T in [{1 / a.T_hi:.8g}, {1 / a.T_lo:.8g}]   (points {a.start}..{a.stop}"
                             + (f"; {_phases(self.orbits[a.start: a.stop + 1])} per period)" if massless else ")"))
        else:
            lines.append("no admissible arc: no admissible orbit in the " + self.source if massless else
                         f"no admissible arc: no admissible {k}-ipp orbit in the {self.source}")
        return "\n".join(lines)

    def stability(self, tol: float | None = None, where=None) -> np.ma.MaskedArray:
        """Floquet verdict of every point: ``True`` (linearly stable) / ``False``, masked where there is no orbit
        or no verdict (:func:`~bladecase.nsm.floquet.branch_stability`; saltation matrices at impacts);
        ``where``: only these points (e.g. ``branch.admissible``), the others masked.

        >>> from bladecase.nsm import backbone, chain
        >>> branch = backbone(chain(2, k=1.0, m=0.5, gap=1.0), np.linspace(6.0, 7.0, 5))
        >>> branch.stability().tolist()
        [True, True, False, True, True]
        """
        from .floquet import FLOQUET_TOL, branch_stability

        return branch_stability(self, FLOQUET_TOL if tol is None else tol, where)

    def plot(self, ax=None, **kwargs):
        """Frequency–energy plot (see :func:`bladecase.post.plots.frequency_energy`)."""
        from ..post.plots import frequency_energy

        return frequency_energy([self], ax=ax, **kwargs)


def _phases(orbits: list) -> str:
    """``"1 contact phase"`` / ``"1 to 3 contact phases"``: the range of the orbits' numbers of contact phases."""
    counts = sorted({int(o.k) for o in orbits if o is not None})
    if not counts:
        return "no contact phase"
    lo, hi = counts[0], counts[-1]
    return f"{lo} contact phase{'s' if lo > 1 else ''}" if lo == hi else f"{lo} to {hi} contact phases"


def _interval_arc(iv: dict, periods: list[float], orbits: list) -> Arc:
    """An arc from a period interval of an old backbone document: the admissible points inside it."""
    idx = [i for i, (T, o) in enumerate(zip(periods, orbits))
           if o is not None and o.admissible and iv["T_lo"] <= T <= iv["T_hi"]]
    if not idx:
        raise ValueError(f"interval [{iv['T_lo']}, {iv['T_hi']}] holds no admissible orbit of the document")
    return Arc(idx[0], idx[-1], float(iv["T_lo"]), float(iv["T_hi"]), bool(iv["refined_lo"]), bool(iv["refined_hi"]))


def _orbit_from_dict(system, rec: dict):
    """An orbit record of either contact model (``contact_model`` key; Newton when absent)."""
    if rec.get("contact_model") == "massless":
        from .massless.orbits import SymmetricOrbit

        if "durations" in rec:
            from .massless.phases import PhasedOrbit

            return PhasedOrbit.from_dict(system, rec)

        return SymmetricOrbit.from_dict(system, rec)
    return PeriodicOrbit.from_dict(system, rec)


#: Former names: the continuation family and the 1-ipp scan are one type now.
Family = Branch
Backbone = Branch
#: Former name of the admissible stretch of a 1-ipp scan: the same type as :class:`Arc`.
Interval = Arc
