"""The figures of an admissible arc an engineer can quote: its engineering ranges over its backbone — its orbits
below the first internal-resonance tongue, where the family's own mode still holds the energy — and where that
tongue starts (whose place moves with the mesh, with the higher mode's frequency)."""

from __future__ import annotations

import numpy as np

from ..nsm import Branch


def _range(values: np.ndarray) -> list[float | None]:
    """``[min, max]`` of the finite values; ``[None, None]`` (JSON ``null``: no value) when there is none."""
    values = values[np.isfinite(values)]
    return [float(values.min()), float(values.max())] if values.size else [None, None]


#: Orbits per admissible arc (evenly spread, both ends included) whose engineering quantities give the summary's
#: ranges: each is expanded to the FE model at a few hundred instants.
ENGINEERING_SAMPLES = 16


def _arc_picks(fam: Branch, arc, cap: int | None, among: set[int] | None = None) -> list[int]:
    """Indices of the admissible orbits of ``arc`` (those in ``among`` if given); at most ``cap`` of them (evenly
    spread, both ends kept)."""
    pool = [j for j in range(arc.start, arc.stop + 1) if fam.orbits[j] is not None and fam.orbits[j].admissible
            and (among is None or j in among)]
    if cap is None or len(pool) <= cap:
        return pool
    return [pool[i] for i in np.unique(np.linspace(0, len(pool) - 1, cap).round().astype(int))]


#: An orbit of an arc whose own mode (the one it grew from) holds less than this share of its energy is inside an
#: internal-resonance tongue: its place moves with the mesh, so the arc's headline figures are read below it.
TONGUE_SHARE = 0.9


def _own_share(fam: Branch, j: int, mode: int) -> float:
    from ..nsm.energy import modal_energy_split

    try:
        return float(modal_energy_split(fam.orbits[j]).shares[mode])
    except (ValueError, IndexError):
        return 1.0


def _backbone(fam: Branch, arc, engineering) -> dict:
    """The arc's engineering ranges (:func:`_arc_engineering`) over its backbone: its orbits below the first
    internal-resonance tongue, where the family's own mode (its lowest-energy orbit's largest share) holds at
    least :data:`TONGUE_SHARE` of the energy (an arc whose first orbit has no such mode is read whole); with a
    tongue, ``tongue``: where it starts (frequency, energy), the mode that takes over and the ratio of its frequency
    to the orbit's, and ``backbone_f_lo``/``backbone_f_hi``."""
    from ..nsm.energy import modal_energy_split

    pool = [j for j in range(arc.start, arc.stop + 1) if fam.orbits[j] is not None and fam.orbits[j].admissible]
    if not pool:
        return {}
    pool.sort(key=lambda j: fam.orbits[j].energy)
    try:
        first = modal_energy_split(fam.orbits[pool[0]])
    except ValueError:
        return {} if engineering is None else _arc_engineering(fam, arc, engineering)
    own = int(np.argmax(first.shares))
    if first.shares[own] < TONGUE_SHARE:  # no mode of its own at its start: not a backbone, no tongue to read below
        return {} if engineering is None else _arc_engineering(fam, arc, engineering)
    shares = np.array([_own_share(fam, j, own) for j in pool])  # every orbit: a thin tongue holds few (ms each)
    below = np.flatnonzero(shares < TONGUE_SHARE)
    out: dict = {}
    keep = pool
    if below.size:
        hi = int(below[0])
        inside = fam.orbits[pool[hi]]
        split = modal_energy_split(inside)
        other = int(np.argmax(np.where(np.arange(split.shares.size) == own, -1.0, split.shares)))
        f = 1.0 / inside.T
        out["tongue"] = {"frequency_hz": float(f), "energy_j": float(inside.energy), "mode": other + 1,
                         "mode_frequency_hz": float(split.frequencies[other]),
                         "ratio": float(split.frequencies[other] / f), "own_mode": own + 1,
                         "own_share": float(split.shares[own])}
        keep = pool[:hi]
    if keep:
        freqs = [1.0 / fam.orbits[j].T for j in keep]
        out.update(backbone_f_lo=float(min(freqs)), backbone_f_hi=float(max(freqs)))
    if engineering is not None and keep:
        sub = _arc_picks(fam, arc, ENGINEERING_SAMPLES, among=set(keep))
        out.update(_arc_engineering(fam, arc, engineering, sub))
    return out


def _arc_engineering(fam: Branch, arc, engineering, picks: list[int] | None = None) -> dict:
    """Ranges ``[min, max]`` of the engineering quantities (``engineering(orbit)``, a dict of numbers or ``None``)
    over the admissible orbits of ``arc`` — at most :data:`ENGINEERING_SAMPLES`, evenly spread, both ends included
    (``engineering_orbits``: how many)."""
    picks = _arc_picks(fam, arc, ENGINEERING_SAMPLES) if picks is None else picks
    values = [engineering(fam.orbits[j]) for j in picks]
    out: dict = {"engineering_orbits": len(picks)}
    for key, ranged in ENGINEERING_RANGES.items():
        nums = np.array([v[key] for v in values if isinstance(v.get(key), (int, float))], dtype=float)
        if nums.size:
            out[ranged] = _range(nums)
    return out


#: The engineering quantities of an orbit whose ranges over an arc the summary gives, and the ranges' keys (the
#: unit stays last, as in ``energy_range_j``).
ENGINEERING_RANGES = {"tip_amplitude_mm": "tip_amplitude_range_mm", "contact_force_n": "contact_force_range_n",
                      "contact_impulse_ns": "contact_impulse_range_ns", "contact_fraction": "contact_fraction_range",
                      "casing_penetration_m": "casing_penetration_range_m"}
