"""Does the mesh error a study reports contain a finer mesh? A held-out measurement on the demo study.

The demo study (``bladecase/study/studies/demo.toml``, its outputs reduced to ``formats = []``: no animation files,
the same search and the same animated orbits) is run with ``[convergence] meshes = [1, 0.7, 0.5]``; from its
``summary.json`` each headline figure's reported value (the study's own mesh, ×1) and its error estimate (1.25 ×
the distance from the Richardson extrapolation of ×1, ×0.7, ×0.5, relative) are read. Then the same study is run
alone on the ×0.25 mesh (:func:`bladecase.study.convergence.stage.mesh_row`: mesh, model, contact, reduced model and
search of the study on element sizes × 0.25) and its figures are read at the same ``T/T₁`` on the same family.
Printed per figure: the ×1 value, the estimated error (relative and absolute), the ×0.25 value, whether the ×0.25
value lies inside ``value ± error`` (the estimate's claim, held out), and whether the Richardson extrapolation is
nearer the ×0.25 value than the finest of the three meshes is.

Nothing is tuned: the study, the meshes and the estimate are the tool's. Exit status 0 whatever it finds.

Run: OPENBLAS_NUM_THREADS=1 nice .venv/bin/python benchmarks/bench_convergence_containment.py   (several minutes)
     ... --json results/containment.json   (the table as JSON too)
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

from bladecase.study import run
from bladecase.study.convergence.stage import mesh_row
from bladecase.study.demo import demo_text
from bladecase.study.schema import loads

FORMATS = 'formats = ["gif", "mp4", "vtu", "png"]'


def study_text(meshes: str) -> str:
    """The demo study without output files, with ``[convergence] meshes``."""
    text = demo_text()
    assert FORMATS in text, "the demo's [output] formats line changed"
    return text.replace(FORMATS, "formats = []") + f"\n[convergence]\nmeshes = {meshes}\n"


def containment(figures: dict, row: dict) -> list[dict]:
    """One line per figure: reported (×1) value, estimated error, the held-out value and whether it is inside."""
    out = []
    for key, f in figures.items():
        v1, held = f["values"][0], row.get(key)
        line = {"figure": key, "words": f["words"], "unit": f["unit"], "value": v1, "error_rel": f["error"],
                "order": f["order"], "extrapolated": f["extrapolated"], "finest": f["values"][-1], "held_out": held,
                "inside": None, "error_abs": None, "nearer": None}
        if f["error"] is not None and v1 is not None:
            scale = abs(f["extrapolated"]) if f["extrapolated"] else abs(f["values"][-1]) or 1.0
            line["error_abs"] = f["error"] * scale
            if held is not None:
                line["inside"] = bool(abs(held - v1) <= line["error_abs"])
        if f["extrapolated"] is not None and held is not None and f["values"][-1] is not None:
            line["nearer"] = bool(abs(f["extrapolated"] - held) < abs(f["values"][-1] - held))
        out.append(line)
    return out


def _fmt(x) -> str:
    return "—" if x is None else f"{x:.6g}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--meshes", default="[1, 0.7, 0.5]", help="[convergence] meshes of the study")
    parser.add_argument("--held-out", type=float, default=0.25, help="the finer mesh's factor (0.25)")
    parser.add_argument("--json", type=Path, default=None, help="also write the table as JSON")
    args = parser.parse_args()
    study = loads(study_text(args.meshes), source="demo + [convergence]")
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        run(study, Path(tmp) / "out", progress=False)
        summary = json.loads((Path(tmp) / "out" / "summary.json").read_text())
    t1 = time.perf_counter()
    c = summary["convergence"]
    print(f"demo study, meshes {c['meshes']} ({c['dofs']} free dofs): {t1 - t0:.0f} s; orbit figures at "
          f"T/T1 = {c['ratio']}, {c['ipp']}-phase family")
    row = mesh_row(study, args.held_out, c["ratio"], c["ipp"])
    t2 = time.perf_counter()
    print(f"held out: the study alone on mesh ×{args.held_out:g} ({row['dofs']} free dofs): {t2 - t1:.0f} s")
    lines = containment(c["figures"], row)
    print()
    print("| figure | ×1 (reported) | est. error | ± abs | observed order | Richardson | "
          f"×{c['meshes'][-1]:g} | ×{args.held_out:g} (held out) | inside ±error | Richardson nearer than finest |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---|---|")
    for x in lines:
        unit = f" ({x['unit']})" if x["unit"] else ""
        err = "—" if x["error_rel"] is None else f"{100 * x['error_rel']:.3g} %"
        inside = {None: "—", True: "yes", False: "**NO**"}[x["inside"]]
        nearer = {None: "—", True: "yes", False: "no"}[x["nearer"]]
        print(f"| {x['figure']}{unit} | {_fmt(x['value'])} | {err} | {_fmt(x['error_abs'])} | {_fmt(x['order'])} | "
              f"{_fmt(x['extrapolated'])} | {_fmt(x['finest'])} | {_fmt(x['held_out'])} | {inside} | {nearer} |")
    judged = [x for x in lines if x["inside"] is not None]
    print(f"\n{sum(x['inside'] for x in judged)} of {len(judged)} figures inside their reported error; "
          f"total {time.perf_counter() - t0:.0f} s")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps({"convergence": c, "held_out": row, "lines": lines}, indent=1))


if __name__ == "__main__":
    main()
