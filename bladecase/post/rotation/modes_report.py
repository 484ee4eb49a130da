"""The report of a study without a contact: the linear modes and the Campbell diagram alone — its verdict in three
lines (no nonsmooth mode without a contact, and how to add one) and its Markdown, from the summary alone.

>>> s = {"study": "strip", "source": "s.toml", "bladecase_version": "0", "timings_s": {"total": 1.0},
...      "model": {"linear_frequencies_hz": [100.0, 400.0]}, "contact": None, "rotation": None,
...      "campbell": {"speeds_rad_s": [0.0, 100.0], "speed_unit": "rad/s", "tracked_frequencies_hz": [[90.0, 100.0]],
...                   "engine_orders": [], "crossings": [], "link_mac": [[1.0, 0.99]]}}
>>> v = modes_verdict(s)
>>> v["reasons"]
['no_contact', 'mesh_error_unknown']
>>> v["found"][:64]
'No nonsmooth modes: the study has no [contact], so it computed t'
>>> v["found"][v["found"].index("(1 mode"):]
'(1 mode over 2 speeds, 0 to 100 rad/s (0 to 954.93 rpm); mode 1 from 90.00 to 100.00 Hz).'
"""

from __future__ import annotations

from .report import rotation_report, to_unit, unit_name

__all__ = ["modes_report", "modes_verdict", "ADD_CONTACT"]

#: How to add a contact, in the words of the verdict and the report.
ADD_CONTACT = ("add a [contact] section — its cold clearance (clearance = 1e-4, m) and where the blade touches "
               "(face = \"tip\", or node = …) — and run again: the Campbell diagram then shows the nonsmooth-mode "
               "band at each speed and the engine orders that enter it")


def modes_verdict(summary: dict) -> dict:
    """The three lines of a run without a contact: what it computed, how far to trust it, what to do next
    (``{"found", "trust", "next", "reasons"}``, as :func:`~bladecase.post.verdict.verdict`)."""
    c = summary.get("campbell") or {}
    w, tracked = c.get("speeds_rad_s") or [], c.get("tracked_frequencies_hz") or []
    unit = unit_name(c.get("speed_unit"))
    other = "rad/s" if unit == "rpm" else "rpm"
    found = "No nonsmooth modes: the study has no [contact], so it computed the linear modes"
    if w and tracked:
        span = (f"{to_unit(w[0], unit):.6g} to {to_unit(w[-1], unit):.6g} {unit} "
                f"({to_unit(w[0], other):.6g} to {to_unit(w[-1], other):.6g} {other})")
        found += (f" and the Campbell diagram alone ({len(tracked)} mode{'s' if len(tracked) != 1 else ''} over "
                  f"{len(w)} speeds, {span}; mode 1 from {tracked[0][0]:.2f} to {tracked[0][-1]:.2f} Hz")
        crossings = c.get("crossings") or []
        n = len(crossings)
        found += f"; {n} engine-order crossing{'s' if n != 1 else ''})." if crossings else ")."
    else:
        found += " alone."
    macs = [v for m in c.get("link_mac") or [] for v in m[1:]]
    trust = ("The frequencies are the FE model's about its centrifugal state at each speed (stress stiffening, spin "
             "softening)")
    if macs:
        low = min(macs)
        trust += (f"; the modes are followed from speed to speed by their shapes, the smallest link MAC {low:.3f}"
                  + (" — below 0.8: two modes may have swapped there, add speeds in between" if low < 0.8 else ""))
    trust += "; the mesh error is not measured."
    return {"found": found, "trust": trust, "next": f"To search the nonsmooth modes, {ADD_CONTACT}.",
            "reasons": ["no_contact", "mesh_error_unknown"]}


def modes_report(summary: dict) -> str:
    """The Markdown report of a run without a contact (``summary["contact"]`` is ``None``)."""
    v = summary.get("verdict") or modes_verdict(summary)
    m = summary["model"]
    lines = [f"# bladecase study `{summary['study']}`", "",
             f"- **Found:** {v['found']}", f"- **Trust:** {v['trust']}", f"- **Next:** {v['next']}", "",
             f"Study file: `{summary['source']}` — bladecase {summary['bladecase_version']} — "
             f"total {summary['timings_s']['total']:.1f} s.", "", "## Model", ""]
    if "mesh" in m:
        lines += [f"- Mesh: {m['mesh']['nodes']} nodes, {m['mesh']['cells']} `{m['mesh']['type']}` cells "
                  f"({m['mesh']['source']}).",
                  f"- FE model: {m['dim']}-D, P{m['order']}, {m['dofs']} free dofs, {m['mass_matrix']} mass, "
                  f"{m['material']['name']}, total mass {m['total_mass_kg']:.5g} kg."]
    lines += ["- Linear frequencies (full FE model, Hz): " + ", ".join(f"{f:.2f}" for f in m["linear_frequencies_hz"])
              + (" — at the operating speed." if summary.get("rotation") else "."),
              "", "## Contact", "",
              "- None: without a contact there are no nonsmooth modes — this run gives the linear modes and the "
              f"Campbell diagram only. To search them, {ADD_CONTACT}."]
    lines += rotation_report(summary.get("rotation"), summary.get("campbell"))
    files = summary.get("files") or {}
    lines += ["", "## Files", ""]
    if files.get("campbell"):
        lines += [f"![Campbell diagram]({files['campbell']})", ""]
    lines.append(f"- `{files.get('mesh', 'mesh.vtu')}`: the mesh with its groups; `summary.json`: every figure above "
                 "(`campbell`: the frequencies at each speed); `run.log`: the run's messages.")
    return "\n".join(lines) + "\n"
