"""The run's Markdown report, written from its summary (``summary.json``) alone."""

from __future__ import annotations

import numpy as np

from .casing.report import casing_report
from .casing.words import weak_casing_words
from .convergence.report import convergence_report
from .nodal.report import nodal_report
from .rotation.modes_report import modes_report
from .rotation.report import rotation_report
from .rub.report import rub_report
from .verdict import (  # noqa: F401 (re-exported)
    NARROW_RTOL,
    massless_summary,
    narrow_words,
    orbit_words,
    rejected_words,
    verdict,
)


def engineering_words(a: dict, massless: bool) -> str:
    """What the blade and the casing see over an animated orbit (its ``summary.json`` entry), in a sentence:
    tip amplitude |u|, contact force (Newton: impulses) and duration, the casing's give.

    >>> text = engineering_words({"tip_amplitude_mm": 0.5, "tip_amplitude_node_id": 3, "tip_amplitude_t_over_T": 0.09,
    ...                           "contact_force_n": 27.3, "contact_fraction": 0.181,
    ...                           "casing_penetration_m": 2.73e-5}, True)
    >>> print(*text.split("; "), sep="\\n")
    tip amplitude |u| up to 0.5 mm (node 3, t/T = 0.090)
    contact force up to 27.3 N, in contact 18.1 % of the period
    the casing yields up to 27.3 µm (λ/k)
    """
    if "tip_amplitude_mm" not in a:
        return "no engineering quantities in this summary"
    words = [f"tip amplitude |u| up to {a['tip_amplitude_mm']:.4g} mm (node {a['tip_amplitude_node_id']}, "
             f"t/T = {a['tip_amplitude_t_over_T']:.3f})"]
    if massless:
        words.append(f"contact force up to {a['contact_force_n']:.4g} N, in contact "
                     f"{100 * a['contact_fraction']:.3g} % of the period")
        if a.get("casing_penetration_m") is not None:
            words.append(f"the casing yields up to {a['casing_penetration_m'] * 1e6:.4g} µm (λ/k)")
    else:
        words.append(f"impulses up to {a['contact_impulse_ns']:.4g} N·s per impact (Newton's law: instantaneous "
                     "impacts, no contact force and no contact duration)")
    return "; ".join(words)


def verdict_lines(summary: dict) -> list[str]:
    """The verdict at the top of the report: what was found, whether to trust it, what to do next — the summary's
    ``verdict`` (:func:`~bladecase.post.verdict.verdict`), or computed from the summary when it has none."""
    v = summary.get("verdict") or verdict(summary)
    return [f"- **Found:** {v['found']}", f"- **Trust:** {v['trust']}", f"- **Next:** {v['next']}"]


def report(summary: dict) -> str:
    """A human-readable Markdown report of a run's :data:`summary` (a run without a contact: the linear modes and
    the Campbell diagram, :func:`~bladecase.post.rotation.modes_report.modes_report`)."""
    if summary.get("contact") is None and summary.get("reduction") is None:
        return modes_report(summary)
    m, c, r = summary["model"], summary["contact"], summary["reduction"]
    massless = massless_summary(summary)
    lines = [f"# bladecase study `{summary['study']}`", "", *verdict_lines(summary), "",
             f"Study file: `{summary['source']}` — bladecase {summary['bladecase_version']} — "
             f"total {summary['timings_s']['total']:.1f} s.", "",
             "## Model", "",
             f"- Mesh: {m['mesh']['nodes']} nodes, {m['mesh']['cells']} `{m['mesh']['type']}` cells "
             f"({m['mesh']['source']}{_mesh_words(m['mesh'])}).",
             f"- FE model: {m['dim']}-D, P{m['order']}, {m['dofs']} free dofs, {m['mass_matrix']} mass, "
             f"{m['material']['name']} (E = {m['material']['E']:.4g} Pa, ν = {m['material']['nu']:g}, "
             f"ρ = {m['material']['rho']:g} kg/m³), total mass {m['total_mass_kg']:.5g} kg, "
             f"{_clamp_words(m)}.",
             "- Linear frequencies (full FE model, Hz): " + ", ".join(f"{f:.2f}" for f in m["linear_frequencies_hz"]),
             *_plausibility_words(m),
             "", "## Contact", "",
             (f"- {_face_words(c)}, centre node {_node(c)}" if len(c.get("face_nodes", [])) > 1
              else f"- Node {_node(c)}")
             + f" at ({', '.join(f'{x * 1e3:.5g}' for x in c['position'])}) mm, casing normal "
             f"({', '.join(f'{x:.4g}' for x in c['normal'])}), clearance {c['clearance_m'] * 1e3:.4g} mm.",
             _model_words(massless),
             _casing_words(c.get("casing_stiffness_n_per_m"), c),
             *_static_words(c),
             *rotation_report(summary.get("rotation"), summary.get("campbell")),
             "", "## Reduced model", "",
             f"- {r['method']} (size {r['size']}): {r['reduced_dofs']} reduced dofs.",
             *_reference_model_words(summary.get("reference")), "",
             "| mode | reduced f (Hz) | contact weight b² | FE counterpart (by mode shape) | rel. error |",
             "|---:|---:|---:|---|---:|"]
    fe = m["linear_frequencies_hz"]
    matches = r.get("fe_match")
    for j, (f, b2) in enumerate(zip(r["frequencies_hz"], r["contact_weights_b2"])):
        if j >= 12:
            break
        if matches is None:  # a summary written before mode-shape matching: nearest frequency
            ref = fe[int(np.argmin(np.abs(np.asarray(fe) - f)))] if fe else float("nan")
            lines.append(f"| {j + 1} | {f:.3f} | {b2:.3e} | nearest {ref:.3f} Hz | {abs(f - ref) / ref:.2e} |")
            continue
        lines.append(f"| {j + 1} | {f:.3f} | {b2:.3e} | {_counterpart(matches[j])} |")
    lines += convergence_report(summary.get("convergence"))
    if summary.get("comparison"):
        lines += comparison_report(summary["comparison"])
    lines += nodal_report(summary.get("nodal_modes"))
    lines += casing_report(summary.get("casing_sweep"))
    lines += rub_report(summary.get("rub"))
    if summary.get("forcing"):
        lines += forcing_report(summary["forcing"], summary["files"].get("forced_animations", []),
                                massless=massless)
    s = summary["search"]
    per = "contact phases per period" if massless else "impacts per period (ipp)"
    lines += ["", "## Nonsmooth modes", "",
              f"Search: {per} {s['ipp']}, periods {s['periods']} × {s['period_unit']} "
              f"(= [{s['periods'][0] * s['period_unit_s']:.6g}, {s['periods'][1] * s['period_unit_s']:.6g}] s), "
              f"scan {s['scan']}.", ""]
    fams = summary["families"]
    with_arcs = [(i, f) for i, f in enumerate(fams) if f["admissible_arcs"]]
    lines.append(f"{len(fams)} {'family' if len(fams) == 1 else 'families'} found, {len(with_arcs)} with admissible "
                 "arcs" + (" (families without any are listed in `summary.json`)." if len(with_arcs) < len(fams)
                           else "."))
    if with_arcs:
        lines += ["", f"| family | {'contact phases / period' if massless else 'ipp'} | orbits | f range (Hz) | "
                  "admissible arc f (Hz) | energy on arc (J) | linearly stable (Floquet) |",
                  "|---:|---:|---:|---|---|---|---|"]
    for i, f in with_arcs:
        for a in f["admissible_arcs"]:
            stable = a.get("stable_fraction")
            lines.append(f"| {i} | {f['ipp']} | {f['orbits']} | {f['frequency_range_hz'][0]:.3f} – "
                         f"{f['frequency_range_hz'][1]:.3f} | {a['f_lo']:.4f} – {a['f_hi']:.4f} | "
                         f"{a['energy_range_j'][0]:.3e} – {a['energy_range_j'][1]:.3e} | "
                         f"{'—' if stable is None else f'{stable:.0%} of its orbits'} |")
    lines += _arc_engineering_table(with_arcs, massless)
    lines += [w for i, f in with_arcs if (w := _resonance_words(i, f))]
    lines += [w for i, f in with_arcs for a in f["admissible_arcs"] if (w := _tongue_words(i, a))]
    narrow = narrow_words(summary)
    if narrow:
        lines += ["", f"**Narrow:** {narrow}."]
    lines += _validity_words(summary.get("validity"))
    files = summary["files"]
    if not files.get("animations") and not with_arcs:
        lines += ["", "**No orbit animated:** no family has an admissible arc in the search range (the verdict at the "
                  "top says why)."]
    elif summary.get("reference") and not files.get("animations"):
        ref = summary["reference"]
        words = rejected_words(summary)
        if words is None:
            lines += ["", f"**No orbit animated:** unless `[output] animate = 0`, no admissible orbit of the "
                      f"{r['method']} model that was tried survives in the reference model {ref['method']} "
                      f"({ref['reduced_dofs']} dofs) — the families above are artefacts of the reduced model (run.log "
                      "names the orbits)."]
        elif ref["rejected"]:
            lines += ["", f"**No orbit animated:** {words} — the families above are artefacts of the reduced "
                      f"model ({r['method']})."]
        else:
            lines += ["", f"**No orbit animated:** {words}."]
    lines += ["", "## Files", ""]
    if "frequency_energy_plot" in files:
        lines += [f"![frequency–energy]({files['frequency_energy_plot']})", ""]
    lines.append(f"- `{files['mesh']}`: the mesh with its groups; `{files['modes']}`: every family and orbit.")
    for a in files.get("animations", []):
        what = ", ".join(f"`{a[k]}`" for k in ("gif", "mp4", "pvd", "manifold") if k in a)
        phases = ("in contact for t/T in " + ", ".join(f"[{c0 / a['T']:.4f}, {c1 / a['T']:.4f}]"
                                                       for c0, c1 in a["contact_intervals"])
                  if "contact_intervals" in a else
                  "impacts at t/T = " + ", ".join(f"{t / a['T']:.4f}" for t in a["impact_times"]))
        check = a["verification"]
        lines.append(f"- family {a['family']}, {orbit_words(a['ipp'], massless)}, T = {a['T']:.8g} s "
                     f"(f = {a['frequency_hz']:.3f} "
                     f"Hz, E = {a['energy_j']:.3e} J, "
                     f"{phases}, displacements × {a['scale']:.4g}; event-driven simulation returns to it to "
                     f"{check['return_error']:.1e}{'' if check['ok'] else ' — CHECK FAILED'}): {what}")
        if a.get("substitutes_for_T"):
            asked = ", ".join(f"{t:.8g}" for t in a["substitutes_for_T"])
            lines.append(f"  - **Not the orbit asked for:** `[output] orbits` asked for T = {asked} s, where no "
                         "admissible orbit of this ipp was found; this is the nearest admissible one.")
        if "reference_check" in a:
            lines.append(f"  - {_reference_words(a['reference_check'], a['ipp'])}")
        if "energy_words" in a:
            lines.append(f"  - {a['energy_words']}")
        if "tip_amplitude_mm" in a:
            text = engineering_words(a, massless)
            lines.append(f"  - Tip and casing: {text}.")
        if "stability" in a:
            how = ("of the one-period map; the massless contact needs no saltation matrices" if massless
                   else "with saltation matrices")
            lines.append(f"  - Stability (Floquet multipliers {how}): {a['stability']}.")
        if a.get("tip_excursion"):
            x = a["tip_excursion"]
            lines.append(f"  - {'**Tip nodes beyond the clearance:** ' if x['nodes_beyond'] else 'Tip: '}"
                         f"{x['words'][:1].upper()}{x['words'][1:]}.")
        if "gif" in a:
            lines.append(f"\n  ![{a['gif']}]({a['gif']})\n")
    lines += _nodal_animation_words(files.get("nodal_animations") or [])
    lines += ["", "Timings (s): " + ", ".join(f"{k} {v:.2f}" for k, v in summary["timings_s"].items()), ""]
    return "\n".join(lines)


def _nodal_animation_words(anims: list[dict]) -> list[str]:
    """The animated orbits of the mode with every face node a contact: files, checks, what the casing does."""
    lines = []
    for a in anims:
        what = ", ".join(f"`{a[k]}`" for k in ("gif", "mp4", "pvd") if k in a)
        check = a["verification"]
        ref = a.get("reference_check") or {}
        lines.append(f"- every face node a contact, T = {a['T']:.8g} s (f = {a['frequency_hz']:.3f} Hz, E = "
                     f"{a['energy_j']:.3e} J, {a['nodes_touching']} nodes touching; the event-driven simulation "
                     f"returns to it to {check['return_error']:.1e}"
                     + (f", and in the reference model {ref['reference']} to {ref['drift']:.1e}" if ref.get("drift")
                        is not None else "") + f"): {what}")
        full = a.get("full_model_check") or {}
        if full.get("drift") is not None:
            lines.append(f"  - In the FE model (a reference converged in size: {', '.join(map(str, full['dofs']))} "
                         f"dofs) it comes back within {full['drift']:.2e} after one period (energy norm), to "
                         f"±{full['bound']:.1e}.")
        lines.append(f"  - Casing: the largest penetration {a['max_penetration_mm'] * 1e3:.4g} µm (the frames show "
                     f"{a['frames_max_penetration_mm'] * 1e3:.4g} µm), contact pressure up to "
                     f"{a.get('max_pressure_mpa', float('nan')):.3g} MPa, total force {a.get('total_force_n', 0):.4g} N"
                     + (f", centred at the {a['load_location']}" if a.get("load_location") else "")
                     + "; the VTK frames carry each contact node's `normal_gap`, `contact_pressure` and "
                     "`casing_yield`.")
        if "gif" in a:
            lines.append(f"\n  ![{a['gif']}]({a['gif']})\n")
    return lines


def _validity_words(v: dict | None) -> list[str]:
    """Where the admissible arcs were cut at the small-displacement limit and at the elastic limit (nothing when
    none was)."""
    if not v:
        return []
    return _amplitude_cut_words(v) + _stress_cut_words(v)


def _stress_cut_words(v: dict) -> list[str]:
    """Where the admissible arcs were cut at ``[material] yield_strength`` (nothing when none was).

    >>> v = {"yield_strength_pa": 8.8e8, "stress_cuts": [{"family": 0, "T_cut": 1 / 212.0, "von_mises_cut": 8.5e8,
    ...      "T_beyond": 1 / 212.5, "von_mises_beyond": 9.1e8, "at_mm": [1.0, 2.0, 0.0], "t_over_T": 0.25}]}
    >>> print(_stress_cut_words(v)[1])  # doctest: +NORMALIZE_WHITESPACE
    **Cut at the elastic limit:** the model is linear elastic, valid while the stress stays below the material's
    yield strength, 880 MPa (`[material] yield_strength`): family 0's arc ends at 212 Hz (T = 0.0047169811 s, peak
    von Mises 850 MPa); beyond it the peak von Mises stress is 910 MPa at 212.5 Hz, at (1, 2, 0) mm, t/T = 0.25.
    The orbits beyond stay in `modes.json` but are no part of any admissible arc.
    """
    if not v.get("stress_cuts"):
        return []
    where = []
    for c in v["stress_cuts"]:
        at = (f"ends at {1 / c['T_cut']:.6g} Hz (T = {c['T_cut']:.8g} s, peak von Mises "
              f"{c['von_mises_cut'] / 1e6:.4g} MPa)" if c.get("T_cut") else "is dropped whole")
        point = ", ".join(f"{x:.4g}" for x in c["at_mm"])
        where.append(f"family {c['family']}'s arc {at}; beyond it the peak von Mises stress is "
                     f"{c['von_mises_beyond'] / 1e6:.4g} MPa at {1 / c['T_beyond']:.6g} Hz, at ({point}) mm, "
                     f"t/T = {c['t_over_T']:.3g}")
    return ["", "**Cut at the elastic limit:** the model is linear elastic, valid while the stress stays below the "
            f"material's yield strength, {v['yield_strength_pa'] / 1e6:.4g} MPa (`[material] yield_strength`): "
            + "; ".join(where) + ". The orbits beyond stay in `modes.json` but are no part of any admissible arc."]


def _amplitude_cut_words(v: dict) -> list[str]:
    """Where the admissible arcs were cut at the small-displacement limit (nothing when none was)."""
    if not v.get("cuts"):
        return []
    where = []
    for c in v["cuts"]:
        at = (f"ends at {1 / c['T_cut']:.6g} Hz (T = {c['T_cut']:.8g} s, tip amplitude "
              f"{c['tip_amplitude_cut'] * 1e3:.4g} mm)" if c.get("T_cut") else "is dropped whole")
        where.append(f"family {c['family']}'s arc {at}; beyond it the tip moves {c['tip_amplitude_beyond'] * 1e3:.4g} "
                     f"mm at {1 / c['T_beyond']:.6g} Hz")
    return ["", f"**Cut at the small-displacement limit:** the model is linear elastic about the undeformed blade, "
            f"valid while the tip moves less than {v['limit_m'] * 1e3:.4g} mm ({100 * v['amplitude_limit']:g} % of the "
            f"blade's {v['span_m'] * 1e3:.4g} mm span, `[search] amplitude_limit`): " + "; ".join(where) + ". The "
            "orbits beyond stay in `modes.json` but are no part of any admissible arc."]


def _mesh_words(mesh: dict) -> str:
    """The mesh's length unit and node numbering, when the summary has them and they are not the plain defaults."""
    words = []
    if mesh.get("unit", "m") != "m":
        words.append(f"coordinates in {mesh['unit']}, scaled to metres")
    if mesh.get("node_numbering") == "file":
        words.append("nodes numbered as in the file")
    return "".join(f"; {w}" for w in words)


def _clamp_words(m: dict) -> str:
    corners = m.get("clamped_corner_nodes")
    extra = f" ({corners} corner nodes)" if corners is not None and corners != m["clamped_nodes"] else ""
    return f"{m['clamped_nodes']} clamped nodes{extra}"


def _node(c: dict) -> str:
    """The contact node as the mesh file numbers it (with the 0-based index of ``mesh.vtu`` when they differ)."""
    node_id = c.get("node_id", c["node"])
    return f"{node_id}" + ("" if node_id == c["node"] else f" (index {c['node']} in `mesh.vtu`)")


def _plausibility_words(m: dict) -> list[str]:
    """A warning when the model's total mass or first frequency is not a blade's (the likely unit slip named)."""
    from ..fe.mesh_checks import plausibility, thin_plate

    f = m["linear_frequencies_hz"]
    source = "geometry" if str(m["mesh"].get("source", "")).startswith("gmsh (parametric") else "mesh"
    sentences = [plausibility(m["total_mass_kg"], f[0] if f else None, unit=m["mesh"].get("unit", "m"),
                              source=source, dim=m["dim"], E=m["material"]["E"])]
    if m.get("thickness_m") and m.get("plane") == "stress" and m["mesh"].get("extent_m"):
        sentences.append(thin_plate(m["thickness_m"], m["mesh"]["extent_m"]))
    return [x for s in sentences if s for x in ("", f"**Warning — {s}.**")]


def _face_words(c: dict) -> str:
    """``Face 'tip' of 26 nodes (area-weighted mean of their normal displacements)``."""
    name = f" '{c['face']}'" if c.get("face") else ""
    weights = "area-weighted" if c.get("face_weights") == "area" else "equal-weight"
    return f"Face{name} of {len(c['face_nodes'])} nodes ({weights} mean of their normal displacements)"


def _model_words(massless: bool) -> str:
    if massless:
        return ("- Contact model: massless — the contact dofs carry no inertia, and the casing pushes back with a "
                "contact force λ over contact phases of finite duration (docs/massless.md).")
    return ("- Contact model: Newton's impact law (restitution 1) — instantaneous impacts, each an impulse (N·s); "
            "the contact has no duration and no force.")


def _kc_words(c: dict) -> str:
    kc = c.get("contact_stiffness_n_per_m")
    if kc is None:
        return "the contact's own stiffness"
    return (f"the contact's own stiffness k_c = {kc:.4g} N/m (its dofs with the interior held, "
            "1/(w_cᵀK_cc⁻¹w_c))")


def _casing_words(k: float | None, c: dict | None = None) -> str:
    c = c or {}
    if k is None:
        if c.get("contact_stiffness_n_per_m") is not None:
            return f"- Casing: rigid; the closed contact is as stiff as {_kc_words(c)}."
        return "- Casing: rigid (the clearance is closed by the contact alone)."
    series = c.get("series_stiffness_n_per_m")
    return (f"- Casing: compliant, k = {k:.4g} N/m in series with {_kc_words(c)}"
            + (f": the closed contact's stiffness is k_s = {series:.4g} N/m" if series is not None else "")
            + "; the contact moves λ/k into the casing while closed (docs/massless.md, \"A compliant casing\").")


def _static_words(c: dict) -> list[str]:
    """The blade's static stiffness at the contact (the whole blade), against the casing's when compliant."""
    ks = c.get("static_stiffness_n_per_m")
    if ks is None:
        return []
    k = c.get("casing_stiffness_n_per_m")
    versus = "" if k is None else f"; the casing's stiffness is {k / ks:.3g} × that"
    soft = None if k is None else weak_casing_words(c.get("series_stiffness_n_per_m", k), ks, casing=k)
    return [f"- The blade's static stiffness at the contact: 1/(wᵀK⁻¹w) = {ks:.4g} N/m (the whole FE model, "
            f"clamped at its root){versus}.", *([f"- **Soft casing:** {soft}."] if soft else [])]


def _arc_engineering_table(with_arcs: list, massless: bool) -> list[str]:
    """Tip displacement, contact force (Newton: impulses), contact duration and casing give over each admissible
    arc, from the arc's ranges in the summary."""
    rows = [(i, a) for i, f in with_arcs for a in f["admissible_arcs"] if "tip_amplitude_range_mm" in a]
    if not rows:
        return []
    casing = massless and any("casing_penetration_range_m" in a for _, a in rows)
    head = ["family", "admissible arc f (Hz)", "orbits used", "tip amplitude |u| (mm)"]
    if massless:
        head += ["peak contact force (N)", "in contact (% of the period)"] + (["casing penetration (µm)"] * casing)
        what = ("the largest contact force λ, the share of the period in contact"
                + (", how far the contact moves into the casing (λ/k)" if casing else ""))
    else:
        head += ["largest impulse (N·s)"]
        what = "the largest impulse"
    lines = ["", "Tip and casing over each admissible arc, lowest – highest over the orbits used (evenly spread over "
             f"the arc, ends included), each expanded to the FE model: the largest tip amplitude |u| over the "
             f"period, {what}.", "", "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]

    def span(a: dict, key: str, scale: float = 1.0, fmt: str = ".4g") -> str:
        lo, hi = a.get(key) or (None, None)
        return "—" if lo is None else f"{lo * scale:{fmt}} – {hi * scale:{fmt}}"

    for i, a in rows:
        band = (f"{a['f_lo']:.4f} – {a['f_hi']:.4f}" if "tongue" not in a else
                f"{a['backbone_f_lo']:.4f} – {a['backbone_f_hi']:.4f} (backbone; to {a['f_hi']:.4f} in a tongue)")
        cells = [str(i), band, str(a["engineering_orbits"]), span(a, "tip_amplitude_range_mm")]
        if massless:
            cells += [span(a, "contact_force_range_n"), span(a, "contact_fraction_range", 100, ".3g")]
            cells += [span(a, "casing_penetration_range_m", 1e6)] * casing
        else:
            cells.append(span(a, "contact_impulse_range_ns"))
        lines.append("| " + " | ".join(cells) + " |")
    if not massless:
        lines += ["", "Newton's law: impacts are instantaneous — an impulse per impact, no contact force and no "
                  "contact duration."]
    return lines


def _resonance_words(index: int, fam: dict) -> str | None:
    """A sentence when the family's energy grows without bound into a higher mode (an internal resonance)."""
    res = fam.get("resonance")
    if not res:
        return None
    return (f"\n**Family {index} ends in an internal resonance:** its energy grows {res['growth']:.1e}-fold towards "
            f"{res['frequency_hz']:.2f} Hz, where {res['share']:.0%} of it sits in mode {res['mode']} "
            f"({res['mode_frequency_hz']:.1f} Hz, {res['ratio']:.2f} × the orbit's frequency: near the "
            f"{round(res['ratio'])}:1 resonance). Read the backbone below that frequency; the energies next to it "
            "are the exchange with that mode.")


def _tongue_words(index: int, arc: dict) -> str | None:
    """Where an admissible arc enters an internal-resonance tongue, and that its figures are read below it."""
    t = arc.get("tongue")
    if not t:
        return None
    return (f"\n**Family {index} enters a resonance tongue at {t['frequency_hz']:.2f} Hz** "
            f"(E = {t['energy_j']:.3g} J): "
            f"there its own mode {t['own_mode']} holds {t['own_share']:.0%} of the energy and mode {t['mode']} "
            f"({t['mode_frequency_hz']:.1f} Hz, {t['ratio']:.2f} × the orbit's frequency: the {round(t['ratio'])}:1 "
            f"resonance) takes the rest. The arc's figures above are read on its backbone, "
            f"{arc['backbone_f_lo']:.2f}–{arc['backbone_f_hi']:.2f} Hz: the tongue's place and its figures move with "
            "the mesh (the higher mode's frequency does).")


def _counterpart(mt: dict | None) -> str:
    """``FE mode (MAC) | error`` cells of the reduced-model table."""
    if mt is None:
        return "not checked (above the FE modes computed) | —"
    if mt["fe_mode"] is None:
        if mt["beyond_fe"]:
            return "not checked (above the FE modes computed) | —"
        return f"**no FE counterpart** (best MAC {mt['mac']:.2f}, FE mode {mt['best_fe']}): an artefact | —"
    err = mt["relative_error"]
    return f"FE mode {mt['fe_mode']} (MAC {mt['mac']:.3f}) | {'—' if err is None else f'{abs(err):.2e}'}"


def _reference_model_words(ref: dict | None) -> list[str]:
    """The reference model of the orbit check, said once where the models are listed."""
    if not ref:
        return []
    how = ("the reduced model's basis extended by the Krylov sequence of its own factorisation (no second "
           "eigen-solve)" if str(ref["method"]).endswith("+krylov") else "a model from its own eigen-solve")
    err = ref.get("relative_error_vs_fe") or []
    fit = (f"; its lowest {len(err)} frequencies agree with the FE model's to {max(err):.1e}" if err else "")
    return [f"- Reference model of the orbit check: {ref['method']}, {ref['reduced_dofs']} dofs — {how}{fit}."]


def _reference_words(check: dict, k: int) -> str:
    where = f"in the reference model {check['reference']}"
    if check["survives"]:
        return f"Survives {where}: one period later it is back within {check['drift']:.2g} (relative, energy norm)."
    return (f"**Does not survive** {where}: after one period it has drifted by {check['drift']:.1%} (energy norm), "
            f"with {check['contacts']} contact(s) for {k} — an artefact of the reduced model, animated only because "
            "it was asked for in [output] orbits.")


def forcing_report(section: dict, animations: list[dict], massless: bool | None = None) -> list[str]:
    """The forced-response section of ``report.md`` (``massless``: the steady states count contact phases, not
    impacts; not set: the section's ``contact_model``)."""
    if massless is None:
        massless = section.get("contact_model") == "massless"
    events = "contact phases" if massless else "impacts"
    files = section["files"]
    lines = ["", "## Forced response", "",
             f"- Load: {section['load']}, amplitude {section['amplitude']:g} {section['amplitude_unit']}; damping: "
             f"{section['damping']}; {section['periods_per_point']} forcing periods per frequency.",
             f"- {section['words']}"]
    if files:
        lines.append("- Steady states: " + ", ".join(f"`{v}`" for v in files.values()) + ".")
    for a in animations:
        shown = ", ".join(f"`{a[k]}`" for k in ("gif", "mp4", "pvd") if k in a)
        lines.append(f"- Animated steady state {a['label']} ({events}/forcing periods) at {a['frequency_hz']:.6g} Hz "
                     f"({a['sweep']} sweep, re-simulation return error {a['return_error']:.1e}): "
                     f"{shown or 'no files'}.")
    return lines


def comparison_report(section: dict) -> list[str]:
    """The comparison section of ``report.md``: the verdict first (which model to use, or why none can be trusted:
    the section's ``verdict``, else computed from its rows), then the table, the sentences in words and the
    figures."""
    from .comparison.table import comparison_verdict, energy_columns, period_labels

    rows = section["rows"]
    energy_cols = energy_columns(rows[0])
    v = section.get("verdict") or comparison_verdict(rows)
    # the impact mass is Newton's (the inertia an impact meets): a comparison of massless models has none
    impact = any(r.get("impact_mass_kept") is not None for r in rows if r.get("method") != "fe")
    versus = any(r.get("is_reference") is not None for r in rows)
    energy_heads = [f"E at {t} (J)" for t in period_labels(energy_cols).values()]
    head = ["model", "dofs", "modes matched / checked", "artefact modes", *["impact mass kept"] * impact,
            "static compliance kept", "families with arcs", *energy_heads,
            *["energy off the reference", "frequencies off the reference"] * versus, "convergence", "observed order"]
    lines = ["", "## Model comparison", "", f"**Verdict:** {_sentence(v['sentence'])}", ""]
    periods = section.get("periods") or {}
    if periods.get("words"):
        lines += [f"Comparison periods: {_sentence(periods['words'])}", ""]
    lines += ["Every model got the same search. Frequencies are matched to FE modes by mode shape (MAC), never by "
              "index; \"kept\" is the model's value over the FE model's; \"off the reference\" is the largest "
              "relative difference from the reference model (the largest) over the comparison periods (energies) and "
              "the modes both match to one FE mode (frequencies). Full table: `comparison.csv`.", "",
              "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        if r.get("method") == "fe":
            continue
        ref = bool(r.get("is_reference"))
        cells = [r["model"], str(r["dofs"]), f"{r.get('modes_matched')} / {r.get('modes_checked')}",
                 r.get("artefact_modes") or "—", *[_num(r.get("impact_mass_kept"), "×")] * impact,
                 _num(r.get("static_compliance_kept"), "×"),
                 f"{r.get('families_with_arcs')} of {r.get('families')}",
                 *[_num(r.get(c), "") for c in energy_cols],
                 *(["reference"] * 2 if ref else [_pct(r.get("ref_energy_deviation")),
                                                  _pct(r.get("ref_frequency_deviation"))]) * versus,
                 r.get("convergence") or "n/a", r.get("observed_order") or "—"]
        lines.append("| " + " | ".join(str(c) for c in cells) + " |")
    lines.append("")
    if section["diagnostics"]:
        lines += ["What the comparison says:", ""] + [f"- {w}" for w in section["diagnostics"]]
    else:
        lines.append("The models agree: frequencies, contact measures and energies at the common periods.")
    lines.append("")
    for key in ("overlay", "convergence", "spectrum"):
        if key in section["figures"]:
            lines += [f"![{key}]({section['figures'][key]})", ""]
    return lines


def _sentence(text: str) -> str:
    """``text`` as a sentence: capital first letter, a full stop."""
    text = text.strip()
    return text[:1].upper() + text[1:] + ("" if text.endswith(".") else ".")


def _pct(x) -> str:
    return "—" if x is None or x == "" else f"{100 * float(x):.2g} %"


def _num(x, unit: str) -> str:
    return "—" if x is None or x == "" else f"{float(x):.3g}{unit}"
