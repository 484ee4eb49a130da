"""The cost of a bladed disk's modes by nodal diameter: the demo blade (NACA 2412, stagger 30°, twist 40°, lean
30 mm) on a 24-sector disk (hub 0.15 m, rim 0.25 m, 50 mm thick), quadratic tetrahedra; the time of every nodal
diameter (its reduced stiffness, one factorisation, the lowest modes) and the disk's frequencies.

    python benchmarks/bench_cyclic.py                    # size 0.01 m, 4 modes a diameter
    python benchmarks/bench_cyclic.py --size 0.008 --sectors 36
"""

from __future__ import annotations

import argparse
import time

from bladecase.fe import BladeGeometry, SectorGeometry, assemble, cyclic_modes, fe_sector, sector_mesh
from bladecase.fe.cyclic import nodal_diameters


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", type=float, default=0.01, help="element size (m)")
    parser.add_argument("--sectors", type=int, default=24, help="blades round the disk")
    parser.add_argument("--modes", type=int, default=4, help="modes per nodal diameter")
    args = parser.parse_args()
    blade = BladeGeometry(span=0.15, root_chord=0.05, tip_chord=0.035, naca="2412", stagger_deg=30.0,
                          twist_deg=40.0, lean=0.03, contact_point=(0.0, 0.03, 0.15))
    geometry = SectorGeometry(args.sectors, 0.15, 0.25, 0.05, blade)
    start = time.perf_counter()
    mesh = sector_mesh(geometry, size=args.size, order=2)
    model = assemble(mesh, "TI6AL4V", order=2, clamp="hub")
    sector = fe_sector(model, args.sectors, geometry.axis)
    print(f"sector: {model.n_dofs} dofs, {len(sector.pairs)} face node pairs; mesh + assembly + faces "
          f"{time.perf_counter() - start:.1f} s")
    total = 0.0
    for k in nodal_diameters(args.sectors):
        modes = cyclic_modes(sector, k, args.modes)
        total += modes.seconds
        print(f"ND {k:2d}: {modes.size:6d} unknowns, {modes.seconds:5.2f} s, x{modes.multiplicity}, f = "
              + ", ".join(f"{f:.2f}" for f in modes.frequencies) + " Hz")
    print(f"all {len(nodal_diameters(args.sectors))} nodal diameters: {total:.1f} s")


if __name__ == "__main__":
    main()
