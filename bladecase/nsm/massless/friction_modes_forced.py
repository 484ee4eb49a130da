"""The forced response of a mode with stick–slip friction, to check the damping ratio of
:func:`~bladecase.nsm.massless.friction_modes_coulomb.coulomb_mode` against a resonance: :func:`forced_point`,
:func:`forced_sweep`, :func:`resonance`.

A harmonic force ``F cos Ωt`` along ``shape`` (interior, N) drives the :class:`NodalSystem` with stick–slip friction;
the exact event-driven simulator of :mod:`~bladecase.nsm.massless.friction_coulomb` flies it (the force enters each
phase's particular solution ``Re(X e^{iΩt})``, ``X = (K − Ω² + iΩC)⁻¹ φᵀF``, as the out-of-round casing does) to a
steady state: whole forcing periods until the followed mode's amplitude (the largest value of its open-phase
modal coordinate over a period: the turning point, as the mode's ``amplitude``) changes by less than ``rtol``
from one period to the next. A sweep continues each frequency from the previous one's end state (its nodes' stick
state too).

The resonance is read two ways. **Phase resonance** (a single nonlinear mode driven at its own frequency): the
force balances the mode's damping, ``F_q = 2ζ(a)ω(a)²a`` (``F_q = φᵀF``, the modal force), so the forced peak
gives ``ζ_F = F_q / (2ω_peak² a_peak)``. **Half-power width**: the frequencies ``Ω₁ < Ω₂`` where the amplitude is
``a_peak/√2``, ``ζ_hp = (Ω₂ − Ω₁)/(2Ω_peak)`` — exact for a linear mode, not for an amplitude-dependent one (the
flanks sit at a lower amplitude, where the mode's frequency and damping differ).

>>> import numpy as np
>>> from bladecase.nsm import Damping
>>> from bladecase.nsm.massless.nodes import NodalSystem
>>> from bladecase.nsm.massless.friction import Friction
>>> s = NodalSystem(np.eye(2), np.diag([1.0, 4.0]), np.array([[0.0], [1.0]]), [[1e-3]], gap=[0.1])
>>> f = Friction(0.4, T=[[1.0], [0.0]], C_tt=[[0.5]], model="coulomb")
>>> p = forced_point(s, f, [0.3, 0.0], 1.0, Damping(zeta=0.02), load=[0.0, 1.404])
>>> bool(p.settled), round(float(p.amplitude), 3)
(True, 0.139)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .friction import Friction
from .friction_coulomb import CoulombFlight, CoulombTrajectory
from .friction_coulomb_phase import CoulombPhase
from .nodes import NodalSystem, lcp

__all__ = ["ForcedPoint", "Resonance", "flank_mode", "forced_point", "forced_sweep", "half_power", "refine_flanks",
           "refine_peak", "resonance"]

#: Samples per forcing period at which the amplitude is read (the phases' starts added).
SAMPLES = 400


class _Forced(CoulombFlight):
    """A :class:`CoulombFlight` driven by ``Re(f e^{iΩt})`` on the interior; its start may take sticking anchors."""

    def __init__(self, system, friction, damping, sliding, load, force, frequency: float, anchors=None):
        super().__init__(system, friction, damping, None, sliding, load)
        self.nu, self.R = float(frequency), np.zeros(2 * self.m, complex)
        self.fh = self.phi.T @ np.asarray(force, dtype=complex)
        self._given = None if anchors is None else np.asarray(anchors, dtype=float)

    def phase(self, codes: np.ndarray) -> CoulombPhase:
        codes = np.asarray(codes, dtype=np.int8)
        key = codes.tobytes()
        ph = self._phases.get(key)
        if ph is None:
            ph = CoulombPhase(self, codes)
            nu, n = self.nu, self.n
            C = self.Cq if self.Cq is not None else np.zeros((n, n))
            ph.X = np.linalg.solve(ph.K - nu**2 * np.eye(n) + 1j * nu * C, self.fh)
            ph.EX = ph.Lq @ ph.X + 1j * nu * (ph.Lp @ ph.X)
            self._phases[key] = ph
        return ph

    def _stick_anchors(self, codes, q, t: float) -> np.ndarray:
        return super()._stick_anchors(codes, q, t) if self._given is None else self._given.copy()


@dataclass(frozen=True, eq=False)
class ForcedPoint:
    """One frequency's steady state: ``frequency`` (rad/s), the followed mode's ``amplitude`` over the last
    period, its relative ``change`` from the period before, ``settled``, the periods flown and the last period's
    trajectory (its end state continues a sweep)."""

    frequency: float
    amplitude: float
    change: float
    settled: bool
    periods: int
    trajectory: CoulombTrajectory


def _static(system: NodalSystem, load) -> np.ndarray:
    omega, phi = system.modes
    fq = phi.T @ np.asarray(load if load is not None else np.zeros(system.n), dtype=float)
    Wq = phi.T @ system.W
    lam = lcp(system.gap - Wq.T @ (fq / omega**2), system.H + Wq.T @ (Wq / omega[:, None] ** 2))
    return phi @ ((fq - Wq @ lam) / omega**2)


def _amplitude(tr: CoulombTrajectory, mode: int, t0: float, t1: float) -> float:
    s = tr.system
    t = np.unique(np.r_[np.linspace(t0, t1, SAMPLES + 1), tr.starts[(tr.starts > t0) & (tr.starts < t1)]])
    x, _ = tr.state(t)
    q = s.modes[1][:, mode] @ (s.M @ x)
    return float(q.max())


def forced_point(system: NodalSystem, friction: Friction, shape, frequency: float, damping=None, load=None,
                 sliding=0.0, mode: int = 0, start: ForcedPoint | None = None, rtol: float = 1e-6,
                 max_periods: int = 400, chunk: int = 10, state=None) -> ForcedPoint:
    """The steady state under ``Re(shape · e^{iΩt})`` at ``Ω = frequency`` (module docstring), from ``start``'s
    end state, or ``state`` = ``(x0, v0, codes, anchors)`` (a mode's start: ``shape`` times ``1j`` then drives it in
    phase resonance), default the static state under ``load``, at rest; flown ``chunk`` periods at a time."""
    if not (np.isfinite(frequency) and frequency > 0):
        raise ValueError(f"frequency must be a finite number > 0 (rad/s), got {frequency!r}")
    T = 2 * np.pi / frequency
    if state is not None:
        x0, v0, codes, anchors = state
    elif start is None:
        x0, v0, codes, anchors = _static(system, load), np.zeros(system.n), None, None
    else:
        tr = start.trajectory
        x, v = tr.state(tr.t_end)
        x0, v0, codes, anchors = x[:, 0], v[:, 0], tr.codes[-1], tr.anchors[-1]
    flown, before = 0, None
    while flown < max_periods:
        fl = _Forced(system, friction, damping, sliding, load, shape, frequency, anchors)
        tr = fl.simulate(x0, v0, chunk * T, codes=codes)
        if not tr.complete:
            raise ValueError(f"the forced response at {frequency:.6g} rad/s needed too many phases")
        flown += chunk
        amp = [_amplitude(tr, mode, (k - 1) * T, k * T) for k in (chunk - 1, chunk)]
        change = abs(amp[1] - amp[0]) / max(amp[1], np.finfo(float).tiny)
        x, v = tr.state(tr.t_end)
        x0, v0, codes, anchors = x[:, 0], v[:, 0], tr.codes[-1], tr.anchors[-1]
        if change <= rtol or (before is not None and abs(amp[1] - before) <= rtol * amp[1]):
            return ForcedPoint(float(frequency), amp[1], change, True, flown, tr)
        before = amp[1]
    return ForcedPoint(float(frequency), amp[1], change, False, flown, tr)


def forced_sweep(system: NodalSystem, friction: Friction, shape, frequencies, damping=None, load=None,
                 sliding=0.0, mode: int = 0, rtol: float = 1e-6, state=None) -> list[ForcedPoint]:
    """:func:`forced_point` at each of ``frequencies`` in turn, each from the previous one's end state (the first
    from ``state``, as :func:`forced_point`).

    >>> s = NodalSystem(np.eye(2), np.diag([1.0, 4.0]), np.array([[0.0], [1.0]]), [[1e-3]], gap=[0.1])
    >>> f = Friction(0.4, T=[[1.0], [0.0]], C_tt=[[0.5]], model="coulomb")
    >>> from bladecase.nsm import Damping
    >>> pts = forced_sweep(s, f, [0.3, 0.0], [0.5, 2.0], Damping(zeta=0.05), load=[0.0, 1.404], rtol=1e-4)
    >>> [round(p.amplitude, 3) for p in pts]      # stuck, a stiffness 1 + 2: 0.3 / 2.75; then slipping
    [0.109, 0.233]
    """
    out, prev = [], None
    for w in np.asarray(frequencies, dtype=float):
        prev = forced_point(system, friction, shape, w, damping, load, sliding, mode, prev, rtol,
                            state=state if prev is None else None)
        out.append(prev)
    return out


def refine_peak(system: NodalSystem, friction: Friction, shape, points: list[ForcedPoint], damping=None, load=None,
                sliding=0.0, mode: int = 0, rtol: float = 1e-6, evaluations: int = 8) -> list[ForcedPoint]:
    """``points`` (a sweep, by frequency) with ``evaluations`` more by golden-section search for the largest
    amplitude between the highest point's neighbours, each from the nearest point's end state: a leaning peak's
    top, where a parabola through three sweep points misreads it.

    >>> s = NodalSystem(np.eye(2), np.diag([1.0, 4.0]), np.array([[0.0], [1.0]]), [[1e-3]], gap=[0.1])
    >>> f = Friction(0.4, T=[[1.0], [0.0]], C_tt=[[0.5]], model="coulomb")
    >>> from bladecase.nsm import Damping
    >>> d, load = Damping(zeta=0.1), [0.0, 1.404]
    >>> pts = forced_sweep(s, f, [0.3, 0.0], [1.0, 1.2, 1.4, 1.6], d, load, rtol=1e-4)
    >>> top = max(refine_peak(s, f, [0.3, 0.0], pts, d, load, rtol=1e-4, evaluations=4), key=lambda p: p.amplitude)
    >>> round(top.frequency, 2), round(top.amplitude, 3)       # between the sweep's 1.4 and 1.6
    (1.51, 0.33)
    """
    pts = sorted(points, key=lambda p: p.frequency)
    a = np.array([p.amplitude for p in pts])
    k = int(np.clip(np.argmax(a), 1, len(pts) - 2))
    lo, hi = pts[k - 1].frequency, pts[k + 1].frequency
    g = (np.sqrt(5) - 1) / 2

    def at(w):
        near = min(pts, key=lambda p: abs(p.frequency - w))
        pt = forced_point(system, friction, shape, w, damping, load, sliding, mode, near, rtol)
        pts.append(pt)
        return pt.amplitude

    c, d = hi - g * (hi - lo), lo + g * (hi - lo)
    fc, fd = at(c), at(d)
    for _ in range(max(evaluations - 2, 0)):
        if fc > fd:
            hi, d, fd = d, c, fc
            c = hi - g * (hi - lo)
            fc = at(c)
        else:
            lo, c, fc = c, d, fd
            d = lo + g * (hi - lo)
            fd = at(d)
    return sorted(pts, key=lambda p: p.frequency)


def half_power(force: float, frequency: float, zeta: float, amplitude: float) -> tuple[float, float]:
    """The two forcing frequencies at which a single nonlinear mode of frequency ``ω(a_h)`` and ratio ``ζ(a_h)``
    (its values at ``a_h = amplitude``, the flank's amplitude) answers the modal force ``F_q`` with the amplitude
    ``a_h``: the roots of ``(F_q/a_h)² = (ω² − Ω²)² + (2ζωΩ)²``.

    >>> [round(w, 4) for w in half_power(0.1, 1.0, 0.05, 1 / np.sqrt(2))]     # linear: ≈ 1 ∓ ζ
    [0.946, 1.0465]
    """
    w2, c = frequency**2, 1 - 2 * zeta**2
    disc = w2**2 * (c**2 - 1) + (force / amplitude) ** 2
    if disc < 0 or w2 * c - np.sqrt(disc) <= 0:
        raise ValueError(f"no two frequencies give the amplitude {amplitude!r} under the modal force {force!r}")
    return float(np.sqrt(w2 * c - np.sqrt(disc))), float(np.sqrt(w2 * c + np.sqrt(disc)))


def flank_mode(low: float, high: float, modal_force: float, amplitude: float) -> tuple[float, float]:
    """The frequency ``ω(a)`` and damping ratio ``ζ(a)`` of a single nonlinear mode from the two forcing frequencies
    ``Ω₁ < Ω₂`` (rad/s) at which it answers the modal force ``F_q`` with the same amplitude ``a`` (the flanks of a
    forced curve at that level): both obey ``(ω² − Ω_i²)² + (2ζωΩ_i)² = (F_q/a)²`` with the same ``ω(a)``, ``ζ(a)``;
    their difference gives ``ω² = (Ω₁² + Ω₂²)/2 + 2(ζω)²`` and then
    ``(ζω)² = (2√(Ω₁²Ω₂² + (F_q/a)²) − Ω₁² − Ω₂²)/4``. The inverse of :func:`half_power`.

    >>> w, z = flank_mode(*half_power(0.1, 1.0, 0.05, 0.8), 0.1, 0.8)   # any level of a linear mode: its ω, ζ
    >>> round(w, 12), round(z, 12)
    (1.0, 0.05)
    """
    w1, w2 = float(low) ** 2, float(high) ** 2
    r = float(modal_force) / float(amplitude)
    if not (0 < w1 < w2 and np.isfinite(w2) and np.isfinite(r) and r > 0):
        raise ValueError(f"need 0 < low < high (rad/s) and modal_force / amplitude > 0, got low = {low!r}, "
                         f"high = {high!r}, modal_force = {modal_force!r}, amplitude = {amplitude!r}")
    c2 = (2 * np.sqrt(w1 * w2 + r**2) - w1 - w2) / 4
    if c2 < 0:
        raise ValueError(f"the flanks {low!r}, {high!r} rad/s are too far apart for the amplitude {amplitude!r} "
                         f"under the modal force {modal_force!r}: no single mode answers both")
    w = np.sqrt(0.5 * (w1 + w2) + 2 * c2)
    return float(w), float(np.sqrt(c2) / w)


def refine_flanks(system: NodalSystem, friction: Friction, shape, points: list[ForcedPoint], level: float,
                  damping=None, load=None, sliding=0.0, mode: int = 0, rtol: float = 1e-6,
                  evaluations: int = 2) -> tuple[float | None, float | None, list[ForcedPoint]]:
    """The two frequencies where a sweep's amplitude is ``level`` either side of its peak, each refined by
    ``evaluations`` secant steps (a forced point at the interpolated frequency, from the nearest point's end state,
    replacing the bracket's end on its side): ``(low, high, points with the new ones)``; ``None`` where the sweep
    does not reach ``level`` on that flank.

    >>> s = NodalSystem(np.eye(2), np.diag([1.0, 4.0]), np.array([[0.0], [1.0]]), [[1e-3]], gap=[0.1])
    >>> f = Friction(0.4, T=[[1.0], [0.0]], C_tt=[[0.5]], model="coulomb")
    >>> from bladecase.nsm import Damping
    >>> d, load = Damping(zeta=0.1), [0.0, 1.404]
    >>> pts = forced_sweep(s, f, [0.3, 0.0], [1.0, 1.3, 1.6, 1.9], d, load, rtol=1e-4)
    >>> lo, hi, pts = refine_flanks(s, f, [0.3, 0.0], pts, 0.3, d, load, rtol=1e-4, evaluations=1)
    >>> round(lo, 2), round(hi, 2)
    (1.46, 1.69)
    """
    pts = sorted(points, key=lambda p: p.frequency)
    out = []
    for side in (-1, +1):
        for _ in range(evaluations + 1):
            w = np.array([p.frequency for p in pts])
            a = np.array([p.amplitude for p in pts])
            k = int(np.argmax(a))
            idx = range(k - 1, -1, -1) if side < 0 else range(k, len(pts) - 1)
            pair = next(((i, i + 1) for i in idx if (a[i] - level) * (a[i + 1] - level) <= 0 and a[i] != a[i + 1]),
                        None)
            if pair is None:
                out.append(None)
                break
            i, j = pair
            x = float(w[i] + (level - a[i]) * (w[j] - w[i]) / (a[j] - a[i]))
            if _ == evaluations or min(abs(x - w[i]), abs(x - w[j])) <= 1e-12 * x:
                out.append(x)
                break
            near = pts[i] if abs(x - w[i]) <= abs(x - w[j]) else pts[j]
            pts = sorted(pts + [forced_point(system, friction, shape, x, damping, load, sliding, mode, near, rtol)],
                         key=lambda p: p.frequency)
    return out[0], out[1], pts


@dataclass(frozen=True)
class Resonance:
    """The resonance of a forced sweep: the peak (``frequency`` rad/s, ``amplitude``, by a parabola through the
    three highest points), ``zeta_phase = F_q / (2ω²a)`` and, where the sweep reaches ``a/√2`` on both flanks,
    the half-power frequencies and ``zeta_half_power = (Ω₂ − Ω₁)/(2Ω_peak)`` (``None`` otherwise)."""

    frequency: float
    amplitude: float
    zeta_phase: float
    low: float | None
    high: float | None
    zeta_half_power: float | None


def _crossing(w, a, level, side) -> float | None:
    idx = range(len(a) - 1)
    for i in (reversed(idx) if side < 0 else idx):
        if (a[i] - level) * (a[i + 1] - level) <= 0 and a[i] != a[i + 1]:
            return float(w[i] + (level - a[i]) * (w[i + 1] - w[i]) / (a[i + 1] - a[i]))
    return None


def resonance(points: list[ForcedPoint], modal_force: float) -> Resonance:
    """The peak and the two damping ratios of a sweep (:class:`Resonance`); ``modal_force``: ``F_q = φᵀF``.

    >>> import numpy as np
    >>> from bladecase.nsm.massless.friction_coulomb import CoulombTrajectory
    >>> pts = [ForcedPoint(w, 1 / np.hypot(1 - w**2, 0.1 * w), 0.0, True, 1, None) for w in np.linspace(0.8, 1.2, 81)]
    >>> r = resonance(pts, 1.0)
    >>> round(r.zeta_phase, 3), round(r.zeta_half_power, 3)     # linear, ζ = 0.05
    (0.05, 0.05)
    """
    w = np.array([p.frequency for p in points])
    a = np.array([p.amplitude for p in points])
    k = int(np.clip(np.argmax(a), 1, len(a) - 2))
    c = np.polyfit(w[k - 1:k + 2], a[k - 1:k + 2], 2)
    wp = float(-c[1] / (2 * c[0])) if c[0] < 0 else float(w[k])
    ap = float(np.polyval(c, wp)) if c[0] < 0 else float(a[k])
    level = ap / np.sqrt(2)
    lo = _crossing(w[: k + 1], a[: k + 1], level, -1)
    hi = _crossing(w[k:], a[k:], level, +1)
    zhp = None if lo is None or hi is None else (hi - lo) / (2 * wp)
    return Resonance(wp, ap, float(modal_force / (2 * wp**2 * ap)), lo, hi, zhp)
