"""The demo blade's first nonsmooth mode under reduced-model refinement, checked in a richer reference model.

For each contact — Newton's law on the tip node (the demo), massless tip node, massless tip face (equal and area
weights) — and reduced sizes 8, 16, 32, 64: the admissible stretch of the branch grown from the first mode, and at
T = 0.99, 0.97, 0.95 T₁ the orbit's energy, whether it is admissible, and its drift and contact count after one
period in the reference model (4 × the largest size; bladecase.study.reference). The last column says, in words,
whether the energy converges (relative change between sizes 32 and 64 < 1 %: the convergence goal).

Run: .venv/bin/python benchmarks/bench_massless_blade.py [--quick]     (about a minute; --quick: sizes 8, 16)
"""

from __future__ import annotations

import sys
import time

import numpy as np

import bladecase as bc
from bladecase.fe import stiffness_factor
from bladecase.reduction import Contact
from bladecase.study import demo_study, stages
from bladecase.study.reference import SURVIVAL_RTOL, check_in_reference

SIZES = (8, 16) if "--quick" in sys.argv else (8, 16, 32, 64)
RATIOS = (0.99, 0.97, 0.95)


def row(reduced, reference, T1: float) -> tuple[str, list[float]]:
    """One model: its admissible stretch near T₁ and, per ratio, E / admissible / drift / contacts."""
    branches = bc.nonsmooth_mode(reduced.system, 1, (0.9 * T1, 1.01 * T1))  # either contact model
    arcs = [(a.T_lo / T1, a.T_hi / T1) for b in branches for a in b.arcs]
    widest = max(arcs, key=lambda a: a[1] - a[0], default=None)
    cells, energies = [], []
    for x in RATIOS:
        orbits = [o for b in branches for o in b.orbit_at(x * T1)]
        if not orbits:
            cells.append(f"{'—':>31}")
            energies.append(np.nan)
            continue
        o = min(orbits, key=lambda o: o.energy)
        chk = check_in_reference(o, reduced, reference)
        cells.append(f"{o.energy:9.3g} {'adm' if o.admissible else 'not':>3} {chk['drift']:8.1e} {chk['contacts']:4d}"
                     f"{' ok' if chk['survives'] else '   '}")
        energies.append(o.energy)
    stretch = "none" if widest is None else f"[{widest[0]:.5f}, {widest[1]:.5f}]"
    return f"{reduced.n:5d} {stretch:>20} " + " ".join(cells), energies


def main() -> None:
    t0 = time.perf_counter()
    st = demo_study("newton")  # the tip node's contact (the demo itself uses the tip face)
    model = stages.build_model(st, stages.build_mesh(st))
    factor = stiffness_factor(model)
    newton = stages.build_contact(st, model)
    contacts = {
        "newton, tip node (lanczos-si; reference modal)": (newton, "lanczos-si"),
        "massless, tip node": (newton, "massless"),
        "massless, tip face (equal weights)": (Contact.face(model, "tip", (0.0, 0.0, 1.0), 1e-4), "massless"),
        "massless, tip face (area weights)": (Contact.face(model, "tip", (0.0, 0.0, 1.0), 1e-4, weights="area"),
                                              "massless"),
    }
    print(f"demo blade: {model}; sizes {SIZES}; reference 4 × {SIZES[-1]}; survival: drift <= {SURVIVAL_RTOL:.0%} "
          "and the orbit's number of contacts")
    head = " ".join(f"{'E(J)  adm  drift  #c at ' + str(x):>31}" for x in RATIOS)
    for name, (contact, method) in contacts.items():
        ref_method = "modal" if method == "lanczos-si" else "massless"
        reference = bc.reduce(model, contact, ref_method, 4 * SIZES[-1], factor=factor)
        T1 = 2 * np.pi / reference.system.spectrum.omega[0]
        kc = f", k_c = {reference.system.kc:.3g} N/m" if method == "massless" else ""
        print(f"\n{name}{kc}; reference {reference.method} ({reference.n} dofs), T₁ = {T1 * 1e3:.5f} ms")
        print(f"{'dofs':>5} {'admissible stretch/T₁':>20} {head}")
        table = []
        for size in SIZES:
            line, energies = row(bc.reduce(model, contact, method, size, factor=factor), reference, T1)
            print(line)
            table.append(energies)
        last = np.array(table[-2:])
        change = np.abs(last[1] / last[0] - 1)
        verdict = ", ".join(f"{x} T₁: {c:.1%}" if np.isfinite(c) else f"{x} T₁: no orbit"
                            for x, c in zip(RATIOS, change))
        ok = np.isfinite(change).all() and (change < 0.01).all()
        print(f"   change between sizes {SIZES[-2]} and {SIZES[-1]}: {verdict} — "
              f"{'CONVERGED (< 1 %)' if ok else 'NOT converged: the energy at a fixed period depends on the model'}")
    print(f"\ntotal {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
