"""Regenerate the reference meshes of this folder with the bladecase API.

    python meshes/make_reference_meshes.py

* ``plate.msh`` — 2-D plane-stress plate, 0.1 m span × 0.02 m chord, order 1,
  refined towards the tip, contact node on the tip edge 5 mm towards the
  trailing edge (group ``contact``);
* ``plate.vtu``, ``plate.inp`` — the same mesh in VTK XML (groups as point-data
  masks ``group:<name>``) and Abaqus (groups as ``*NSET``) form;
* ``twisted_blade.msh`` — 3-D NACA 2412 blade, 0.15 m span, chord 50 → 35 mm,
  stagger 30°, twist 40°, order 1, refined towards the tip, contact node at the
  tip's mid-chord point (on the stacking axis).

Units are SI (metres).  Every file has the groups ``root``, ``tip``, ``blade``
and ``contact``.
"""

from __future__ import annotations

import time
from pathlib import Path

import bladecase as bc

HERE = Path(__file__).resolve().parent

PLATE = bc.PlateGeometry(span=0.1, chord=0.02, contact_point=(0.005, 0.1))
PLATE_MESH = dict(size=0.0025, tip_size=0.00125, order=1)

BLADE = bc.BladeGeometry(
    span=0.15, root_chord=0.05, tip_chord=0.035, naca="2412",
    stagger_deg=30.0, twist_deg=40.0, contact_point=(0.0, 0.0, 0.15),
)
BLADE_MESH = dict(size=0.003, tip_size=0.0015, order=1)


def _report(name: str, mesh: bc.Mesh, seconds: float) -> None:
    groups = ", ".join(f"{k}: {len(v)}" for k, v in sorted(mesh.groups.items()))
    print(f"{name}: {len(mesh.points)} nodes, {len(mesh.cells[mesh.body_type])} {mesh.body_type} "
          f"({seconds:.2f} s); groups {groups}")


def main() -> None:
    t = time.perf_counter()
    plate = bc.blade_mesh(PLATE, path=HERE / "plate.msh", **PLATE_MESH)
    _report("plate.msh", plate, time.perf_counter() - t)
    for suffix in (".vtu", ".inp"):
        bc.save_mesh(plate, HERE / f"plate{suffix}")
        print(f"plate{suffix}: written")
    t = time.perf_counter()
    blade = bc.blade_mesh(BLADE, path=HERE / "twisted_blade.msh", **BLADE_MESH)
    _report("twisted_blade.msh", blade, time.perf_counter() - t)


if __name__ == "__main__":
    main()
