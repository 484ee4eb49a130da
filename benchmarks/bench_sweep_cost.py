"""What one speed of a rotating-blade sweep costs as the FE model grows, and what a 1000-speed sweep would cost.

The model: the twisted, tapered NACA 0012 blade of ``bench_fem.py`` (``blade(size)``; P2, Ti-6Al-4V, root
clamped), mesh sizes 5.5 / 2.5 / 1.75 mm (about 5.5k / 26k / 62k dofs; ``--large`` adds 1.4 mm, about 110k),
spun about an axis along the root chord through a 0.25 m hub radius (the docs' example axis).

One speed is the task of the Campbell stage, ``bladecase.study.rotation.stage._speed_point`` with ``bands = false``:
``spin`` (the rotating stiffness ``K + K_σ − Ω² M⊥``, the static centrifugal state — ``static = "auto"``, the
study default, so one extra second-order step is tried — and the factorisation of ``K(Ω)``), then the lowest
``modes + EXTRA_MODES`` = 6 + 4 = 10 modes with that factorisation (``modes_at_speed``).  The operating point
(``operating_point``) is the same ``spin`` once.  The task's arguments are the ones ``campbell_stage`` maps
with: ``shared = {study, model, contact, axis, count, bands, sample}`` (scattered once per worker by the Dask executor)
and one speed per task.

For each size, two fresh child processes (as ``bench_fe_pipeline.py``: each one's ``ru_maxrss`` is its own):

* the *client*: mesh, assemble (timed), then the bytes the executor ships: the shared dict pickled with
  cloudpickle (once per worker), one task's function and item (per task); the shared dict is written to a
  temporary file;
* the *worker*: reads and unpickles that file (the per-worker deserialisation), runs one cold speed (it builds
  the model's rotation operators, cached for later speeds: a one-time cost per worker) and ``--repeat`` warm
  speeds (the per-speed cost, with a breakdown: factorisations, stress stiffness, eigen-solution), the pickled
  size of one result (what comes back per speed: 10 mode shapes), the client's per-speed cost of following the
  modes (``from_modes`` on two speeds), and its own peak memory.

Every figure has CPU seconds (``time.process_time``) and wall seconds (``time.perf_counter``).  The machine is
shared with other CPU-heavy jobs: the CPU seconds are what a dedicated core would take; the wall seconds say
how loaded the machine was.  The extrapolation uses CPU seconds.

Extrapolation: exponents ``p`` of ``y = a · dofs^p`` fitted (least squares in log–log) over every size measured,
and the exponent of the two largest sizes; at ``--target-dofs`` (1M) both are printed as a range for the
per-speed costs and the memory (the one-time costs, bytes and the client's link: the all-size fit only, their
figures being small and noisy). Memory is fitted above the worker's baseline after its imports. A sparse direct
factorisation of a 3-D mesh grows faster than these small sizes show (nested dissection: time ~ n², memory ~
n^4/3 asymptotically): take the upper end. A sweep of ``--speeds`` (1000) speeds on N workers (``--workers``,
8,32,128) = cluster start + per-worker set-up + ceil(speeds / N) × per-speed CPU + the client's mode following
(speeds × per-link CPU). The cluster start is one fixed figure for every N: the 2-worker LocalCluster measured
below (its start plus the first map's extra wall time over the second one, i.e. the workers' imports), or
``--cluster-start`` with ``--skip-dask``; the set-up is the transfer of the shared bytes at an ASSUMED
``--bandwidth`` of 1 GB/s, their deserialisation and the rotation operators. Serially: the operators + speeds ×
(per-speed + link). The per-speed CPU also comes with ``static = "linear"`` (no second-order iteration) for
comparison.

Sanity check (measured): the Campbell stage itself (``campbell_stage``) at 8 speeds on the 5.5k blade, serial
and on a Dask LocalCluster of 2 workers (as the tests make one): the same numbers (exactly), and the wall
times (cluster start, first and second map).  ``OPENBLAS_NUM_THREADS=1`` everywhere (as the executor's
workers).

Run (about 3–4 minutes on a loaded 2-core machine)::

    cd /work/main && .venv/bin/python benchmarks/bench_sweep_cost.py [--large] [--json FILE]
        [--workers 8,32,128] [--speeds 1000] [--repeat 2] [--skip-dask]

Exit status 0 whatever the figures.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import pickle  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from bench_core import in_child, line, machine  # noqa: E402
from bench_fe_pipeline import peak_mib  # noqa: E402

#: Mesh sizes (m) of the default blades (~5.5k, ~26k, ~62k P2 dofs) and the one ``--large`` adds (~110k).
SIZES = (0.0055, 0.0025, 0.00175)
LARGE_SIZE = 0.0014
#: The cold speed (builds the operators) and the warm speeds (the per-speed cost), rpm.
RPM_COLD, RPM_WARM = 9000.0, (10000.0, 11000.0, 12000.0)
#: Modes followed on the Campbell diagram (the study default); the task computes 4 more.
MODES = 6
#: The 8 speeds of the Dask sanity check (rpm).
CHECK_RPM = tuple(float(r) for r in range(5000, 13000, 1000))
#: Extrapolation targets.
TARGET_DOFS, SPEEDS, WORKERS, BANDWIDTH = 1_000_000, 1000, (8, 32, 128), 1e9

ROTATION = """
[rotation]
speeds = {speeds}
axis = {{ origin = [0.0, 0.0, -0.25], direction = [1.0, 0.0, 0.0] }}
modes = {modes}
bands = false
"""


class Clock:
    """CPU (``process_time``) and wall (``perf_counter``) seconds of a ``with`` block."""

    def __enter__(self) -> Clock:
        self.c0, self.w0 = time.process_time(), time.perf_counter()
        return self

    def __exit__(self, *exc) -> None:
        self.cpu, self.wall = time.process_time() - self.c0, time.perf_counter() - self.w0

    def record(self) -> dict:
        return {"cpu": self.cpu, "wall": self.wall}


def study_for(speeds_rpm):
    """The demo study with a ``[rotation]`` section (speeds, the docs' axis, no bands): its keys only are used."""
    from bladecase.study.demo import demo_text
    from bladecase.study.schema import loads

    text = demo_text() + ROTATION.format(speeds=[float(s) for s in speeds_rpm], modes=MODES)
    return loads(text, source="<bench_sweep_cost>")


def blade_model(size: float):
    """``(mesh seconds, assemble seconds, model, contact)`` of the benchmark blade."""
    from bench_fem import blade

    import bladecase

    with Clock() as t_mesh:
        mesh = blade(size)
    with Clock() as t_asm:
        model = bladecase.assemble(mesh, "Ti-6Al-4V", order=2, clamp="root")
    contact = bladecase.Contact.farthest(model, [0.0, 0.0, 1.0], None, 1e-4, group="tip")
    return t_mesh.record(), t_asm.record(), model, contact


def shared_for(study, model, contact) -> dict:
    """The ``shared`` dict ``campbell_stage`` maps ``_speed_point`` with."""
    from bladecase.fe.campbell import mac_sample
    from bladecase.study.rotation.stage import rotation_axis

    r = study["rotation"]
    return {"study": study, "model": model, "contact": contact, "axis": rotation_axis(study, model),
            "count": min(int(r.get("modes", 6)), model.n_dofs - 1), "bands": bool(r.get("bands", True)),
            "sample": mac_sample(model)[0]}


# ---------------------------------------------------------------------------
# The two child processes of one size


def run_client(size: float, path: str) -> dict:
    """Mesh, assemble, and the bytes the executor ships (the shared dict is written to ``path``)."""
    import cloudpickle

    from bladecase.fe.rotation import to_rad_s
    from bladecase.study.executor import _Logged
    from bladecase.study.rotation.stage import _speed_point

    base = peak_mib()
    t_mesh, t_asm, model, contact = blade_model(size)
    shared = shared_for(study_for([RPM_COLD, *RPM_WARM]), model, contact)
    with Clock() as t_ser:
        blob = cloudpickle.dumps(shared, protocol=5)
    Path(path).write_bytes(blob)
    task = len(cloudpickle.dumps(_Logged(_speed_point), protocol=5))
    item = len(cloudpickle.dumps(to_rad_s(RPM_COLD, "rpm"), protocol=5))
    return {"size": size, "dofs": int(model.n_dofs), "seconds": {"mesh": t_mesh, "assemble": t_asm,
            "serialise": t_ser.record()}, "shared_bytes": len(blob),
            "shared_bytes_by_key": {k: len(cloudpickle.dumps(v, protocol=5)) for k, v in shared.items()},
            "task_bytes": task + item, "baseline_MiB": base, "peak_MiB": peak_mib()}


def _instrument(acc: dict) -> None:
    """Time the parts of one speed (in this child only): operators, factorisations, stress stiffness, spin,
    eigen-solution; ``acc[name] = [cpu, wall, calls]``."""
    import bladecase.fe.campbell as campbell
    import bladecase.fe.rotation as rotation

    def wrap(owner, name: str, key: str) -> None:
        fn = getattr(owner, name)
        acc.setdefault(key, [0.0, 0.0, 0])

        def timed(*args, **kwargs):
            c0, w0 = time.process_time(), time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                a = acc[key]
                a[0] += time.process_time() - c0
                a[1] += time.perf_counter() - w0
                a[2] += 1

        setattr(owner, name, timed)

    wrap(rotation._Operators, "stress_stiffness", "stress stiffness")
    wrap(rotation, "_Operators", "operators")
    wrap(rotation, "spd_factor", "factorisations")
    wrap(rotation, "symmetric_factor", "factorisations")
    wrap(campbell, "spin", "spin")
    wrap(campbell, "lowest_modes", "eigen")


def run_worker(path: str, repeat: int) -> dict:
    """What a worker does: unpickle the shared dict, one cold speed, ``repeat`` warm ones, peak memory."""
    import cloudpickle

    from bladecase.fe.campbell import EXTRA_MODES, from_modes, modes_at_speed
    from bladecase.fe.rotation import to_rad_s
    from bladecase.linalg import factor_backend
    from bladecase.study.rotation.stage import _speed_point

    base = peak_mib()
    acc: dict = {}
    _instrument(acc)
    with Clock() as t_load:
        shared = pickle.loads(Path(path).read_bytes())
    loaded = peak_mib()

    def one(rpm: float) -> tuple[dict, dict]:
        for a in acc.values():
            a[:] = [0.0, 0.0, 0]
        with Clock() as t:
            point = _speed_point(to_rad_s(rpm, "rpm"), **shared)
        parts = {k: {"cpu": a[0], "wall": a[1], "calls": a[2]} for k, a in acc.items()}
        return point, {"rpm": rpm, "cpu": t.cpu, "wall": t.wall, "parts": parts}

    cold_point, cold = one(RPM_COLD)
    warm, points = [], [cold_point]
    for rpm in RPM_WARM[:repeat]:
        point, rec = one(rpm)
        warm.append(rec)
        points.append(point)
    from bladecase.fe.campbell import mac_sample

    model, count = shared["model"], shared["count"]
    with Clock() as t_linear:  # the same speed with the linear static state (no second-order iteration)
        modes_at_speed(model, to_rad_s(RPM_WARM[0], "rpm"), shared["axis"], count + EXTRA_MODES, static="linear")
    with Clock() as t_link:  # the client's mode following over len(points) - 1 links
        from_modes([to_rad_s(p, "rpm") for p in (RPM_COLD, *RPM_WARM[:repeat])], [p["shapes"] for p in points],
                   [p["frequencies_hz"] for p in points], mac_sample(model)[1], count)
    links = len(points) - 1
    return {"backend": factor_backend(), "baseline_MiB": base, "loaded_MiB": loaded, "peak_MiB": peak_mib(),
            "load": t_load.record(), "cold": cold, "warm": warm, "linear": t_linear.record(),
            "link": {"cpu": t_link.cpu / links, "wall": t_link.wall / links},
            "result_bytes": len(cloudpickle.dumps(points[-1], protocol=5)),
            "frequencies_hz": [[float(f) for f in p["frequencies_hz"][:MODES]] for p in points],
            "static_iterations": [p["clearance"]["static_iterations"] for p in points]}


def child(call: str) -> dict:
    """``call`` (an expression on this module, ``b``) in a fresh interpreter; its JSON result."""
    return in_child("bench_sweep_cost", call)


def measure(size: float, repeat: int) -> dict:
    with tempfile.TemporaryDirectory(prefix="bench_sweep_cost_") as tmp:
        path = str(Path(tmp) / "shared.pkl")
        client = child(f"b.run_client({size!r}, {path!r})")
        if "error" in client:
            return {"size": size, "error": "client: " + client["error"]}
        worker = child(f"b.run_worker({path!r}, {repeat!r})")
    if "error" in worker:
        return {"size": size, "dofs": client["dofs"], "error": "worker: " + worker["error"]}
    w = worker["warm"]
    per_speed = {k: float(np.mean([r[k] for r in w])) for k in ("cpu", "wall")}
    parts = {name: float(np.mean([r["parts"][name]["cpu"] for r in w])) for name in w[0]["parts"]}
    calls = {name: w[0]["parts"][name]["calls"] for name in w[0]["parts"]}
    operators = worker["cold"]["parts"]["operators"]
    return {"size": size, "dofs": client["dofs"], "client": client, "worker": worker, "per_speed": per_speed,
            "parts_cpu": parts, "calls": calls, "operators": {"cpu": operators["cpu"], "wall": operators["wall"]},
            "worker_MiB_above_baseline": worker["peak_MiB"] - worker["baseline_MiB"]}


# ---------------------------------------------------------------------------
# The Dask sanity check


def dask_check(repeat_maps: int = 2) -> dict:
    """``campbell_stage`` at 8 speeds on the 5.5k blade: serial vs a 2-worker LocalCluster."""
    from bladecase.study.executor import DaskExecutor, SerialExecutor
    from bladecase.study.rotation.stage import campbell_stage

    warnings.filterwarnings("ignore", message="Port .* is already in use")  # another job's dashboard
    _, _, model, contact = blade_model(SIZES[0])
    study = study_for(CHECK_RPM)
    with Clock() as t_serial:
        c_serial, s_serial = campbell_stage(study, model, contact, SerialExecutor())
    out = {"dofs": int(model.n_dofs), "speeds": len(CHECK_RPM), "serial": t_serial.record(), "maps": []}
    ex = DaskExecutor(workers=2)
    try:
        with Clock() as t_start:
            _ = ex.client  # starts the LocalCluster
        out["start"] = t_start.record()
        same = True
        diff = 0.0
        for _ in range(repeat_maps):
            with Clock() as t_map:
                c_dask, s_dask = campbell_stage(study, model, contact, ex)
            out["maps"].append(t_map.record())
            same &= json.dumps(s_dask, sort_keys=True, default=str) == json.dumps(s_serial, sort_keys=True,
                                                                                  default=str)
            same &= bool(np.array_equal(c_dask.frequencies, c_serial.frequencies))
            diff = max(diff, float(np.max(np.abs(c_dask.frequencies / c_serial.frequencies - 1))))
    finally:
        ex.close()
    out.update(same=same, max_relative_difference=diff, f1_hz=[float(f) for f in c_serial.frequencies[:, 0]])
    return out


# ---------------------------------------------------------------------------
# Fits and the report


def fit(x, y) -> tuple[float, float, float]:
    """``(p, a, p_last)``: ``y ≈ a x^p`` over all points (log–log least squares) and the last pair's exponent."""
    lx, ly = np.log(np.asarray(x, float)), np.log(np.maximum(np.asarray(y, float), 1e-12))
    p, la = np.polyfit(lx, ly, 1)
    p_last = (ly[-1] - ly[-2]) / (lx[-1] - lx[-2])
    return float(p), float(math.exp(la)), float(p_last)


def extrapolate(x, y, target: float, last: bool = True) -> dict:
    """``y`` at ``target`` by the all-point fit and (``last``) by the last pair, from the largest measured point."""
    p, a, p_last = fit(x, y)
    by_fit = a * target**p
    by_last = y[-1] * (target / x[-1]) ** p_last if last else by_fit
    return {"p": p, "p_last": p_last, "fit": by_fit, "last": by_last, "lo": min(by_fit, by_last),
            "hi": max(by_fit, by_last)}


def fmt_range(e: dict, scale: float = 1.0, digits: int = 3) -> str:
    lo, hi = e["lo"] / scale, e["hi"] / scale
    return f"{lo:.{digits}g}" if abs(hi / lo - 1) < 0.05 else f"{lo:.{digits}g}–{hi:.{digits}g}"


def span(lo: float, hi: float, fmt) -> str:
    """``fmt(lo)–fmt(hi)``, or ``fmt(lo)`` when both print the same."""
    a, b = fmt(lo), fmt(hi)
    return a if a == b else f"{a}–{b}"


def hms(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.1f} min"
    return f"{seconds / 3600:.1f} h"


def report(runs: list[dict], check: dict | None, args) -> dict:
    ok = [r for r in runs if "error" not in r]
    out: dict = {}
    print("\nPer size (CPU s = process_time, wall s = perf_counter; per speed: mean of the warm speeds)")
    head = (f"  {'dofs':>8} {'mesh+asm':>9} {'deser.':>7} {'operators':>9} {'speed CPU':>9} {'speed wall':>10} "
            f"{'linear':>6} {'factor':>7} {'K_σ':>6} {'eigen':>6} {'link':>6} {'worker MiB':>10} {'shared MB':>9} "
            f"{'task B':>6} {'result MB':>9}")
    print(head)
    for r in runs:
        if "error" in r:
            print(f"  size {r['size']:g} m: {r['error']}")
            continue
        c, w, p = r["client"], r["worker"], r["parts_cpu"]
        print(f"  {r['dofs']:>8} {c['seconds']['mesh']['cpu'] + c['seconds']['assemble']['cpu']:>9.2f} "
              f"{w['load']['cpu']:>7.2f} {r['operators']['cpu']:>9.2f} {r['per_speed']['cpu']:>9.2f} "
              f"{r['per_speed']['wall']:>10.2f} {w['linear']['cpu']:>6.2f} {p.get('factorisations', 0):>7.2f} "
              f"{p.get('stress stiffness', 0):>6.2f} "
              f"{p.get('eigen', 0):>6.2f} {w['link']['cpu']:>6.3f} {w['peak_MiB']:>10.0f} "
              f"{c['shared_bytes'] / 1e6:>9.1f} {c['task_bytes']:>6} {w['result_bytes'] / 1e6:>9.2f}")
    if ok:
        r0 = ok[-1]
        print(f"  (backend {r0['worker']['backend']}; per speed {r0['calls'].get('factorisations', 0)} "
              f"factorisations, {r0['calls'].get('stress stiffness', 0)} stress stiffnesses, 10 modes; worker "
              f"baseline after imports {r0['worker']['baseline_MiB']:.0f} MiB; static = 'auto': second-order "
              f"iterations per speed {r0['worker']['static_iterations']}; f1 at {RPM_WARM[0]:g} rpm "
              f"{r0['worker']['frequencies_hz'][1][0]:.2f} Hz)")
    if len(ok) < 2:
        print("\nfewer than two sizes measured: no extrapolation")
        return out
    x = [r["dofs"] for r in ok]
    N = args.target_dofs
    q = {
        "per_speed_cpu": [r["per_speed"]["cpu"] for r in ok],
        "per_speed_wall": [r["per_speed"]["wall"] for r in ok],
        "per_speed_linear_cpu": [r["worker"]["linear"]["cpu"] for r in ok],
        "worker_MiB_above_baseline": [r["worker_MiB_above_baseline"] for r in ok],
        "shared_bytes": [r["client"]["shared_bytes"] for r in ok],
        "result_bytes": [r["worker"]["result_bytes"] for r in ok],
        "deserialise_cpu": [r["worker"]["load"]["cpu"] for r in ok],
        "operators_cpu": [r["operators"]["cpu"] for r in ok],
        "link_cpu": [r["worker"]["link"]["cpu"] for r in ok],
        "assemble_cpu": [r["client"]["seconds"]["assemble"]["cpu"] for r in ok],
    }
    # the range (all sizes / last pair) for the per-speed costs and the memory; the small one-time costs, the bytes
    # and the link: the all-size fit only (their last-pair exponent is noise on a loaded machine)
    ranged = ("per_speed_cpu", "per_speed_wall", "per_speed_linear_cpu", "worker_MiB_above_baseline")
    ex = {k: extrapolate(x, v, N, last=k in ranged) for k, v in q.items()}
    from bladecase.fe.campbell import MAC_DOFS

    if x[-1] > MAC_DOFS:  # the shapes come back on MAC_DOFS dofs whatever the model: the result does not grow
        flat = q["result_bytes"][-1]
        ex["result_bytes"].update(p=0.0, p_last=0.0, lo=flat, hi=flat, fit=flat, last=flat)
    base = ok[-1]["worker"]["baseline_MiB"]
    out["exponents"] = {k: {"all_sizes": e["p"], "last_pair": e["p_last"]} for k, e in ex.items()}
    out["at_target"] = {k: {"fit": e["fit"], "last_pair": e["last"]} for k, e in ex.items()}
    print(f"\nExponents p of y ~ dofs^p (all {len(ok)} sizes / the two largest) and the value at {N:,} dofs "
          "(EXTRAPOLATED: the range of the two for the "
          "per-speed costs and the memory, the all-size fit for the rest)")
    for k, e in ex.items():
        print(f"  {k:<28} p = {e['p']:5.2f} / {e['p_last']:5.2f}   at {N:,}: {fmt_range(e)}")

    last = ok[-1]
    big = f"{last['dofs'] / 1e3:.1f}k"
    setup_m = last["worker"]["load"]["cpu"] + last["operators"]["cpu"] + last["client"]["shared_bytes"] / args.bandwidth
    setup_lo = ex["deserialise_cpu"]["lo"] + ex["operators_cpu"]["lo"] + ex["shared_bytes"]["lo"] / args.bandwidth
    setup_hi = ex["deserialise_cpu"]["hi"] + ex["operators_cpu"]["hi"] + ex["shared_bytes"]["hi"] / args.bandwidth
    mem_m = last["worker"]["peak_MiB"] / 1024
    mem_lo, mem_hi = (base + ex["worker_MiB_above_baseline"]["lo"]) / 1024, \
        (base + ex["worker_MiB_above_baseline"]["hi"]) / 1024
    print(f"\nOne speed: {big} dofs MEASURED, {N:,} dofs EXTRAPOLATED (CPU seconds of one core)")
    line("per-speed CPU", f"{last['per_speed']['cpu']:.2f} s  |  {fmt_range(ex['per_speed_cpu'])} s")
    line("  with static = 'linear'", f"{last['worker']['linear']['cpu']:.2f} s  |  "
         f"{fmt_range(ex['per_speed_linear_cpu'])} s")
    line("worker peak memory", f"{mem_m:.2f} GiB  |  {span(mem_lo, mem_hi, lambda v: f'{v:.1f}')} GiB")
    line("shared data per worker (pickled)", f"{last['client']['shared_bytes'] / 1e6:.0f} MB  |  "
         f"{fmt_range(ex['shared_bytes'], 1e9)} GB")
    line("per task sent / result returned", f"{last['client']['task_bytes']} B / "
         f"{last['worker']['result_bytes'] / 1e6:.1f} MB  |  {last['client']['task_bytes']} B / "
         f"{fmt_range(ex['result_bytes'], 1e6)} MB")
    setup_range = span(setup_lo, setup_hi, lambda v: f"{v:.0f}")
    line("one-time per worker (deser. + operators + transfer)", f"{setup_m:.1f} s  |  {setup_range} s"
         f"  (transfer at an ASSUMED {args.bandwidth / 1e9:g} GB/s)")
    line("  or ship the mesh, assemble on the worker", f"{q['assemble_cpu'][-1]:.1f} s  |  "
         f"{fmt_range(ex['assemble_cpu'])} s")
    line("client: following the modes, per speed", f"{last['worker']['link']['cpu']:.3f} s  |  "
         f"{fmt_range(ex['link_cpu'])} s")

    measured = bool(check and "start" in check)
    if measured:  # the cluster start and the first map's extra time (the workers import bladecase)
        maps = check["maps"]
        start = check["start"]["wall"] + (max(maps[0]["wall"] - maps[-1]["wall"], 0.0) if len(maps) > 1 else 0.0)
    else:
        start = args.cluster_start
    S = args.speeds
    rows = []
    where = ("the 2-worker LocalCluster measured above: its start + first map − second map" if measured
             else "a fixed figure, --cluster-start")
    print(f"\nA {S}-speed Campbell sweep (modes only, bands = false): {big} dofs from MEASURED per-speed CPU, "
          f"{N:,} dofs EXTRAPOLATED; cluster start {start:.1f} s ({where})")
    print(f"  {'executor':<14} {'speeds/worker':>13} {big + ' wall':>12} {'1M wall':>18} {'memory per worker':>18} "
          f"{'results at client':>18}")
    link_m, link_lo, link_hi = last["worker"]["link"]["cpu"] * S, ex["link_cpu"]["lo"] * S, ex["link_cpu"]["hi"] * S
    res_m, res_lo, res_hi = (last["worker"]["result_bytes"] * S / 1e9, ex["result_bytes"]["lo"] * S / 1e9,
                             ex["result_bytes"]["hi"] * S / 1e9)
    t_m, t_lo, t_hi = last["per_speed"]["cpu"], ex["per_speed_cpu"]["lo"], ex["per_speed_cpu"]["hi"]
    for n in (1, *args.workers):
        k = math.ceil(S / n)
        if n == 1:
            name = "serial"
            wall_m = last["operators"]["cpu"] + S * t_m + link_m
            wall_lo = ex["operators_cpu"]["lo"] + S * t_lo + link_lo
            wall_hi = ex["operators_cpu"]["hi"] + S * t_hi + link_hi
        else:
            name = f"dask {n} workers"
            wall_m = start + setup_m + k * t_m + link_m
            wall_lo = start + setup_lo + k * t_lo + link_lo
            wall_hi = start + setup_hi + k * t_hi + link_hi
        rows.append({"workers": n, "speeds_per_worker": k, "wall_measured_size_s": wall_m,
                     "wall_target_s": [wall_lo, wall_hi], "worker_GiB": [mem_m, mem_lo, mem_hi]})
        mem = f"{mem_m:.1f} | {span(mem_lo, mem_hi, lambda v: f'{v:.0f}')} GiB"
        res = f"{res_m:.1f} | {span(res_lo, res_hi, lambda v: f'{v:.0f}')} GB"
        print(f"  {name:<14} {k:>13} {hms(wall_m):>12} {span(wall_lo, wall_hi, hms):>18} {mem:>18} {res:>18}")
    print("  (memory per worker and results at the client: measured size | 1M extrapolated; the client keeps every "
          "speed's mode shapes for the MAC tracking, on at most MAC_DOFS dofs)")
    out.update(sweep=rows, cluster_start_s=start, target_dofs=N, speeds=S, bandwidth_Bps=args.bandwidth,
               measured_dofs=last["dofs"], per_worker_setup_s={"measured": setup_m, "target": [setup_lo, setup_hi]})
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--large", action="store_true", help="also the 1.4 mm blade (~110k dofs)")
    parser.add_argument("--sizes", default=None, help="mesh sizes in m, comma-separated (overrides the default)")
    parser.add_argument("--workers", default=",".join(map(str, WORKERS)),
                        help="Dask worker counts of the sweep table (default 8,32,128)")
    parser.add_argument("--speeds", type=int, default=SPEEDS, help="speeds of the extrapolated sweep (1000)")
    parser.add_argument("--target-dofs", type=int, default=TARGET_DOFS, help="extrapolation size (1000000)")
    parser.add_argument("--repeat", type=int, default=2, choices=(1, 2, 3), help="warm speeds per size (2)")
    parser.add_argument("--bandwidth", type=float, default=BANDWIDTH,
                        help="ASSUMED bytes/s of the transfer to a worker (1e9)")
    parser.add_argument("--cluster-start", type=float, default=2.0,
                        help="cluster start (s) used with --skip-dask (default 2.0, docs/performance.md)")
    parser.add_argument("--skip-dask", action="store_true", help="leave out the Dask sanity check")
    parser.add_argument("--json", metavar="FILE", type=Path, help="also write every figure to FILE (JSON)")
    args = parser.parse_args(argv)
    args.workers = [int(w) for w in args.workers.split(",") if w.strip()]
    sizes = [float(s) for s in args.sizes.split(",")] if args.sizes else [*SIZES, *([LARGE_SIZE] if args.large else [])]

    print("bladecase sweep cost: one speed of the Campbell stage vs FE size, and a 1000-speed sweep extrapolated")
    info: dict = {"machine": machine(), "sizes": sizes, "rpm_cold": RPM_COLD, "rpm_warm": RPM_WARM[:args.repeat]}
    t0 = time.perf_counter()
    runs = []
    for size in sizes:
        r = measure(size, args.repeat)
        runs.append(r)
        print(f"  size {size:g} m: " + (r["error"] if "error" in r else
              f"{r['dofs']} dofs, per speed {r['per_speed']['cpu']:.2f} s CPU / {r['per_speed']['wall']:.2f} s wall,"
              f" worker peak {r['worker']['peak_MiB']:.0f} MiB"), flush=True)
    info["runs"] = runs
    check = None
    if not args.skip_dask:
        try:
            check = dask_check()
        except Exception as exc:  # no distributed, a cluster that does not start: report, go on
            check = {"error": f"{type(exc).__name__}: {exc}"}
        info["dask_check"] = check
        print(f"\nDask sanity check: campbell_stage, {len(CHECK_RPM)} speeds, 5.5k blade, serial vs LocalCluster(2)")
        if "error" in check:
            print(f"  failed: {check['error']}")
            check = None
        else:
            line("dofs / speeds", f"{check['dofs']} / {check['speeds']}")
            line("serial (wall / CPU)", f"{check['serial']['wall']:.2f} s / {check['serial']['cpu']:.2f} s")
            line("cluster start (wall)", f"{check['start']['wall']:.2f} s")
            for i, m in enumerate(check["maps"]):
                line(f"dask map {i + 1} (wall; client CPU)", f"{m['wall']:.2f} s; {m['cpu']:.2f} s  "
                     f"({check['serial']['wall'] / m['wall']:.2f}x serial)")
            line("start + first map vs serial", f"{check['start']['wall'] + check['maps'][0]['wall']:.2f} s vs "
                 f"{check['serial']['wall']:.2f} s")
            line("same numbers as serial (exact)", f"{check['same']} (max relative frequency difference "
                 f"{check['max_relative_difference']:.1e})")
    info["extrapolation"] = report(runs, check, args)
    print("\nRub sweep (quoted from docs/performance.md, bench_rub.py; not re-run): 50 speeds of the demo blade, "
          "26 tip nodes, 40 revolutions each, 2 local processes: 86.6 s, i.e. about 3.5 s of worker time per speed")
    print(f"\ntotal benchmark time {time.perf_counter() - t0:.0f} s; load average at the end "
          f"{os.getloadavg()[0]:.2f}")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(info, indent=1, default=str))
    return 0


if __name__ == "__main__":
    sys.exit(main())
