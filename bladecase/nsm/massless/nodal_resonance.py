"""A nodal family followed through its internal resonances (theory §8): the steps along the family, the tongues it
meets, and their crossing.

:func:`~bladecase.nsm.massless.nodal_modes.nodal_family` checks its input and builds the shooting problem
(:mod:`~bladecase.nsm.massless.nodal_modes`: Gauss–Newton on the exact flow, the exact Jacobian) and the grazing
orbit; the driver here steps along the family — natural-parameter steps in the energy, or pseudo-arclength — applies
the stop tests, and records the tongues met (``NodalFamily.tongues``) and where and why the family ends
(``NodalFamily.end``, with the backbone's trend below it: :func:`backbone_trend`).

**Internal resonances.** Where the family's frequency meets ``ω_j/N`` for a higher open-phase mode ``j`` (a
frequency ratio ``N:1``, or ``p:q``), the family turns into that mode: a "tongue" along which the energy grows at
an almost constant period while mode ``j`` takes the modal energy (measured by each mode's share of
``Σ ½(ω_i²q_i² + p_i²)`` at ``t = 0``). An energy step lands beyond a tongue thinner than itself, on the same
backbone; arclength follows it. Followed, a tongue does not lead back: on the demo blade (8:1 with the third mode,
215.50 Hz) and on the 3-mass chain of the tests (3:1) the arclength family keeps turning into mode ``j`` — 0.5 %
of the modal energy left in the first mode at 25 times the energy where the tongue began — it has become mode
``j``'s subharmonic family, and the first mode's backbone goes on beyond the resonance on a separate branch (the
two modes' branches avoid crossing; no fold leads from one to the other). Where such a resonance falls depends on
the mesh (the high modes move with it: 215.50 Hz, 8:1, on the demo's tip mesh; 215.90 Hz, 4:1 with the second
mode, on a finer one), so a family that stops there stops at a property of the mesh.

An orbit whose mode holds less than ``backbone_share`` (:data:`BACKBONE_SHARE`) of the modal energy is in a tongue
(``NodalFamily.tongues``, ``NodalFamily.on_backbone``); below :data:`RESONANCE_SHARE` the family has
turned. Then, by default, it stops, and says where and why (``NodalFamily.end``: the mode, the ratio, the
backbone's trend below it, :func:`backbone_trend`). With ``through_resonances=True`` the tongue is CROSSED: from
the backbone's reference orbit before the tongue (the last one at least :data:`TREND_SHARE` in the mode, else the
cleanest of the stretch), orbits are solved at fixed periods beyond the tongue's frequency, ``f_tongue ±
d·2^(k/2)`` (``d`` the distance in frequency from the last orbit on the backbone to the tongue; as far as the
backbone's span from grazing or :data:`CROSS_SPAN` of the frequency), by Newton from the secant along the
backbone's last two orbits or, failing that, from the reference orbit itself; the first one on the backbone
(share ``>= backbone_share``, energy above the reference's, the same turning point, the energy growing along the
curve in the backbone's direction of frequency) resumes the family — by pseudo-arclength along the tangent there
(a stretch between two resonances can dip in energy), by the family's own steps once its energy grows. That orbit
is not connected to the tongue's by continuation (``NodalFamily.landings``; ``NodalFamily.at_energy`` does
not interpolate across it). A tongue with no backbone orbit beyond it — the motion stays shared between the two
modes, as at the chain's 2:1 resonance when its first mass is doubled — ends the family.

>>> resonance_ratio(3.02), BACKBONE_SHARE, RESONANCE_SHARE
((3, 1), 0.9, 0.5)
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from ... import log
from .nodal_orbit import NodalOrbit, _Flow, _Shooter

__all__ = ["BACKBONE_SHARE", "RESONANCE_SHARE", "TONGUE_POINTS", "backbone_trend", "resonance_ratio"]

#: A family has turned into another mode (an internal resonance: it stops there, or crosses it) when its mode holds
#: less than this share of the modal energy at t = 0.
RESONANCE_SHARE = 0.5

#: An orbit is on the backbone when its mode holds at least this share of the modal energy at t = 0; a run of orbits
#: below it is a tongue (``NodalFamily.tongues``).
BACKBONE_SHARE = 0.9

#: The backbone's trend (the crossing's predictor, :func:`backbone_trend`) is read on orbits at least this clean.
TREND_SHARE = 0.98

#: Most orbits followed inside a tongue (still above ``resonance_share``) before crossing it.
TONGUE_POINTS = 12

#: Most periods tried beyond a tongue when crossing it: ``f_tongue ± d·2^(k/2)``, ``k = 0, 1, …`` (module docstring),
#: as far as the backbone's own span from grazing or this share of the frequency, whichever is larger.
CROSS_TRIES = 16
CROSS_SPAN = 0.02

#: Steps of the pseudo-arclength stretch that follows a crossing (the family's own steps resume after it).
RESUME_STEPS = (0.02, 0.5, 1e-4)


# ----------------------------------------------------------------------------- the steps


def _energy_step(prob, state: dict, h: float) -> tuple[_Flow, int]:
    """One natural-parameter step ``ln E → ln E + h`` from the secant predictor."""
    us, Es = state["u"], state["E"]
    E = Es[-1] * np.exp(h)
    if len(us) == 1:
        up = us[0].copy()
        up[:-1] *= np.sqrt(E / Es[0])
    else:
        up = us[-1] + (us[-1] - us[-2]) * (h / np.log(Es[-1] / Es[-2]))

    def extra(u):
        value, row = prob.energy_row(u)
        return (value - E) / E, row / E
    u, f, _, its = prob.newton(up, extra)
    us.append(u)
    Es.append(prob.sh.energy(*prob.unpack(u)[:2]))
    return f, its


def _arclength_step(prob, state: dict, h: float) -> tuple[_Flow, int]:
    """One pseudo-arclength step of length ``h`` along the tangent (the amplitude's direction at grazing)."""
    u0 = state["u"][-1]
    tan = state["tan"]
    if tan is None:
        tan = np.r_[u0[:-1] / np.linalg.norm(u0[:-1]), 0.0]  # the amplitude grows; dT/ds = 0 at grazing
    up = u0 + h * tan

    def extra(v):
        return float(tan @ (v - up)), tan
    u, f, _, its = prob.newton(up, extra)
    if (u - u0) @ tan <= 0:
        raise ValueError(f"the continuation turned back at T = {f.T:.12g} s")
    state["tan"] = prob.tangent(prob.jacobian(f), tan)
    state["u"].append(u)
    state["E"].append(prob.sh.energy(*prob.unpack(u)[:2]))
    return f, its


# ----------------------------------------------------------------------------- the driver


class _Run:
    """One family being followed (:func:`~bladecase.nsm.massless.nodal_modes.nodal_family`): the orbits, the
    stepper's state, the tongues crossed.

    ``prob`` is the family's shooting problem (``nodal_modes._Problem``: ``pack``/``unpack``, ``newton``,
    ``jacobian``, ``tangent``, ``energy_row``, scaled by ``grazing``), ``grazing`` its first orbit."""

    def __init__(self, prob, grazing: NodalOrbit, method: str, steps: tuple, opts: dict):
        g = grazing
        self.sh, self.mode, self.method, self.steps, self.opts = prob.sh, prob.mode, method, steps, opts
        self.prob = prob
        self.state = {"u": [self.prob.pack(g.q0, g.p0, g.T)], "E": [g.energy], "tan": None}
        self.orbits, self.shares = [g], [1.0]
        self.stepping, self.h = method, float(steps[0])
        self.segment = 0            # the first orbit of the current stretch: grazing or the last landing
        self.crossed: dict[int, float] = {}  # landing index -> the tongue's frequency the crossing started from
        self.stop, self.end, self.failure = "", None, ""

    # -- the loop ----------------------------------------------------------------------------------------------

    def _limits(self) -> tuple:
        return self.steps if self.stepping == self.method else RESUME_STEPS

    def follow(self, max_points: int) -> None:
        step = {"energy": _energy_step, "arclength": _arclength_step}
        while len(self.orbits) < max_points:
            try:
                f, its = step[self.stepping](self.prob, self.state, self.h)
            except ValueError as exc:
                if self.h / 2 >= self._limits()[2]:
                    self.h /= 2
                    continue
                if self.shares[-1] < self.opts["backbone"] and self.opts["resonance"] > 0:
                    why = f"the step fell below ds_min = {self._limits()[2]:g} inside it ({exc})"
                    if self.opts["through"] and self._cross():
                        if self._checked(self.orbits[-1]):
                            return
                        continue
                    self._resonance_end(why)
                else:
                    self._finish("step", f"step below ds_min = {self._limits()[2]:g} after {len(self.orbits)} "
                                         f"orbits: {exc}")
                return
            self._add(NodalOrbit._of(self.sh, f, self.mode))
            self.h = min(self.h * (1.5 if its <= 3 else 1.0 if its <= 5 else 0.5), self._limits()[1])
            if self._checked(self.orbits[-1]):
                return
        self._finish("max_points", f"max_points = {max_points} reached")

    def _add(self, orbit: NodalOrbit) -> None:
        self.orbits.append(orbit)
        self.shares.append(float(orbit.modal_energy_share[self.mode]))

    def _checked(self, orbit: NodalOrbit) -> bool:
        """The stop tests on the newest orbit (a crossing happens here); True when the family ends."""
        o = self.opts
        ratio = orbit.frequency / self.orbits[0].frequency
        on = self.shares[-1] >= o["backbone"]
        if o["freq_ratio"] is not None and (ratio >= o["freq_ratio"] or ratio <= 1 / o["freq_ratio"]):
            self._finish("frequency_ratio", f"frequency ratio {ratio:.6g} reached (freq_ratio = {o['freq_ratio']:g})")
            return True
        limit = o.get("stop_when")
        if limit is not None:
            why = limit(orbit)
            if why:  # the caller's own limit (e.g. the small-displacement limit): nothing beyond it is computed
                self._finish("limit", str(why))
                return True
        over = o["energy_max"] is not None and orbit.energy >= o["energy_max"]
        if over and (on or not o["through"] or o["resonance"] == 0):
            self._finish("energy_max", f"energy {orbit.energy:.6g} J reached (energy_max = {o['energy_max']:g})")
            return True
        E = self.state["E"]
        if self.stepping != self.method and on and len(E) >= 2 and np.log(E[-1] / E[-2]) >= self.steps[0] / 4:
            self.stepping, self.h = self.method, float(self.steps[0])  # the energy grows again: the family's steps
        if o["resonance"] == 0 or on:
            return False
        run = len(self.orbits) - self._last_on() - 1
        deep = self.shares[-1] < o["resonance"]
        if not deep and not (o["through"] and (over or run >= TONGUE_POINTS)):
            return False
        why = "" if deep else f"its energy {orbit.energy:.4g} J is past energy_max" if over else f"{run} orbits in it"
        if o["through"] and self._cross():
            return self._checked(self.orbits[-1])
        self._resonance_end(why)
        return True

    def _last_on(self) -> int:
        """Index of the last orbit on the backbone (the stretch's first orbit always is)."""
        return max(i for i in range(self.segment, len(self.orbits)) if self.shares[i] >= self.opts["backbone"])

    # -- crossing a tongue -------------------------------------------------------------------------------------

    def _cross(self) -> bool:
        """Find the backbone beyond the tongue the family is in (module docstring); on success the orbit found is
        appended and the family resumes from it; else :attr:`failure` says why not."""
        orbits, prob = self.orbits, self.prob
        b = self._last_on()
        r = _reference(self.shares, self.segment, b)
        ref = orbits[r]
        d = (ref.frequency - orbits[0].frequency) or (orbits[-1].frequency - orbits[0].frequency)
        s = 1.0 if d >= 0 else -1.0   # the backbone's direction in frequency
        f_tongue = s * max(s * o.frequency for o in orbits[b:])
        d0 = max(s * (f_tongue - orbits[b].frequency), 1e-4 * f_tongue)
        span = max(abs(f_tongue - orbits[0].frequency), CROSS_SPAN * f_tongue, d0)
        pair = [i for i in range(self.segment, r + 1) if self.shares[i] >= self.opts["backbone"]][-2:]
        ua, ub = (prob.pack(orbits[i].q0, orbits[i].p0, orbits[i].T) for i in (pair[0], r))
        fa = orbits[pair[0]].frequency
        tried = 0
        for k in range(CROSS_TRIES):
            jump = d0 * 2 ** (k / 2)
            if jump > span:
                break
            f_t = f_tongue + s * jump
            tried += 1
            secant = ua + (ub - ua) * ((f_t - fa) / (ref.frequency - fa) if ref.frequency != fa else 1.0)
            landed = self._land((secant, ub), f_t, s, ref)
            if landed is None:
                continue
            orbit, u, tan = landed
            self._add(orbit)
            i = len(orbits) - 1
            self.crossed[i] = f_tongue
            self.segment, self.stepping = i, "arclength"
            self.h = float(self.steps[0] if self.method == "arclength" else RESUME_STEPS[0])
            self.state = {"u": [u], "E": [orbit.energy], "tan": tan}
            log.info("nodal family of mode %d: internal resonance near %.6g Hz crossed to the backbone at %.6g Hz "
                     "(%.4g J)", self.mode, f_tongue, orbit.frequency, orbit.energy)
            return True
        hi = f_tongue + s * d0 * 2 ** ((tried - 1) / 2) if tried else f_tongue
        self.failure = (f"no orbit on the backbone (the mode holding >= {self.opts['backbone']:.0%} of the modal "
                        f"energy, the energy growing along it) at {tried} periods beyond it, "
                        f"{min(f_tongue + s * d0, hi):.6g} to {max(f_tongue + s * d0, hi):.6g} Hz")
        return False

    def _land(self, guesses: tuple, f_t: float, s: float, last: NodalOrbit):
        """The orbit at frequency ``f_t`` by Newton from the first of ``guesses`` that converges (the secant along the
        backbone's last stretch, then the state of ``last``, its reference orbit before the tongue) if it is on the
        backbone beyond the tongue: ``(orbit, u, tangent)``, else None."""
        prob, mode = self.prob, self.mode
        T_t = 1.0 / f_t
        row = np.zeros(guesses[0].size)
        row[-1] = 1.0
        for up in guesses:
            up = up.copy()
            up[-1] = T_t / prob.T_ref
            try:
                u, f, _, _ = prob.newton(up, lambda v: (v[-1] - T_t / prob.T_ref, row))
                break
            except ValueError:
                continue
        else:
            return None
        orbit = NodalOrbit._of(self.sh, f, mode)
        if (orbit.modal_energy_share[mode] < self.opts["backbone"] or orbit.energy <= last.energy
                or np.sign(orbit.q0[mode]) != np.sign(last.q0[mode])):
            return None
        tan = prob.tangent(prob.jacobian(f), np.r_[np.zeros(u.size - 1), -s])
        if abs(tan[-1]) < 1e-9 or prob.energy_row(u)[1] @ tan <= 0:
            return None
        return orbit, u, tan

    # -- the end -----------------------------------------------------------------------------------------------

    def _finish(self, kind: str, stop: str) -> None:
        last = self.orbits[-1]
        self.stop = stop
        self.end = {"kind": kind, "frequency_hz": float(last.frequency), "energy_j": float(last.energy),
                    "trend": backbone_trend(self.orbits, self.shares, self.segment, backbone=self.opts["backbone"])}

    def _resonance_end(self, why: str) -> None:
        b = self._last_on()
        k = b + 1 + int(np.argmin(self.shares[b + 1:]))
        res = _resonance(self.sh, self.orbits[k], self.mode)
        trend = backbone_trend(self.orbits, self.shares, self.segment, upto=b)
        f_end = float(max(o.frequency for o in self.orbits[b:])) if trend is None or trend["df_dlnE_hz"] >= 0 \
            else float(min(o.frequency for o in self.orbits[b:]))
        crossing = ("not crossed (through_resonances=False)" if not self.opts["through"]
                    else f"not crossed: {self.failure}")
        share = self.shares[k]
        self.stop = (f"internal resonance at T = {self.orbits[k].T:.9g} s ({self.orbits[k].frequency:.6g} Hz): "
                     f"open-phase mode {res['mode']} ({res['mode_frequency_hz']:.6g} Hz, {res['ratio_value']:.4f} × "
                     f"the orbit's frequency, {res['ratio']}) holds {res['share']:.0%} of the modal energy, mode "
                     f"{self.mode} {share:.0%}" + (f" ({why})" if why else "") + f"; {crossing}. Where a "
                     "resonance with a high mode falls depends on the mesh, so this end is the mesh's, not the "
                     "blade's" + (f": {_trend_words(trend)}" if trend else ""))
        self.end = {"kind": "internal_resonance", "frequency_hz": f_end, "energy_j": float(self.orbits[-1].energy),
                    **{key: res[key] for key in ("mode", "mode_frequency_hz", "ratio", "ratio_value")},
                    "share": share, "other_share": res["share"], "crossing": crossing, "mesh_dependent": True,
                    "trend": trend}
        log.info("nodal family of mode %d: %s", self.mode, self.stop)

    def tongues(self) -> tuple:
        """The tongues met (:attr:`NodalFamily.tongues`)."""
        out, i, n = [], 1, len(self.orbits)
        while i < n:
            if self.shares[i] >= self.opts["backbone"]:
                i += 1
                continue
            j = i
            while j + 1 < n and self.shares[j + 1] < self.opts["backbone"]:
                j += 1
            k = i + int(np.argmin(self.shares[i:j + 1]))
            rec = {"start": i, "stop": j, **_resonance(self.sh, self.orbits[k], self.mode),
                   "frequency_hz": float(self.orbits[k].frequency), "least_share": float(self.shares[k]),
                   "energy_range_j": [float(min(o.energy for o in self.orbits[i:j + 1])),
                                      float(max(o.energy for o in self.orbits[i:j + 1]))]}
            rec.pop("share")
            if j + 1 in self.crossed:
                land = self.orbits[j + 1]
                rec.update(left="crossed", landing=j + 1, from_frequency_hz=float(self.crossed[j + 1]),
                           to_frequency_hz=float(land.frequency), to_energy_j=float(land.energy))
            elif j + 1 < n:
                rec["left"] = "continued"
            else:
                rec["left"] = "end" if self.end and self.end["kind"] == "internal_resonance" else "open"
            out.append(rec)
            i = j + 1
        return tuple(out)


# ----------------------------------------------------------------------------- tongues and the backbone's trend


def _resonance(sh: _Shooter, orbit: NodalOrbit, mode: int) -> dict:
    """The open-phase mode that takes the most modal energy from ``mode`` on ``orbit``, its frequency and the ratio
    of that frequency to the orbit's (``"p:q"``, :func:`resonance_ratio`)."""
    share = orbit.modal_energy_share
    j = int(np.argmax(np.where(np.arange(share.size) == mode, -1.0, share)))
    value = float(sh.omega[j] * orbit.T / (2 * np.pi))
    p, q = resonance_ratio(value)
    return {"mode": j, "mode_frequency_hz": float(sh.omega[j] / (2 * np.pi)), "ratio": f"{p}:{q}",
            "ratio_value": value, "share": float(share[j])}


def resonance_ratio(value: float, q_max: int = 4, rtol: float = 0.02) -> tuple[int, int]:
    """The ratio ``p:q`` of a resonance with frequency ratio ``value`` (a high mode's frequency over the orbit's):
    the smallest ``q <= q_max`` with ``|value − p/q| <= rtol·value`` (the mode's frequency moves with the contact,
    so the measured ratio is not exact), else the nearest fraction with ``q <= q_max``.

    >>> resonance_ratio(7.9924), resonance_ratio(2.9741), resonance_ratio(7.49)
    ((8, 1), (3, 1), (15, 2))
    """
    for q in range(1, q_max + 1):
        p = int(round(value * q))
        if p >= 1 and abs(value - p / q) <= rtol * value:
            return p, q
    best = Fraction(value).limit_denominator(q_max)
    return max(best.numerator, 1), best.denominator


def _reference(shares, lo: int, hi: int) -> int:
    """The backbone's reference orbit before a tongue, in ``[lo, hi]``: the last at least :data:`TREND_SHARE` clean,
    else the one of highest share (the orbits after it already bend into the tongue)."""
    clean = [i for i in range(lo, hi + 1) if shares[i] >= TREND_SHARE]
    return clean[-1] if clean else lo + int(np.argmax(shares[lo:hi + 1]))


def _trend_indices(shares, lo: int, hi: int, backbone: float | None = None) -> list[int]:
    """The orbits that show the backbone's trend up to ``hi``: those of ``[lo, hi]`` at least :data:`TREND_SHARE`
    clean; with ``backbone`` (the last stretch wanted), else those of ``[lo, hi]`` on the backbone; else the clean
    ones of ``[0, hi]`` (before a tongue: the stretch between two resonances bends into both); else those of
    ``[lo, hi]`` up to the reference (:func:`_reference`)."""
    sets = [[i for i in range(lo, hi + 1) if shares[i] >= TREND_SHARE]]
    if backbone is not None:
        sets.append([i for i in range(lo, hi + 1) if shares[i] >= backbone])
    sets.append([i for i in range(hi + 1) if shares[i] >= TREND_SHARE])
    return next((idx for idx in sets if len(idx) >= 2), list(range(lo, _reference(shares, lo, hi) + 1)))


def backbone_trend(orbits, shares, lo: int = 0, upto: int | None = None, count: int = 3,
                   backbone: float | None = None) -> dict | None:
    """The frequency–energy relation of the backbone's last stretch, ``f ≈ f₀ + b·ln(E/E₀)`` fitted (least
    squares) on the last ``count`` orbits up to ``orbits[upto]`` at least :data:`TREND_SHARE` clean (``shares``: the
    family's mode's share of the modal energy) from ``orbits[lo]`` (the current stretch); if it has fewer than
    two, with ``backbone``, its orbits on the backbone (``shares >= backbone``: the family's end), else the clean
    orbits of the whole family (before a tongue); ``(f₀, E₀)`` the last of them: what a reader extrapolates along.

    Returns ``frequency_hz`` (``f₀``), ``energy_j`` (``E₀``), ``df_dlnE_hz`` (``b``), ``hz_per_doubling``
    (``b ln 2``), ``dE_df_j_per_hz`` (``E₀/b`` at ``E₀``), ``frequency_range_hz`` and ``energy_range_j`` of the
    fitted orbits and their number ``orbits``; None with fewer than two.
    """
    upto = len(orbits) - 1 if upto is None else upto
    idx = _trend_indices(shares, lo, upto, backbone)[-count:]
    if len(idx) < 2:
        return None
    f = np.array([orbits[i].frequency for i in idx])
    lnE = np.log([orbits[i].energy for i in idx])
    if np.ptp(lnE) <= 0:
        return None
    b = float(np.polyfit(lnE - lnE[-1], f, 1)[0])
    E0 = float(np.exp(lnE[-1]))
    return {"frequency_hz": float(f[-1]), "energy_j": E0, "df_dlnE_hz": b, "hz_per_doubling": float(b * np.log(2)),
            "dE_df_j_per_hz": E0 / b if b != 0 else float("inf"), "frequency_range_hz": [float(f[0]), float(f[-1])],
            "energy_range_j": [float(np.exp(lnE[0])), E0], "orbits": len(idx)}


def _trend_words(trend: dict) -> str:
    return (f"below it the backbone rises {trend['hz_per_doubling']:.3g} Hz per doubling of the energy "
            f"(f ≈ {trend['frequency_hz']:.6g} Hz + {trend['df_dlnE_hz']:.4g} Hz × ln(E / {trend['energy_j']:.4g} J), "
            f"fitted on {trend['orbits']} orbits from {trend['frequency_range_hz'][0]:.6g} Hz): extrapolate along it")
