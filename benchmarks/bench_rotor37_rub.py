"""NASA Rotor 37's rub sweep with every tip-face node a contact: cost per speed, switches per revolution, memory.

The blade of NLstep's CalculiX deck (``blade.inp``: N-mm-t-s, C3D15, 61k free dofs; ``bench_rotor37.py``), every
corner node of its tip face a massless contact of its own (134 nodes: the corner nodes of the body cells on the
tip's cone ``r = 640.006 mm − 0.27245 (z − 6.55 mm)``), turning inside a conical casing ``--clearance`` outside the
tip with 3 lobes of ``--amplitude`` reaching in (a compliant casing, ``casing_stiffness_per_area``), 9 speeds around
the engine-order-3 crossing of mode 1 (about 1014 rad/s), 40 revolutions each (``max_revolutions = 40``: the
cost of 40 revolutions; ``--run-on`` lets an unsettled speed run on to the study default, 10 × revolutions), the
study's own ``[rub]`` stage (:func:`bladecase.study.rub.stage.rub_stage`) on ``--workers`` local processes.

Printed: the model's build, each speed as it ends (the stage's log line: switches, revolutions, the CPU seconds of
the centrifugal state, the reduction and the simulation), then per speed its ratio to the crossing speed, switches
per revolution and response, the sweep's wall time against the 5-minute goal, the CPU seconds summed by part, and
the peak memory of the workers and of this process. ``--campbell`` also times a 3-speed Campbell diagram
(``campbell_stage``, modes only, no bands) of the blade about the same axis, cost per speed.

Run (OPENBLAS_NUM_THREADS=1: the workers run single-threaded BLAS anyway)::

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_rotor37_rub.py DATA/blade.inp [--speeds 9]
        [--workers 2] [--revolutions 40] [--run-on] [--campbell] [--campbell-only]

Latest (with METIS's nested-dissection ordering of the factorisations, :mod:`bladecase.ordering`; 2026-11-29, the
machine nearly idle, load 2): the 9 speeds in 220 s of wall time on 2 processes (0.73 × the 5-minute goal), the whole
script 3 min 45 s; 398 CPU s = centrifugal state 185 s (46 %), reduction 64 s, simulation 149 s; per speed: the
first of each process 40–42 s (7 Newton iterations, 2 factorisations, 108–115 conjugate-gradient solves), the later
ones 30–62 s (3–4 Newton iterations, 2 factorisations, 27–32 solves; the simulation 26–36 s past the crossing, where
28 962–31 166 switches in 40 revolutions); peak memory 2.4 GiB per worker.

Figures (CPU seconds, the stable measure on a shared machine; 2 processes, cvxopt's CHOLMOD; the machine's load
average 5 to 10 on 2 cores, so the wall times are 3 to 4 times an idle machine's).  Before: every speed's
``static = "auto"`` state took about nine factorisations of the 61k-dof model (the linear and the second-order
probes, six Newton tangents from rest, ``K(Ω)``): 9 speeds 1546 CPU s, 79 % of it the centrifugal state (773 s on
two idle cores, 2.6 × the goal); ``--speeds 3`` (load 8.4) 403 CPU s, the state 103.5–105.6 s a speed, reduction
9.9–10.8 s, simulation 6.0–45.0 s.  After (each speed's state passed on to the next speed its process runs:
:func:`bladecase.fe.rotation.spin`'s ``previous``; Newton's steps by conjugate gradients preconditioned with one
reused factorisation, :mod:`bladecase.fe.krylov`), the 9 speeds (load 7–10, 28 % of the CPU for this run, 2125 s
wall): 602 CPU s = centrifugal state 306 s (51 %), reduction 87 s, simulation 209 s (35 %: 3.4–58.5 s a speed,
most past the crossing, where all 134 nodes touch); on two idle cores 301 s, 1.00 × the goal.  The first speed of
each process, from rest: 43.9 and 53.8 s (6–7 Newton iterations, 2–3 factorisations with ``K(Ω)``'s, 100–103
conjugate-gradient solves); every later speed: 25.6–37.0 s (3–5 Newton iterations from the extrapolated earlier
states, 2 factorisations — ``K(Ω)``'s and one for the probes —, 33–48 solves).  The responses are the same
(switches, revolutions and responses identical to the before run at the speeds both ran).  On one speed
(1014 rad/s, from 953 rad/s's state and ``K(Ω)``, one process): the nonlinear state itself 8.4 CPU s (4 Newton
iterations, no factorisation, 17 solves) against 73.6 s from rest with a factorisation per iteration (6), the
states equal to 1.1e-12 and the tangents to 3e-14 (relative, max norms).  The price: a worker keeps the previous
speed's factorisation of ``K(Ω)`` and the states of the last two speeds, its peak memory 2.8 GiB against 1.5 GiB.
Then Newton's last step solved only as tightly as the residual test needs, and ``"auto"``'s probes to 1e-6 when
earlier states precondition them (load 4–10, 52 % of the CPU, 1295 s wall): 696 CPU s, the state 368 s (53 %), the
first speed of each process 57–59 s (2 factorisations, 100–108 solves), the later ones 33–38 s (3–4 Newton
iterations, 2 factorisations, 24–32 solves); the unchanged reduction, a control, took 115 s against 87 s above:
CPU seconds inflate by a quarter on this loaded machine, so the two runs tie.  The responses again identical.
The factorisation left besides ``K(Ω)``'s is ``"auto"``'s linear probe: ``K − Ω² M⊥`` preconditioned by the
previous ``K(Ω)`` starts at a residual 46 times the load's and needs some 45 iterations to 1e-6 (the stress
stiffness it lacks is large on this twisted blade), so it is factorised (10 s a speed).
"""

from __future__ import annotations

import argparse
import logging
import os
import re
import resource
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_rotor37 import deck_text  # noqa: E402

#: The tip's cone (m): r = R0 − SLOPE (z − Z0), from z = Z0 to Z1 (bench_rotor37.rub_text).
R0, SLOPE, Z0, Z1 = 0.640006, 0.27245, 0.00655, 0.06859
#: The engine-order-3 crossing of mode 1 (rad/s), f1² linear in Ω² from f1 = 454.6 Hz at 900 rad/s and 624.8 Hz
#: at 1500 rad/s (this blade, nonlinear centrifugal state); the sweep's speeds are spread about it.
CROSSING = 1014.0
GOAL_S = 300.0


def tip_face(model) -> list[int]:
    """The file numbers of the corner nodes of the body cells on the tip's cone (within 10 µm)."""
    from bladecase.fe.cells import KINDS

    mesh = model.mesh
    p = np.asarray(mesh.points, dtype=float)
    corners = np.unique(np.asarray(mesh.cells[mesh.body_type])[:, : KINDS[mesh.body_type].corners])
    r = np.hypot(p[corners, 0], p[corners, 1])
    on = np.abs(r - (R0 - SLOPE * (p[corners, 2] - Z0))) < 1e-5
    return [int(mesh.node_id(k)) for k in corners[on]]


def study_text(deck: Path, nodes, speeds, args) -> str:
    r = lambda z: R0 - SLOPE * (z - Z0) + args.clearance * 1e-3  # noqa: E731
    cap = "" if args.run_on else f"max_revolutions = {args.revolutions}\n"
    return deck_text(deck, "rotor37_rub", "lumped") + f"""
[contact]
nodes = {list(nodes)}
model = "massless"
casing_stiffness_per_area = {args.stiffness:g}

[casing]
radii = [[{Z0}, {r(Z0)!r}], [{Z1}, {r(Z1)!r}]]
axis = {{origin = [0.0, 0.0, 0.0], direction = [0.0, 0.0, 1.0]}}
lobes = 3
amplitude = {args.amplitude * 1e-3:g}

[search]
ipp = [1]

[rub]
speeds = {[round(float(w), 3) for w in speeds]}
speed_unit = "rad/s"
ratio = 0.005
revolutions = {args.revolutions}
window = {args.revolutions // 4}
{cap}"""


class Lines(logging.Handler):
    """Prints the ``bladecase`` log's per-speed lines as they come, and keeps them."""

    def __init__(self):
        super().__init__(logging.INFO)
        self.lines: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        msg = record.getMessage()
        if re.match(r"rub: [\d.]+ rad/s: ", msg):
            self.lines.append(msg)
            print(f"   [{time.strftime('%H:%M:%S')}] {msg}", flush=True)


def parse(line: str) -> dict:
    """The numbers of one per-speed log line."""
    m = re.match(r"rub: ([\d.]+) rad/s: (\d+) switches over (\d+) revolutions, ([\w-]+); ([\d.]+) s \(centrifugal "
                 r"state ([\d.]+) s, reduction ([\d.]+) s, simulation ([\d.]+) s\)(?:; centrifugal state: (\d+) Newton "
                 r"iterations, (\d+) factorisations, (\d+) conjugate-gradient solves)?", line)
    if m is None:
        return {"line": line}
    keys = ("speed", "switches", "revolutions", "response", "total", "state", "reduction", "simulation", "newton",
            "factorisations", "cg")
    return {k: (v if k == "response" else np.nan if v is None else float(v)) for k, v in zip(keys, m.groups())}


def peak_mib(who: int) -> float:
    return resource.getrusage(who).ru_maxrss / 1024


def build(deck: Path, speeds, args):
    from bladecase.study.schema import loads
    from bladecase.study.stages import build_contact, build_mesh, build_model

    t = time.perf_counter()
    first = loads(study_text(deck, [1], speeds, args).replace("nodes = [1]", "nodes = [188, 190]"), source=str(deck))
    nodes = tip_face(build_model(first, build_mesh(first)))  # the mesh keeps its contact face: built again below
    study = loads(study_text(deck, nodes, speeds, args), source=str(deck))
    model = build_model(study, build_mesh(study))
    contact = build_contact(study, model)
    print(f"model: {model!r}, {len(nodes)} tip-face contact nodes ({time.perf_counter() - t:.1f} s)", flush=True)
    return study, model, contact


def sweep(deck: Path, args) -> None:
    from bladecase.study.executor import make_executor
    from bladecase.study.rub import stage

    speeds = CROSSING * np.linspace(0.88, 1.12, args.speeds) if args.speeds > 1 else np.array([CROSSING])
    study, model, contact = build(deck, speeds, args)
    print(f"rub sweep: {speeds.size} speeds {speeds.min():.0f}–{speeds.max():.0f} rad/s, {args.revolutions} "
          f"revolutions each{' (run on to 10 × until settled)' if args.run_on else ''}, {len(contact.nodes)} contact "
          f"nodes, {args.workers} processes", flush=True)
    handler = Lines()
    logger = logging.getLogger("bladecase")
    logger.addHandler(handler)
    logger.setLevel(logging.INFO)
    ex = make_executor("processes", workers=args.workers)
    try:
        t = time.perf_counter()
        section = stage.rub_stage(study, model, contact, executor=ex, folder=None)
        wall = time.perf_counter() - t
    finally:
        ex.close()
        logger.removeHandler(handler)
    per = {round(p["speed"], 3): p for p in map(parse, handler.lines) if "speed" in p}
    print(f"\n   {'rad/s':>8} {'ratio':>6} {'switches':>8} {'revs':>5} {'sw/rev':>7} {'response':>15} {'tip mm':>7} "
          f"{'total N':>9} {'nodes':>5} {'CPU s':>7} {'state':>6} {'reduce':>6} {'simul.':>6} {'Newton':>6} "
          f"{'fact.':>5} {'CG':>4}")
    cpu = {"state": 0.0, "reduction": 0.0, "simulation": 0.0}
    for row in section["rows"]:
        p = per.get(round(row["speed"], 3), {})
        for k in cpu:
            cpu[k] += p.get(k, np.nan)
        ratio = row["speed_ratio"] if row["speed_ratio"] is not None else np.nan
        print(f"   {row['speed']:8.1f} {ratio:6.3f} {row['switches']:8d} {row['revolutions_run']:5d} "
              f"{row['switches'] / row['revolutions_run']:7.0f} {row['response']:>15} "
              f"{row['tip_normal_displacement_mm']:7.3f} {row['total_force_n']:9.1f} {row['nodes_touching']:5d} "
              f"{p.get('total', np.nan):7.1f} {p.get('state', np.nan):6.1f} {p.get('reduction', np.nan):6.1f} "
              f"{p.get('simulation', np.nan):6.1f} {p.get('newton', np.nan):6.0f} "
              f"{p.get('factorisations', np.nan):5.0f} {p.get('cg', np.nan):4.0f}")
    total = sum(cpu.values())
    n = len(section["rows"])
    print(f"\n   sweep wall time {wall:.0f} s on {args.workers} processes: {wall / GOAL_S:.2f} × the 5-minute goal "
          f"({'MET' if wall <= GOAL_S else 'NOT MET'}); crossing speed {section['crossing']['speed']:.1f} rad/s"
          if section.get("crossing") else f"\n   sweep wall time {wall:.0f} s")
    print(f"   CPU seconds of the {n} speeds: {total:.0f} s = centrifugal state {cpu['state']:.0f} s "
          f"({100 * cpu['state'] / total:.0f} %), reduction {cpu['reduction']:.0f} s "
          f"({100 * cpu['reduction'] / total:.0f} %), simulation {cpu['simulation']:.0f} s "
          f"({100 * cpu['simulation'] / total:.0f} %); per speed {total / n:.0f} s; on {args.workers} idle cores "
          f"{total / args.workers:.0f} s ({total / args.workers / GOAL_S:.2f} × the goal)")
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    print(f"   worker processes' CPU time in all (the model shipped, the interior basis, every speed): "
          f"{children.ru_utime + children.ru_stime:.0f} s")
    print(f"   peak memory: workers {peak_mib(resource.RUSAGE_CHILDREN):.0f} MiB (the largest), this process "
          f"{peak_mib(resource.RUSAGE_SELF):.0f} MiB; load average at the end {os.getloadavg()[0]:.1f}")


def campbell(deck: Path, args) -> None:
    from bladecase.study.executor import make_executor
    from bladecase.study.rotation.stage import campbell_stage
    from bladecase.study.schema import loads
    from bladecase.study.stages import build_mesh, build_model

    speeds = [900.0, 1350.0, 1800.0]
    text = deck_text(deck, "rotor37_campbell") + f"""
[contact]
nodes = [188, 190]
normal = [1.0, 0.0, 0.0]
clearance = 3.56e-4
[rotation]
speeds = {speeds}
speed_unit = "rad/s"
axis = {{origin = [0.0, 0.0, 0.0], direction = [0.0, 0.0, 1.0]}}
modes = 4
bands = false
"""
    study = loads(text, source=str(deck))
    model = build_model(study, build_mesh(study))
    ex = make_executor("processes", workers=args.workers)
    try:
        t = time.perf_counter()
        c, _ = campbell_stage(study, model, None, ex)
        wall = time.perf_counter() - t
    finally:
        ex.close()
    f = np.asarray(c.frequencies)
    print(f"\n3-speed Campbell ({', '.join(f'{w:g}' for w in speeds)} rad/s, 4 modes, no bands) on {args.workers} "
          f"processes: {wall:.0f} s wall, {wall * args.workers / len(speeds):.0f} s of a worker per speed; f1 "
          + ", ".join(f"{x:.1f}" for x in f[:, 0]) + " Hz")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("deck", type=Path)
    ap.add_argument("--speeds", type=int, default=9, help="speeds, spread over 0.88–1.12 × the crossing (9)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--revolutions", type=int, default=40)
    ap.add_argument("--run-on", action="store_true", help="let an unsettled speed run on (10 × revolutions)")
    ap.add_argument("--clearance", type=float, default=0.3, help="the casing's cold clearance over the tip (mm)")
    ap.add_argument("--amplitude", type=float, default=0.5, help="the lobes' amplitude (mm)")
    ap.add_argument("--stiffness", type=float, default=1e11, help="casing stiffness per area (N/m³)")
    ap.add_argument("--campbell", action="store_true", help="also a 3-speed Campbell diagram, timed")
    ap.add_argument("--campbell-only", action="store_true")
    args = ap.parse_args()
    if not args.campbell_only:
        sweep(args.deck, args)
    if args.campbell or args.campbell_only:
        campbell(args.deck, args)


if __name__ == "__main__":
    sys.exit(main())
