"""Convergence study of the 1-D bar's first nonsmooth mode: massless vs Newton contact, against the continuum.

Bar L = 1, EA = 1, ρA = 1, gap d = 0.5, fixed at x = 0 (bladecase.nsm.massless.bar). The continuum's one-contact-phase
mode (d'Alembert, bladecase.nsm.massless.bar.bar_continuum_energy) has E = d²/(2(T-3)²) for 3 < T < 4. Printed:

1. the admissible one-phase symmetric orbits of the massless bar at T = 3.35, 3.45, 3.55 for n = 50…400
   (pointwise values at fixed T: do they converge?);
2. the admissible stretch of the branch grown from the first linear mode (grazing at T ≈ 4);
3. the continuum orbit started in each discrete model: its return defect after one period (relative L2 of the
   displacement) and the number of contact phases / impacts it makes — with the observed order in h;
4. the measure that converges: the energy of the smoothest one-phase orbit (least energy outside the lowest
   K = 10 modes) held by those K modes, against the continuum's, with the observed order — beside the total;
5. the mode from grazing followed through changes of its number of contact phases (bladecase.nsm.massless_mode):
   how far it goes, its phases, its energy at a few periods against the continuum.

Run: .venv/bin/python benchmarks/bench_massless_bar.py [--quick]
"""

from __future__ import annotations

import sys
import time

import numpy as np

import bladecase as bc
from bladecase.nsm.massless.bar import bar, bar_continuum_band_energy, bar_continuum_energy, bar_continuum_field
from bladecase.nsm.massless.model import simulate_massless
from bladecase.nsm.massless.orbits import follow_from_grazing, orbits_at_period, smoothest

D = 0.5
QUICK = "--quick" in sys.argv
SIZES = (25, 50, 100) if QUICK else (50, 100, 200, 400)
PERIODS = (3.35, 3.45, 3.55)


def fixed_period_table() -> None:
    print("1. Admissible one-phase orbits of the massless bar at fixed T (energy, relative to the continuum)")
    print(f"   {'n':>5} " + " ".join(f"{'T = ' + str(T):>30}" for T in PERIODS) + "   roots found")
    for n in SIZES:
        s = bar(n, D, contact="massless")
        cells, roots = [], []
        for T in PERIODS:
            orbits = orbits_at_period(s, T, samples=8 * n)
            roots.append(len(orbits))
            Ec = float(bar_continuum_energy(T, D))
            adm = [o for o in orbits if o.admissible]
            cells.append(", ".join(f"{o.energy:.4f} ({o.energy / Ec - 1:+.0%})" for o in adm) or "none admissible")
        print(f"   {n:>5} " + " ".join(f"{c:>30}" for c in cells) + f"   {roots}")
    print("   continuum " + ", ".join(f"T={T}: {float(bar_continuum_energy(T, D)):.4f}" for T in PERIODS))
    print("   -> pointwise energies at fixed T scatter and the admissible orbit disappears as n grows: co-existing")
    print("      branches (roots ∝ n) from internal resonances with the discrete spectrum. Not a converging measure.")


def grazing_branch_table() -> None:
    print("\n2. Branch grown from the first linear mode: admissible stretch (periods)")
    for n in SIZES:
        s = bar(n, D, contact="massless")
        orbits = follow_from_grazing(s, T_min=3.3, ds=2e-3, ds_max=1e-2, max_points=400)
        flags = [o.admissible for o in orbits]
        k = flags.index(False) if False in flags else len(flags)
        print(f"   n = {n:4d}: admissible for T in [{orbits[k - 1].T:.5f}, {orbits[0].T:.5f}] "
              f"(width {orbits[0].T - orbits[k - 1].T:.2e}); beyond it λ < 0 inside the contact phase")
    print("   -> the one-phase branch from grazing shrinks towards T = 4 as n grows: the discrete mode splits its")
    print("      contact into several phases; pointwise in T it has no limit.")


def return_defect_table() -> None:
    print("\n3. The continuum orbit in the discrete models: one-period return defect ‖u(T) - u(0)‖/‖u(0)‖")
    print(f"   {'T':>5} {'n':>5} {'massless':>10} {'phases':>7} {'Newton':>10} {'impacts':>8} {'t (s)':>6}")
    for T in PERIODS:
        u, _, _ = bar_continuum_field(T, D)
        rows = []
        for n in SIZES:
            t0 = time.perf_counter()
            s = bar(n, D, contact="massless")
            x0 = u(np.arange(1, n) / n, 1.0)  # t = 1: middle of the open phase, u_t = 0 everywhere
            tr = simulate_massless(s, x0, np.zeros(n - 1), T)
            e_m = np.linalg.norm(tr.x_end - x0) / np.linalg.norm(x0)
            phases = sum(p == "closed" for p in tr.phases)
            sn = bar(n, D, contact="newton")
            xn = u(np.arange(1, n + 1) / n, 1.0)
            trn = bc.simulate(sn, xn, np.zeros(n), T)
            e_n = np.linalg.norm(trn.x_end - xn) / np.linalg.norm(xn)
            rows.append((n, e_m, e_n))
            print(f"   {T:5.2f} {n:5d} {e_m:10.4f} {phases:7d} {e_n:10.4f} {len(trn.impact_times):8d} "
                  f"{time.perf_counter() - t0:6.2f}")
        (n0, m0, w0), (n1, m1, w1) = rows[-2], rows[-1]
        print(f"   observed order (last two n): massless {np.log(m0 / m1) / np.log(n1 / n0):.2f}, "
              f"Newton {np.log(w0 / w1) / np.log(n1 / n0):.2f}")
    print("   -> both discretisations carry the continuum orbit for one period with a defect that decreases as n grows")
    print("      (the initial-value problem converges); the massless model does it with ONE contact phase per period,")
    print("      as the continuum, while the Newton model chatters (impacts ∝ n).")


def band_energy_table(K: int = 10) -> None:
    print(f"\n4. Band-limited energy (lowest {K} open-phase modes) of the smoothest one-phase orbit vs the continuum")
    print(f"   {'T':>5} {'n':>5} {'E_band':>9} {'error':>9} {'order':>6} {'E_total':>9} {'total error':>11} {'adm':>4}")
    for T in PERIODS:
        ref, prev = bar_continuum_band_energy(T, D, K), None
        for n in SIZES:
            o = smoothest(orbits_at_period(bar(n, D, contact="massless"), T, samples=3 * n), K)
            err = abs(o.band_energy(K) / ref - 1)
            order = f"{np.log(prev / err) / np.log(2):6.2f}" if prev else f"{'':>6}"
            tot = o.energy / float(bar_continuum_energy(T, D)) - 1
            print(f"   {T:5.2f} {n:5d} {o.band_energy(K):9.5f} {err:9.2e} {order} {o.energy:9.5f} {tot:+11.1%} "
                  f"{'yes' if o.admissible else 'no':>4}")
            prev = err
        print(f"   continuum: E_band = {ref:.5f}, E = {float(bar_continuum_energy(T, D)):.5f}")
    print("   -> the band-limited energy converges (order ≈ 2 once resolved) while the total does not: the excess sits")
    print("      in mesh-scale modes. This is the quantity bladecase reports for the massless bar.")


def multi_phase_table() -> None:
    print("\n5. The mode from grazing followed through phase splits (massless_mode, T in [3.2, 4.1])")
    print(f"   {'n':>5} {'down to T':>10} {'phases':>8} {'E max':>9} " + " ".join(f"{'E(' + str(T) + ')':>9}"
                                                                          for T in (3.9, 3.7, 3.45)) + f" {'t (s)':>6}")
    for n in (10, 20) + SIZES:
        t = time.perf_counter()
        branch = bc.nsm.massless_mode(bar(n, D, contact="massless"), (3.2, 4.1), max_points=3000)
        T, E = branch.T, branch.energy
        cells = []
        for Tq in (3.9, 3.7, 3.45):
            i = np.flatnonzero((T[:-1] - Tq) * (T[1:] - Tq) <= 0)
            cells.append(f"{E[i[0]] + (E[i[0] + 1] - E[i[0]]) * (Tq - T[i[0]]) / (T[i[0] + 1] - T[i[0]]):9.4f}"
                         if i.size else f"{'—':>9}")
        ks = sorted({o.k for o in branch.orbits})
        print(f"   {n:>5} {T.min():>10.5f} {'→'.join(map(str, ks)):>8} {E.max():>9.3g} " + " ".join(cells)
              + f" {time.perf_counter() - t:>6.1f}")
    print("   continuum " + ", ".join(f"E({T}) = {float(bar_continuum_energy(T, D)):.4f}" for T in (3.9, 3.7, 3.45)))
    print("   -> every orbit is exact (re-simulated in the tests) and the mode does gain contact phases, but it runs")
    print("      into an internal resonance (energy diverging at an almost fixed T) whose period approaches grazing")
    print("      as n grows: the followed branch has no pointwise limit either.")


if __name__ == "__main__":
    t0 = time.perf_counter()
    fixed_period_table()
    grazing_branch_table()
    return_defect_table()
    band_energy_table()
    multi_phase_table()
    print(f"\ntotal {time.perf_counter() - t0:.1f} s")
