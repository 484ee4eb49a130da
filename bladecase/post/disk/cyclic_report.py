"""The report of a cyclic study (a bladed disk from one sector, ``summary["cyclic"]``): its verdict in three lines
and its Markdown — the frequencies by nodal diameter, which nodal diameter each engine order excites, the modes near
the engine-order lines at the SAFE speed and the speed at which each order meets each mode.

>>> s = {"study": "disk", "source": "d.toml", "bladecase_version": "0", "timings_s": {"total": 2.0},
...      "model": {"linear_frequencies_hz": [100.0]}, "files": {"cyclic": "cyclic.csv"},
...      "cyclic": {"sectors": 4, "speed_rpm": 3000.0, "speed_rad_s": 314.159, "faces": {"pairs": 5, "from": "deck"},
...                 "diameters": [{"nd": 0, "frequencies_hz": [100.0], "multiplicity": 1},
...                               {"nd": 1, "frequencies_hz": [150.0], "multiplicity": 2}],
...                 "engine_orders": [{"order": 3, "diameter": 1, "frequency_hz": 150.0, "near": [1],
...                                    "modes": [{"mode": 1, "frequency_hz": 150.0, "crossing_rpm": 3000.0,
...                                               "margin": 0.0}]}], "expanded": None, "campbell": None}}
>>> found = cyclic_verdict(s)["found"]
>>> found[:72]
'The modes of a disk of 4 sectors by nodal diameter (0 … 1, 1 mode each):'
>>> found[72:]
' the lowest 100.00 Hz (ND 0); 1 engine order within 5 % of a mode at 3000 rpm: EO 3 on mode 1 of ND 1.'
>>> "| 3 | 1 | 150.00 | mode 1 at 3000 rpm (0.0 %) |" in cyclic_report(s)
True
"""

from __future__ import annotations

from .mistuning_report import mistuning_lines, mistuning_sentence
from .rub_plot import rub_lines

__all__ = ["cyclic_report", "cyclic_verdict", "engine_order_words", "nonsmooth_lines", "nonsmooth_sentence"]


def engine_order_words(c: dict) -> list[str]:
    """One sentence per engine order near a mode at the SAFE speed (``near``), e.g. ``EO 3 on mode 1 of ND 1``."""
    return [f"EO {r['order']} on mode {j} of ND {r['diameter']}" for r in c["engine_orders"] for j in r["near"]]


def nonsmooth_sentence(n: dict) -> str:
    """The whole disk's travelling nonsmooth mode in one sentence (``summary["cyclic"]["nonsmooth"]``).

    >>> n = {"diameter": 2, "direction": "forward", "mode": 1, "orbits": [{"frequency_hz": 100.0},
    ...      {"frequency_hz": 101.5, "max_force_n": 3.0}], "check": {"periods": 10, "return_error": 1e-12},
    ...      "stable": True}
    >>> nonsmooth_sentence(n)[:91]
    'Against the casing, the forward travelling wave of mode 1 of ND 2 rubs: 2 orbits, 100.00 → '
    """
    o = n["orbits"]
    return (f"Against the casing, the {n['direction']} travelling wave of mode {n['mode']} of ND {n['diameter']} "
            f"rubs: {len(o)} orbit{'s' if len(o) != 1 else ''}, {o[0]['frequency_hz']:.2f} → "
            f"{o[-1]['frequency_hz']:.2f} Hz, the last (largest force {o[-1]['max_force_n']:.3g} N) back within "
            f"{n['check']['return_error']:.1e} after {n['check']['periods']} periods in the whole disk without the "
            f"symmetry, {'stable' if n['stable'] else 'unstable'}.")


def nonsmooth_lines(n: dict | None) -> list[str]:
    """The report's section on the whole disk's travelling nonsmooth mode (empty without one)."""
    if not n:
        return []
    lines = ["", "## The whole disk against the casing", "",
             f"- Reduced disk: {n['contacts']} contacts (each blade's own), {n['reduced_dofs']} modal coordinates "
             f"({n['modes_per_diameter']} modes per nodal diameter, the contacts' residual flexibility restored).",
             f"- The {n['direction']} wave of mode {n['mode']} of nodal diameter {n['diameter']} "
             f"({n['linear_frequency_hz']:.2f} Hz linear): blade j moves as blade 0 {n['diameter']}·j/N of a period "
             f"later, found over 1/{n['fraction']} of the period against the blade shift.", "",
             "| orbit | frequency (Hz) | energy (J) | largest force (N) | return after 1 period |",
             "|---|---|---|---|---|"]
    lines += [f"| {r['orbit']} | {r['frequency_hz']:.4f} | {r['energy_j']:.4g} | {r['max_force_n']:.4g} | "
              f"{r['return_error_1T']:.1e} |" for r in n["orbits"]]
    lines += ["", f"- The last orbit flown {n['check']['periods']} periods in the whole disk without the symmetry: "
              f"back within {n['check']['return_error']:.1e}; Floquet: {'stable' if n['stable'] else 'unstable'} "
              f"(largest non-trivial |μ| {n['largest_multiplier']:.6f})."]
    a = n.get("animated")
    if a:
        lines.append(f"- Animated on the annulus ({a['disk_nodes']} nodes, {a['frames']} frames): "
                     + ", ".join(f"`{a[k]}`" for k in ("pvd", "gif", "mp4") if k in a)
                     + f"; largest penetration into the casing {a['max_penetration_mm'] * 1e3:.4g} µm "
                     f"(blade {a['worst_blade']}), largest force {a['max_force_n']:.4g} N.")
    return lines


def cyclic_verdict(summary: dict) -> dict:
    """The three lines of a cyclic run (``{"found", "trust", "next", "reasons"}``, as
    :func:`~bladecase.post.verdict.verdict`)."""
    c = summary["cyclic"]
    ds = c["diameters"]
    count = max(len(d["frequencies_hz"]) for d in ds)
    low = min(ds, key=lambda d: d["frequencies_hz"][0])
    found = (f"The modes of a disk of {c['sectors']} sectors by nodal diameter ({ds[0]['nd']} … {ds[-1]['nd']}, "
             f"{count} mode{'s' if count != 1 else ''} each): the lowest {low['frequencies_hz'][0]:.2f} Hz "
             f"(ND {low['nd']})")
    near = engine_order_words(c)
    if c.get("speed_rpm"):
        found += (f"; {len(near)} engine order{'s' if len(near) != 1 else ''} within 5 % of a mode at "
                  f"{c['speed_rpm']:.0f} rpm" + (": " + ", ".join(near) if near else "") + ".")
    else:
        found += "; at rest (no speed: no engine-order line)."
    if c.get("nonsmooth"):
        found += " " + nonsmooth_sentence(c["nonsmooth"])
    if summary.get("mistuning"):
        found += " " + mistuning_sentence(summary["mistuning"])
    trust = ("The tuned disk's modes from one sector under the cyclic constraint (every sector identical, the faces "
             f"matched node by node: {c['faces']['pairs']} pairs); the mesh error is not measured.")
    figures = " and campbell_nd.png" if c.get("campbell") else ""
    nxt = f"Check the engine orders near a mode on safe.png{figures}; " + (
        "the whole disk's mode is in vtk/ (open the .pvd in ParaView, Warp By Vector)." if c.get("expanded") else
        "add 'vtu' to [output] formats to see the whole disk's mode.")
    return {"found": found, "trust": trust, "next": nxt, "reasons": ["cyclic", "mesh_error_unknown"]}


def cyclic_report(summary: dict) -> str:
    """The Markdown report of a cyclic run."""
    v = summary.get("verdict") or cyclic_verdict(summary)
    c, m = summary["cyclic"], summary["model"]
    lines = [f"# bladecase study `{summary['study']}`", "",
             f"- **Found:** {v['found']}", f"- **Trust:** {v['trust']}", f"- **Next:** {v['next']}", "",
             f"Study file: `{summary['source']}` — bladecase {summary['bladecase_version']} — "
             f"total {summary['timings_s']['total']:.1f} s.", "", "## Sector model", ""]
    if "mesh" in m:
        lines += [f"- Mesh of one sector: {m['mesh']['nodes']} nodes, {m['mesh']['cells']} `{m['mesh']['type']}` "
                  f"cells ({m['mesh']['source']}).",
                  f"- FE model: P{m['order']}, {m['dofs']} free dofs a sector, {m['material']['name']}."]
    f = c["faces"]
    lines += [f"- A disk of {c['sectors']} sectors; cyclic faces: {f['pairs']} matched node pairs (from the "
              f"{f['from']})."]
    at = f"about the centrifugal state at {c['speed_rpm']:.0f} rpm" if c.get("speed_rpm") else "at rest"
    lines += ["", f"## Frequencies by nodal diameter (Hz, {at})", "",
              "| ND | multiplicity | frequencies (Hz) |", "|---|---|---|"]
    lines += [f"| {d['nd']} | {d['multiplicity']} | " + ", ".join(f"{x:.2f}" for x in d["frequencies_hz"]) + " |"
              for d in c["diameters"]]
    lines += ["", "Each frequency of nodal diameter 0 < k < N/2 is double in the disk (two standing waves, or a "
              "forward and a backward travelling wave)."]
    lines += ["", "## Engine orders", "", "An engine order e excites the nodal diameter k ≡ ±e (mod N). Each mode of "
              "that diameter meets the order at the speed 60 f / e (rpm)"
              + (f"; at {c['speed_rpm']:.0f} rpm the order's frequency is e Ω / 2π (margin: its distance to the mode)."
                 if c.get("speed_rpm") else "."), "",
              "| EO | ND | frequency at speed (Hz) | meets |", "|---|---|---|---|"]
    for r in c["engine_orders"]:
        meets = "; ".join(f"mode {x['mode']} at {x['crossing_rpm']:.0f} rpm"
                          + (f" ({100 * x['margin']:.1f} %)" if x["margin"] is not None else "") for x in r["modes"])
        fe = f"{r['frequency_hz']:.2f}" if r["frequency_hz"] is not None else "—"
        lines.append(f"| {r['order']} | {r['diameter']} | {fe} | {meets or 'no computed mode'} |")
    e = c.get("expanded")
    if e:
        lines += ["", "## The whole disk", "",
                  f"- Mode {e['mode']} of nodal diameter {e['diameter']} ({e['frequency_hz']:.2f} Hz) as a "
                  f"{e['wave']} wave on the whole disk ({e['disk_nodes']} nodes), {e['frames']} frames over a period: "
                  f"`{e['file']}` (displacements drawn × {e['scale']:.3g})."]
    if c.get("campbell"):
        lines += ["", "## Campbell diagram per nodal diameter", "",
                  f"- {len(c['campbell']['speeds_rad_s'])} speeds, every nodal diameter's modes about the disk's "
                  "centrifugal state (the sector's faces tied): `campbell_nd.png`."]
    lines += nonsmooth_lines(c.get("nonsmooth"))
    lines += rub_lines(c.get("rub"))
    lines += mistuning_lines(summary.get("mistuning"))
    files = summary.get("files") or {}
    lines += ["", "## Files", ""] + [f"- `{x}`" for k, x in files.items() if isinstance(x, str)]
    return "\n".join(lines) + "\n"
