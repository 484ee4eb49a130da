"""Where the model stops being the blade: the small-displacement limit of the nonsmooth modes' arcs.

The FE model is linear elastic about an undeformed blade (small displacements), and the contact model adds only the
casing. Followed far enough, a family reaches energies no blade survives — tip amplitudes of a large part of the span
— and its figures stop meaning anything. A study cuts every admissible arc at ``[search] amplitude_limit`` (a
fraction of the blade's span, 5 % by default: a cantilever's linear tip deflection is within about 0.6 % of the
large-deflection (elastica) answer up to 10 % of the span, so 5 % leaves a margin for twisted and plate-like
blades): an orbit whose tip amplitude (the largest ``|u|`` of a contact node
over the period, :func:`~bladecase.study.render.orbit_engineering`) exceeds it is not part of an arc, and the report
says where each arc was cut and why. The span is the distance from the clamp's centroid to the farthest node.

The every-node family (``[contact] points = "nodes"``, :mod:`~bladecase.study.nodal.stage`) is one followed curve,
not a set of arcs: it is cut at its first orbit beyond the limit (:func:`first_beyond`, :func:`cut_family`), and its
figures — energy, pressure, total force, casing yield — stop at the last orbit within it.

>>> from bladecase.nsm import backbone, chain
>>> branch = backbone(chain(2, k=1.0, m=0.5, gap=1.0), [4.0, 4.5, 5.0, 5.5, 6.0, 6.5, 7.0])
>>> [(a.start, a.stop) for a in branch.arcs]
[(0, 2), (4, 6)]
>>> cut, cuts = cut_arcs([branch], [lambda o: 10.0 / o.T], limit=2.0)   # "amplitude" 10/T: above 2 for T < 5
>>> [(a.start, a.stop, a.T_lo, a.refined_lo) for a in cut[0].arcs]       # the first arc now starts at T = 5
[(2, 2, 5.0, False), (4, 6, 5.650148507207632, True)]
>>> cuts[0]["T_cut"], cuts[0]["T_beyond"], cuts[0]["tip_amplitude_beyond"]
(5.0, 4.5, 2.2222222222222223)
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

import numpy as np

__all__ = ["blade_span", "cut_arcs", "cut_family", "first_beyond"]


def blade_span(model) -> float:
    """The blade's span (m): the distance from the centroid of its clamped nodes to the farthest node."""
    points = model.mesh.points
    clamped = np.unique(np.asarray(model.clamped, dtype=int)) if model.clamped is not None else np.array([], int)
    root = points[clamped].mean(axis=0) if clamped.size else points.min(axis=0)
    return float(np.linalg.norm(points - root, axis=1).max())


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """``(first, last)`` of each run of ``True`` in ``mask``."""
    edges = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1))


def cut_arcs(families: Sequence, amplitudes: Sequence[Callable], limit: float, name: str = "tip_amplitude"
             ) -> tuple[list, list[dict]]:
    """Every family's arcs cut where ``amplitude(orbit) > limit`` (one function per family, its model's); returns the
    families with their cut arcs and one record per cut (family, the first orbit beyond: its index ``orbit_beyond``
    in the family, its period and its value ``{name}_beyond``; the last orbit within: ``T_cut``, ``{name}_cut``).
    An arc's end that is kept keeps its refined period; a new end is the last orbit within the limit (not refined).
    Any measure of an orbit cuts the same way (the peak von Mises stress against the yield strength:
    :mod:`~bladecase.study.stress_limit`)."""
    out, cuts = [], []
    for i, (fam, amplitude) in enumerate(zip(families, amplitudes)):
        arcs = []
        for arc in fam.arcs:
            index = np.arange(arc.start, arc.stop + 1)
            orbits = [fam.orbits[j] for j in index]
            values = np.array([amplitude(o) if o is not None and o.admissible else np.nan for o in orbits])
            within = ~(values > limit)  # nan (not admissible, or no orbit): left as the arc had it
            if within.all():
                arcs.append(arc)
                continue
            onset = int(np.nanargmin(np.where(within, np.nan, values)))  # the least amplitude beyond the limit
            kept = np.flatnonzero(within & np.isfinite(values))
            edge = int(kept[np.argmin(np.abs(kept - onset))]) if kept.size else None
            cuts.append({"family": i, "ipp": int(fam.k), "orbit_beyond": int(index[onset]),
                         "T_beyond": float(orbits[onset].T), f"{name}_beyond": float(values[onset]),
                         "T_cut": None if edge is None else float(orbits[edge].T),
                         f"{name}_cut": None if edge is None else float(values[edge])})
            for a, b in _runs(within):
                arcs.append(_sub_arc(fam, arc, int(index[a]), int(index[b])))
        out.append(dataclasses.replace(fam, arcs=arcs) if arcs != fam.arcs else fam)
    return out, cuts


def _sub_arc(fam, arc, start: int, stop: int):
    """The part ``start..stop`` of ``arc``: its periods from the orbits, the original (refined) ends where kept."""
    T = np.array([fam.orbits[j].T for j in range(start, stop + 1)])
    whole = np.array([fam.orbits[j].T for j in range(arc.start, arc.stop + 1)])
    keep_lo, keep_hi = T.min() == whole.min(), T.max() == whole.max()
    return dataclasses.replace(
        arc, start=start, stop=stop, T_lo=arc.T_lo if keep_lo else float(T.min()),
        T_hi=arc.T_hi if keep_hi else float(T.max()), refined_lo=bool(arc.refined_lo and keep_lo),
        refined_hi=bool(arc.refined_hi and keep_hi))


def first_beyond(orbits: Sequence, amplitude: Callable, limit: float) -> tuple[int | None, list[float]]:
    """The index of the first of ``orbits`` (in order along a family) whose ``amplitude(orbit)`` exceeds ``limit``
    (``None``: none does) and the amplitudes measured up to it.

    >>> first_beyond([1.0, 2.0, 3.0, 1.0], lambda a: a, 2.5)
    (2, [1.0, 2.0, 3.0])
    """
    measured = []
    for i, o in enumerate(orbits):
        measured.append(float(amplitude(o)))
        if measured[-1] > limit:
            return i, measured
    return None, measured


def cut_family(family, index: int, stop: str, end: dict):
    """``family`` (a :class:`~bladecase.nsm.massless.NodalFamily`) up to, not including, orbit ``index``: its tongues
    clipped there (a tongue left beyond it, or reaching past it, is ``left = "cut"``), its ``stop`` and ``end`` the
    given ones.

    >>> import numpy as np
    >>> from bladecase.nsm.massless import NodalSystem, nodal_family
    >>> K = np.array([[18.0, -8.0, 0.0, 0.0, 0.0], [-8.0, 34.0, -6.0, -20.0, 0.0], [0.0, -6.0, 21.0, 0.0, -15.0],
    ...               [0.0, -20.0, 0.0, 25.0, -5.0], [0.0, 0.0, -15.0, -5.0, 20.0]])
    >>> i, c = [0, 1, 2], [3, 4]
    >>> Kcc, Kci = K[np.ix_(c, c)], K[np.ix_(c, i)]
    >>> s = NodalSystem(np.diag([2.0, 1.5, 0.7]), K[np.ix_(i, i)] - Kci.T @ np.linalg.solve(Kcc, Kci),
    ...                 -Kci.T @ np.linalg.inv(Kcc), np.linalg.inv(Kcc), gap=[0.2, 0.3])
    >>> fam = nodal_family(s, mode=0, freq_ratio=1.15)
    >>> k, _ = first_beyond(fam.orbits, lambda o: o.max_tip, 0.25)   # the first orbit reaching past 0.25
    >>> cut = cut_family(fam, k, "cut at 0.25", {"kind": "amplitude_limit"})
    >>> len(fam.orbits) > k == len(cut.orbits), max(o.max_tip for o in cut.orbits) <= 0.25, cut.stop
    (True, True, 'cut at 0.25')
    """
    tongues = []
    for t in family.tongues:
        if t["start"] >= index:
            continue
        t = dict(t)
        if t["stop"] >= index or t.get("landing", -1) >= index:
            t.update(stop=min(t["stop"], index - 1), left="cut")
            for key in ("landing", "from_frequency_hz", "to_frequency_hz", "to_energy_j"):
                t.pop(key, None)
        tongues.append(t)
    return dataclasses.replace(family, orbits=list(family.orbits[:index]), stop=stop, tongues=tuple(tongues),
                               end=end)
