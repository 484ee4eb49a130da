"""Friction (μ = 0.15, rotation-dominated sliding) and abradable wear on the demo blade: what they cost and how well
the energy balance closes.

1. The rub of the demo blade (26 tip nodes, 8 lobes of 0.3 mm, 0.5 % damping) at one speed with μ = 0.15: the
   energy balance of every revolution (casing input = friction + damping + change of stored energy; goal: 1e-9
   relative), the friction work per revolution, the sliding check (ΩR against the tips' tangential vibration
   velocity), and friction off against the plain simulation (bit for bit).
2. The first mode with friction by the extended periodic motion concept at 1.2 and 1.5 times its grazing amplitude
   (0.5 % damping): frequency, damping ratio with and without friction, and the free decay's ratio (certified
   simulator) beside it.
3. The cost of a 50-speed friction/wear sweep as the ``[rub]`` study runs it with ``[contact] friction`` (μ = 0.15)
   and ``[casing] abradable`` (1 mm, yield 5 MPa, 1e12 Pa/m, 360 cells), in turn in one process: per speed the
   stage's own calls (``bladecase.study.rub.stage._rub_point``), each timed — the model (its centrifugal state from
   the speeds before, the nodal model on the shared interior basis), the rub response with friction
   (``friction_response``: ``[rub] revolutions`` = ``--revolutions``, window half of them, run on to at most
   ``--max-revolutions``) and the coupled rub and wear with the coating yielding in flight (``wear_rub``, its
   default coupling, over the same revolutions). The offline wear pass of the last revolution this section timed
   before is not what a study runs and is left out.

    python benchmarks/bench_friction.py                 # everything
    python benchmarks/bench_friction.py --speeds 5      # a short sweep
    python benchmarks/bench_friction.py --sweep-only --speeds 50   # section 3 alone

Section 3, measured on 2026-11-29 on 2 cores shared with two other people's jobs (load 2.3 to 4 throughout: the wall
times carry that noise, the CPU seconds less), one process, 4 revolutions a speed, no run-on:

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_friction.py --sweep-only --speeds 50

- 50 speeds, 1400-1700 rpm: 546.1 s in all (10.9 s a speed; 436.2 s of CPU): models 27.0 s, rubs with friction and
  their energy 28.6 s, wear rubs in flight 490.5 s (90 %); worst energy residual 1.1e-12. The wear rub takes 4.5 to
  25.1 s a speed (9.9 s on average), growing with its phases (8.2 k to 19.4 k over the 4 revolutions: the profile
  steps under each of the 26 nodes are most of them) as the wear deepens towards the crossing of mode 1 with the 8
  lobes. One speed, 1657.1 rpm, is refused by the wear rub (a grazing switch: a node that stopped yielding does not
  leave its yield force; the code before these figures refuses it at the same instant); the stage reports such a
  speed and goes on, and so does this section.
- After the fix of that stop (a flat signal a hair below its surface with a cell's edge 1.2 ns ahead is flown to the
  edge), the same command, load about 2.3 (a helper's benchmark and a diagnostic beside it): every speed runs,
  658.0 s in all (13.2 s a speed; 451.0 s of CPU): models 29.7 s, rubs 32.9 s, wear rubs 595.4 s; worst energy
  residual 1.13e-12; 1657.1 rpm: 18 008 phases, 1.394e4 mm3 removed, as when it runs alone.
- The wear rub with its energy balance per revolution, as the study now flies it (``wear_rub(..., energy=True)``),
  load about 1.5 (a benchmark beside it): every speed runs, 497.0 s in all (9.9 s a speed; 495.3 s of CPU): models
  18.8 s, rubs 21.3 s, wear rubs with their energy 456.9 s; worst energy residual 1.13e-12 (rub), 4.52e-11 (wear).
- Before the coating flight's shortcuts (next profile edges from the runs of equal depth, a flight started from the
  start its decision computed, phases kept for the sampling; the same numbers bit for bit), the same sweep's first
  3 speeds back to back: wear rubs 77.0 s -> 53.6 s, 58.4 s -> 44.3 s of CPU for the 3 speeds; one speed at
  1650 rpm alone (17 566 phases), best of several runs: 15.6 s -> 11.0 s of CPU.
- The figure this section gave before (549.7 s for 50 speeds) timed an offline wear pass of each speed's last
  revolution, not the in-flight coupling a study runs; it is not comparable.
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

from bladecase.fe.rotation import spin  # noqa: E402
from bladecase.nsm import Damping  # noqa: E402
from bladecase.nsm.massless.friction import Friction  # noqa: E402
from bladecase.nsm.massless.friction_modes import decay_ratio, friction_mode  # noqa: E402
from bladecase.nsm.massless.friction_rub import friction_rub  # noqa: E402
from bladecase.nsm.massless.nodes import Rub, simulate_nodes  # noqa: E402
from bladecase.nsm.massless.rub import rub_response  # noqa: E402
from bladecase.nsm.massless.wear_rub import wear_rub  # noqa: E402
from bladecase.reduction.nodal_friction import nodal_friction  # noqa: E402
from bladecase.reduction.nodes import nodal_model  # noqa: E402
from bladecase.study.rub import stage  # noqa: E402
from bladecase.study.rub.friction import friction_response  # noqa: E402
from bladecase.study.rub.wear import coating_of  # noqa: E402
from bladecase.study.schema import loads  # noqa: E402
from bladecase.study.stages import build_contact, build_mesh, build_model  # noqa: E402

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


#: The coating of section 3 (``[casing] abradable``).
COATING = "{thickness = 1e-3, yield = 5e6, stiffness = 1e12, cells = 360}"


def wear_study(revolutions: int, max_revolutions: int):
    """The demo blade's rub study with friction (μ = 0.15) and an abradable coating (:data:`COATING`), its model and
    contact: ``[rub] revolutions`` = ``revolutions``, the window half of them, at most ``max_revolutions``."""
    from test_friction_study import _wear_study

    rub = (f"\n[rub]\nspeeds = [1650]\nratio = 0.005\nrevolutions = {revolutions}\n"
           f"window = {max(1, revolutions // 2)}\nmax_revolutions = {max_revolutions}\n")
    study = loads(_wear_study(COATING, rub, friction=f"{{mu = {MU}}}"), source="<bench>")
    model = build_model(study, build_mesh(study))
    return study, model, build_contact(study, model)


def sweep(count: int, revolutions: int, max_revolutions: int) -> None:
    """Section 3: the stage's calls per speed (``_rub_point``), each timed."""
    study, model, contact = wear_study(revolutions, max_revolutions)
    speeds = np.linspace(1400, 1700, count)
    r, k = study["rub"], study["casing"]
    kind, shares = stage.check_rub_contact(study, model, contact)
    axis, static = stage._axis(study), "auto"
    casing = stage._node_stiffness(study, model, contact, shares)
    angles = stage.node_angles(model, list(contact.nodes), axis)
    damping, cap, coating = stage._damping(r), stage.max_revolutions(r), coating_of(study, model, contact)
    friction = study["contact"]["friction"]
    w_all = speeds * 2 * np.pi / 60
    interior, earlier = stage._Interior(float(np.sqrt(w_all.min() * w_all.max()))), stage._Earlier()
    print(f"3. a {count}-speed friction/wear sweep as the study runs it ({speeds[0]:g}-{speeds[-1]:g} rpm, "
          f"mu = {MU}, coating {COATING}, {revolutions} revolutions (at most {cap}), wear in flight)")
    print("   rpm      model s   rub s   wear s   total s  (cpu s)  rub revs  wear phases  removed mm3  "
          "energy residual (rub, wear)")
    t0, c0 = time.perf_counter(), time.process_time()
    sums, worst, worn_worst, refusals = np.zeros(3), 0.0, 0.0, 0
    for rpm, w in zip(speeds, w_all):
        t, cpu = time.perf_counter(), time.process_time()
        state = spin(model, w, axis, static=static, previous=earlier.states)
        earlier.add(state)
        hot = stage._running(model, contact, state.displacement, w)
        own = None if state.static == "nonlinear" else interior.of(model, contact, r["size"], casing, axis, static)
        reduced = nodal_model(state.model, hot, r["size"], factor=state.factor, casing=casing, interior=own,
                              residual=True)
        t_model = time.perf_counter() - t
        t = time.perf_counter()
        times, refused = [], None
        try:  # as the stage: a speed the simulation refuses is that speed's result, the others go on
            fr, flight, response = friction_response(reduced, friction, axis, state.factor, w, k["lobes"],
                                                     k["amplitude"], angles, damping, r["revolutions"], r["window"],
                                                     cap, respond=rub_response)
            times.append(time.perf_counter() - t)
            t = time.perf_counter()
            worn = wear_rub(reduced.system, coating, w, k["lobes"], k["amplitude"], angles, damping,
                            r["revolutions"], areas=reduced.areas, friction=fr, flight=flight, energy=True)
        except ValueError as exc:
            refused = str(exc)
        times.append(time.perf_counter() - t)
        t_rub, t_wear = times if len(times) == 2 else (times[0], 0.0)  # the rub refused: no wear
        sums += (t_model, t_rub, t_wear)
        head = (f"   {rpm:7.1f}  {t_model:7.2f}  {t_rub:6.2f}  {t_wear:7.2f}  {t_model + t_rub + t_wear:8.2f}  "
                f"({time.process_time() - cpu:6.2f})  ")
        if refused is not None:
            refusals += 1
            print(f"{head}refused ({'wear' if len(times) == 2 else 'rub'}): {refused[:90]}", flush=True)
            continue
        res = response.as_dict().get("friction", {}).get("relative_residual", float("nan"))
        worst = max(worst, abs(res))
        balance = max(abs(e.relative) for e in worn.energy)
        worn_worst = max(worn_worst, balance)
        print(f"{head}{response.revolutions_run:8d}  {worn.phases:11d}  {1e9 * worn.profile.removed:11.4g}  "
              f"{res:.1e}, {balance:.1e}", flush=True)
    total, cpu = time.perf_counter() - t0, time.process_time() - c0
    print(f"   {total:.1f} s in all ({total / count:.2f} s a speed; {cpu:.1f} s of CPU): models {sums[0]:.1f} s, rubs "
          f"with friction and energy {sums[1]:.1f} s, wear rubs in flight with their energy {sums[2]:.1f} s; worst "
          f"energy residual {worst:.2e} (rub), {worn_worst:.2e} (wear); {refusals} speeds refused")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--speeds", type=int, default=50)
    ap.add_argument("--revolutions", type=int, default=4)
    ap.add_argument("--max-revolutions", type=int, default=None, help="section 3's [rub] max_revolutions "
                    "(default: --revolutions, no run-on)")
    ap.add_argument("--sweep-only", action="store_true")
    ap.add_argument("--rpm", type=float, default=1650.0)
    ap.add_argument("--skip-sweep", action="store_true")
    ap.add_argument("--skip-modes", action="store_true")
    a = ap.parse_args()
    if not a.sweep_only:
        study, model, contact = demo()
        one_speed(study, model, contact, a.rpm, a.revolutions)
        if not a.skip_modes:
            modes(study, model, contact, a.rpm)
    if not a.skip_sweep:
        sweep(a.speeds, a.revolutions, a.max_revolutions or a.revolutions)


if __name__ == "__main__":
    main()
