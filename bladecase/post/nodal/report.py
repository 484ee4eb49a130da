"""The report's words on the nonsmooth mode with every face node a contact (``summary["nodal_modes"]``), beside the
face-mean mode.

>>> section = {"contact_nodes": 26, "reduced_dofs": 8, "size": 8, "orbits": 18, "stop": "internal resonance",
...            "frequency_range_hz": [210.5, 215.5], "energy_range_j": [0.0031, 0.026], "stable_fraction": 1.0,
...            "first_touch_nodes": ["3"], "most_nodes_touching": 18, "face_area_mm2": 103.2,
...            "rows": [{"energy_j": 0.026, "max_pressure_mpa": 0.41, "total_force_n": 36.0, "loaded_area_mm2": 70.1,
...                      "peak_loaded_area_mm2": 74.0, "load_centre": 0.45, "load_location": "mid-chord",
...                      "max_penetration_mm": 0.118, "max_contact_fraction": 0.31, "nodes_touching": 18}],
...            "face_mean": {"energy_j": [0.0082, 0.07], "node_beyond_clearance_mm": [0.06, 0.18]}}
>>> lines = nodal_report(section)
>>> lines[5][:58]
'- From 210.5 Hz, where node 3 touches first, to 215.5 Hz: '
>>> lines[5].split("; ")[1].split(", ")
['at the top (0.026 J) the contact pressure peaks at 0.41 MPa and the total contact force at 36 N', \
"over 70.1 mm² of the tip's 103 mm²", 'centred mid-chord (0.45 of the chord from the leading edge)']
"""

from __future__ import annotations

import numpy as np

__all__ = ["backbone_rows", "end_words", "limit_words", "load_words", "nodal_report", "tongue_words"]


def load_words(row: dict, face_mm2: float | None = None) -> str:
    """The casing's load in words from a row with ``max_pressure_mpa``, ``total_force_n``, ``loaded_area_mm2``,
    ``load_centre`` and ``load_location`` (a row of ``nodal_modes.csv`` or ``rub.csv``): the peak contact pressure,
    the peak total force, the area in contact then and where its centre sits along the chord.

    >>> load_words({"max_pressure_mpa": 2.5, "total_force_n": 12.0, "loaded_area_mm2": 9.5, "load_centre": 0.9,
    ...             "load_location": "trailing edge"}).split(", ")
    ['the contact pressure peaks at 2.5 MPa and the total contact force at 12 N', 'over 9.5 mm² of the tip', \
'centred at the trailing edge (0.90 of the chord from the leading edge)']
    """
    if not row.get("total_force_n"):
        return "the casing carries no load"
    where = row.get("load_location")
    at = "" if where is None else (f", centred {'' if where == 'mid-chord' else 'at the '}{where} "
                                   f"({row['load_centre']:.2f} of the chord from the leading edge)")
    face = f" of the tip's {face_mm2:.3g} mm²" if face_mm2 else " of the tip"
    return (f"the contact pressure peaks at {row['max_pressure_mpa']:.3g} MPa and the total contact force at "
            f"{row['total_force_n']:.3g} N, over {row['loaded_area_mm2']:.3g} mm²{face}{at}")


def _ordinal(n: int) -> str:
    return f"{n}{'th' if 10 <= n % 100 <= 20 else {1: 'st', 2: 'nd', 3: 'rd'}.get(n % 10, 'th')}"


def backbone_rows(section: dict) -> list[dict]:
    """The rows of the orbits on the backbone: a row's ``on_backbone`` if it has one, else every row outside the
    section's ``tongues`` (``start``–``stop`` index ranges, :attr:`~bladecase.nsm.massless.NodalFamily.tongues`);
    all rows when neither says (a summary from before the tongues were recorded)."""
    rows = section.get("rows") or []
    if rows and "on_backbone" in rows[0]:
        return [r for r in rows if r["on_backbone"]] or rows
    off = {i for t in section.get("tongues") or [] for i in range(t["start"], t["stop"] + 1)}
    return [r for i, r in enumerate(rows) if i not in off] or rows


def _trend_words(trend: dict | None) -> str:
    if not trend:
        return ""
    return (f"; below it the backbone rises {trend['hz_per_doubling']:.2g} Hz per doubling of the energy "
            f"(f ≈ {trend['frequency_hz']:.5g} Hz + {trend['df_dlnE_hz']:.3g} Hz × ln(E / {trend['energy_j']:.3g} J), "
            f"from {trend['frequency_range_hz'][0]:.5g} Hz): extrapolate along it to read the backbone beyond")


def end_words(section: dict) -> str:
    """The report's line on how the family ends, from ``section["end"]``
    (:attr:`~bladecase.nsm.massless.NodalFamily.end`), else from ``section["stop"]``.

    >>> end = {"kind": "internal_resonance", "frequency_hz": 215.4987, "energy_j": 0.0263, "mode": 2,
    ...        "mode_frequency_hz": 1722.36, "ratio": "8:1", "ratio_value": 7.9924, "share": 0.44, "other_share": 0.553,
    ...        "crossing": "not crossed (through_resonances=False)", "mesh_dependent": True,
    ...        "trend": {"frequency_hz": 213.9, "energy_j": 0.00925, "df_dlnE_hz": 5.1, "hz_per_doubling": 3.5,
    ...                  "frequency_range_hz": [211.3, 213.9]}}
    >>> print(end_words({"end": end, "stop": "internal resonance at …"}))
    - The family ends in an internal resonance at 215.5 Hz: its motion turns into the 3rd mode of the blade with \
the contacts open (1722 Hz, 8:1 — 7.99 × the orbit's frequency), which takes 55% of the modal energy. Where such a \
resonance falls depends on the mesh (the high modes move with it), so this is where the mesh ends the backbone, not \
the blade; below it the backbone rises 3.5 Hz per doubling of the energy (f ≈ 213.9 Hz + 5.1 Hz × \
ln(E / 0.00925 J), from 211.3 Hz): extrapolate along it to read the backbone beyond.
    """
    end = section.get("end")
    if end and end.get("kind") == "amplitude_limit":
        return limit_words(end)
    if end and end.get("kind") == "yield_strength":
        return yield_words(end)
    if not end or end.get("kind") != "internal_resonance":
        return f"- The family ends: {section.get('stop', 'where the continuation stopped')}."
    return (f"- The family ends in an internal resonance at {end['frequency_hz']:.5g} Hz: its motion turns into the "
            f"{_ordinal(end['mode'] + 1)} mode of the blade with the contacts open ({end['mode_frequency_hz']:.4g} Hz, "
            f"{end['ratio']} — {end['ratio_value']:.3g} × the orbit's frequency), which takes "
            f"{end.get('other_share', 1 - end['share']):.0%} of the modal energy. Where such a resonance falls depends "
            "on the mesh (the high modes move with it), so this is where the mesh ends the backbone, not the blade"
            f"{_trend_words(end.get('trend'))}.")


def limit_words(end: dict) -> str:
    """The report's line on a family cut at the small-displacement limit (``end["kind"] == "amplitude_limit"``,
    :func:`bladecase.study.nodal.stage.nodal_stage`): where, why, and how far the continuation went on unreported.

    >>> print(limit_words({"frequency_beyond_hz": 231.2, "energy_beyond_j": 4.1, "tip_amplitude_beyond_mm": 7.9,
    ...     "limit_mm": 7.6, "amplitude_limit": 0.05, "span_mm": 152.9, "frequency_cut_hz": 230.8,
    ...     "energy_cut_j": 3.2, "tip_amplitude_cut_mm": 7.1, "orbits_beyond": 40, "continuation_top_energy_j": 4e14,
    ...     "continuation_top_yield_mm": 3.2e6}))
    - **The family is cut at the small-displacement limit**: at 231.2 Hz (4.1 J) a contact node moves 7.9 mm, \
more than 7.6 mm (5 % of the blade's 153 mm span, `[search] amplitude_limit`), where a linear-elastic, \
small-displacement model of the blade no longer holds; every figure above stops at the last orbit within it, \
230.8 Hz (3.2 J, 7.1 mm). The continuation went on for 40 more orbits, to 4e+14 J and a casing yield of 3.2e+06 \
mm: not figures of the blade.
    """
    last = ("the grazing orbit is already beyond it" if end.get("frequency_cut_hz") is None else
            f"every figure above stops at the last orbit within it, {end['frequency_cut_hz']:.5g} Hz "
            f"({end['energy_cut_j']:.3g} J, {end['tip_amplitude_cut_mm']:.3g} mm)")
    return (f"- **The family is cut at the small-displacement limit**: at {end['frequency_beyond_hz']:.5g} Hz "
            f"({end['energy_beyond_j']:.3g} J) a contact node moves {end['tip_amplitude_beyond_mm']:.3g} mm, more "
            f"than {end['limit_mm']:.3g} mm ({100 * end['amplitude_limit']:g} % of the blade's {end['span_mm']:.3g} mm "
            "span, `[search] amplitude_limit`), where a linear-elastic, small-displacement model of the blade no "
            f"longer holds; {last}. " + (
                "The continuation stops at that orbit: nothing beyond the limit is computed."
                if end["orbits_beyond"] <= 1 else
                f"The continuation went on for {end['orbits_beyond']} more orbits, to "
                f"{end['continuation_top_energy_j']:.3g} J and a casing yield of "
                f"{end['continuation_top_yield_mm']:.3g} mm: not figures of the blade."))


def tongue_words(section: dict) -> str | None:
    """The report's line on the internal resonances the family passed (``section["tongues"]`` whose ``left`` is
    ``"crossed"`` or ``"continued"``), or None.

    >>> print(tongue_words({"tongues": [{"start": 11, "stop": 17, "mode": 2, "mode_frequency_hz": 1722.4,
    ...     "ratio": "8:1", "frequency_hz": 215.499, "left": "crossed", "to_frequency_hz": 215.69}]}))
    - On the way it passes 1 internal resonance: with the 3rd open-contact mode (1722 Hz) at 8:1 near 215.5 Hz, \
crossed to the backbone at 215.69 Hz; the family's 7 orbits inside its tongue are not on the backbone (`on_backbone` \
in `nodal_modes.csv`). Where a tongue sits depends on the mesh; the backbone on either side does not.
    """
    passed = [t for t in section.get("tongues") or [] if t.get("left") in ("crossed", "continued")]
    if not passed:
        return None
    items = [f"with the {_ordinal(t['mode'] + 1)} open-contact mode ({t['mode_frequency_hz']:.4g} Hz) at {t['ratio']} "
             f"near {t['frequency_hz']:.5g} Hz, " + (f"crossed to the backbone at {t['to_frequency_hz']:.5g} Hz"
                                                      if t["left"] == "crossed" else "passed by the continuation")
             for t in passed]
    inside = sum(t["stop"] - t["start"] + 1 for t in passed)
    many = len(passed) > 1
    return (f"- On the way it passes {len(passed)} internal resonance{'s' if many else ''}: " + "; ".join(items)
            + f"; the family's {inside} orbits inside {'their tongues' if many else 'its tongue'} are not on the "
            "backbone (`on_backbone` in `nodal_modes.csv`). Where a tongue sits depends on the mesh; the backbone on "
            "either side does not.")


def yield_words(end: dict) -> str:
    """The report's line on a family cut at the elastic limit (``end["kind"] == "yield_strength"``,
    :func:`bladecase.study.stress_limit.cut_nodal_family`).

    >>> print(yield_words({"frequency_beyond_hz": 231.2, "energy_beyond_j": 4.1, "von_mises_beyond_pa": 9.1e8,
    ...     "at_mm": [1.0, 2.0, 0.0], "yield_strength_pa": 8.8e8, "frequency_cut_hz": 230.8, "energy_cut_j": 3.2,
    ...     "von_mises_cut_pa": 8.6e8}))
    - **The family is cut at the elastic limit**: at 231.2 Hz (4.1 J) the peak von Mises stress is 910 MPa (at \
(1, 2, 0) mm), above the yield strength 880 MPa (`[material] yield_strength`), where a linear-elastic model of the \
blade no longer holds; every figure above stops at the last orbit within it, 230.8 Hz (3.2 J, 860 MPa).
    """
    last = ("the grazing orbit is already beyond it" if end.get("frequency_cut_hz") is None else
            f"every figure above stops at the last orbit within it, {end['frequency_cut_hz']:.5g} Hz "
            f"({end['energy_cut_j']:.3g} J, {end['von_mises_cut_pa'] / 1e6:.4g} MPa)")
    point = ", ".join(f"{x:.4g}" for x in end["at_mm"])
    return (f"- **The family is cut at the elastic limit**: at {end['frequency_beyond_hz']:.5g} Hz "
            f"({end['energy_beyond_j']:.3g} J) the peak von Mises stress is {end['von_mises_beyond_pa'] / 1e6:.4g} MPa "
            f"(at ({point}) mm), above the yield strength {end['yield_strength_pa'] / 1e6:.4g} MPa "
            f"(`[material] yield_strength`), where a linear-elastic model of the blade no longer holds; {last}.")


def nodal_report(section: dict | None) -> list[str]:
    """Markdown lines for ``summary["nodal_modes"]`` (:func:`bladecase.study.nodal.stage.nodal_stage`)."""
    if not section or not section.get("rows"):
        if not section:
            return []
        end = section.get("end") or {}
        return ["", "## Every face node a contact", "",
                limit_words(end) if end.get("kind") == "amplitude_limit" else
                yield_words(end) if end.get("kind") == "yield_strength" else
                f"- No orbit: {section.get('stop', 'the family could not be started')}."]
    rows = section["rows"]
    top = max(backbone_rows(section), key=lambda r: r["energy_j"])
    lo, hi = section["frequency_range_hz"]
    first = section.get("first_touch_nodes") or []
    stable = section.get("stable_fraction")
    lines = ["", "## Every face node a contact", "",
             f"- The same blade with each of its {section['contact_nodes']} face nodes a contact of its own (the "
             f"massless model, {section['reduced_dofs']} dofs: {section['size']} modes with the nodes' residual "
             "flexibility); its nonsmooth mode followed from the first node's grazing. `nodal_modes.csv`: every "
             "orbit; `nodal_modes.png`: both models' frequency–energy curves and how far the tip goes.",
             "",
             f"- From {lo:.5g} Hz, where node{'s' if len(first) > 1 else ''} {', '.join(first[:6])} "
             f"touch{'' if len(first) > 1 else 'es'} first, to {hi:.5g} Hz: {len(rows)} orbits, up to "
             f"{section['most_nodes_touching']} nodes touching; at the top ({top['energy_j']:.3g} J) "
             f"{load_words(top, section.get('face_area_mm2'))}; a node is in contact for up to "
             f"{top['max_contact_fraction']:.0%} of the period and the casing yields up to "
             f"{top['max_penetration_mm'] * 1e3:.0f} µm"
             + ("" if stable is None else f"; {stable:.0%} of the orbits are linearly stable") + ".",
             end_words(section)]
    passed = tongue_words(section)
    if passed:
        lines.append(passed)
    ref = section.get("reference")
    if ref and ref.get("checked"):
        bad = ref["checked"] - ref["survived"]
        lines.append(f"- Checked: {ref['checked']} orbits, evenly spread over the family, re-simulated for one period "
                     f"in the reference model {ref['model']} (the model extended by the Krylov sequence of its "
                     f"factorisation): " + (f"all come back within {ref['max_drift']:.1e} (energy norm)." if not bad
                                            else f"**{bad} do not come back** (drift up to {ref['max_drift']:.1e}): "
                                            "those orbits are artefacts of the reduced model; enlarge "
                                            "`[reduction] size`."))
    fm = section.get("face_mean")
    if fm and fm.get("energy_j"):
        e = np.asarray(fm["energy_j"])
        beyond = np.asarray(fm["node_beyond_clearance_mm"])
        at = float(np.interp(top["energy_j"], e, beyond)) if e.min() <= top["energy_j"] <= e.max() else None
        lines.append(f"- The face-mean model (one constraint on the face's mean) starts touching only at "
                     f"{e.min():.3g} J, when the mean reaches the clearance; by then its farthest node is "
                     f"{beyond[int(np.argmin(e))] * 1e3:.0f} µm past its own clearance"
                     + (f", and at {top['energy_j']:.3g} J {at * 1e3:.0f} µm, where every node as a contact lets the "
                        f"casing yield {top['max_penetration_mm'] * 1e3:.0f} µm" if at is not None else "")
                     + ": where on the tip it rubs, and how hard, comes from this model, not from the mean.")
    return lines
