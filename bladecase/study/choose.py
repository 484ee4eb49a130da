"""Which orbits a run animates, and at which instants: ``[output] orbits`` or the middles of the widest
admissible arcs; frames with one frame on each impact instant."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from .. import log
from ..nsm import Branch, PeriodicOrbit
from .schema import Study, StudyError


@dataclass(frozen=True)
class Choice:
    """An orbit chosen for animation: family index and the orbit; ``digits`` of the period in its file stem
    (more than 7 only where two chosen orbits would otherwise share one, see :func:`distinct_stems`) and a
    ``suffix`` for orbits whose periods agree to every digit."""

    family: int
    orbit: PeriodicOrbit
    digits: int = 7
    suffix: str = ""
    #: The periods (s) asked for in ``[output] orbits`` that this orbit stands for, when it is not at them: no
    #: admissible orbit was there and this, the nearest, was animated instead (empty: chosen as asked or
    #: automatically).
    substitutes: tuple[float, ...] = ()

    @property
    def stem(self) -> str:
        """The file stem of the orbit's animations and VTK files, e.g. ``mode00_1ipp_T1p396486e-03``."""
        return _stem(self.family, self.orbit.k, self.orbit.T, self.digits) + self.suffix


def _stem(family: int, k: int, T: float, digits: int) -> str:
    return f"mode{family:02d}_{k}ipp_T{T:.{digits - 1}e}".replace("+", "").replace(".", "p")


def _distinct(chosen: list[Choice], members: list[int], digits: int) -> int:
    return len({_stem(chosen[i].family, chosen[i].orbit.k, chosen[i].orbit.T, digits) for i in members})


def distinct_stems(chosen: list[Choice]) -> list[Choice]:
    """``chosen`` with one file stem per orbit: where stems collide at 7 digits of the period, those orbits'
    periods are written with as many digits as tell them apart (up to 17); orbits whose periods agree to every
    digit (the same orbit asked for twice, or two families through one orbit) are numbered ``_2``, ``_3`` …

    >>> import bladecase as bc
    >>> o = bc.orbit_1ipp(bc.chain(2, k=1.0, m=1.0, gap=1.0), 5.0)
    >>> near = bc.orbit_1ipp(o.system, 5.0000001)
    >>> [c.stem for c in distinct_stems([Choice(0, o), Choice(0, near), Choice(0, o)])]
    ['mode00_1ipp_T5p0000000e00', 'mode00_1ipp_T5p0000001e00', 'mode00_1ipp_T5p0000000e00_2']
    """
    out = list(chosen)
    groups: dict[str, list[int]] = {}
    for i, c in enumerate(out):
        groups.setdefault(c.stem, []).append(i)
    for members in groups.values():
        if len(members) < 2:
            continue
        digits = next(d for d in range(7, 18) if _distinct(out, members, d) == _distinct(out, members, 17))
        seen: dict[str, int] = {}
        for i in members:
            c = replace(out[i], digits=digits)
            n = seen[c.stem] = seen.get(c.stem, 0) + 1
            out[i] = c if n == 1 else replace(c, suffix=f"_{n}")
    return out


def _admissible_at(fam: Branch, T: float) -> PeriodicOrbit | None:
    try:
        hits = [o for o in fam.orbit_at(T) if o.admissible]
    except ValueError:
        hits = []
    return hits[0] if hits else None


def choose_orbits(study: Study, families: list[Branch], unit: float,
                  accept: Callable[[PeriodicOrbit], bool] | None = None) -> list[Choice]:
    """The orbits to animate: ``[output] orbits`` if given, else the middles of the widest arcs.

    ``accept``: a further test of an automatically chosen orbit (e.g. that it survives in a reference model);
    an orbit it rejects is not animated and the next arc is tried. Orbits named in ``[output] orbits`` are
    animated whatever it says (the caller flags them).
    """
    o = study["output"]
    if o["orbits"]:
        return _requested(study, families, unit)
    chosen: list[Choice] = []
    arcs = sorted((((a.T_hi - a.T_lo) / a.T_hi, i, n) for i, fam in enumerate(families)
                   for n, a in enumerate(fam.arcs)), reverse=True)
    # Widest arcs first, one per family; then further arcs of the same families if fewer families than asked.
    order = [x for x in arcs if x[1] not in {y[1] for y in arcs[:arcs.index(x)]}]
    order += [x for x in arcs if x not in order]
    for _width, i, n in order:
        if len(chosen) >= o["animate"]:
            break
        fam = families[i]
        arc = fam.arcs[n]
        orbit = _admissible_at(fam, 0.5 * (arc.T_lo + arc.T_hi))
        if orbit is None:  # the arc is a single point, or the middle did not converge
            candidates = [fam.orbits[j] for j in range(arc.start, arc.stop + 1) if fam.orbits[j].admissible]
            if not candidates:
                continue
            orbit = candidates[len(candidates) // 2]
        if accept is not None and not accept(orbit):
            continue
        chosen.append(Choice(i, orbit))
    return distinct_stems(chosen)


def _requested(study: Study, families: list[Branch], unit: float) -> list[Choice]:
    """The orbits of ``[output] orbits``: the admissible orbit at each period asked for, else the nearest admissible
    one of its ipp — a substitution said by a warning and kept on the choice (the report says it too); requests
    that end on one orbit give it once, with a warning that names them."""
    o = study["output"]
    picks: list[tuple[int, PeriodicOrbit, float, float]] = []  # family, orbit, period asked (s), distance (s)
    for req in o["orbits"]:
        T = req["T"] * unit
        best = None
        for i, fam in enumerate(families):
            if fam.k != req["ipp"]:
                continue
            if any(a.T_lo <= T <= a.T_hi for a in fam.arcs):
                orbit = _admissible_at(fam, T)
                if orbit is not None:
                    best = (0.0, i, orbit)
                    break
            for orbit in fam.orbits:
                if orbit.admissible and (best is None or abs(orbit.T - T) < best[0]):
                    best = (abs(orbit.T - T), i, orbit)
        if best is None:
            raise StudyError(f"[output] orbits: no admissible {req['ipp']}-ipp orbit was found in the search "
                             f"range (asked T = {req['T']} {study['search']['period_unit']})")
        picks.append((best[1], best[2], T, best[0]))
    chosen: list[Choice] = []
    where: dict[tuple[int, float], int] = {}  # (family, period of the orbit) → its place in chosen
    asked: dict[int, list[float]] = {}
    for family, orbit, T, distance in picks:
        key = (family, float(orbit.T))
        if key not in where:
            where[key] = len(chosen)
            chosen.append(Choice(family, orbit))
        n = where[key]
        asked.setdefault(n, []).append(T)
        if distance > 0:
            chosen[n] = replace(chosen[n], substitutes=(*chosen[n].substitutes, T))
    for n, periods in asked.items():
        c = chosen[n]
        if c.substitutes:
            log.warning("[output] orbits: no admissible %d-ipp orbit at T = %s s; animating the nearest admissible "
                        "one, T = %.8g s, instead", c.orbit.k, ", ".join(f"{t:.8g}" for t in c.substitutes),
                        c.orbit.T)
        if len(periods) > 1:
            log.warning("[output] orbits: %d requests (T = %s s) give one orbit, T = %.8g s: animated once",
                        len(periods), ", ".join(f"{t:.8g}" for t in periods), c.orbit.T)
    return distinct_stems(chosen)


def frame_times(orbit: PeriodicOrbit, frames: int) -> tuple[np.ndarray, np.ndarray]:
    """``frames`` instants over one period, with one frame moved onto each impact instant.

    Each impact takes the nearest frame that is not already an impact and
    can move there without reordering the frames (so close impacts get
    neighbouring frames).  Returns the times (increasing, in ``[0, T)``) and
    the impact-frame mask; ``t = 0`` (``= t_k = T``) is always an impact.
    """
    T = orbit.T
    t = np.arange(frames) * T / frames
    impact = np.zeros(frames, dtype=bool)
    impact[0] = True
    edges = np.append(t, T)
    for ti in np.sort(np.mod(orbit.impact_times, T)):
        if ti <= 1e-12 * T or ti >= T * (1 - 1e-12):
            continue  # the impact at t = 0
        for j in np.argsort(np.abs(t - ti), kind="stable"):
            if j > 0 and not impact[j] and edges[j - 1] < ti < edges[j + 1]:
                t[j] = edges[j] = ti
                impact[j] = True
                break
    return t, impact
