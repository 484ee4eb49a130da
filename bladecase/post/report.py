"""The run's Markdown report, written from its summary (``summary.json``) alone."""

from __future__ import annotations

import numpy as np

from .rotation_report import rotation_report

#: Admissible arcs narrower than this (relative, in frequency) are called narrow in words.
NARROW_RTOL = 1e-3


def report(summary: dict) -> str:
    """A human-readable Markdown report of a run's :data:`summary`."""
    m, c, r = summary["model"], summary["contact"], summary["reduction"]
    lines = [f"# bladecase study `{summary['study']}`", "",
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
             (f"- Face of {len(c['face_nodes'])} nodes ({c.get('face_weights', 'equal')} weights; mean normal "
              f"displacement), centre node {_node(c)}" if len(c.get("face_nodes", [])) > 1 else f"- Node {_node(c)}")
             + f" at ({', '.join(f'{x * 1e3:.5g}' for x in c['position'])}) mm, casing normal "
             f"({', '.join(f'{x:.4g}' for x in c['normal'])}), clearance {c['clearance_m'] * 1e3:.4g} mm.",
             _casing_words(c.get("casing_stiffness_n_per_m")),
             *rotation_report(summary.get("rotation"), summary.get("campbell")),
             "", "## Reduced model", "",
             f"- {r['method']} (size {r['size']}): {r['reduced_dofs']} reduced dofs.", "",
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
    if summary.get("comparison"):
        lines += comparison_report(summary["comparison"])
    if summary.get("forcing"):
        lines += forcing_report(summary["forcing"], summary["files"].get("forced_animations", []))
    s = summary["search"]
    lines += ["", "## Nonsmooth modes", "",
              f"Search: ipp {s['ipp']}, periods {s['periods']} × {s['period_unit']} "
              f"(= [{s['periods'][0] * s['period_unit_s']:.6g}, {s['periods'][1] * s['period_unit_s']:.6g}] s), "
              f"scan {s['scan']}.", ""]
    fams = summary["families"]
    with_arcs = [(i, f) for i, f in enumerate(fams) if f["admissible_arcs"]]
    lines.append(f"{len(fams)} families found, {len(with_arcs)} with admissible arcs "
                 f"(families without any are listed in `summary.json`).")
    lines += ["", "| family | ipp | orbits | f range (Hz) | admissible arc f (Hz) | energy on arc (J) | "
              "linearly stable (Floquet) |", "|---:|---:|---:|---|---|---|---|"]
    for i, f in with_arcs:
        for a in f["admissible_arcs"]:
            stable = a.get("stable_fraction")
            lines.append(f"| {i} | {f['ipp']} | {f['orbits']} | {f['frequency_range_hz'][0]:.3f} – "
                         f"{f['frequency_range_hz'][1]:.3f} | {a['f_lo']:.4f} – {a['f_hi']:.4f} | "
                         f"{a['energy_range_j'][0]:.3e} – {a['energy_range_j'][1]:.3e} | "
                         f"{'—' if stable is None else f'{stable:.0%} of its orbits'} |")
    lines += [w for i, f in with_arcs if (w := _resonance_words(i, f))]
    widths = [(a["f_hi"] - a["f_lo"]) / a["f_hi"] for _, f in with_arcs for a in f["admissible_arcs"] if a["f_hi"] > 0]
    if widths and max(widths) < NARROW_RTOL:
        lines += ["", f"**Narrow:** the widest admissible arc spans {max(widths):.1e} of its frequency — in this model "
                  "the mode exists only next to where it grows from a linear mode (grazing); beyond, its orbits are "
                  "not admissible (for the massless model the contact splits into several phases, "
                  "docs/massless.md). Read its energies as those of a barely touching linear mode."]
    files = summary["files"]
    if summary.get("reference") and not files.get("animations"):
        ref = summary["reference"]
        lines += ["", f"**No orbit animated:** no admissible orbit of the {r['method']} model that was tried survives "
                  f"in the reference model {ref['method']} ({ref['reduced_dofs']} dofs) — the families above are "
                  "artefacts of the reduced model (see run.log). With Newton's impact law the orbits depend on the "
                  "node's reduced mass; enlarging the model does not cure that: the massless contact model "
                  "([contact] model = \"massless\", docs/massless.md) removes the impact law."]
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
        lines.append(f"- family {a['family']}, {a['ipp']}-ipp orbit T = {a['T']:.8g} s (f = {a['frequency_hz']:.3f} "
                     f"Hz, E = {a['energy_j']:.3e} J, "
                     f"{phases}, displacements × {a['scale']:.4g}; event-driven simulation returns to it to "
                     f"{check['return_error']:.1e}{'' if check['ok'] else ' — CHECK FAILED'}): {what}")
        if "reference_check" in a:
            lines.append(f"  - {_reference_words(a['reference_check'], a['ipp'])}")
        if "energy_words" in a:
            lines.append(f"  - {a['energy_words']}")
        if "stability" in a:
            lines.append(f"  - Stability (Floquet multipliers with saltation matrices): {a['stability']}.")
        if a.get("tip_excursion"):
            x = a["tip_excursion"]
            lines.append(f"  - {'**Tip nodes beyond the clearance:** ' if x['nodes_beyond'] else 'Tip: '}"
                         f"{x['words'][:1].upper()}{x['words'][1:]}.")
        if "gif" in a:
            lines.append(f"\n  ![{a['gif']}]({a['gif']})\n")
    lines += ["", "Timings (s): " + ", ".join(f"{k} {v:.2f}" for k, v in summary["timings_s"].items()), ""]
    return "\n".join(lines)


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


def _casing_words(k: float | None) -> str:
    if k is None:
        return "- Casing: rigid (the clearance is closed by the contact alone)."
    return (f"- Casing: compliant, {k:.4g} N/m in series with the contact's own stiffness — the contact moves λ/k "
            "beyond the clearance while closed (docs/massless.md, \"A compliant casing\").")


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


def _reference_words(check: dict, k: int) -> str:
    where = f"in the reference model {check['reference']}"
    if check["survives"]:
        return f"Survives {where}: one period later it is back within {check['drift']:.2g} (relative, energy norm)."
    return (f"**Does not survive** {where}: after one period it has drifted by {check['drift']:.1%} (energy norm), "
            f"with {check['contacts']} contact(s) for {k} — an artefact of the reduced model, animated only because "
            "it was asked for in [output] orbits.")


def forcing_report(section: dict, animations: list[dict]) -> list[str]:
    """The forced-response section of ``report.md``."""
    files = section["files"]
    lines = ["", "## Forced response", "",
             f"- Load: {section['load']}, amplitude {section['amplitude']:g} {section['amplitude_unit']}; damping: "
             f"{section['damping']}; {section['periods_per_point']} forcing periods per frequency.",
             f"- {section['words']}"]
    if files:
        lines.append("- Steady states: " + ", ".join(f"`{v}`" for v in files.values()) + ".")
    for a in animations:
        shown = ", ".join(f"`{a[k]}`" for k in ("gif", "mp4", "pvd") if k in a)
        lines.append(f"- Animated steady state {a['label']} (impacts/forcing periods) at {a['frequency_hz']:.6g} Hz "
                     f"({a['sweep']} sweep, re-simulation return error {a['return_error']:.1e}): "
                     f"{shown or 'no files'}.")
    return lines


def comparison_report(section: dict) -> list[str]:
    """The comparison section of ``report.md``: a table, the verdicts and the sentences in words."""
    rows = section["rows"]
    energy_cols = [k for k in rows[0] if k.startswith("energy_")]
    head = ["model", "dofs", "modes matched / checked", "artefact modes", "impact mass kept",
            "static compliance kept", "families with arcs", *[c.replace("energy_", "E at ") for c in energy_cols],
            "convergence"]
    lines = ["", "## Model comparison", "",
             "Every model got the same search. Frequencies are matched to FE modes by mode shape (MAC), never by "
             "index; \"kept\" is the model's value over the FE model's. Full table: `comparison.csv`.", "",
             "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        if r.get("method") == "fe":
            continue
        cells = [r["model"], str(r["dofs"]), f"{r.get('modes_matched')} / {r.get('modes_checked')}",
                 r.get("artefact_modes") or "—", _num(r.get("impact_mass_kept"), "×"),
                 _num(r.get("static_compliance_kept"), "×"),
                 f"{r.get('families_with_arcs')} of {r.get('families')}",
                 *[_num(r.get(c), " J") for c in energy_cols], r.get("convergence") or "n/a"]
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


def _num(x, unit: str) -> str:
    return "—" if x is None or x == "" else f"{float(x):.3g}{unit}"
