"""The study executors on a 16-point grid: serial vs local processes vs a Dask LocalCluster.

Tasks (``--task``):

* ``forced`` (default) — the forced response of the seed paper's 2-dof chain (``chain(2, k=1, m=0.5, gap=1)``,
  ``C = 0.05 K``, ``F₀ = 0.6``) at ``--points`` forcing periods evenly spaced in ``[4.0, 6.4]``, ``--n-periods``
  forcing periods each (the paper's 500): ``forced_point`` mapped with ``keyword_task(forced_point, "T")``, the
  system and the forcing sent once per worker (``shared``);
* ``modes`` — the 2-ipp nonsmooth modes of ``--points`` chains ``chain(n, k=1, m=1/n, gap=1)``,
  ``n = 3, 4, …``, in ``T ∈ [0.9, 0.9999]·T₁`` (a comparison grid of models: one search per model).

Printed: the wall time of the serial map; of ``ProcessExecutor(workers)`` (its pool is spawned by the map, so
the start-up of the processes is included); of ``DaskExecutor(workers=…)`` — the cluster start-up, the first
map (the workers import bladecase) and a second, warm map; the speed-ups over serial; and whether every executor
gave the same numbers (exactly).  The CPU seconds the tasks took in their workers (summed) are printed too:
on a loaded machine the wall times mostly measure the other processes, the CPU sums still compare the work.
``OPENBLAS_NUM_THREADS=1`` is set here (and in every worker).

Run::

    .venv/bin/python benchmarks/bench_executor.py                 # forced, 16 points, 2 workers
    .venv/bin/python benchmarks/bench_executor.py --task modes --workers 2 --json /tmp/bench_executor.json

On a 2-core machine the ideal speed-up with 2 workers is 2; the figures depend on the load of the machine
(the load average is printed).
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from bladecase.nsm import Damping, chain, forced_point, nonsmooth_mode  # noqa: E402
from bladecase.study.executor import DaskExecutor, ProcessExecutor, SerialExecutor, keyword_task  # noqa: E402


def grid(task: str, points: int, n_periods: int) -> tuple:
    """``(fn, items, shared, fingerprint)`` of the benchmark's grid."""
    if task == "forced":
        shared = {"system": chain(2, k=1.0, m=0.5, gap=1.0), "damping": Damping(alpha=0.05), "amplitude": 0.6,
                  "n_periods": n_periods}
        periods = np.linspace(4.0, 6.4, points).tolist()

        def fingerprint(pts):
            return [(p.T, p.label, p.energy, p.x_end.tolist(), p.v_end.tolist()) for p in pts]

        return keyword_task(forced_point, "T"), periods, shared, fingerprint
    if task == "modes":
        systems = [chain(n, k=1.0, m=1.0 / n, gap=1.0) for n in range(3, 3 + points)]
        T1 = [2 * np.pi / s.spectrum.omega[0] for s in systems]
        items = [(s, (0.9 * t, 0.9999 * t)) for s, t in zip(systems, T1)]

        def fingerprint(found):
            return [[[(o.T if o is not None else None) for o in b.orbits] for b in fams] for fams in found]

        return _modes, items, {"k": 2}, fingerprint
    raise ValueError(f"--task must be 'forced' or 'modes', got {task!r}")


def _modes(item, k):
    system, T_range = item
    return nonsmooth_mode(system, k, T_range)


class CpuTimed:
    """``fn`` returning ``(result, CPU seconds of the task in its worker)``."""

    def __init__(self, fn):
        self.fn = fn

    def __call__(self, item, **shared):
        t0 = time.process_time()
        out = self.fn(item, **shared)
        return out, time.process_time() - t0


def timed(fn):
    """``(results, task CPU seconds summed, wall seconds)`` of a map returning ``CpuTimed`` pairs."""
    t0 = time.perf_counter()
    out = fn()
    wall = time.perf_counter() - t0
    return ([r for r, _ in out], sum(c for _, c in out), wall) if isinstance(out, list) else (out, 0.0, wall)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--task", choices=["forced", "modes"], default="forced")
    ap.add_argument("--points", type=int, default=16)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--n-periods", type=int, default=500)
    ap.add_argument("--json", metavar="FILE", help="also write the figures as JSON")
    args = ap.parse_args()
    fn, items, shared, fingerprint = grid(args.task, args.points, args.n_periods)
    fn = CpuTimed(fn)
    print(f"bench_executor: task {args.task}, {len(items)} points, {args.workers} workers; {platform.platform()}, "
          f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f}")
    serial, c_serial, t_serial = timed(lambda: SerialExecutor().map(fn, items, shared=shared))
    procs, c_procs, t_procs = timed(lambda: ProcessExecutor(args.workers).map(fn, items, shared=shared))
    ex = DaskExecutor(workers=args.workers)
    _, _, t_start = timed(lambda: ex.client)
    dask1, c_dask1, t_dask1 = timed(lambda: ex.map(fn, items, shared=shared))
    dask2, c_dask2, t_dask2 = timed(lambda: ex.map(fn, items, shared=shared))
    ex.close()
    same = fingerprint(serial) == fingerprint(procs) == fingerprint(dask1) == fingerprint(dask2)
    rows = [("serial", t_serial, c_serial), (f"processes ({args.workers}, pool start included)", t_procs, c_procs),
            (f"dask LocalCluster start ({args.workers} workers)", t_start, None), ("dask first map", t_dask1, c_dask1),
            ("dask warm map", t_dask2, c_dask2), ("dask start + first map", t_start + t_dask1, None)]
    print(f"  {'':<44} {'wall':>8}   {'speed-up':>8}   {'task CPU':>8}")
    for name, t, cpu in rows:
        speed = "" if "start (" in name else f"{t_serial / t:7.2f}x"
        print(f"  {name:<44} {t:7.2f}s   {speed:>8}   " + ("" if cpu is None else f"{cpu:7.2f}s"))
    print(f"  same results from every executor (exact): {same}; load average at the end "
          f"{os.getloadavg()[0]:.2f}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"task": args.task, "points": len(items), "workers": args.workers,
                       "wall_s": {name: t for name, t, _ in rows}, "task_cpu_s": {name: c for name, _, c in rows},
                       "same": same, "load_average": os.getloadavg()[0]}, fh, indent=1)


if __name__ == "__main__":
    main()
