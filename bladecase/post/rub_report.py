"""The report's words on the rub response over speeds — written from ``summary["rub"]`` alone: where on the tip it
rubs, how hard, at which speed, and whether each figure can be trusted (a response that had not settled).

>>> rows = [{"speed": s, "speed_rad_s": s * 0.10472, "tip_displacement_mm": d, "max_pressure_mpa": q,
...          "total_force_n": f, "loaded_area_mm2": a, "peak_loaded_area_mm2": a, "load_centre": x,
...          "load_location": where, "max_node_force_n": f / 4, "contact_fraction": c, "penetration_mm": p,
...          "nodes_touching": n, "switches": 100, "settled": ok}
...         for s, d, q, f, a, x, where, c, p, n, ok in [
...             (1400, 0.01, 0.07, 4.4, 30.0, 0.1, "leading edge", 0.2, 0.07, 11, True),
...             (1650, 0.69, 0.3, 21.0, 40.0, 0.05, "leading edge", 0.4, 0.31, 13, False)]]
>>> section = {"speed_unit": "rpm", "lobes": 8, "amplitude_m": 3e-4, "revolutions": 30, "window": 10,
...            "damping": {"ratio": 0.005}, "nodes": list(range(26)), "rows": rows,
...            "worst": {**rows[1], "touching_nodes": [3, 5, 98], "touching_along_tip": [0.0, 0.05, 0.1]},
...            "unsettled_speeds": [1650], "resonances": [{"mode": 1, "speed": 1626.3, "frequency_hz": 216.8}],
...            "nonsmooth_bands_hz": [], "model": {"size": 8, "casing_n_per_m": 1e6, "face_area_mm2": 103.2}}
>>> lines = rub_report(section)
>>> lines[5].split(':')[0]
'- The hardest rub is at 1650 rpm'
>>> where, load, rest = lines[5].split("; ")
>>> where.split(", ")[1:]
['13 nodes touch (nodes 3', '5', '98) — all near the leading edge (0.00–0.10 of the chord from it)']
>>> load.split(", ")
['the contact pressure peaks at 0.3 MPa and the total contact force at 21 N', "over 40 mm² of the tip's 103 mm²", \
'centred at the leading edge (0.05 of the chord from the leading edge)']
"""

from __future__ import annotations

from .nodal_report import load_words

__all__ = ["rub_report"]


def _where(along: list[float] | None) -> str:
    """Where the touching nodes sit along the chord (0 leading edge – 1 trailing edge), in words."""
    if not along:
        return ""
    lo, hi = min(along), max(along)
    if hi - lo < 0.15:
        end = "the leading edge" if hi <= 0.2 else "the trailing edge" if lo >= 0.8 else "mid-chord"
        return f" — all near {end} ({lo:.2f}–{hi:.2f} of the chord from it)" if end != "mid-chord" else \
            f" — all near mid-chord ({lo:.2f}–{hi:.2f} of the chord from the leading edge)"
    return f" — spread over {lo:.2f}–{hi:.2f} of the chord from the leading edge"


def rub_report(section: dict | None) -> list[str]:
    """Markdown lines for ``summary["rub"]`` (:func:`bladecase.study.rub.rub_stage`)."""
    if not section:
        return []
    unit, rows = section["speed_unit"], section["rows"]
    w = section["worst"]
    damping = section["damping"]
    damp = (f"modal damping ratio {damping['ratio']:g}" if "ratio" in damping
            else f"Rayleigh damping α = {damping['rayleigh'][0]:g} s, β = {damping['rayleigh'][1]:g} 1/s")
    lines = ["", "## Rub response", "",
             f"- The blade turns from rest inside a casing with {section['lobes']} lobes of "
             f"{section['amplitude_m'] * 1e3:.4g} mm, every one of its {len(section['nodes'])} contact nodes a "
             f"contact of its own, {damp}; {len(rows)} speeds from {rows[0]['speed']:.6g} to {rows[-1]['speed']:.6g} "
             f"{unit}, {section['revolutions']} revolutions each, the figures read on the last {section['window']} "
             "(the stiffness and the running clearances at each speed: centrifugal state about the casing's axis).",
             "- Files: `rub.csv` (per speed), `rub_nodes.csv` (per speed and node, with each node's contact pressure), "
             "`rub.png` (peak tip displacement, total contact force and contact pressure against speed)."]
    touching = w["touching_nodes"]
    if w["total_force_n"] > 0:
        face = (section.get("model") or {}).get("face_area_mm2")
        lines.append(f"- The hardest rub is at {w['speed']:.6g} {unit}: the tip reaches {w['tip_displacement_mm']:.4g} "
                     f"mm outwards, {w['nodes_touching']} nodes touch (nodes {', '.join(map(str, touching[:12]))}"
                     f"{', …' if len(touching) > 12 else ''}){_where(w.get('touching_along_tip'))}; "
                     f"{load_words(w, face)}; a node is in contact for up to {w['contact_fraction']:.0%} of a "
                     "revolution"
                     + (f" and the casing yields up to {w['penetration_mm']:.4g} mm under it."
                        if w["penetration_mm"] > 0 else "."))
    else:
        lines.append("- No node touches the casing at any speed: the lobes' amplitude stays within every node's "
                     "running clearance (see `rub_nodes.csv`, clearance_mm).")
    quiet = [r["speed"] for r in rows if r["nodes_touching"] == 0]
    if quiet and len(quiet) < len(rows):
        lines.append(f"- No contact at {len(quiet)} of the speeds ({', '.join(f'{s:.6g}' for s in quiet[:8])}"
                     f"{', …' if len(quiet) > 8 else ''} {unit}).")
    for res in section.get("resonances") or []:
        lines.append(f"- The lobes excite linear mode {res['mode']} ({res['frequency_hz']:.5g} Hz at that speed) at "
                     f"about {res['speed']:.6g} {unit}.")
    bands = section.get("nonsmooth_bands_hz") or []
    if bands:
        lines.append("- The study's nonsmooth modes (face-mean contact, " + section.get("bands_at", "at rest")
                     + ") span " + ", ".join(f"{lo:.5g}–{hi:.5g} Hz" for lo, hi in bands)
                     + f": a casing with {section['lobes']} lobes excites them at "
                     + ", ".join(f"{lo * 60 / section['lobes']:.6g}–{hi * 60 / section['lobes']:.6g} rpm"
                                 for lo, hi in bands) + " (shaded on `rub.png`).")
    for f in section.get("failed_speeds") or []:
        lines.append(f"- **No result at {f['speed']:.6g} {unit}**: the simulation was refused there ({f['reason']}); "
                     "the other speeds are unaffected.")
    unsettled = section.get("unsettled_speeds") or []
    if unsettled:
        lines.append(f"- **Not settled** at {len(unsettled)} of {len(rows)} speeds ("
                     f"{', '.join(f'{s:.6g}' for s in unsettled[:8])}{', …' if len(unsettled) > 8 else ''} {unit}): "
                     f"the peaks of the last {section['window']} revolutions differ from those of the "
                     f"{section['window']} before by more than 2 %, so the transient from rest has not died out (or "
                     "the response is not periodic); read those figures as a lower bound of the steady state, or "
                     "raise [rub] revolutions.")
    return lines
