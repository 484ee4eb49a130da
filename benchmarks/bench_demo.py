"""The demo study end to end (``bladecase demo``), stage by stage, against the aim of about a minute.

    .venv/bin/python benchmarks/bench_demo.py [--out DIR]

Prints each stage's wall time (mesh, assemble incl. the FE frequencies, reduce, search, plots, render
incl. VTK export) from the run's summary, the total, and its ratio to the 60 s aim on a 2-core machine.
"""

from __future__ import annotations

import argparse
import tempfile
import time

from bladecase.study.demo import demo_study
from bladecase.study.pipeline import run

AIM_S = 60.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", help="output directory (default: a temporary one)")
    args = ap.parse_args()
    out = args.out or tempfile.mkdtemp(prefix="bladecase-bench-demo-")
    t0 = time.perf_counter()
    result = run(demo_study(), out=out, progress=False)
    wall = time.perf_counter() - t0
    s = result.summary
    print(f"demo study: {s['model']['dofs']} dofs, {s['reduction']['method']} {s['reduction']['reduced_dofs']} "
          f"reduced dofs, {len(s['families'])} families, "
          f"{sum(len(f['admissible_arcs']) for f in s['families'])} admissible arcs, "
          f"{len(s['files']['animations'])} animations")
    for stage, seconds in s["timings_s"].items():
        if stage != "total":
            print(f"  {stage:<10s} {seconds:7.2f} s")
    print(f"  {'total':<10s} {wall:7.2f} s   (aim {AIM_S:.0f} s: ratio {wall / AIM_S:.2f} — "
          f"{'MET' if wall <= AIM_S else 'NOT MET'})")
    print(f"results in {out}")


if __name__ == "__main__":
    main()
