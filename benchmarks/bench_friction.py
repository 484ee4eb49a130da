"""Friction (μ = 0.15, rotation-dominated sliding) and abradable wear on the demo blade: what they cost and how well
the energy balance closes.

1. The rub of the demo blade (26 tip nodes, 8 lobes of 0.3 mm, 0.5 % damping) at one speed with μ = 0.15: the
   energy balance of every revolution (casing input = friction + damping + change of stored energy; goal: 1e-9
   relative), the friction work per revolution, the sliding check (ΩR against the tips' tangential vibration
   velocity), and friction off against the plain simulation (bit for bit).
2. The first mode with friction by the extended periodic motion concept at 1.2 and 1.5 times its grazing amplitude
   (0.5 % damping): frequency, damping ratio with and without friction, and the free decay's ratio (certified
   simulator) beside it.
3. The cost of a 50-speed friction sweep (each speed: its own centrifugal state and nodal model, the rub with
   friction over ``--revolutions`` turns, the per-revolution energy balance) and of a wear pass of each speed's
   last revolution over a 360-cell abradable profile (in turn, one process).

    python benchmarks/bench_friction.py                 # everything
    python benchmarks/bench_friction.py --speeds 5      # a short sweep
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from bench_rub import at_speed, demo  # noqa: E402

from bladecase.nsm import Damping  # noqa: E402
from bladecase.nsm.massless.friction import Friction  # noqa: E402
from bladecase.nsm.massless.friction_modes import decay_ratio, friction_mode  # noqa: E402
from bladecase.nsm.massless.friction_rub import friction_rub  # noqa: E402
from bladecase.nsm.massless.nodes import Rub, simulate_nodes  # noqa: E402
from bladecase.nsm.massless.wear import Abradable, WearProfile, pass_tip  # noqa: E402
from bladecase.reduction.nodal_friction import nodal_friction  # noqa: E402
from bladecase.study.rub import stage  # noqa: E402

LOBES, AMPLITUDE, DAMPING, MU = 8, 3e-4, Damping(zeta=0.005), 0.15


def friction_at(study, model, contact, rpm: float):
    reduced, w, angles = at_speed(study, model, contact, rpm)
    axis = stage._axis(study)
    return reduced, w, angles, nodal_friction(reduced, MU, axis.origin, axis.direction)


def one_speed(study, model, contact, rpm: float, revolutions: int) -> None:
    print(f"1. the demo blade's rub with mu = {MU} at {rpm:g} rpm ({LOBES} lobes of {AMPLITUDE * 1e3:g} mm, "
          f"{revolutions} revolutions)")
    reduced, w, angles, fr = friction_at(study, model, contact, rpm)
    s = reduced.system
    t = time.perf_counter()
    r = friction_rub(s, fr, w, LOBES, AMPLITUDE, angles, DAMPING, revolutions)
    took = time.perf_counter() - t
    print(f"   n = {s.n}, m = {s.m}: {r.trajectory.switch_times.size} switches in {took:.2f} s (energy included)")
    for k, e in enumerate(r.energy):
        print(f"   rev {k + 1:2d}: casing {e.casing:+.4e} J, friction {e.friction:+.4e} J, damping {e.damping:.4e} J, "
              f"stored {e.stored_change:+.4e} J, residual {e.relative:.1e} (quadrature {e.quadrature_error:.1e} J)")
    print(f"   worst relative residual {r.worst_relative:.2e} (goal 1e-9); {r.sliding.message}")
    off = friction_rub(s, None, w, LOBES, AMPLITUDE, angles, DAMPING, revolutions)
    plain = simulate_nodes(s, np.zeros(s.n), np.zeros(s.n), revolutions * 2 * np.pi / w, DAMPING,
                           Rub(LOBES, AMPLITUDE, w, angles))
    same = np.array_equal(off.trajectory.starts, plain.starts) and np.array_equal(off.trajectory.q, plain.q)
    print(f"   friction off against the plain simulation: bit for bit {same}; worst residual off "
          f"{off.worst_relative:.1e}")


def modes(study, model, contact, rpm: float) -> None:
    reduced, _, _, fr = friction_at(study, model, contact, rpm)
    s = reduced.system
    omega, phi = s.modes
    grazing = float(np.min(s.gap / np.abs(s.W.T @ phi[:, 0])))
    print(f"2. mode 1 with friction at {rpm:g} rpm (f1 = {omega[0] / 2 / np.pi:.2f} Hz open), 0.5 % damping")
    for k in (1.2, 1.5):
        for mu in (0.0, MU):
            f = Friction(mu, T=fr.T, C_nt=fr.C_nt, C_tt=fr.C_tt, radius=fr.radius)
            t = time.perf_counter()
            m = friction_mode(s, f, amplitude=k * grazing, damping=DAMPING)
            z = decay_ratio(s, f, m, DAMPING)
            print(f"   {k:.1f} x grazing, mu = {mu:4.2f}: f = {m.frequency / 2 / np.pi:.3f} Hz "
                  f"({m.frequency / omega[0] - 1:+.2e}), zeta {m.zeta:.6f}, free decay {z:.6f} "
                  f"({z / m.zeta - 1:+.1e}), closed to {m.residual:.0e}, {time.perf_counter() - t:.1f} s")


def sweep(study, model, contact, count: int, revolutions: int) -> None:
    speeds = np.linspace(1400, 1700, count)
    coating = Abradable(thickness=1e-3, yield_pressure=5e6, stiffness=1e12, cells=360, radius=0.4505, width=0.02)
    print(f"3. a {count}-speed friction/wear sweep ({speeds[0]:g}-{speeds[-1]:g} rpm, {revolutions} revolutions each)")
    t0 = time.perf_counter()
    worst, t_model, t_rub, t_wear = 0.0, 0.0, 0.0, 0.0
    for rpm in speeds:
        t = time.perf_counter()
        reduced, w, angles, fr = friction_at(study, model, contact, rpm)
        t_model += time.perf_counter() - t
        t = time.perf_counter()
        r = friction_rub(reduced.system, fr, w, LOBES, AMPLITUDE, angles, DAMPING, revolutions)
        t_rub += time.perf_counter() - t
        worst = max(worst, r.worst_relative)
        t = time.perf_counter()
        turn = 2 * np.pi / w
        times = np.linspace((revolutions - 1) * turn, revolutions * turn, 3601)
        x, _ = r.trajectory.state(times)
        incursion = (reduced.system.W.T @ x).max(axis=0) - reduced.system.gap.min()
        pass_tip(WearProfile.new(coating), w * times, incursion)
        t_wear += time.perf_counter() - t
    total = time.perf_counter() - t0
    print(f"   {total:.1f} s in all ({total / count:.2f} s a speed): models {t_model:.1f} s, rubs with friction and "
          f"energy {t_rub:.1f} s, wear passes {t_wear:.2f} s; worst energy residual {worst:.2e}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--speeds", type=int, default=50)
    ap.add_argument("--revolutions", type=int, default=4)
    ap.add_argument("--rpm", type=float, default=1650.0)
    ap.add_argument("--skip-sweep", action="store_true")
    ap.add_argument("--skip-modes", action="store_true")
    a = ap.parse_args()
    study, model, contact = demo()
    one_speed(study, model, contact, a.rpm, a.revolutions)
    if not a.skip_modes:
        modes(study, model, contact, a.rpm)
    if not a.skip_sweep:
        sweep(study, model, contact, a.speeds, a.revolutions)


if __name__ == "__main__":
    main()
