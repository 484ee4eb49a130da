"""Periodic orbits with impacts: the record, its construction and certification, and the 1-ipp orbit.

An orbit with impacts at ``0 < t₁ < … < t_k = T`` and impulses ``Λ_i`` is ``x(t) = -Σ_i Λ_i G((t - t_i) mod T)``
(theory §3–4; ``G`` in :mod:`bladecase.nsm.newton.modal`).  One impact per period (k = 1) gives ``Λ = -d / g(0)``,
``g = wᵀG``.  Orbits with k >= 2 impacts are found by :func:`bladecase.nsm.newton.kipp.orbits_kipp`.

A :class:`PeriodicOrbit` is a small record (period, impact times, impulses, energy, certified admissibility)
bound to its system; it pickles without the system (:meth:`PeriodicOrbit.bind` re-attaches one).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..signals import POINTS_PER_PERIOD, TrigSum, certified_max, sincos
from ..system import LinearSystem
from .certify import certify_flights
from .modal import RESONANCE_RTOL, ModalKernel, check_period, impact_matrices

__all__ = [
    "ADMISSIBILITY_RTOL", "MAX_MODE_PERIODS", "REPEAT_RTOL", "RESONANCE_RTOL", "PeriodicOrbit", "check_long_period",
    "check_newton_system", "check_period", "impact_matrices", "make_orbit", "make_orbits", "orbit_1ipp", "repetitions",
]




def check_newton_system(system, what: str) -> LinearSystem:
    """``system`` if it is a :class:`LinearSystem` (Newton's contact model), else ``ValueError`` naming ``what``."""
    if isinstance(system, LinearSystem):
        return system
    if getattr(system, "contact_model", None) == "massless":
        raise ValueError(f"{what} solves Newton's contact model (a LinearSystem); got a MasslessSystem: its modes "
                         "come from nonsmooth_mode(system, 1, T_range) or massless_mode(system, T_range)")
    raise ValueError(f"{what}: system must be a LinearSystem (e.g. chain(...), LinearSystem(M, K, w, gap) or a "
                     f"reduced model's .system), got {type(system).__name__}")


#: An orbit is admissible when its impulses are >= 0 and
#: ``wᵀx(t) - d <= ADMISSIBILITY_RTOL · d`` is PROVED for every ``t`` of the
#: period (see :mod:`bladecase.nsm.signals`); the tolerance is raised to
#: ``10⁴ ε Σ|coefficients|`` when round-off in evaluating ``wᵀx`` is larger.
ADMISSIBILITY_RTOL = 1e-9

#: Relative tolerance (of ``T`` for times, of ``max|Λ|`` for impulses) of the
#: repeated-orbit test.
REPEAT_RTOL = 1e-7

#: Most periods of a contact mode a period ``T`` may span: beyond, ``ω_j T`` lies within the resonance
#: tolerance of a multiple of 2π whatever ``T`` (``|r - round(r)| <= 1/2 <= RESONANCE_RTOL · r`` for
#: ``r = ω_j T / 2π``): every such period is resonant to :func:`check_period`, and the phases ``ω_j t`` of the
#: impulse response are round-off.  Messages say :func:`check_long_period`'s bound on ``T``.
MAX_MODE_PERIODS = 0.5 / RESONANCE_RTOL


def check_long_period(system: LinearSystem, T, what: str) -> None:
    """``ValueError`` when the period ``T`` spans :data:`MAX_MODE_PERIODS` or more periods of a mode that sees the
    contact (the fastest is named): too long for its phases, with the valid range of ``T``.  Anything else (not a
    number, not finite or not > 0, resonant) is left to :func:`check_period` and the callers' own checks.

    >>> from bladecase.nsm import chain
    >>> check_long_period(chain(2, k=1.0, m=0.5, gap=1.0), 1e300, "orbit_1ipp")  # doctest: +NORMALIZE_WHITESPACE
    Traceback (most recent call last):
        ...
    ValueError: orbit_1ipp: period T = 1e+300 is too long: it spans 3.64186e+299 periods of mode 2 (ω = 2.28825,
    linear period 2.74585), the fastest that sees the contact; beyond 5e+11 periods every T is within the resonance
    tolerance 1e-12 of a resonance and ω_j T keeps no phase; valid: 0 < T < 1.37292e+12, away from resonances
    """
    try:
        T = float(T)
    except (TypeError, ValueError):
        return
    sp = system.spectrum
    active = np.flatnonzero(sp.active)
    if not (np.isfinite(T) and T > 0) or active.size == 0:
        return
    omega = sp.omega[active]
    j = int(np.argmax(omega))
    with np.errstate(over="ignore"):
        periods = float(omega[j] * T / (2 * np.pi))
    if periods >= MAX_MODE_PERIODS:
        linear = 2 * np.pi / omega[j]
        raise ValueError(f"{what}: period T = {_g(T)} is too long: it spans {periods:.6g} periods of mode "
                         f"{active[j] + 1} (ω = {omega[j]:.6g}, linear period {linear:.6g}), the fastest that sees the "
                         f"contact; beyond {MAX_MODE_PERIODS:.6g} periods every T is within the resonance tolerance "
                         f"{RESONANCE_RTOL:g} of a resonance and ω_j T keeps no phase; valid: 0 < T < "
                         f"{_g_below(MAX_MODE_PERIODS * linear)}, away from resonances")


def _g(x) -> str:
    """A number for a message: as written when that is short (``6.0``, ``0.95``, ``1e+300``), else ``%.6g``."""
    text = repr(float(x))
    return text if len(text) <= 8 else f"{float(x):.6g}"


def _g_below(x: float) -> str:
    """``x > 0`` to 6 significant digits, rounded down (a bound a reader may take as it is printed)."""
    shown = float(f"{x:.6g}")
    if shown > x:  # rounded up: one unit of the 6th digit less
        shown -= 10.0 ** (math.floor(math.log10(shown)) - 5)
    return f"{shown:.6g}"


def _gs(values, at_most: int = 8) -> str:
    """A list of numbers for a message, ``%.6g`` each; a long one cut (its first numbers and its length)."""
    values = list(values)
    shown = ", ".join(_g(v) for v in values[:at_most])
    return f"[{shown}]" if len(values) <= at_most else f"[{shown}, … ({len(values)} numbers)]"


@dataclass(frozen=True, eq=False)
class PeriodicOrbit:
    """A periodic orbit with ``k`` impacts per period.

    Attributes
    ----------
    system : LinearSystem or None
        The system it is an orbit of; ``None`` once unpickled (:meth:`bind` re-attaches one).
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
    stable : bool or None
        Floquet stability; ``None`` when not computed.
    multipliers : ndarray or None
        Floquet multipliers; ``None`` when not computed.

    Examples
    --------
    The 1-ipp orbit of period 6 of the two-mass chain (:func:`orbit_1ipp`):

    >>> from bladecase.nsm import chain, orbit_1ipp
    >>> orbit = orbit_1ipp(chain(2, k=1.0, m=0.5, gap=1.0), 6.0)
    >>> orbit.k, round(orbit.frequency, 6), orbit.impact_times.tolist(), round(float(orbit.impulses[0]), 6)
    (1, 0.166667, [6.0], 0.791202)
    >>> round(orbit.energy, 6), orbit.admissible, orbit.max_violation, orbit.repeats
    (0.602841, True, 0.0, 1)
    >>> orbit.contact([0.0, 3.0, 6.0]).round(6).tolist()   # wᵀx: at the obstacle (gap 1) at the impacts
    [1.0, -1.493426, 1.0]
    """

    system: LinearSystem | None = field(repr=False)
    T: float
    impact_times: np.ndarray
    impulses: np.ndarray
    energy: float
    admissible: bool
    max_violation: float
    max_violation_time: float = field(repr=False)
    repeats: int = 1
    stable: bool | None = field(default=None, repr=False)
    multipliers: np.ndarray | None = field(default=None, repr=False)

    @property
    def k(self) -> int:
        """Impacts per period."""
        return int(self.impact_times.size)

    @property
    def frequency(self) -> float:
        """``1 / T``."""
        return 1.0 / self.T

    # -- pickling without the system -------------------------------------------------------------

    def __getstate__(self) -> dict:
        state = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        state["system"] = None  # the record only: the system's matrices are not shipped
        return state

    def __setstate__(self, state: dict) -> None:
        for f in dataclasses.fields(self):
            object.__setattr__(self, f.name, state.get(f.name, f.default))

    @classmethod
    def _record(cls, system, T, impact_times, impulses, energy, admissible, max_violation, max_violation_time,
                repeats) -> PeriodicOrbit:
        """The record with these fields (``stable``, ``multipliers``: ``None``), as ``PeriodicOrbit(...)`` makes
        it, without its field-by-field frozen assignments (the searches make tens of thousands)."""
        self = object.__new__(cls)
        self.__dict__.update(system=system, T=T, impact_times=impact_times, impulses=impulses, energy=energy,
                             admissible=admissible, max_violation=max_violation,
                             max_violation_time=max_violation_time, repeats=repeats, stable=None, multipliers=None)
        return self

    def bind(self, system: LinearSystem) -> PeriodicOrbit:
        """This orbit attached to ``system`` (a copy; the record is unchanged).

        >>> import pickle
        >>> from bladecase.nsm import chain, orbit_1ipp
        >>> s = chain(2, k=1.0, m=0.5, gap=1.0)
        >>> o = pickle.loads(pickle.dumps(orbit_1ipp(s, 4.5)))
        >>> o.system is None, float(o.bind(s).contact(0.0)[0])
        (True, 1.0)
        """
        if not isinstance(system, LinearSystem):
            raise ValueError(f"bind needs a LinearSystem, got {type(system).__name__}")
        return dataclasses.replace(self, system=system)

    def _bound(self) -> LinearSystem:
        if self.system is None:
            raise ValueError("this PeriodicOrbit is not bound to a system (it was unpickled or loaded): "
                             "call orbit.bind(system) first")
        return self.system

    @cached_property
    def _modal(self) -> ModalKernel:
        return ModalKernel.of(self._bound(), self.T)

    # -- the motion ------------------------------------------------------------------------------

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
        return _segment_sum(self._modal, self.T, self.impact_times, self.impulses, i, self._bound().gap)

    # -- plain data ------------------------------------------------------------------------------

    def to_dict(self) -> dict:
        """Plain-data record (JSON-ready); :meth:`from_dict` reads it back."""
        return {
            "T": self.T,
            "frequency": self.frequency,
            "ipp": self.k,
            "impact_times": self.impact_times.tolist(),
            "impulses": self.impulses.tolist(),
            "energy": self.energy,
            "admissible": bool(self.admissible),
            "max_violation": self.max_violation,
            "max_violation_time": self.max_violation_time,
            "repeats": self.repeats,
            "stable": self.stable,
            "multipliers": None if self.multipliers is None else [[z.real, z.imag] for z in self.multipliers],
        }

    @classmethod
    def from_dict(cls, system: LinearSystem | None, data: dict) -> PeriodicOrbit:
        """The orbit back from :meth:`to_dict` (as stored: not re-solved, not re-certified)."""
        mult = data.get("multipliers")
        return cls(
            system=system, T=float(data["T"]), impact_times=np.asarray(data["impact_times"], dtype=float),
            impulses=np.asarray(data["impulses"], dtype=float), energy=_number(data["energy"]),
            admissible=bool(data["admissible"]), max_violation=_number(data["max_violation"]),
            max_violation_time=_number(data.get("max_violation_time")), repeats=int(data.get("repeats", 1)),
            stable=None if data.get("stable") is None else bool(data["stable"]),
            multipliers=None if mult is None else np.array([complex(_number(a), _number(b)) for a, b in mult]),
        )


def _number(value) -> float:
    """A stored number; ``None`` (JSON ``null``, how strict JSON writes a non-finite value) is ``NaN``."""
    return np.nan if value is None else float(value)


def _segment_sum(md: ModalKernel, T: float, times: np.ndarray, impulses: np.ndarray, i: int, d: float) -> TrigSum:
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
    _md: ModalKernel | None = None,
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

    Examples
    --------
    The 1-ipp orbit of period 6 rebuilt from its impact data; the same impact with the opposite
    (pulling) impulse is a periodic solution too, but not a motion of the impacting system:

    >>> from bladecase.nsm import chain, orbit_1ipp
    >>> system = chain(2, k=1.0, m=0.5, gap=1.0)
    >>> impulse = orbit_1ipp(system, 6.0).impulses
    >>> orbit = make_orbit(system, 6.0, [6.0], impulse)
    >>> round(orbit.energy, 6), orbit.admissible
    (0.602841, True)
    >>> pulled = make_orbit(system, 6.0, [6.0], -impulse)
    >>> pulled.admissible, round(pulled.max_violation, 6)     # wᵀx - d > 0: it crosses the casing
    (False, 0.493426)
    """
    if _md is None:  # a call from outside (the searches pass their kernel): the data checked
        T, times, lam = _orbit_data(system, T, impact_times, impulses, "make_orbit")
    else:
        times = np.asarray(impact_times, dtype=float)
        lam = np.asarray(impulses, dtype=float)
    md = _md if _md is not None else ModalKernel.of(system, T)
    d = system.gap
    q, qd = md.start_state(times, lam)  # energy from the post-impact modal state at t = 0
    energy = 0.5 * float(qd @ qd + (md.omega * q) @ (md.omega * q))
    if not certify:  # not checked: marked non-admissible, no flight looked at
        return PeriodicOrbit(system=system, T=T, impact_times=times, impulses=lam, energy=energy, admissible=False,
                             max_violation=np.nan, max_violation_time=0.0, repeats=repetitions(times, lam, T))
    # Admissibility, flight by flight.
    starts = np.concatenate([[0.0], times[:-1]])
    segments = [_segment_sum(md, T, times, lam, i, d) for i in range(times.size)]
    tols = [max(ADMISSIBILITY_RTOL * d, 1e4 * np.finfo(float).eps * f.magnitude) for f in segments]
    worst, worst_t, certified = 0.0, 0.0, True
    quick = not polish
    if quick and np.any(lam < 0):
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


def _orbit_data(system, T, impact_times, impulses, what: str) -> tuple[float, np.ndarray, np.ndarray]:
    """``(T, times, impulses)`` of one orbit checked: a LinearSystem, a finite period > 0, and as many finite
    impulses as impact times, ``0 < t₁ < … < t_k <= T`` (``ValueError`` naming ``what`` otherwise)."""
    check_newton_system(system, what)
    try:
        T = float(T)
        times = np.asarray(impact_times, dtype=float).reshape(-1)
        lam = np.asarray(impulses, dtype=float).reshape(-1)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{what}: T, impact_times and impulses must be numbers ({exc})") from None
    if not np.isfinite(T) or T <= 0:
        raise ValueError(f"{what}: period T must be finite and > 0, got {_g(T)}")
    check_long_period(system, T, what)
    if times.size == 0 or lam.shape != times.shape or not (np.all(np.isfinite(times)) and np.all(np.isfinite(lam))):
        raise ValueError(f"{what}: impact_times and impulses must be as many finite numbers (one impulse per impact), "
                         f"got {times.size} time(s) and {lam.size} impulse(s)")
    if times[0] <= 0 or np.any(np.diff(times) <= 0) or times[-1] > T * (1 + 1e-12):
        late = (f"; the last impact time exceeds T by {_g(times[-1] - T)}" if times[-1] > T * (1 + 1e-12) and
                times[0] > 0 and not np.any(np.diff(times) <= 0) else "")
        raise ValueError(f"{what}: impact_times must satisfy 0 < t1 < ... < tk = T = {_g(T)}, got "
                         f"{_gs(times)}{late}")
    return T, times, lam


def make_orbits(system: LinearSystem, T, impact_times, impulses, certify: bool = True, probe=None
                ) -> list[PeriodicOrbit]:
    """:func:`make_orbit` with ``polish=False`` of many orbits with ``k`` impacts at once (periods ``T``
    ``(B,)``, impact times and impulses ``(B, k)``): the energies, the flights' trigonometric sums and their
    certification (:func:`~bladecase.nsm.signals.certified_max_stack`'s proof, as
    :func:`~bladecase.nsm.newton.certify.certify_flights` runs it) computed for all orbits together.
    ``probe`` ``(B,)``: as in :func:`make_orbit`, a time per orbit where a violation is suspected (NaN: none),
    checked first so that an orbit violated there is rejected without its flights' proofs.

    The same records as one :func:`make_orbit` call each: admissibility proved on every flight exactly as
    there (flight by flight, stopping at the first flight not proved admissible; ``max_violation`` of a
    violated orbit is its largest sampled violation).

    >>> from bladecase.nsm import chain, orbits_kipp
    >>> system = chain(2, k=1.0, m=0.5, gap=1.0)
    >>> found = orbits_kipp(system, 13.5, 2)
    >>> again = make_orbits(system, [o.T for o in found], [o.impact_times for o in found], [o.impulses for o in found])
    >>> [(o.admissible, o.repeats, round(o.energy, 9)) for o in again] == [(o.admissible, o.repeats,
    ...                                                                     round(o.energy, 9)) for o in found]
    True
    """
    check_newton_system(system, "make_orbits")
    try:
        T = np.atleast_1d(np.asarray(T, dtype=float))
        if T.size == 0:
            return []
        times = np.asarray(impact_times, dtype=float).reshape(T.size, -1)
        lam = np.asarray(impulses, dtype=float).reshape(times.shape)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"make_orbits: T (B,), impact_times and impulses (B, k) must be numbers of matching "
                         f"shapes ({exc})") from None
    finite = T[np.isfinite(T)]
    if finite.size:
        check_long_period(system, finite.max(), "make_orbits")
    omega, b, _ = system.spectrum.contact_modes
    d = system.gap
    sh = np.sin(np.multiply.outer(T / 2, omega))  # (B, m)
    scale = b / (2 * sh)
    cos_s, sin_s = _impulse_phases(omega, T, np.zeros(T.size), times)  # the state just after the impact at t = 0
    q = -(scale / omega) * np.einsum("bmk,bk->bm", cos_s, lam)
    qd = scale * np.einsum("bmk,bk->bm", sin_s, lam)
    energy = 0.5 * (np.einsum("bm,bm->b", qd, qd) + np.einsum("bm,bm->b", omega * q, omega * q))
    worst = np.full(T.size, np.nan if not certify else 0.0)
    worst_t = np.zeros(T.size)
    certified = np.full(T.size, certify) & np.all(lam >= 0, axis=1)
    c = -b**2 / (2 * omega * sh)
    if probe is not None:
        _refute_at(np.asarray(probe, dtype=float), omega, c, d, T, times, lam, certified, worst, worst_t)
    for i in range(times.shape[1]):  # flight by flight, the orbits not yet refuted
        rows = np.flatnonzero(certified)
        if rows.size == 0:
            break
        start = np.zeros(rows.size) if i == 0 else times[rows, i - 1]
        phases = (cos_s[rows], sin_s[rows]) if i == 0 else None  # the first flight's: the energy's
        alpha, beta, tol = _flight_sums(omega, c[rows], d, T[rows], start, times[rows], lam[rows], phases)
        value, where, ok = certify_flights(alpha, beta, omega, np.full(rows.size, -d), times[rows, i] - start, tol,
                                           ends_at_zero=True)
        raise_ = value > worst[rows]
        worst[rows[raise_]], worst_t[rows[raise_]] = value[raise_], (start + where)[raise_]
        certified[rows] = ok
    repeats = _repetitions_stack(times, lam, T)
    record = PeriodicOrbit._record
    return [record(system, Ti, ti.copy(), li.copy(), ei, ai, wi, wti, ri)
            for Ti, ti, li, ei, ai, wi, wti, ri in zip(T.tolist(), times, lam, energy.tolist(), certified.tolist(),
                                                       worst.tolist(), worst_t.tolist(), repeats.tolist())]


def _refute_at(probe: np.ndarray, omega, c, d: float, T, times, lam, certified, worst, worst_t) -> None:
    """The probe of :func:`make_orbit` for the orbits of :func:`make_orbits` still ``certified`` with a finite
    ``probe``: the contact distance at 9 points within two grid steps of the probe time, in its flight; an orbit
    violated there (beyond its flight's tolerance) is marked refuted, its largest probed violation recorded."""
    rows = np.flatnonzero(certified & np.isfinite(probe))
    if rows.size == 0:
        return
    k = times.shape[1]
    at = np.mod(probe[rows], T[rows])
    i = np.minimum((times[rows] <= at[:, None]).sum(axis=1), k - 1)  # the flight (searchsorted, side="right")
    r = np.arange(rows.size)
    start = np.where(i == 0, 0.0, times[rows, np.maximum(i - 1, 0)])
    alpha, beta, tol = _flight_sums(omega, c[rows], d, T[rows], start, times[rows], lam[rows])
    step = 2 * np.pi / (POINTS_PER_PERIOD * float(omega.max()))  # TrigSum.step
    tau = np.clip((at - start)[:, None] + step * np.linspace(-2, 2, 9), 0, (times[rows, i] - start)[:, None])
    ph = tau[:, :, None] * omega
    vals = np.einsum("bjm,bm->bj", np.cos(ph), alpha) + np.einsum("bjm,bm->bj", np.sin(ph), beta) - d
    j = np.argmax(vals, axis=1)
    bad = vals[r, j] > tol
    worst[rows[bad]], worst_t[rows[bad]] = vals[r, j][bad], (start + tau[r, j])[bad]
    certified[rows[bad]] = False


def _flight_sums(omega, c, d: float, T, start, times, lam, phases=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The flights from ``start`` of many orbits: the contact distance ``-d + Σ α cos(ωτ) + β sin(ωτ)`` at
    ``τ`` after ``start`` as ``(α, β)`` ``(B, m)``, and each flight's admissibility tolerance ``(B,)``
    (``c = -b²/(2ω sin(ωT/2))`` per orbit; ``phases``: :func:`_impulse_phases` there, when known)."""
    cs, sn = _impulse_phases(omega, T, start, times) if phases is None else phases
    alpha = c * np.einsum("bmk,bk->bm", cs, lam)
    beta = -c * np.einsum("bmk,bk->bm", sn, lam)
    tol = np.maximum(ADMISSIBILITY_RTOL * d, 1e4 * np.finfo(float).eps * np.hypot(alpha, beta).sum(axis=1))
    return alpha, beta, tol


def _impulse_phases(omega: np.ndarray, T: np.ndarray, start: np.ndarray, times: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
    """``cos``, ``sin`` of ``ω_m θ_j`` ``(B, m, k)``, ``θ_j = ((start - t_j) mod T) - T/2``: the phase of each
    impulse at ``start`` (the terms of :func:`_segment_sum` and :meth:`ModalKernel.start_state`)."""
    theta = np.mod(start[:, None] - times, T[:, None]) - (T / 2)[:, None]
    sn, cs = sincos(omega[None, :, None] * theta[:, None, :])
    return cs, sn


def _repetitions_stack(times: np.ndarray, impulses: np.ndarray, T: np.ndarray) -> np.ndarray:
    """:func:`repetitions` of each row."""
    k = times.shape[1]
    scale = np.maximum(np.abs(impulses).max(axis=1), np.finfo(float).tiny)
    out = np.ones(len(T), dtype=int)
    for j in range(2, k + 1):  # the largest j that repeats wins
        if k % j:
            continue
        shift = k // j
        dt = np.mod(np.roll(times, -shift, axis=1) - times, T[:, None])
        same = np.all(np.abs(dt - (T / j)[:, None]) <= REPEAT_RTOL * T[:, None], axis=1) & np.all(
            np.abs(np.roll(impulses, -shift, axis=1) - impulses) <= REPEAT_RTOL * scale[:, None], axis=1)
        out[same] = j
    return out


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
        ``T`` not a positive finite number, too long (:func:`check_long_period`), resonant (some
        ``ω_j T ∈ 2πℤ`` with ``b_j ≠ 0``), or ``g(0) = 0`` (no impulse brings the orbit to the obstacle).

    ``options`` are passed to :func:`make_orbit` (``polish``, ``probe``, ``certify``).

    Examples
    --------
    >>> from bladecase.nsm import chain
    >>> o = orbit_1ipp(chain(2, k=1.0, m=0.5, gap=1.0), 4.5)
    >>> o.k, o.admissible, round(float(o.impulses[0]), 6), round(o.energy, 6)
    (1, True, 2.486244, 1.833362)
    >>> x, v = o.state(0.0)       # post-impact state, at the obstacle
    >>> round(float(x[1, 0]), 12)
    1.0
    """
    check_newton_system(system, "orbit_1ipp")
    check_long_period(system, T, "orbit_1ipp")
    T = check_period(system, T)
    md = ModalKernel.of(system, T)
    g0 = float(np.sum(md.b**2 * np.cos(md.omega * T / 2) / (2 * md.omega * md.sin_half)))
    if g0 == 0.0 or not np.isfinite(g0):
        raise ValueError(f"no 1-ipp orbit at T = {_g(T)}: the impulse response does not reach the obstacle "
                         f"(g(0) = {_g(g0)})")
    lam = -system.gap / g0
    return make_orbit(system, T, [T], [lam], md, **options)
