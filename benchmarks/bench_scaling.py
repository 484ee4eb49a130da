"""How the cost of each solver stage grows: measured points and fitted exponents.

Every figure is the CPU time of this process (``time.process_time``, ``OPENBLAS_NUM_THREADS=1``), so a loaded
machine changes it less than the wall time.  The cost of a stage is fitted as ``t = c · x^p`` by least squares
in log–log over the measured points; the table prints the points, ``p`` and what the fit predicts one step
beyond the largest point.  Stages (all on ``chain(n, k=1, m=1/n, gap=1)`` unless said):

* ``search k=1 vs n``: ``nonsmooth_mode(system, 1, [0.9, 0.9999]·T₁)`` for n = 10 … 160;
* ``search k=2 vs n``: the 2-ipp families, n = 10, 20, 40 (``--big`` adds 80);
* ``search k=2 vs range``: n = 10, periods ``[1 - w, 0.9999]·T₁`` for w = 0.05 … 0.4 (the number of resonances
  crossed grows with the range);
* ``search vs k``: n = 5, k = 1, 2, 3 with scan = 6 (k >= 3 uses the grid start search, whose cells grow as
  ``resolution^(k-1)``): fitted as a growth factor per impact, ``t = c · g^k``;
* ``simulate per impact vs n``: ``simulate`` from a 1-ipp orbit over 200 periods, seconds per impact;
* ``orbit state vs n``: ``orbit.state`` at 1000 instants, seconds per state (2n coordinates).

Run: ``.venv/bin/python benchmarks/bench_scaling.py [--big] [--json FILE]`` (about 2 minutes; ``--big`` 4).
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402

import numpy as np  # noqa: E402

import bladecase as bc  # noqa: E402


def _cpu(fn, repeat: int = 1) -> float:
    best = np.inf
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        best = min(best, time.process_time() - t0)
    return best


def _chain(n: int):
    return bc.chain(n, k=1.0, m=1.0 / n, gap=1.0)


def _T1(system) -> float:
    return float(2 * np.pi / system.spectrum.omega[0])


def _search(n: int, k: int, lo: float = 0.9, scan: int = 24):
    s = _chain(n)
    T1 = _T1(s)
    return lambda: bc.nonsmooth_mode(s, k, (lo * T1, 0.9999 * T1), scan=scan, progress=False)


def _simulate_per_impact(n: int) -> float:
    s = _chain(n)
    o = bc.orbit_1ipp(s, 0.97 * _T1(s))
    x0, v0 = (z[:, 0] for z in o.state(0.0))
    out = {}

    def go():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            out["tr"] = bc.simulate(s, x0, v0, 200 * o.T)

    t = _cpu(go)
    return t / max(out["tr"].impact_times.size, 1)


def _state_per_instant(n: int) -> float:
    s = _chain(n)
    o = bc.orbit_1ipp(s, 0.97 * _T1(s))
    t = np.linspace(0, o.T, 1000)
    return _cpu(lambda: o.state(t), repeat=3) / t.size


def fit(x, t) -> tuple[float, float]:
    """``(p, c)`` of ``t = c x^p`` by least squares in log–log."""
    p, logc = np.polyfit(np.log(np.asarray(x, float)), np.log(np.maximum(np.asarray(t, float), 1e-9)), 1)
    return float(p), float(np.exp(logc))


def stages(big: bool) -> list[dict]:
    """Every stage: ``{"stage", "variable", "x", "seconds"}``."""
    cases = [
        ("search k=1 vs n", "n", [10, 20, 40, 80, 160], lambda n: _cpu(_search(n, 1))),
        ("search k=2 vs n", "n", [10, 20, 40, 80] if big else [10, 20, 40], lambda n: _cpu(_search(n, 2))),
        ("search k=2 vs range", "w (× T₁)", [0.05, 0.1, 0.2, 0.4], lambda w: _cpu(_search(10, 2, 1 - w))),
        ("search vs k (n = 5)", "k", [1, 2, 3], lambda k: _cpu(_search(5, k, scan=6))),
        ("simulate per impact vs n", "n", [10, 100, 1000], _simulate_per_impact),
        ("orbit state vs n", "n", [10, 100, 1000, 4000], _state_per_instant),
    ]
    out = []
    for name, var, xs, fn in cases:
        seconds = []
        for x in xs:
            seconds.append(fn(x))
            print(f"  {name}: {var} = {x}: {seconds[-1]:.4g} s", flush=True)
        out.append({"stage": name, "variable": var, "x": xs, "seconds": seconds})
    return out


def table(rows: list[dict]) -> str:
    lines = ["| stage | variable | measured (CPU s) | exponent p | next point predicted |", "|---|---|---|---|---|"]
    for r in rows:
        pts = ", ".join(f"{x}: {t:.3g}" for x, t in zip(r["x"], r["seconds"]))
        if r["variable"] == "k":  # exponential in k: the k >= 3 start grid has resolution^(k-1) cells
            g, c = fit(np.exp(r["x"][1:]), r["seconds"][1:])  # t = c e^{pk} = c g^k from k = 2 on
            nxt = r["x"][-1] + 1
            lines.append(f"| {r['stage']} | {r['variable']} | {pts} | × {np.exp(g):.3g} per impact | "
                         f"{nxt}: {c * np.exp(g * nxt):.3g} s |")
            continue
        p, c = fit(r["x"], r["seconds"])
        nxt = r["x"][-1] * 2
        lines.append(f"| {r['stage']} | {r['variable']} | {pts} | {p:.2f} | {nxt}: {c * nxt ** p:.3g} s |")
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--big", action="store_true", help="add the n = 40 2-ipp search (~2 more minutes)")
    ap.add_argument("--json", help="write the measured points as JSON")
    args = ap.parse_args(argv)
    print(f"bench_scaling: CPU seconds, OPENBLAS_NUM_THREADS={os.environ['OPENBLAS_NUM_THREADS']}, "
          f"load average {os.getloadavg()[0]:.2f}")
    rows = stages(args.big)
    print(table(rows))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(rows, fh, indent=1)


if __name__ == "__main__":
    main()
