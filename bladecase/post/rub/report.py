"""The report's words on the rub response over speeds — written from ``summary["rub"]`` alone: where on the tip it
rubs, how hard, at which speed and at what ratio to the crossing speed of mode 1, and whether each figure can be
trusted (a speed that ran on to settle, a sub-harmonic, a response that never settled and what it is).

>>> rows = [{"speed": s, "speed_rad_s": s * 0.10472, "tip_normal_displacement_mm": d, "max_pressure_mpa": q,
...          "total_force_n": f, "loaded_area_mm2": a, "peak_loaded_area_mm2": a, "load_centre": x,
...          "load_location": where, "max_node_force_n": f / 4, "contact_fraction": c, "penetration_mm": p,
...          "nodes_touching": n, "switches": 100, "settled": ok}
...         for s, d, q, f, a, x, where, c, p, n, ok in [
...             (1400, 0.01, 0.07, 4.4, 30.0, 0.1, "leading edge", 0.2, 0.07, 11, True),
...             (1650, 0.69, 0.3, 21.0, 40.0, 0.05, "leading edge", 0.4, 0.31, 13, False)]]
>>> rows[1]["speed_ratio"] = 1650 / 1626.3
>>> section = {"speed_unit": "rpm", "lobes": 8, "amplitude_m": 3e-4, "revolutions": 30, "window": 10,
...            "damping": {"ratio": 0.005}, "nodes": list(range(26)), "rows": rows,
...            "worst": {**rows[1], "touching_nodes": [3, 5, 98], "touching_along_tip": [0.0, 0.05, 0.1]},
...            "unsettled_speeds": [1650], "resonances": [{"mode": 1, "speed": 1626.3, "frequency_hz": 216.8}],
...            "crossing": {"mode": 1, "speed": 1626.3, "frequency_hz": 216.8, "how": "interpolated"},
...            "characterised": [{"speed": 1650, "response": "transient", "settled": False, "revolutions_run": 300,
...                               "read_revolutions": 10, "change": 0.05, "decay": 0.5}],
...            "nonsmooth_bands_hz": [], "model": {"size": 8, "casing_n_per_m": 1e6, "face_area_mm2": 103.2}}
>>> lines = rub_report(section)
>>> lines[5].split(':')[0]
'- The hardest rub is at 1650 rpm (1.01 × the crossing speed of mode 1)'
>>> where, load, rest = lines[5].split("; ")
>>> where.split(", ")[1:]
['13 nodes touch (nodes 3', '5', '98) — all near the leading edge (0.00–0.10 of the chord from it)']
>>> load.split(", ")
['the contact pressure peaks at 0.3 MPa and the total contact force at 21 N', "over 40 mm² of the tip's 103 mm²", \
'centred at the leading edge (0.05 of the chord from the leading edge)']
"""

from __future__ import annotations

import numpy as np

from ...nsm.massless.wear_lobes import lobe_words
from ..nodal.report import load_words

__all__ = ["rub_report"]


def _where(along: list[float] | None, line: bool = False) -> str:
    """Where the touching nodes sit along the chord (0 leading edge – 1 trailing edge), in words; along a ``line``
    of nodes (no area: no thick end to tell the leading edge) from the line's first end."""
    if not along:
        return ""
    if line:
        return f" — at {min(along):.2f}–{max(along):.2f} of the line from its first end"
    lo, hi = min(along), max(along)
    if hi - lo < 0.15:
        end = "the leading edge" if hi <= 0.2 else "the trailing edge" if lo >= 0.8 else "mid-chord"
        return f" — all near {end} ({lo:.2f}–{hi:.2f} of the chord from it)" if end != "mid-chord" else \
            f" — all near mid-chord ({lo:.2f}–{hi:.2f} of the chord from the leading edge)"
    return f" — spread over {lo:.2f}–{hi:.2f} of the chord from the leading edge"


def _line_words(row: dict, section: dict) -> str:
    """The casing's load in words for a line of contact nodes (no area, so no pressure): the total force and where
    it sits along the line, from its first end (the end of lowest coordinate along it: a line has no thick end to
    tell the leading edge).

    >>> _line_words({"total_force_n": 12.0, "load_centre": 0.9, "load_location": "trailing edge"},
    ...             {"model": {"line_length_mm": 36.05}})
    'the total contact force peaks at 12 N on the line of contact nodes (36 mm long; a line has no area, so no \
contact pressure), centred at 0.90 of the line from its first end'
    """
    length = (section.get("model") or {}).get("line_length_mm")
    span = f" ({length:.3g} mm long; a line has no area, so no contact pressure)" if length else ""
    at = "" if row.get("load_centre") is None else f", centred at {row['load_centre']:.2f} of the line from its " \
                                                   "first end"
    return f"the total contact force peaks at {row['total_force_n']:.3g} N on the line of contact nodes{span}{at}"


def rub_report(section: dict | None) -> list[str]:
    """Markdown lines for ``summary["rub"]`` (:func:`bladecase.study.rub.stage.rub_stage`)."""
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
             "`rub.png` (peak tip normal displacement, total contact force and contact pressure against speed)."]
    touching = w["touching_nodes"]
    if w["total_force_n"] > 0:
        face = (section.get("model") or {}).get("face_area_mm2")
        line = (section.get("model") or {}).get("contact_measure") == "length"
        load = _line_words(w, section) if line else load_words(w, face)
        ratio = (f" ({w['speed_ratio']:.3g} × the crossing speed of mode 1)" if w.get("speed_ratio") is not None
                 else "")
        lines.append(f"- The hardest rub is at {w['speed']:.6g} {unit}{ratio}: the tip reaches "
                     f"{w['tip_normal_displacement_mm']:.4g} "
                     f"mm outwards, {w['nodes_touching']} nodes touch (nodes {', '.join(map(str, touching[:12]))}"
                     f"{', …' if len(touching) > 12 else ''}){_where(w.get('touching_along_tip'), line)}; "
                     f"{load}; a node is in contact for up to {w['contact_fraction']:.0%} of a "
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
    crossing = section.get("crossing")
    for res in section.get("resonances") or []:
        lines.append(f"- The lobes excite linear mode {res['mode']} ({res['frequency_hz']:.5g} Hz at that speed) at "
                     f"about {res['speed']:.6g} {unit}"
                     + (_CROSSING if res["mode"] == 1 and crossing and crossing.get("how") == "interpolated" else "")
                     + ".")
    if crossing and crossing.get("how") != "interpolated":
        lines.append(f"- The lobes would excite linear mode 1 ({crossing['frequency_hz']:.5g} Hz) at about "
                     f"{crossing['speed']:.6g} {unit}, outside the speeds run ("
                     + ("extrapolated from mode 1's frequency at the two nearest speeds"
                        if crossing["how"] == "extrapolated" else "mode 1's frequency at the one speed taken constant")
                     + ")" + _CROSSING + ".")
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
    lines += _settling(section, unit)
    lines += _friction_lines(section.get("friction"), unit)
    lines += _wear_lines(section.get("wear"), unit)
    return lines


def _wear_lines(w: dict | None, unit: str) -> list[str]:
    """The abradable coating's words: the coating, the coupling, per speed the lobes and depth worn, the removed
    volume against the profile's missing volume, the response's frequency over the rotation's."""
    if not w:
        return []
    c = w["coating"]
    out = [f"- Abradable coating: {c['thickness_m'] * 1e3:.4g} mm thick, removed above {c['yield_pa'] * 1e-6:.4g} MPa "
           f"(stiffness {c['stiffness_pa_per_m']:.4g} Pa/m: it yields {c['yield_depth_m'] * 1e6:.3g} µm elastically), "
           f"{c['cells']} cells round the casing over the {c['width_m'] * 1e3:.4g} mm band the tip rubs; "
           f"{w['coupling']}. Files: `wear.csv` (per speed and revolution), `wear_profile.csv`, `wear.png` (the "
           "profile unrolled over the angle after each revolution), `wear.vtu` (the worn casing).",
           ]
    for r in w["speeds"]:
        if r["removed_mm3"] == 0:
            out.append(f"- At {r['speed']:.6g} {unit} the tip removes no coating in {r['revolutions']} revolutions.")
            continue
        c = r.get("lobe_check")
        check = (f"; over revolutions {c['last'] - c['window'] + 1}–{c['last']}, the last that wore the coating, "
                 f"{lobe_words(c)}" if c and c.get("last") else f"; {lobe_words(c)}" if c else "")
        out.append(f"- At {r['speed']:.6g} {unit} after {r['revolutions']} revolutions the profile has {r['lobes']} "
                   f"lobes, {r['lobe_depth_um']:.3g} µm deep (deepest {r['max_depth_um']:.3g} µm); "
                   f"{r['removed_mm3']:.4g} mm³ removed (the profile's missing volume to {r['volume_mismatch']:.0e}); "
                   f"the tip vibrates at {r['vibration_ratio']:.3g} × the rotation frequency{check}"
                   + ("; **the tip has worn through to the casing**." if r["worn_through"] else "."))
    if len(w["speeds"]) > 1:
        out.append(f"- The most coating is removed at {w['most_wear']:.6g} {unit}.")
    top = next((r for r in w["speeds"] if r["speed"] == w["most_wear"]), None)
    e = top and top.get("energy")
    if e:
        out.append(f"- Energy of the last revolution at {top['speed']:.6g} {unit}: the casing puts in "
                   f"{e['casing_input_j']:.4g} J, friction does {e['friction_work_j']:.4g} J on the vibration, damping "
                   f"takes {e['damping_j']:.4g} J, removing the coating {e['removal_work_j']:.4g} J, the worn "
                   f"profile's steps under the touching nodes do {e['surface_steps_j']:.4g} J and the stored energy "
                   f"changes by {e['stored_change_j']:.4g} J; the balance closes to "
                   f"{w['worst_balance_residual']:.1e} (relative, worst revolution of every speed; `wear.csv` gives "
                   "each).")
    out.append("- The wear's depths and volumes are this mesh's: their mesh error is not measured (the tip nodes' "
               "areas share the coating's pressure, and the crossing speed moves with the mesh's first frequency); "
               "compare meshes at the same `speed_ratio` before quoting them.")
    return out


def _friction_lines(f: dict | None, unit: str) -> list[str]:
    """The friction's words (:func:`_friction_energy_lines`) and those of its mode (:func:`_mode_lines`)."""
    if not f:
        return []
    return _friction_energy_lines(f, unit) + _mode_lines(f.get("modes"), unit)


def _mode_lines(m: dict | None, unit: str) -> list[str]:
    """The first mode with friction: at the speed where its damping ratio moves most from the structural one, its
    frequency and ratio from the least to the largest amplitude, the free decay's check, and what is doubtful."""
    if not m:
        return []
    per = [(s, [q for q in s["points"] if "error" not in q]) for s in m["speeds"]]
    per = [(s, good) for s, good in per if good]
    out = []
    if per:
        s, good = max(per, key=lambda sg: max(abs(q["zeta"] - sg[0]["structural_zeta"]) for q in sg[1]))
        lo, hi = good[0], good[-1]
        out.append(f"- The first mode with friction (the extended periodic motion concept: a term balancing what "
                   f"friction and damping take over a period; `friction_modes.csv`, `friction_modes.png`): at "
                   f"{s['speed']:.6g} {unit} (where its damping ratio moves most from the structural one), from "
                   f"{lo['amplitude_ratio']:g} to {hi['amplitude_ratio']:g} × its grazing amplitude "
                   f"({lo['tip_amplitude_m'] * 1e3:.4g} to {hi['tip_amplitude_m'] * 1e3:.4g} mm at the tip) its "
                   f"frequency goes {lo['frequency_hz']:.6g} → {hi['frequency_hz']:.6g} Hz (open {s['open_hz']:.6g} "
                   f"Hz) and its damping ratio {100 * lo['zeta']:.4f} → {100 * hi['zeta']:.4f} % (structural "
                   f"{100 * s['structural_zeta']:.4f} %).")
        if m.get("worst_decay_error") is not None:
            out.append(f"- Checked by the free decay from each orbit's start without the balancing term: its damping "
                       f"ratio within {100 * abs(m['worst_decay_error']):.2g} % of the mode's at every speed and "
                       "amplitude. These figures are this mesh's: their mesh error is not measured.")
    for words in m["doubts"]:
        out.append(f"- **The mode with friction is doubtful** {words}.")
    return out


def _friction_energy_lines(f: dict, unit: str) -> list[str]:
    """The friction's model and assumption, the energy of the hardest speed's last revolution, the balance and the
    sliding check."""
    out = [f"- Friction: {f['assumption']}."]
    rows = [r for r in f["speeds"] if r["casing_input_j"] is not None]
    if rows:
        top = max(rows, key=lambda r: abs(r["casing_input_j"]))
        out.append(f"- Energy over the last revolution at {top['speed']:.6g} {unit}: the casing puts in "
                   f"{top['casing_input_j']:.4g} J, friction does {top['friction_work_j']:.4g} J on the vibration, "
                   f"damping takes {top['damping_j']:.4g} J and the stored energy changes by "
                   f"{top['stored_change_j']:.4g} J; the balance closes to {f['worst_residual']:.1e} (relative, worst "
                   "revolution of every speed's window; `rub.csv` gives every speed).")
    if f.get("model") == "coulomb":
        if rows:
            out.append("- Stick–slip, the share of contact time a node spends sticking to the casing (largest over the "
                       "nodes): " + ", ".join(f"{r['stick_share']:.3g} at {r['speed']:.6g} {unit}" for r in rows)
                       + ".")
        return out
    bad = f.get("not_rotation_dominated") or []
    if bad:
        out.append(f"- **The sliding is not dominated by the rotation** at {', '.join(f'{s:.6g}' for s in bad)} "
                   f"{unit}: a node's tangential vibration velocity exceeds 0.1 × ΩR there, so the friction's "
                   "direction is not the circumferential one and the results with friction are not to be trusted "
                   "at those speeds (a stick–slip model is needed).")
    elif rows:
        worst = max(r["sliding_ratio"] or 0.0 for r in rows)
        out.append(f"- The sliding is dominated by the rotation at every speed: the largest tangential vibration "
                   f"velocity is {worst:.2g} × ΩR (the assumption holds below 0.1).")
    return out


#: Said of the crossing speed of mode 1 where the report names it.
_CROSSING = (" — the crossing speed: `speed_ratio` in `rub.csv` is each speed over it; compare meshes at the same "
             "ratio, which carries each mesh's error in f1 out of the comparison")


def _settling(section: dict, unit: str) -> list[str]:
    """Which speeds ran on to settle, which repeat over another period, and what those that never settled are."""
    rows, window = section["rows"], section["window"]
    out = []
    cases = section.get("characterised") or []
    ran = [c for c in cases if c["settled"] and c["revolutions_run"] > section["revolutions"]]
    if ran:
        runs = [c["revolutions_run"] for c in ran]
        out.append(f"- {len(ran)} of {len(rows)} speeds had not settled after {section['revolutions']} revolutions and "
                   f"ran on until they did ({min(runs)}–{max(runs)} revolutions"
                   + (f", of at most {section['max_revolutions']}" if section.get("max_revolutions") else "") + ").")
    for c in cases:
        out.extend(_verdict(c, section, unit))
    unsettled = section.get("unsettled_speeds") or []
    if unsettled:
        cap = section.get("max_revolutions") or section["revolutions"]
        out.append(f"- **Not settled** at {len(unsettled)} of {len(rows)} speeds ("
                   f"{', '.join(f'{s:.6g}' for s in unsettled[:8])}{', …' if len(unsettled) > 8 else ''} {unit}) "
                   f"within {cap} revolutions: the peaks of the last {window} revolutions still differ from those of "
                   f"the {window} before by more than 2 %; what each of them is is said above — read its figures "
                   "as that, not as a steady state.")
    return out


def _over(c: dict) -> str:
    """How many lobe passings the 0-1 test had (it wants a few hundred)."""
    n = c.get("samples")
    return "" if not n else f" over {n} lobe passings" + (", too few to be sure" if n < 200 else "")


def _verdict(c: dict, section: dict, unit: str) -> list[str]:
    """One speed's response in words, when it is not a plain settled one."""
    at, window, kind = f"At {c['speed']:.6g} {unit}", section["window"], c["response"]
    change = f"{c['change']:.1%}"
    if kind.startswith("periodic-"):
        q, lobes = int(kind.split("-")[1]), section["lobes"]
        rev = q / lobes
        over = (f"{rev:.0f} revolution{'s' if rev != 1 else ''} ({q} lobe passings" if rev == int(rev)
                else f"{q} lobe passings ({rev:.3g} revolutions")
        times = round(c["read_revolutions"] / rev)
        read = "that period" if times == 1 else f"{times} of those periods ({c['read_revolutions']:.3g} revolutions)"
        return [f"- {at} the response is periodic over {over}: a sub-harmonic, at 1/{q} of the lobes' frequency); "
                f"its figures are the peaks over {read}."]
    if kind == "transient":
        more = ""
        if c.get("decay") and 0 < c["decay"] < 1 and c["change"] > 0:
            windows = max(1, int(np.ceil(np.log(0.02 / c["change"]) / np.log(c["decay"]))))
            more = (f"; at that rate about {windows * window} more revolutions would settle it (raise [rub] "
                    "max_revolutions)")
        return [f"- {at} the response was still settling when the cap of {c['revolutions_run']} revolutions was "
                f"reached: its change from one window to the next falls steadily (by a factor "
                f"{c.get('decay', float('nan')):.2g} per window of {window} revolutions) and was {change} at the end"
                f"{more}; its figures are those of the last {window} revolutions, not yet of the steady state."]
    if kind == "quasi-periodic":
        turn = f" (once per lobe passing its state turns {c['rotation']:.3g} of a cycle)" if c.get("rotation") else ""
        return [f"- {at} the response is quasi-periodic: regular (0-1 test for chaos K = {c.get('k', 0):.2f}"
                f"{_over(c)}) but "
                f"repeating at no period within {c['revolutions_run']} revolutions — a second frequency, "
                f"incommensurate with the lobes', modulates it{turn}; its figures are the peaks over the last "
                f"{window} revolutions, which change by {change} from one window to the next."]
    if kind == "irregular":
        return [f"- {at} the response is irregular — chaotic, or wandering among states (0-1 test for chaos K = "
                f"{c.get('k', 1):.2f}{_over(c)}, no period within {c['revolutions_run']} revolutions); its figures are "
                "the "
                f"peaks over the last {window} revolutions, one sample of a fluctuating response, which change by "
                f"{change} from one window to the next."]
    return []
