"""The rub response with one contact per tip node: the speed goals and the figures that say what the model is worth.

1. The exact event-driven simulation against ``solve_ivp`` (DOP853, rtol 1e-12, the complementarity problem
   solved at every right-hand-side evaluation, restarted at every switch) on a 3-dof chain with two contacts and on
   the demo blade (26 tip nodes, two revolutions inside the out-of-round casing): time ratio and the switch times'
   agreement (goal: >= 10x faster at equal switch-time accuracy).
2. One contact: the one-constraint massless simulator against the m-contact one on the same system (the cost of
   taking the one-contact model as the m = 1 case).
3. A 50-speed rub sweep of the demo blade, 26 contact nodes, through the study's rub stage on 2 local processes
   (goal: <= 120 s).
4. How the answer moves with the number of contact nodes (every 4th, every 2nd, all) at one speed past resonance.
5. Why it moves, node subsets and meshes alike: each model's own crossing speed of mode 1 with the lobes, and the
   rub at a fixed speed against the rub at the same ratio to each model's crossing speed.

    python benchmarks/bench_rub.py                 # everything
    python benchmarks/bench_rub.py --skip-sweep    # without the 50-speed sweep
    python benchmarks/bench_rub.py --sweep-only    # the 50-speed sweep alone
    python benchmarks/bench_rub.py --ratio-only    # section 5 alone
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from test_nodes import V0, X0, chain, reference  # noqa: E402
from test_rub_study import CASING, _study  # noqa: E402

from bladecase.fe.rotation import spin  # noqa: E402
from bladecase.nsm import Damping, simulate_massless  # noqa: E402
from bladecase.nsm.massless.nodes import NodalSystem, Rub, simulate_nodes  # noqa: E402
from bladecase.nsm.massless.rub import rub_response  # noqa: E402
from bladecase.reduction.massless import massless_model  # noqa: E402
from bladecase.reduction.nodes import contact_pressure, nodal_model  # noqa: E402
from bladecase.study.executor import make_executor  # noqa: E402
from bladecase.study.rub import stage  # noqa: E402
from bladecase.study.schema import loads  # noqa: E402
from bladecase.study.stages import build_contact, build_mesh, build_model  # noqa: E402


def timed(fn, repeat: int = 3):
    best, out = np.inf, None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def demo(rub_text: str = "", mesh: float = 1.0):
    """The demo blade, its element sizes ([geometry] size and tip_size) times ``mesh``."""
    text = _study(CASING, rub_text)
    assert "\nsize = 0.008\ntip_size = 0.004\n" in text
    text = text.replace("\nsize = 0.008\ntip_size = 0.004\n",
                        f"\nsize = {0.008 * mesh:.6g}\ntip_size = {0.004 * mesh:.6g}\n")
    study = loads(text, source="<bench>")
    mesh = build_mesh(study)
    model = build_model(study, mesh)
    return study, model, build_contact(study, model)


def at_speed(study, model, contact, rpm: float, nodes=None, size: int = 8):
    axis = stage._axis(study)
    casing = stage._node_stiffness(study, model, contact)
    if nodes is not None:  # a subset: the casing's total shared by the subset's own areas
        keep = np.asarray(nodes)
        share = np.asarray(contact.weights)[keep]
        casing = casing.sum() * share / share.sum()
        contact = dataclasses.replace(contact, nodes=tuple(np.asarray(contact.nodes)[keep].tolist()),
                                      weights=tuple((share / share.sum()).tolist()),
                                      normals=tuple(np.asarray(contact.normals)[keep].tolist()),
                                      clearances=tuple(np.asarray(contact.clearances)[keep].tolist()),
                                      node=int(np.asarray(contact.nodes)[keep][0]))
    w = rpm * 2 * np.pi / 60
    state = spin(model, w, axis, static="auto")
    hot = stage._running(model, contact, state.displacement, w)
    reduced = nodal_model(state.model, hot, size, factor=state.factor, casing=casing, residual=True)
    return reduced, w, stage.node_angles(model, list(contact.nodes), axis)


def against_solve_ivp() -> None:
    print("1. exact event-driven simulation vs solve_ivp (DOP853, rtol 1e-12, atol 1e-14)")
    for label, casing in (("chain, rigid casing", np.inf), ("chain, compliant casing", 12.0)):
        s = chain(casing)
        t_ev, tr = timed(lambda s=s: simulate_nodes(s, X0, V0, 30.0))
        t_ref, (times, _) = timed(lambda s=s: reference(s, X0, V0, 30.0), repeat=1)
        err = np.abs(tr.switch_times - times).max()
        print(f"   {label}: {tr.switch_times.size} switches, event-driven {t_ev * 1e3:.1f} ms, solve_ivp "
              f"{t_ref * 1e3:.0f} ms: {t_ref / t_ev:.0f}x faster; switch times agree to {err:.1e} s")
    study, model, contact = demo()
    reduced, w, angles = at_speed(study, model, contact, 1650.0)
    s = reduced.system
    rub, damping = Rub(8, 3e-4, w, angles), Damping(zeta=0.005)
    t_end = 2 * 2 * np.pi / w
    t_ev, tr = timed(lambda: simulate_nodes(s, np.zeros(s.n), np.zeros(s.n), t_end, damping=damping, rub=rub))
    t_ref, (times, z) = timed(lambda: reference(s, np.zeros(s.n), np.zeros(s.n), t_end, damping, rub), repeat=1)
    k = min(times.size, tr.switch_times.size)
    err = np.abs(tr.switch_times[:k] - times[:k]).max() if k else float("nan")
    print(f"   demo blade, 26 tip nodes (n = {s.n}), 2 revolutions at 1650 rpm: {tr.switch_times.size} switches "
          f"(solve_ivp {times.size}), event-driven {t_ev:.2f} s, solve_ivp {t_ref:.1f} s: {t_ref / t_ev:.0f}x faster; "
          f"switch times agree to {err:.1e} s (goal >= 10x)")


def one_contact() -> None:
    print("2. one contact: the one-constraint simulator vs the m-contact one on the same system")
    study, model, contact = demo()
    one = massless_model(model, contact, 8).system
    nodal = NodalSystem(one.M, one.S, one.w[:, None], np.array([[1.0 / one.kc]]), gap=[one.gap])
    x0 = 3 * one.gap * np.linalg.lstsq(one.w[None, :], [1.0], rcond=None)[0]
    v0 = np.zeros(one.n)
    T = 2 * np.pi / one.open.omega[0]
    t_one, a = timed(lambda: simulate_massless(one, x0, v0, 200 * T))
    t_m, b = timed(lambda: simulate_nodes(nodal, x0, v0, 200 * T))
    err = np.abs(a.switch_times - b.switch_times).max()
    print(f"   demo face model (n = {one.n}), 200 periods, {a.switch_times.size} switches: one-contact "
          f"{t_one * 1e3:.0f} ms, m-contact {t_m * 1e3:.0f} ms (ratio {t_m / t_one:.2f}); switch times agree to "
          f"{err:.1e} s")


def sweep(workers: int) -> None:
    print(f"3. a 50-speed rub sweep of the demo blade (26 tip nodes, 40 revolutions each) on {workers} processes")
    speeds = np.linspace(1400, 1700, 50).round(3).tolist()
    study, model, contact = demo(f"\n[rub]\nspeeds = {speeds}\nratio = 0.005\n")
    ex = make_executor("processes", workers=workers)
    try:
        t = time.perf_counter()
        section = stage.rub_stage(study, model, contact, executor=ex, folder=None)
        dt = time.perf_counter() - t
    finally:
        ex.close()
    rows = section["rows"]
    peak = max(rows, key=lambda r: r["tip_normal_displacement_mm"])
    print(f"   {dt:.1f} s ({'MET' if dt <= 120 else 'NOT MET'}: goal <= 120 s); {sum(r['switches'] for r in rows)} "
          f"switches; hardest rub at {peak['speed']:.0f} rpm: {peak['tip_normal_displacement_mm']:.3f} mm, "
          f"{peak['total_force_n']:.2f} N in total, {peak['max_pressure_mpa']:.3g} MPa, {peak['nodes_touching']} "
          f"nodes; not settled at "
          f"{len(section['unsettled_speeds'])} of 50 speeds")


def node_count() -> None:
    print("4. how the answer moves with the number of contact nodes (1650 rpm, 8 lobes of 0.3 mm, casing 1e6 N/m "
          "shared by area, 40 revolutions)")
    study, model, contact = demo()
    m = len(contact.nodes)
    for label, keep in (("every 4th", np.arange(0, m, 4)), ("every 2nd", np.arange(0, m, 2)), ("all", None)):
        reduced, w, angles = at_speed(study, model, contact, 1650.0, nodes=keep)
        t = time.perf_counter()
        r = rub_response(reduced.system, w, 8, 3e-4, angles, Damping(zeta=0.005), 40, 10)
        total = r.peak_force.sum()
        print(f"   {label:9s} ({reduced.system.m:2d} nodes): tip {r.tip_displacement * 1e3:.4f} mm, largest node "
              f"force {r.peak_force.max():.3f} N, sum of node peaks {total:.3f} N, contact fraction "
              f"{r.contact_fraction.max():.3f}, {len(r.touching)} touching ({time.perf_counter() - t:.1f} s)")


def _rub(study, model, contact, rpm: float, nodes=None) -> tuple:
    reduced, w, angles = at_speed(study, model, contact, rpm, nodes=nodes)
    r = rub_response(reduced.system, w, 8, 3e-4, angles, Damping(zeta=0.005), 40, 10, areas=reduced.areas)
    pressure = np.nan_to_num(contact_pressure(r.peak_force, reduced.areas)).max() * 1e-6
    return r, pressure


def crossing_ratio() -> None:
    print("5. the rub at 1650 rpm and at the same ratio to each model's own crossing speed of mode 1 (8 lobes of "
          "0.3 mm, casing 1e6 N/m shared by area, damping ratio 0.005, 40 revolutions, run on until settled)")
    rpm = 2 * np.pi / 60
    target = None
    study, model, contact = demo()
    m = len(contact.nodes)
    cases = [(f"mesh 1, {label}", (study, model, contact), keep)
             for label, keep in (("every 4th node", np.arange(0, m, 4)), ("every 2nd node", np.arange(0, m, 2)))]
    cases += [(f"mesh {f:g}, all nodes", demo(mesh=f) if f != 1 else (study, model, contact), None) for f in (1, 0.7)]
    for label, (st, mo, co), keep in cases:
        f1 = [at_speed(st, mo, co, s, nodes=keep)[0].system.modes[0][0] / (2 * np.pi) for s in (1600.0, 1650.0)]
        cross = stage.crossing_speed(np.array([1600.0, 1650.0]) * rpm, f1, 8)["speed_rad_s"] / rpm
        target = 1650.0 / cross if target is None else target
        fixed, p_fixed = _rub(st, mo, co, 1650.0, keep)
        same, p_same = _rub(st, mo, co, target * cross, keep)
        mpa = (lambda p: f", {p:.3f} MPa") if keep is None else (lambda p: "")  # a subset: areas not re-shared
        print(f"   {label:22s} ({len(fixed.nodes):2d} contact nodes): f1 {f1[1]:.2f} Hz at 1650 rpm, crossing "
              f"{cross:.1f} rpm; at 1650 rpm ({1650 / cross:.4f} x): tip {fixed.tip_displacement * 1e3:.4f} mm, total "
              f"{fixed.total_force:.2f} N{mpa(p_fixed)}; at {target:.4f} x ({target * cross:.1f} rpm): tip "
              f"{same.tip_displacement * 1e3:.4f} mm, total {same.total_force:.2f} N{mpa(p_same)} "
              f"({same.response}, {same.revolutions_run} revolutions)")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--skip-sweep", action="store_true")
    p.add_argument("--sweep-only", action="store_true", help="only the 50-speed sweep")
    p.add_argument("--ratio-only", action="store_true", help="only section 5")
    p.add_argument("--workers", type=int, default=2)
    a = p.parse_args()
    if a.ratio_only:
        crossing_ratio()
        return
    if not a.sweep_only:
        against_solve_ivp()
        one_contact()
        node_count()
        crossing_ratio()
    if not a.skip_sweep:
        sweep(a.workers)


if __name__ == "__main__":
    main()
