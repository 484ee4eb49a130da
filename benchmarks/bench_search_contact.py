"""The 2-ipp family search on a Craig–Bampton blade with a 16-node contact face (58 dofs), timed, fingerprinted.

The case (no industrial mesh needed): a steel strip 150 × 30 × 6 mm clamped at its root, P1 tetrahedra of a tensor
grid (16 × 4 × 4 nodes), whose whole 4 × 4-node tip face rubs the casing (``Contact.face``: the mean flapwise (+z)
displacement of its 16 nodes, clearance 0.1 mm), reduced by Craig–Bampton with 10 fixed-interface modes: 48
boundary dofs + 10 modes = 58 dofs, as a user's industrial CB model with a 16-node face.  Searched as the study
does: ``nonsmooth_mode(system, 2, (0.9 T₁, 0.9999 T₁))`` with the ``[search]`` defaults (scan = 24, step = 0.01,
max_points = 400, ``T₁ = 2π/ω₁``).

Cases:

* ``cb58`` — that search.  It is capped at ``--timeout`` CPU seconds (default 600): a search cut there reports the
  families and arcs completed so far (counted as the search hands them over, marked ``partial``);
* ``cb58w`` — the same search in the window ``[0.9, 0.902]·T₁`` with 2 scan periods: a slice that finishes, to
  compare families and arcs before/after;

What it shows (measured, CPU s on a loaded 2-core machine): ``cb58w`` 52 s for 4 962 families (506 with arcs,
683 arcs); the full ``cb58`` passes 300 s without finishing and its baseline went past 23 GB.  With the faster
search (idle machine) ``cb58w`` takes 24.7 s, and with cvxopt's block solves the CB model differs by round-off
(``10⁻¹⁴`` in ``K``): 4 968 families, 643 arcs — the family set of this model is that fragile (with the old
solves the new search gives the old families and arcs exactly).  The "middle orbits on no family" count is not a
test here: the old code compared with its own run gives 111 of 683. The families do not
multiply through modes the contact barely sees (none has ``b_j² < 1e-12 Σb²``, six are below ``1e-6``; deflating
those changes nothing), but through the boundary modes that it sees strongly, up to ``ω ≈ 6700 ω₁``: 3 500–6 000
roots of the 2-ipp equations per period, 12 349 resonances in the range cutting the families into pieces (median
5 points, 0.001 T₁), and a certification whose grid follows the highest frequency (about 60 % of the time).

Figures are CPU seconds (``time.process_time``; ``OPENBLAS_NUM_THREADS=1``): the machine may be shared.  Each
case prints the time, families, families with arcs, arcs, orbits, and the contact's spectral measure (how many
modes, how many of them weak, the highest ``ω/ω₁``, the resonances ``T = 2πm/ω_j`` in the period range).  ``--save
FILE`` / ``--compare FILE`` as in ``bench_search.py`` (whose fingerprint, comparison and "middle orbits of the arcs
of before on no family of after" helpers are imported), e.g.::

    PYTHONPATH=/tmp/bc_baseline .venv/bin/python benchmarks/bench_search_contact.py --cases cb58w --save /tmp/cb.json
    .venv/bin/python benchmarks/bench_search_contact.py --cases cb58w --compare /tmp/cb.json

``--profile CASE`` prints a cProfile of one run.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import cProfile  # noqa: E402
import json  # noqa: E402
import pstats  # noqa: E402
import signal  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bench_search  # noqa: E402

import bladecase as bc  # noqa: E402

DEFAULT_CASES = "cb58w,cb58"
#: The study's [search] defaults.
STUDY_SEARCH = {"scan": 24, "step": 0.01, "max_points": 400}
GOALS_S = {"cb58": 60.0}


def cb_system(size: int = 10) -> bc.LinearSystem:
    """The 58-dof Craig–Bampton strip with a 16-node tip face (module doc)."""
    from skfem import MeshTet

    from bladecase.fe import Mesh, assemble
    from bladecase.reduction import Contact

    m = MeshTet.init_tensor(np.linspace(0, 0.15, 16), np.linspace(-0.015, 0.015, 4), np.linspace(-0.003, 0.003, 4))
    p = m.p.T.copy()
    mesh = Mesh(p, {"tetra": m.t.T.copy()}, dim=3,
                groups={"root": np.flatnonzero(p[:, 0] == 0), "tip": np.flatnonzero(np.isclose(p[:, 0], 0.15))})
    model = assemble(mesh, "steel")
    contact = Contact.face(model, "tip", (0.0, 0.0, 1.0), 1e-4)
    return bc.reduce(model, contact, "craig-bampton", size).system


def case(name: str):
    """``(system, T1, call)``: ``call()`` runs the case's search."""
    system = cb_system()
    T1 = 2 * np.pi / system.spectrum.omega[0]
    if name == "cb58":
        return system, T1, (0.9 * T1, 0.9999 * T1), lambda: bc.nonsmooth_mode(system, 2, (0.9 * T1, 0.9999 * T1),
                                                                              **STUDY_SEARCH)
    if name == "cb58w":
        rng = (0.9 * T1, 0.902 * T1)
        return system, T1, rng, lambda: bc.nonsmooth_mode(system, 2, rng, **{**STUDY_SEARCH, "scan": 2})
    raise ValueError(f"unknown case {name!r}: cb58 or cb58w")


def measure_spectrum(system, rng) -> str:
    """The contact's spectral measure in a line: modes, weak ones, highest ω/ω₁, the share of ``Σb²`` above
    ``100 ω₁``, resonances in ``rng``."""
    sp = system.spectrum
    b2 = sp.b**2 / (sp.b**2).sum()
    res = np.floor(sp.omega * rng[1] / (2 * np.pi)) - np.floor(sp.omega * rng[0] / (2 * np.pi))
    return (f"{sp.omega.size} modes, b_j²/Σb² < 1e-12: {(b2 < 1e-12).sum()}, < 1e-6: {(b2 < 1e-6).sum()}, "
            f"< 1e-3: {(b2 < 1e-3).sum()}; ω_max/ω₁ = {sp.omega[-1] / sp.omega[0]:.0f}; share of Σb² (the contact's "
            f"inverse mass) above 100 ω₁: {100 * b2[sp.omega > 100 * sp.omega[0]].sum():.1f} %; resonances in the "
            f"range: {int(res.sum())}")


class _CpuLimit(Exception):
    pass


def _on_limit(signum, frame):
    raise _CpuLimit


def measure(name: str, timeout: float, before: dict | None = None) -> dict:
    """One run of ``name``, cut after ``timeout`` CPU seconds (then the families completed so far)."""
    from bladecase.nsm import modes

    system, T1, rng, call = case(name)
    print(f"{name}: {system}; {measure_spectrum(system, rng)}", flush=True)
    done: list = []
    original = modes.complete_families

    def counting(traced, *args, **kwargs):  # the families as the search completes them (for a cut run)
        out = original(traced, *args, **kwargs)
        done.extend(f for pieces in out for f in pieces if f.orbits)
        return out

    modes.complete_families = counting
    signal.signal(signal.SIGPROF, _on_limit)
    signal.setitimer(signal.ITIMER_PROF, timeout)
    c0 = time.process_time()
    try:
        fams, partial = call(), False
    except _CpuLimit:
        fams, partial = done, True
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        modes.complete_families = original
    cpu = time.process_time() - c0
    fp = bench_search.fingerprint(fams, T1)
    if before is not None and before.get("arc_orbits") and not partial:
        fp["off_families"] = bench_search.off_families(system, before["arc_orbits"], fams)
    return {"case": name, "n": system.n, "wall_s": cpu, "cpu_s": cpu, "walls": [cpu], "cpus": [cpu],
            "partial": partial, **fp}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default=DEFAULT_CASES)
    ap.add_argument("--timeout", type=float, default=600.0, help="CPU seconds a case may take (then cut)")
    ap.add_argument("--save", type=Path, help="write figures and fingerprints as JSON")
    ap.add_argument("--compare", type=Path, help="JSON of an earlier run (--save) to compare with")
    ap.add_argument("--rtol", type=float, default=1e-8, help="tolerance on arc ends (in T/T1)")
    ap.add_argument("--profile", help="cProfile one run of this case")
    args = ap.parse_args()
    print(f"bladecase {bc.__file__}; OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}; "
          f"load average {os.getloadavg()[0]:.2f}; times are CPU seconds", flush=True)
    if args.profile:
        _, _, _, call = case(args.profile)
        prof = cProfile.Profile()
        prof.runcall(call)
        pstats.Stats(prof).sort_stats("cumulative").print_stats(40)
        return
    before = json.loads(args.compare.read_text()) if args.compare else {}
    results = {}
    for name in args.cases.split(","):
        res = measure(name, args.timeout, before.get(name))
        results[name] = res
        if res["partial"]:
            print(f"{name}: CUT at {res['cpu_s']:.0f} s CPU (--timeout): {res['families']} families completed so far "
                  f"({res['with_arcs']} with arcs, {len(res['arcs'])} arcs) — partial figures", flush=True)
        bench_search.GOALS_S.update(GOALS_S)
        bench_search.report(res, before.get(name), args.rtol)
        old = before.get(name)
        if old is not None:
            cut = ("  (before was cut)" if old.get("partial") else "") + ("  (after was cut)" if res["partial"] else "")
            print(f"         ratios after/before: cpu {res['cpu_s'] / old['cpu_s']:.3f}, families "
                  f"{res['families'] / max(old['families'], 1):.3f}, arcs "
                  f"{len(res['arcs']) / max(len(old['arcs']), 1):.3f}{cut}", flush=True)
        if args.save:
            args.save.write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
