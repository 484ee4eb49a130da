"""The casing-stiffness sensitivity of a study's nonsmooth modes: ``[contact] casing_stiffness = [k1, k2, …]``.

A compliant casing's local radial stiffness is rarely known to better than a factor of a few, and the massless
contact model's nonsmooth modes depend on it: where the admissible arc ends, how much energy it reaches, whether
it stays stable. With a list, the run's results use the first value; the same reduced model (the same interior
basis: only the contact's spring changes) is searched with each of the others, and the stage reports how much
the answer moves — the admissible arc's frequency range, its energy and tip amplitude at the top, its stable
share — with one figure (``casing.png``: the backbone for each stiffness).

The issue it settles, measured on the demo blade (casing 1e5 / 1e6 / 1e7 / 1e8 N/m): the admissible arc ends at
213.55 / 215.42 / 215.69 / 214.47 Hz with a top energy of 23 / 0.070 / 0.013 / 0.0096 J and 100 / 100 / 86 / 53 %
of its orbits stable — the frequency barely moves, the energy the arc reaches moves by three decades.

>>> rows = [{"casing_n_per_m": 1e5, "series_n_per_m": 1e5, "f_lo_hz": 210.5, "f_hi_hz": 213.55, "energy_top_j": 23.0,
...          "stable_fraction": 1.0},
...         {"casing_n_per_m": 1e7, "series_n_per_m": 9.98e6, "f_lo_hz": 210.5, "f_hi_hz": 215.69,
...          "energy_top_j": 0.013, "stable_fraction": 0.86}]
>>> spread(rows)["f_hi_hz"]
[213.55, 215.69]
>>> round(spread(rows)["f_hi_relative"], 4)
0.0099
"""

from __future__ import annotations

import dataclasses

from ... import log
from ...reduction import Contact

__all__ = ["casing_sweep", "spread"]


def _arc_row(k: float, series: float, families) -> dict:
    """The widest admissible arc of the families (the main mode's): its frequency range, top energy and stable share
    (as the run's summary gives them: :func:`bladecase.study.documents.family_summary`)."""
    from ..documents import family_summary

    arcs = [a for f in families for a in family_summary(f)["admissible_arcs"]]
    row = {"casing_n_per_m": float(k), "series_n_per_m": float(series), "families": len(families)}
    if not arcs:
        return {**row, "f_lo_hz": None, "f_hi_hz": None, "energy_top_j": None, "stable_fraction": None}
    a = max(arcs, key=lambda a: a["f_hi"] - a["f_lo"])
    return {**row, "f_lo_hz": a["f_lo"], "f_hi_hz": a["f_hi"], "energy_top_j": a["energy_range_j"][1],
            "stable_fraction": a["stable_fraction"]}


def spread(rows: list[dict]) -> dict:
    """How much the answer moves across the stiffnesses: the ranges of the arc's ends and top energy."""
    ok = [r for r in rows if r.get("f_hi_hz") is not None]
    if not ok:
        return {"with_arcs": 0}
    hi = [r["f_hi_hz"] for r in ok]
    en = [r["energy_top_j"] for r in ok]
    return {"with_arcs": len(ok), "f_hi_hz": [min(hi), max(hi)], "f_hi_relative": (max(hi) - min(hi)) / max(hi),
            "energy_top_j": [min(en), max(en)], "energy_top_ratio": max(en) / min(en) if min(en) > 0 else None}


def casing_sweep(study, model, contact: Contact, stiffnesses, *, factor=None, search_fn=None, unit=None,
                 progress: bool = False, first: tuple | None = None) -> dict:
    """Search the study's nonsmooth modes with each casing stiffness (N/m) of ``stiffnesses``; return the summary
    section ``{"rows": [...], "spread": {...}, "branches": [...]}`` (``branches``: each stiffness's families, for
    the figure; not JSON). ``first``: ``(series stiffness, families)`` already found with the first stiffness (the
    run's own), not searched again."""
    from ..stages import build_reduced, search

    search_fn = search if search_fn is None else search_fn
    rows, branches = [], []
    for i, k in enumerate(stiffnesses):
        if i == 0 and first is not None:
            rows.append(_arc_row(k, first[0], first[1]))
            branches.append(first[1])
            continue
        c = dataclasses.replace(contact, casing=float(k))
        reduced = build_reduced(study, model, c, factor=factor)
        fams = search_fn(study, reduced.system, progress=progress, unit=unit, label=f"casing {k:.3g} N/m")
        rows.append(_arc_row(k, reduced.system.kc, fams))
        branches.append(fams)
        r = rows[-1]
        log.info("casing %.4g N/m (in series with the blade: %.4g N/m): %s", k, reduced.system.kc,
                 "no admissible arc" if r["f_hi_hz"] is None else
                 f"admissible arc {r['f_lo_hz']:.5g}–{r['f_hi_hz']:.5g} Hz, top energy {r['energy_top_j']:.3g} J")
    return {"rows": rows, "spread": spread(rows), "branches": branches}
