"""Mistuning of a 24-blade lumped disk: 1000 random samples through Dask, their amplification factor against
Whitehead's bound ½(1 + √N), and the worst mistuning pattern found by optimisation (at the samples' damping and at
a lighter one).

The disk: a disk mass on a ground spring, a blade mass on it, neighbouring disk masses coupled (``lumped_disk``'s
defaults), the blade family's subset-of-nominal-modes model (24 modes), engine order 3 on each blade's mass, modal
damping ratio ``zeta``; each sample's largest blade amplitude over the family's band (801 frequencies, peaks
refined) divided by the tuned disk's.

    python benchmarks/bench_mistuning.py                       # 1000 samples, std 0.5 %, 2 Dask workers
    python benchmarks/bench_mistuning.py --samples 200 --workers 1 --figure amplification.png
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from bladecase.post.disk.mistuning_plot import amplification_figure
from bladecase.reduction.mistuning import lumped_disk, mistuning_model
from bladecase.reduction.mistuning_stats import mistuning_statistics, worst_mistuning
from bladecase.study.executor import make_executor


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sectors", type=int, default=24, help="blades")
    parser.add_argument("--samples", type=int, default=1000, help="random mistuning samples")
    parser.add_argument("--std", type=float, default=0.005, help="standard deviation of the blade stiffness")
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--order", type=int, default=3, help="engine order")
    parser.add_argument("--zeta", type=float, default=0.001, help="modal damping ratio")
    parser.add_argument("--workers", type=int, default=2, help="Dask workers (1: serial)")
    parser.add_argument("--limit", type=float, default=0.02, help="the worst pattern's largest |δ|")
    parser.add_argument("--worst-zeta", type=float, default=1e-4, help="a lighter damping for the worst pattern")
    parser.add_argument("--figure", default=None, help="write the histogram there (png)")
    args = parser.parse_args()
    forcing = {"zeta": args.zeta, "force": 1, "response": 1}
    start = time.perf_counter()
    model = mistuning_model(*lumped_disk(args.sectors))
    print(f"model: {model.size} modes, family {model.frequencies.min():.5f} … {model.frequencies.max():.5f} Hz, "
          f"{time.perf_counter() - start:.2f} s")
    executor = make_executor("dask" if args.workers > 1 else "serial", workers=args.workers)
    start = time.perf_counter()
    try:
        stats = mistuning_statistics(model, args.order, std=args.std, samples=args.samples, seed=args.seed,
                                     executor=executor, **forcing)
    finally:
        close = getattr(executor, "close", None)
        if close:
            close()
    seconds = time.perf_counter() - start
    s = stats.summary()
    print(f"{s['samples']} samples, std {args.std:g}, EO {args.order}, zeta {args.zeta:g}, {executor!r}: "
          f"{seconds:.1f} s ({1e3 * seconds / s['samples']:.1f} ms a sample)")
    print("amplification: mean {:.4f}, ".format(s["mean"])
          + ", ".join(f"{k} {v:.4f}" for k, v in s["percentiles"].items()))
    over = int(np.sum(stats.factors > stats.bound))
    print(f"largest {s['largest']:.4f} (sample {s['largest_sample']}, blade {s['largest_blade']}); Whitehead's "
          f"bound ½(1 + √{args.sectors}) = {stats.bound:.4f}; samples above it: {over}")
    worst = 0.0
    for zeta in (args.zeta, args.worst_zeta):
        start = time.perf_counter()
        delta, factor = worst_mistuning(model, args.order, limit=args.limit, starts=1, **{**forcing, "zeta": zeta})
        worst = max(worst, factor)
        print(f"worst pattern within |δ| <= {args.limit:g}, zeta {zeta:g}: amplification {factor:.4f} "
              f"({factor / stats.bound:.1%} of the bound), {time.perf_counter() - start:.1f} s")
    if args.figure:
        amplification_figure(stats).savefig(args.figure, dpi=120)
        print(f"histogram: {args.figure}")
    if over or worst > stats.bound:
        raise SystemExit("an amplification factor exceeds Whitehead's bound")


if __name__ == "__main__":
    main()
