"""The whole bladed disk against the casing: the demo blade (NACA 2412, stagger 30°, twist 40°, lean 30 mm) on a
disk of N sectors (hub 0.15 m, rim 0.25 m, 50 mm thick), linear tetrahedra with lumped mass, each blade's tip
face (its area-weighted mean, radial) its own massless contact against a rigid casing.

Prints: the massless sector's frequencies per nodal diameter and their cost, the reduced annulus (built from the
cyclic modes, never assembled), one standing family (nodal diameter 0: one sector alone against the annulus) and
one travelling family (found over T/N' with the blade shift), each travelling orbit flown in the annulus model
WITHOUT the symmetry for 1 and 10 periods (the return error), its Floquet stability, and the costs.

    python benchmarks/bench_disk.py                          # 12 sectors, size 0.03 m, ND 2 forward
    python benchmarks/bench_disk.py --sectors 24 --diameter 5 --size 0.025
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from bladecase.fe import BladeGeometry, SectorGeometry, assemble, fe_sector, sector_mesh
from bladecase.nsm.massless.disk_modes import full_orbit, return_error, rotating_family
from bladecase.nsm.massless.nodal_modes import nodal_family
from bladecase.nsm.massless.nodes import simulate_nodes
from bladecase.reduction import Contact
from bladecase.reduction.disk import disk_model, massless_sector, sector_system


def _standing(disk, ms, W, gap, count: int) -> None:
    """ND 0: the orbit of one sector and the same state flown on the annulus."""
    start = time.perf_counter()
    one = sector_system(ms, W, gap, 0, count=count)
    fam = nodal_family(one, mode=0, freq_ratio=1.02)
    o = fam.orbits[-1]
    s, N = disk.system, disk.sectors
    x, v = np.zeros(s.n), np.zeros(s.n)
    phi = one.modes[1]
    for i in range(one.n):
        a = disk.index(0, i, 0)
        sign = np.sign(one.W[i, 0] * s.W[a, 0]) or 1.0
        x[a], v[a] = sign * math.sqrt(N) * (phi @ o.q0)[i], sign * math.sqrt(N) * (phi @ o.p0)[i]
    err = return_error(s, x, v, o.T)
    tr = simulate_nodes(one, phi @ o.q0, phi @ o.p0, o.T)
    ta = simulate_nodes(s, x, v, o.T)
    print(f"standing ND 0: {len(fam.orbits)} orbits of one sector ({one.n} dofs), f {fam.frequency[0]:.2f} → "
          f"{fam.frequency[-1]:.2f} Hz; last orbit flown on the annulus: return error {err:.2e}, contact time "
          f"sector {tr.contact_time()[0] / o.T:.4f} T vs annulus {ta.contact_time().min() / o.T:.4f}–"
          f"{ta.contact_time().max() / o.T:.4f} T; {time.perf_counter() - start:.1f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sectors", type=int, default=12)
    parser.add_argument("--size", type=float, default=0.03, help="element size (m)")
    parser.add_argument("--modes", type=int, default=3, help="modes per nodal diameter")
    parser.add_argument("--diameter", type=int, default=2, help="travelling wave's nodal diameter (k > N/2: "
                        "backward)")
    parser.add_argument("--gap", type=float, default=1e-4, help="clearance (m)")
    args = parser.parse_args()
    blade = BladeGeometry(span=0.15, root_chord=0.05, tip_chord=0.035, naca="2412", stagger_deg=30.0,
                          twist_deg=40.0, lean=0.03, contact_point=(0.0, 0.03, 0.15))
    geometry = SectorGeometry(args.sectors, 0.15, 0.25, 0.05, blade)
    start = time.perf_counter()
    mesh = sector_mesh(geometry, size=args.size, order=1)
    model = assemble(mesh, "TI6AL4V", order=1, clamp="hub", mass="lumped")
    sector = fe_sector(model, args.sectors, geometry.axis)
    contact = Contact.face(model, "tip", (0.0, 0.0, 1.0), args.gap, weights="area")
    ms, W, gap = massless_sector(model, sector, contact)
    print(f"sector: {model.n_dofs} dofs, tip face {len(contact.nodes)} nodes; mesh + assembly + faces "
          f"{time.perf_counter() - start:.1f} s")
    disk = disk_model(ms, W, gap, count=args.modes)
    for k, d in disk.diameters.items():
        print(f"ND {k:2d}: {d.seconds:5.2f} s, f = " + ", ".join(f"{f:.1f}" for f in np.sqrt(d.lam) / 2 / np.pi)
              + " Hz")
    s = disk.system
    print(f"annulus model: {s.n} dofs, {s.m} contacts; {disk.seconds:.1f} s in all")
    _standing(disk, ms, W, gap, args.modes)

    start = time.perf_counter()
    k = args.diameter
    P, n1 = disk.rotating(k)
    x0, v0, w = disk.travelling_wave(k)
    fam = rotating_family(s, P, n1, x0, v0, 2 * math.pi / w, growth=(1.05, 1.2, 1.4, 1.7, 2.0))
    cost = time.perf_counter() - start
    print(f"travelling ND {k} ({'forward' if k < args.sectors / 2 else 'backward'}), shot over T/{n1}: "
          f"{len(fam)} orbits in {cost:.1f} s, f {w / 2 / math.pi:.2f} Hz (linear) →")
    for o in fam:
        start = time.perf_counter()
        one, ten = return_error(s, o.x0, o.v0, o.T, 1), return_error(s, o.x0, o.v0, o.T, 10)
        full = full_orbit(s, o.x0, o.v0, o.T, phase=int(np.argmax(np.abs(s.modes[1].T @ o.x0))))
        mu = full.nontrivial_multipliers
        print(f"  f {o.frequency:.3f} Hz, E/E0 {o.energy / fam[0].energy * 1.05:.2f}, symmetric residual "
              f"{o.residual:.1e}; annulus without symmetry: back after 1 period {one:.1e}, after 10 periods "
              f"{ten:.1e}; Floquet max |μ| {np.abs(mu).max():.6f} ({'stable' if full.stable() else 'UNSTABLE'}); "
              f"check {time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    main()
