"""The 2-ipp family search (issue 14): chain n = 10/20/50 and the demo blade's reduced model, timed, fingerprinted.

Cases (each ``bladecase.nonsmooth_mode(system, 2, T_range)`` with the defaults the caller uses):

* ``chainN`` — ``chain(N, k=1, m=1/N, gap=1)``, ``T ∈ [0.9, 0.9999]·T₁`` (``T₁ = 2π/ω₁``; the default study's
  range: the issue's family counts 16/65/361 for N = 10/20/50 come from it), default options;
* ``demoS`` — the 2-ipp search of the demo study as issue 14 timed it (Newton contact on the tip node, the
  one-node mesh group ``contact``, clearance 0.1 mm; ``[search]`` scan = 6, step = 0.01, max_points = 400,
  ``T ∈ [0.9, 0.9999]·T₁``; these are pinned here, whatever the demo study says now) on the demo blade (its
  geometry, material and FE settings) reduced by lanczos-si to size ``S`` (``demo8`` is that demo).  The
  reduced model is cached as ``.npz`` in ``--cache`` (default: the temporary directory): the FE model is built
  once.

For each case: the median wall time and CPU time of ``--repeat`` runs (``OPENBLAS_NUM_THREADS=1`` is set here),
the number of families, of families with arcs, of arcs, and a fingerprint: the sorted arcs ``(T_lo/T₁, T_hi/T₁)``
rounded to 1e-8 plus each family's period span.  ``--save FILE`` writes figures and fingerprints as JSON;
``--compare FILE`` reads such a file (e.g. made by the code before a change) and prints the speed-up ratios,
whether the families and arcs are the same (arc ends within ``--rtol`` relative, default 1e-8) and whether the
sets of distinct arcs are.  ``--raw`` switches off the geometric de-duplication of the search (issue 15: a family
whose orbits lie on another is dropped, a stretch traced twice is listed once), to compare the rest with code
that has none.

Run the baseline from a copy of the old package, then compare::

    PYTHONPATH=/tmp/bc_baseline .venv/bin/python benchmarks/bench_search.py --save /tmp/before.json
    .venv/bin/python benchmarks/bench_search.py --compare /tmp/before.json

``--cases chain10,demo8`` picks cases; ``--profile CASE`` prints a cProfile of one run of that case instead.
All cases take about 3 minutes with the fast search (the search before issue 14 needs hours for demo16/demo32:
compare those with a copy that has only the start-coverage lookup, or skip them with ``--cases``).

Figures (CPU s, one core, median of 3; demo16/32 one run; load average about 2) before -> after the vectorised
certification and arc ends (``make_orbits``, ``bisect_ends``), uncertified starts and a wider trace window:
chain10 2.1 -> 1.6, chain20 7.5 -> 4.2, chain50 20.3 -> 9.6, demo8 2.65 -> 2.1, demo16 19.3 -> 12.5,
demo32 84 -> 82; the same families and arcs, but for demo16's one arc: its upper end, unrefined either way, is
a certified orbit 4e-6 T1 further (a near-grazing end, Λ ≈ 4e-6 d, where one fixed-period Newton solve of the
bisection passes its 1e-9 d residual test only in the stacked evaluation).  Then the coverage lookup of all
crossings of a period at once (the same families and arcs; gain within the machine's noise). Half-angle sines in
the batched kernel sums (chain50 median 11.5 -> 9.8, demo32 84 -> 78) were not kept: one chain50 family longer
(0.9276 -> 0.9307 T1, the corrector's 1e-10 residual test at a point whose round-off floor is 6.6e-10) and
demo32 one family fewer; docs/performance.md has the analysis.  Third pass: the corrector's round-off floor
(a fix: chain50 356 -> 371 arcs, none lost), then those half-angle sines (identical families under it),
then k = 2 fixed-period solves by the scalar equation (``solve_pairs``): interleaved, chain50 12.2 -> 9.9,
demo8 3.08 -> 2.11, demo32 92 -> 50 (loaded machine).  Fourth pass (families, spans and arcs identical):
stacked matches in the de-duplication, the corrector's closed-form 3×2 least squares for big stacks, the arc-end
probe; medians of 5 interleaved runs chain20 4.75 -> 3.99, chain50 9.60 -> 8.41, demo8 2.23 -> 1.98.  Fifth
pass (every orbit and arc bit for bit the same, k = 2, 3, 4): the trace's kernel terms in a scratch space reused
from evaluation to evaluation (fresh temporaries of a few hundred kB took ~620 000 page faults in a fresh process),
the first corrector evaluation shared by the chord and the Newton retry, full Newton's Jacobian at its converged
points kept, no last evaluation for rows that can no longer converge, the chord's pseudo-inverse kept while a step
is halved; certification by ``newton.certify`` (the grid's powers of a batch of flights at once in reused memory,
a flight whose grid shows a violation finished there: polished orbits' certification 3x cheaper); vectorised
acceptance and records of the polished orbits, k = 2 canonical rotations in scalar arithmetic.  CPU medians of 3
(load 2-3.5, ``--cases chain10,chain20,chain50,demo8``, interleaved): chain10 1.31 -> 1.01, chain20 2.77 -> 2.23,
chain50 5.73 -> 4.44, demo8 1.42 -> 1.21; ``--cases chain50,demo8`` (chain50 first: the baseline's first run
6.98-8.1 s, faulting) chain50 5.65 -> 4.28 and 5.60 -> 4.59.  Sixth pass, not kept (load 7-10, CPU s of
``--repeat 3``, base and new interleaved, three rounds): the chord method and its full-Newton fallback run in
lockstep, one evaluation per iteration (Newton's Jacobians only), halves the evaluations of chain20
(24 214 -> 13 510) with every family, span and arc the same, but not the time: chain20 3.60/3.89/3.76 ->
3.56/3.79/3.71, chain50 8.14/8.66/8.80 -> 8.69/8.19/10.77, demo8 2.91/2.82/2.32 -> 3.10/2.96/1.99 (replayed
corrector calls: -12 % on stacks below 64 rows, +5 % on stacks of 256 and more, where the kernel's ``tan`` over
``(2, rows, modes)`` dominates).  Most chord attempts fail (chain20: 37 656 of 45 964 rows, mostly at the 10th
iteration, contracting by ~0.75 per iteration); dropping a chord row whose contraction cannot reach ``step_tol``
in time (then Newton's point) changes the families: chain20 94 -> 90 arcs (the middle orbit of one arc of before
on no family after), demo8 4 -> 3 arcs and 278 -> 266 families, chain50 379 -> 387 arcs (two middle orbits lost).

With ``--compare`` each case also reports the arcs of before inside no arc of after (and the reverse) and how
many middle orbits of the arcs of before lie on no family of after (re-solved from every new family,
``modes.on_curve``): the strict "nothing lost" test.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import cProfile  # noqa: E402
import json  # noqa: E402
import pstats  # noqa: E402
import statistics  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

import bladecase as bc  # noqa: E402

DEFAULT_CASES = "chain10,chain20,chain50,demo8,demo16,demo32"
GOALS_S = {"chain50": 5.0, "demo8": 2.0, "demo32": 60.0}
#: The demo's 2-ipp search as issue 14 timed it (demo.toml then: tip node, lanczos-si 8, ipp = [1, 2]).
DEMO_GAP = 1e-4
DEMO_PERIODS = (0.9, 0.9999)
DEMO_SEARCH = {"scan": 6, "step": 0.01, "max_points": 400, "resolution": None}


def demo_system(size: int, cache: Path) -> bc.LinearSystem:
    """The demo blade reduced by lanczos-si to ``size`` dofs (cached as ``.npz``)."""
    path = cache / f"demo-lanczos-si-{size}.npz"
    if not path.exists():
        from bladecase.reduction import Contact
        from bladecase.study import demo_study, stages

        st = demo_study()
        model = stages.build_model(st, stages.build_mesh(st))
        (node,) = model.mesh.group("contact")
        reduced = bc.reduce(model, Contact.at(model, int(node), None, DEMO_GAP), "lanczos-si", size)
        s = reduced.system
        cache.mkdir(parents=True, exist_ok=True)
        M = s.M.toarray() if hasattr(s.M, "toarray") else np.asarray(s.M)
        K = s.K.toarray() if hasattr(s.K, "toarray") else np.asarray(s.K)
        np.savez(path, M=M, K=K, w=np.asarray(s.w, dtype=float), gap=s.gap)
    data = np.load(path)
    return bc.LinearSystem(data["M"], data["K"], data["w"], float(data["gap"]))


def case(name: str, cache: Path):
    """``(system, T1, call)`` of a case: ``call()`` runs the search and returns the families."""
    if name.startswith("chain"):
        n = int(name[5:])
        system = bc.chain(n, k=1.0, m=1.0 / n, gap=1.0)
        T1 = 2 * np.pi / system.spectrum.omega[0]
        return system, T1, lambda: bc.nonsmooth_mode(system, 2, (0.9 * T1, 0.9999 * T1))
    if name.startswith("demo"):
        system = demo_system(int(name[4:]), cache)
        T1 = 2 * np.pi / system.spectrum.contact_modes[0][0]
        lo, hi = DEMO_PERIODS
        return system, T1, lambda: bc.nonsmooth_mode(system, 2, (lo * T1, hi * T1), **DEMO_SEARCH)
    raise ValueError(f"unknown case {name!r}: chainN or demoS (e.g. chain50, demo16)")


def fingerprint(families, T1: float) -> dict:
    """Counts, the sorted arcs ``(T_lo/T₁, T_hi/T₁)`` and the families' period spans, rounded to 1e-8."""
    arcs = sorted((round(a.T_lo / T1, 8), round(a.T_hi / T1, 8)) for f in families for a in f.arcs)
    spans = sorted((round(min(o.T for o in f.orbits) / T1, 8), round(max(o.T for o in f.orbits) / T1, 8))
                   for f in families if f.orbits)
    mids = [[o.T, *o.impact_times.tolist(), *o.impulses.tolist()]
            for f in families for a in f.arcs for o in [f.orbits[(a.start + a.stop) // 2]]]
    return {"families": len(families), "with_arcs": sum(1 for f in families if f.arcs), "arcs": arcs,
            "spans": spans, "orbits": sum(len(f.orbits) for f in families), "arc_orbits": mids}


def off_families(system, mids: list, families) -> int:
    """How many of the orbits ``mids`` (``[T, times…, impulses…]`` rows, e.g. the middle orbit of each arc of
    an earlier run) lie on none of ``families`` (re-solved from the family's curve at their period,
    :func:`bladecase.nsm.modes.on_curve`): admissible orbits the search no longer lists."""
    from bladecase.nsm.modes import on_curve
    from bladecase.nsm.newton.orbits import make_orbit

    if not mids:
        return 0
    k = (len(mids[0]) - 1) // 2
    orbits = [make_orbit(system, m[0], np.array(m[1:1 + k]), np.array(m[1 + k:]), polish=False) for m in mids]
    found = np.zeros(len(orbits), dtype=bool)
    for f in families:
        rest = np.flatnonzero(~found)
        if rest.size == 0 or len(f.orbits) < 2:
            continue
        found[rest] = on_curve(f.orbits, [orbits[i] for i in rest])
    return int((~found).sum())


def measure(name: str, cache: Path, repeat: int, before: dict | None = None) -> dict:
    system, T1, call = case(name, cache)
    walls, cpus, fams = [], [], None
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        fams = call()
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
    fp = fingerprint(fams, T1)
    if before is not None and before.get("arc_orbits"):
        fp["off_families"] = off_families(system, before["arc_orbits"], fams)
    return {"case": name, "n": system.n, "wall_s": statistics.median(walls), "cpu_s": statistics.median(cpus),
            "walls": walls, "cpus": cpus, **fp}


def raw_search() -> None:
    """Switch off the geometric de-duplication of the k-ipp search (where the code has it)."""
    from bladecase.nsm import modes

    if hasattr(modes, "distinct_runs"):
        modes.distinct_runs = lambda orbits: [list(range(len(orbits)))]
        modes._contained = lambda families, pairs: None


def same_arcs(a: list, b: list, rtol: float) -> bool:
    return len(a) == len(b) and all(abs(x[0] - y[0]) <= rtol and abs(x[1] - y[1]) <= rtol for x, y in zip(a, b))


def uncovered(arcs: list, by: list, rtol: float) -> list:
    """The arcs of ``arcs`` that no arc of ``by`` contains (ends within ``rtol``): periods lost."""
    return [a for a in arcs if not any(b[0] <= a[0] + rtol and a[1] - rtol <= b[1] for b in by)]


def report(res: dict, before: dict | None, rtol: float) -> None:
    goal = GOALS_S.get(res["case"])
    line = (f"{res['case']:<8} n={res['n']:<4d} wall {res['wall_s']:8.2f} s  cpu {res['cpu_s']:8.2f} s  "
            f"{res['families']:4d} families ({res['with_arcs']} with arcs, {len(res['arcs'])} arcs, "
            f"{res['orbits']} orbits)")
    if goal is not None:
        line += f"  goal <= {goal:g} s: {'MET' if res['cpu_s'] <= goal else 'NOT MET'} (cpu)"
    print(line, flush=True)
    if before is None:
        return
    same = (before["families"] == res["families"] and same_arcs(before["arcs"], res["arcs"], rtol))
    spans = same_arcs(before["spans"], res["spans"], rtol)
    distinct = same_arcs(sorted(set(map(tuple, before["arcs"]))), sorted(set(map(tuple, res["arcs"]))), rtol)
    print(f"         before: wall {before['wall_s']:8.2f} s  cpu {before['cpu_s']:8.2f} s  {before['families']:4d} "
          f"families, {len(before['arcs'])} arcs  ->  speed-up wall x{before['wall_s'] / res['wall_s']:.1f}, "
          f"cpu x{before['cpu_s'] / res['cpu_s']:.1f};  same families and arcs (rtol {rtol:g}): "
          f"{'YES' if same else 'NO'}; same family spans: {'YES' if spans else 'NO'}; same distinct arcs: "
          f"{'YES' if distinct else 'NO'}", flush=True)
    lost, gained = uncovered(before["arcs"], res["arcs"], rtol), uncovered(res["arcs"], before["arcs"], rtol)
    print(f"         arcs of before inside none of after: {len(lost)} (of {len(before['arcs'])}); arcs of after inside "
          f"none of before: {len(gained)} (of {len(res['arcs'])})", flush=True)
    if "off_families" in res:
        print(f"         middle orbits of the arcs of before on no family of after: {res['off_families']} "
              f"(of {len(before['arc_orbits'])})", flush=True)
    if not same:
        old, new = set(map(tuple, before["arcs"])), set(map(tuple, res["arcs"]))
        print(f"         arcs only before: {sorted(old - new)[:8]}\n         arcs only after: {sorted(new - old)[:8]}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default=DEFAULT_CASES)
    ap.add_argument("--repeat", type=int, default=3, help="runs per case (median reported); demo16/32 run once")
    ap.add_argument("--cache", type=Path, default=Path(tempfile.gettempdir()) / "bladecase-bench-search")
    ap.add_argument("--save", type=Path, help="write figures and fingerprints as JSON")
    ap.add_argument("--compare", type=Path, help="JSON of an earlier run (--save) to compare with")
    ap.add_argument("--rtol", type=float, default=1e-8, help="tolerance on arc ends (in T/T1)")
    ap.add_argument("--profile", help="cProfile one run of this case")
    ap.add_argument("--raw", action="store_true", help="no geometric de-duplication of the families (issue 15)")
    args = ap.parse_args()
    if args.raw:
        raw_search()
    print(f"bladecase {bc.__file__}; OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}; "
          f"load average {os.getloadavg()[0]:.2f}{'; no de-duplication' if args.raw else ''}", flush=True)
    if args.profile:
        _, _, call = case(args.profile, args.cache)
        prof = cProfile.Profile()
        prof.runcall(call)
        pstats.Stats(prof).sort_stats("tottime").print_stats(25)
        pstats.Stats(prof).sort_stats("cumulative").print_stats(40)
        return
    before = json.loads(args.compare.read_text()) if args.compare else {}
    results = {}
    for name in args.cases.split(","):
        repeat = 1 if name in ("demo16", "demo32") else args.repeat
        results[name] = measure(name, args.cache, repeat, before.get(name))
        report(results[name], before.get(name), args.rtol)
        if args.save:
            args.save.write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
