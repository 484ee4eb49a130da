"""The report's mesh-convergence section: each headline figure on every mesh of ``[convergence] meshes``, its
observed order, its Richardson extrapolation and the error of the study's own mesh — or, without the section, that
the mesh error is unknown.

>>> section = {"meshes": [1.0, 0.7, 0.5], "dofs": [5787, 11454, 22308], "ratio": 0.99, "ipp": 1, "flag": 0.02,
...            "figures": {"f1_hz": {"words": "first natural frequency", "unit": "Hz",
...                                  "values": [210.5, 212.479, 213.094], "order": 3.39, "extrapolated": 213.38,
...                                  "error": 0.0171, "monotone": True, "flag": False}}, "flagged": []}
>>> print("\\n".join(convergence_report(section)[5:7]))
| figure | ×1 (this study) | ×0.7 | ×0.5 | observed order | converged (Richardson) | error of this study's mesh |
|---|---:|---:|---:|---:|---:|---:|
>>> convergence_report(section)[7]
'| first natural frequency (Hz) | 210.5 | 212.5 | 213.1 | 3.4 | 213.4 | 1.7 % |'
"""

from __future__ import annotations

__all__ = ["convergence_report"]


def _value(x: float | None) -> str:
    return "—" if x is None else f"{x:.4g}"


def _how(figure: dict) -> str:
    """Why a figure's error is 3 × the range (its order not established), in words; ``""`` otherwise."""
    if figure.get("error") is None or figure.get("safety", 1.25) == 1.25:
        return ""
    if not figure.get("monotone"):
        return "not monotone"
    if figure.get("regime") == "order out of range":
        return "order out of range" if figure.get("order") is None else f"order {figure['order']:.2g} out of range"
    return "changes not shrinking"


def convergence_report(section: dict | None) -> list[str]:
    """Markdown lines of the ``convergence`` section of a run's summary (``None``: the mesh error is unknown)."""
    if not section:
        return ["", "**Mesh error: unknown.** The figures of this report are those of one mesh; "
                "`[convergence] meshes = [1, 0.7, 0.5]` runs the study on finer meshes too and states each headline "
                "figure's mesh error (observed order, Richardson estimate)."]
    meshes = section["meshes"]
    ratio = section.get("ratio")
    dofs = ", ".join(str(d) for d in section["dofs"])
    at = (f"; the orbit's figures at T/T₁ = {ratio:.6g} (each mesh's own T₁, the backbone's admissible orbit of least "
          "energy)" if ratio is not None else "")
    made = "element sizes × each factor"
    if section.get("refinement") == "split":
        made = (f"the study's mesh file with every cell edge split in {', '.join(str(n) for n in section['splits'])} "
                f"parts (sizes {', '.join(f'×{h:.4g}' for h in meshes)}; asked "
                f"{', '.join(f'×{h:g}' for h in section['requested'])})")
    lines = ["", "## Mesh convergence", "",
             f"The study run on meshes {', '.join(f'×{h:.4g}' for h in meshes)} ({made}; {dofs} "
             f"free dofs){at}. Error (the grid convergence index): 1.25 × the distance of this study's value from the "
             "Richardson extrapolation of the three finest meshes where they establish an observed order; where they "
             "do not (not monotone, or an order out of range), 3 × the range of the values over the meshes; relative, "
             f"above {100 * section['flag']:g} % in bold.", "",
             "| figure | " + " | ".join(f"×{h:.4g}" + (" (this study)" if h == 1 else "") for h in meshes)
             + " | observed order | converged (Richardson) | error of this study's mesh |",
             "|---|" + "---:|" * (len(meshes) + 3)]
    for f in section["figures"].values():
        error = "—" if f["error"] is None else f"{100 * f['error']:.2g} %"
        if f["flag"]:
            error = f"**{error}**"
        how = _how(f)
        if how:
            error += f" ({how})"
        unit = f" ({f['unit']})" if f["unit"] else ""
        order = "—" if f["order"] is None else f"{f['order']:.2g}"
        lines.append(f"| {f['words']}{unit} | " + " | ".join(_value(v) for v in f["values"])
                     + f" | {order} | {_value(f['extrapolated'])} | {error} |")
    missing = [f"×{h:.4g}" for h, row in zip(meshes, section.get("rows", [])) if row.get("energy_j") is None]
    if ratio is not None and missing:
        lines += ["", f"No admissible orbit at T/T₁ = {ratio:.6g} on mesh(es) {', '.join(missing)}: the orbit's "
                  "figures there are missing."]
    if section["flagged"]:
        lines += ["", "Quote the figures in bold with their mesh error, or refine the study's mesh."]
    return lines
