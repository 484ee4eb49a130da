"""Contact pressure against per-node force under tip-mesh refinement, with every tip node a contact.

The demo blade (``bladecase.study.demo``) with ``[contact] points = "nodes"`` — its tip meshed at several
``[geometry] tip_size`` — against a casing of fixed stiffness per unit area (``casing_stiffness_per_area``: the
demo's 1e6 N/m over its coarse tip's 103.2 mm², so each node gets ``k_A·A_j`` on every mesh). On each mesh the
every-node model of the study stage (``nodal_model(model, contact, 8, residual=True)``) is followed from the first
node's grazing (``nodal_family``) and solved at one energy (``NodalFamily.at_energy``, 10 mJ by default); printed
per mesh: the tip nodes, the orbit's frequency, the peak contact pressure over the nodes and the period (MPa), the
peak total contact force (N), the area in contact at that peak and the largest over the period (mm²), where the
load sits along the chord, and the largest force on one node (N) — then each figure's relative change from the
previous mesh. The pressure, the total force and the loaded area are figures of the blade; a node's force falls
like its area.

Run: .venv/bin/python benchmarks/bench_pressure_convergence.py      (about a minute, 2 cores: 26 to 170 tip nodes)
     .venv/bin/python benchmarks/bench_pressure_convergence.py --tip-sizes 0.004 0.003 --energy 0.008
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from bladecase.nsm.massless.nodal_modes import nodal_family
from bladecase.reduction.nodes import contact_pressure, nodal_model
from bladecase.study.demo import demo_text
from bladecase.study.schema import loads
from bladecase.study.stages import build_contact, build_mesh, build_model

#: The demo's casing (1e6 N/m) per unit area of its coarse tip (103.2 mm²), N/m³.
PER_AREA = 1e6 / 103.21e-6

DEMO_CASING = ("casing_stiffness = 1e6      # N/m: a thin casing's local radial stiffness; the modes converge "
               "(docs/massless.md)\n")


def study_text(tip_size: float, per_area: float) -> str:
    """The demo study with every tip node a contact, its tip meshed at ``tip_size`` (m), a casing per unit area."""
    text = demo_text()
    assert DEMO_CASING in text and "tip_size = 0.004\n" in text
    text = text.replace(DEMO_CASING, f"casing_stiffness_per_area = {per_area:.6g}\n")
    text = text.replace("tip_size = 0.004\n", f"tip_size = {tip_size}\n")
    return text.replace('model = "massless"', 'model = "massless"\npoints = "nodes"')


def one_mesh(tip_size: float, energy: float, per_area: float) -> dict:
    t0 = time.perf_counter()
    study = loads(study_text(tip_size, per_area), source=f"<tip {tip_size}>")
    model = build_model(study, build_mesh(study))
    contact = build_contact(study, model)
    nodal = nodal_model(model, contact, study["reduction"]["size"] or 8, residual=True)
    t1 = time.perf_counter()
    fam = nodal_family(nodal.system, 0, energy_max=1.05 * energy)
    t2 = time.perf_counter()
    if fam.energy.max() < energy:
        raise SystemExit(f"tip_size {tip_size}: the family stops at {fam.energy.max() * 1e3:.3g} mJ ({fam.stop})")
    (orbit,) = fam.at_energy(energy)[:1]
    load = nodal.contact_load(orbit.forces(orbit.total_force_time)[:, 0])
    return {"tip_size_mm": tip_size * 1e3, "nodes": nodal.system.m, "dofs": model.n_dofs,
            "face_mm2": nodal.areas.sum() * 1e6, "frequency_hz": orbit.frequency,
            "pressure_mpa": np.nanmax(contact_pressure(orbit.peak_force, nodal.areas)) * 1e-6,
            "total_n": orbit.total_force, "loaded_mm2": load["loaded_area_m2"] * 1e6,
            "peak_loaded_mm2": orbit.loaded_area(nodal.areas) * 1e6, "centre": load["centre"],
            "location": load["location"], "node_force_n": float(orbit.peak_force.max()),
            "touching": int(orbit.touching.sum()), "orbits": len(fam.orbits),
            "build_s": t1 - t0, "family_s": t2 - t1}


COLUMNS = [("nodes", "tip nodes", "d"), ("frequency_hz", "f (Hz)", ".4f"), ("pressure_mpa", "peak p (MPa)", ".4g"),
           ("total_n", "total F (N)", ".4g"), ("loaded_mm2", "loaded (mm²)", ".4g"),
           ("peak_loaded_mm2", "max loaded (mm²)", ".4g"), ("node_force_n", "max node F (N)", ".4g")]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--tip-sizes", type=float, nargs="+", default=[0.004, 0.003, 0.0022, 0.0016, 0.0013, 0.001],
                        help="[geometry] tip_size of each mesh (m)")
    parser.add_argument("--energy", type=float, default=0.01, help="the orbits' energy (J)")
    parser.add_argument("--per-area", type=float, default=PER_AREA, help="casing stiffness per unit area (N/m³)")
    args = parser.parse_args()
    print(f"load average at start: {os.getloadavg()[0]:.2f}; casing {args.per_area:.4g} N/m³; orbits at "
          f"{args.energy * 1e3:g} mJ")
    rows = []
    for h in args.tip_sizes:
        r = one_mesh(h, args.energy, args.per_area)
        rows.append(r)
        print(f"  tip_size {h * 1e3:.2f} mm: {r['nodes']} tip nodes ({r['face_mm2']:.2f} mm²), {r['dofs']} dofs; "
              f"model {r['build_s']:.1f} s, family {r['family_s']:.1f} s ({r['orbits']} orbits); at "
              f"{args.energy * 1e3:g} mJ {r['touching']} nodes touch, the load centred at {r['centre']:.3f} of the "
              f"chord ({r['location']})")
    head = "| tip_size (mm) | " + " | ".join(label for _, label, _ in COLUMNS) + " |"
    print("\n" + head + "\n|" + "---:|" * (len(COLUMNS) + 1))
    for r in rows:
        print(f"| {r['tip_size_mm']:.2f} | " + " | ".join(format(r[k], f) for k, _, f in COLUMNS) + " |")
    print("\nrelative change from the previous mesh:\n")
    print(head + "\n|" + "---:|" * (len(COLUMNS) + 1))
    for a, b in zip(rows, rows[1:]):
        cells = [f"{b['nodes']}/{a['nodes']}"] + [f"{b[k] / a[k] - 1:+.2%}" for k, _, _ in COLUMNS[1:]]
        print(f"| {b['tip_size_mm']:.2f} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
