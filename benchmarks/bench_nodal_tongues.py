"""The every-node mode of the demo blade through its internal resonances, on several tip meshes.

The demo study (``bladecase.study.demo``) with ``[contact] points = "nodes"``, its tip meshed at ``[geometry]
tip_size`` scaled by each factor, reduced as the study stage does (``nodal_model(model, contact, 8,
residual=True)``) and followed from the first node's grazing (``nodal_family(system, 0)``) up to the energy the face
mean's backbone reaches (the top of its admissible arc, computed on the demo's own mesh: 70.3 mJ), twice:

- the family of before (``through_resonances=False``, the study stage's call with ``energy_max``): it stops at the
  first internal resonance it cannot step over, where that falls depending on the mesh;
- the family through the resonances (``through_resonances=True``): each tongue crossed to the backbone beyond it.

Printed per mesh: the tip nodes and the linear frequency f₁; where the family of before stops (frequency, energy,
why); where the new one reaches (the last orbit on the backbone: frequency, energy) and its frequency at the face
mean's top energy (a figure of the blade to compare across the meshes, in Hz and over f₁); the tongues passed (the
open-contact mode, 1 = the first, the ratio of its frequency to the orbit's, where, and where the backbone
resumes); each run's time.

Run: .venv/bin/python benchmarks/bench_nodal_tongues.py                  (about a minute on 2 idle cores)
     .venv/bin/python benchmarks/bench_nodal_tongues.py --scales 1 0.7 --energy 0.05
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from bladecase.nsm.massless.nodal_modes import nodal_family
from bladecase.reduction.nodes import nodal_model
from bladecase.study.demo import demo_study, demo_text
from bladecase.study.schema import loads
from bladecase.study.stages import build_contact, build_mesh, build_model, build_reduced, search

#: The demo's tip mesh size (m).
TIP_SIZE = 0.004


def face_top_energy() -> float:
    """The top energy of the face mean's first admissible arc on the demo (``summary["families"][0]
    ["admissible_arcs"][0]["energy_range_j"][1]`` of a demo run), J."""
    study = demo_study()
    model = build_model(study, build_mesh(study))
    reduced = build_reduced(study, model, build_contact(study, model))
    fam = next(f for f in search(study, reduced.system) if f.arcs)
    a = fam.arcs[0]
    return float(fam.energy[a.start:a.stop + 1][fam.admissible[a.start:a.stop + 1]].max())


def nodal_system(scale: float):
    """The every-node system of the demo with its tip meshed at ``scale`` × the demo's tip size."""
    text = demo_text()
    assert f"tip_size = {TIP_SIZE}\n" in text
    text = text.replace(f"tip_size = {TIP_SIZE}\n", f"tip_size = {TIP_SIZE * scale:.6g}\n")
    study = loads(text.replace('model = "massless"', 'model = "massless"\npoints = "nodes"'), source=f"<×{scale}>")
    model = build_model(study, build_mesh(study))
    return nodal_model(model, build_contact(study, model), study["reduction"]["size"] or 8, residual=True).system


def _why(fam) -> str:
    end = fam.end
    if end["kind"] == "internal_resonance":
        return f"{end['ratio']} with mode {end['mode'] + 1} ({end['mode_frequency_hz']:.0f} Hz)"
    return {"energy_max": "target energy", "frequency_ratio": "freq_ratio", "max_points": "max_points",
            "step": "step collapsed"}[end["kind"]]


def one_mesh(scale: float, energy: float) -> dict:
    t0 = time.perf_counter()
    system = nodal_system(scale)
    t1, c1 = time.perf_counter(), time.process_time()
    old = nodal_family(system, 0, energy_max=energy)
    t2, c2 = time.perf_counter(), time.process_time()
    new = nodal_family(system, 0, energy_max=energy, through_resonances=True)
    t3, c3 = time.perf_counter(), time.process_time()
    on = new.on_backbone
    last = int(np.flatnonzero(on)[-1])
    at = new.at_energy(energy, backbone=True) if new.energy[on].max() >= energy else []
    return {"scale": scale, "nodes": system.m, "build_s": t1 - t0, "old_s": t2 - t1, "new_s": t3 - t2,
            "old_cpu": c2 - c1, "new_cpu": c3 - c2,
            "old_f": float(old.frequency.max()), "old_E": float(old.energy.max()), "old_why": _why(old),
            "new_f": float(new.frequency[last]), "new_E": float(new.energy[last]), "new_why": _why(new),
            "f_at_target": at[0].frequency if at else None, "orbits": len(new.orbits), "f1": new.linear_frequency,
            "tongues": list(new.tongues), "residual": max(o.residual for o in new.orbits)}


def _tongue(t: dict) -> str:
    where = (f"→ {t['to_frequency_hz']:.2f}" if t["left"] == "crossed" else t["left"])
    return f"{t['ratio']} mode {t['mode'] + 1} at {t['frequency_hz']:.2f} Hz {where}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scales", type=float, nargs="+", default=[1.4, 1.0, 0.85, 0.7, 0.5],
                        help=f"tip_size of each mesh, × the demo's {TIP_SIZE * 1e3:g} mm")
    parser.add_argument("--energy", type=float, default=None,
                        help="the target energy (J); default: the face mean's admissible arc's top on the demo")
    args = parser.parse_args()
    t = time.perf_counter()
    energy = face_top_energy() if args.energy is None else args.energy
    print(f"load average at start: {os.getloadavg()[0]:.2f}; target energy {energy * 1e3:.4g} mJ"
          + (f" (the face mean's backbone top, {time.perf_counter() - t:.1f} s)" if args.energy is None else ""))
    rows = []
    for scale in args.scales:
        r = one_mesh(scale, energy)
        rows.append(r)
        print(f"  tip_size ×{scale:g}: {r['nodes']} tip nodes; model {r['build_s']:.1f} s, family of before "
              f"{r['old_s']:.1f} s ({r['old_cpu']:.1f} s CPU), through the resonances {r['new_s']:.1f} s "
              f"({r['new_cpu']:.1f} s CPU; {r['orbits']} orbits, closing residuals <= {r['residual']:.1e})",
              flush=True)
    print("\n| tip_size | tip nodes | f₁ (Hz) | before: stops at (Hz, mJ) | why | now: reaches (Hz, mJ) | "
          "f at target (Hz, × f₁) | tongues passed (ratio, open-contact mode, Hz → backbone resumes at Hz) | "
          "CPU before / now (s) |")
    print("|---:|---:|---:|---|---|---|---:|---|---:|")
    for r in rows:
        f_at = "—" if r["f_at_target"] is None else f"{r['f_at_target']:.2f}, {r['f_at_target'] / r['f1']:.4f}"
        tongues = "; ".join(_tongue(t) for t in r["tongues"]) or "none (the energy steps step over them)"
        print(f"| ×{r['scale']:g} | {r['nodes']} | {r['f1']:.2f} | {r['old_f']:.2f}, {r['old_E'] * 1e3:.3g} | "
              f"{r['old_why']} | "
              f"{r['new_f']:.2f}, {r['new_E'] * 1e3:.3g} ({r['new_why']}) | {f_at} | {tongues} | "
              f"{r['old_cpu']:.1f} / {r['new_cpu']:.1f} |")


if __name__ == "__main__":
    main()
