"""Sparse SPD factorisation of the blade's K: SuperLU against the other backends, and the eigen-solvers on it.

For each blade size (``bench_fe_pipeline.py``'s 5 490 / 26 316 / 110 424 P2 dofs and 61 704 between) the
stiffness ``K`` and mass ``M`` are assembled once and saved; then, for each installed backend
(``bladecase.linalg.available_backends()``: ``superlu``, ``cvxopt``, ``cholmod``), a fresh process (its own peak
memory) loads them and times (``time.perf_counter``):

* the factorisation ``bladecase.linalg.spd_factor(K)`` alone, the peak resident memory it adds (Linux
  ``VmHWM`` reset just before, minus ``VmRSS`` before), the memory its factor keeps, and the process's peak
  (``ru_maxrss``) right after it;
* one solve, and one solve of a block of 20 right-hand sides, and the largest difference of that block's
  solution from SuperLU's, relative to its largest entry;
* with ``--eigen``, 20 lowest modes reusing the factor: ARPACK shift-invert (``lowest_modes(method="arpack")``),
  the block shift-invert Lanczos (``method="block"``) and, with ``--lobpcg``, scipy's LOBPCG preconditioned by
  the factor (block 30, tol 1e-9, at most 40 iterations) — each with its largest relative frequency difference
  from ARPACK's and its largest relative residual ``‖Kφ - λMφ‖ / ‖Kφ‖``.

``--repeat N`` runs every backend N times, interleaved (SuperLU, the others, SuperLU, …), and reports the
medians (and the range of the factorisation times); each other backend is then compared with SuperLU: the
ratio of each figure, SuperLU / backend (above 1: the backend is faster or leaner).  Single-threaded BLAS
(``OPENBLAS_NUM_THREADS=1`` is set for the children unless already set).  Exit status 0.

Run::

    cd /work/main && OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_solvers.py
        [--skip-110k] [--sizes 0.0055,0.0025,0.00175,0.0014] [--backends superlu,cvxopt,cholmod] [--repeat 3]
        [--eigen] [--lobpcg] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_core import machine

SIZES = (0.0055, 0.0025, 0.00175, 0.0014)
COUNT = 20
#: Figures compared with SuperLU's (medians over the repeats), and their labels.
COMPARED = {"factor_seconds": "factor", "factor_peak_MiB": "factor peak memory", "factor_maxrss_MiB": "ru_maxrss",
            "solve_seconds": "1 solve", "block_solve_seconds": "20-rhs solve"}


def peak_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def _status_mib(field: str) -> float | None:
    """``VmRSS`` / ``VmHWM`` of ``/proc/self/status`` in MiB (Linux), else ``None``."""
    try:
        for row in Path("/proc/self/status").read_text().splitlines():
            if row.startswith(field + ":"):
                return int(row.split()[1]) / 1024
    except OSError:
        pass
    return None


def reset_peak() -> float | None:
    """Reset the peak resident memory (``VmHWM``, Linux ``clear_refs``) and return the current one (MiB)."""
    try:
        Path("/proc/self/clear_refs").write_text("5")
    except OSError:
        return None
    return _status_mib("VmRSS")


def save_model(size: float, folder: Path) -> tuple[int, Path]:
    """Assemble the blade of mesh size ``size`` and save ``K``, ``M`` to ``folder/K_M_<size>.npz``."""
    import numpy as np
    from bench_fem import blade

    import bladecase

    model = bladecase.assemble(blade(size), "Ti-6Al-4V", order=2, clamp="root")
    K, M = model.K.tocsc(), model.M.tocsc()
    path = folder / f"K_M_{size:g}.npz"
    np.savez(path, **{f"{name}_{part}": getattr(A, part) for name, A in (("K", K), ("M", M))
                      for part in ("data", "indices", "indptr")}, n=K.shape[0])
    return model.n_dofs, path


def _eigen(K, M, factor, method: str) -> tuple[float, object, object]:
    import numpy as np
    import scipy.sparse.linalg as spla

    from bladecase.linalg import lowest_modes

    t0 = time.perf_counter()
    if method == "lobpcg":
        X = np.random.default_rng(0).standard_normal((K.shape[0], 30))
        lam, phi = spla.lobpcg(K, X, B=M, M=factor.operator(), largest=False, tol=1e-9, maxiter=40)
        order = np.argsort(lam)[:COUNT]
        lam, phi = lam[order], phi[:, order]
    else:
        lam, phi = lowest_modes(K, M, COUNT, factor=factor, method=method)
    return time.perf_counter() - t0, lam, phi


def run_one(path: str, methods: list[str], reference: str | None = None) -> dict:
    """Factorise the saved ``K`` (backend from ``$BLADECASE_FACTOR``), solve, and run the eigen-solvers.

    ``reference``: a ``.npy`` file with SuperLU's solution of the 20 right-hand sides (written by the SuperLU
    run if missing, compared with otherwise).
    """
    import warnings

    import numpy as np
    import scipy.sparse as sp

    from bladecase.linalg import spd_factor

    z = np.load(path)
    n = int(z["n"])
    K, M = (sp.csc_array((z[f"{a}_data"], z[f"{a}_indices"], z[f"{a}_indptr"]), shape=(n, n)) for a in "KM")
    before = reset_peak()  # the factorisation's own peak, not the loading's
    t0 = time.perf_counter()
    factor = spd_factor(K, "K")
    seconds = time.perf_counter() - t0
    hwm = _status_mib("VmHWM")
    out = {"dofs": n, "backend": factor.backend, "factor_seconds": seconds,
           "factor_peak_MiB": hwm - before if None not in (hwm, before) else float("nan"),
           "factor_kept_MiB": _status_mib("VmRSS") - before if before is not None else float("nan"),
           "factor_maxrss_MiB": peak_mib()}
    B = np.random.default_rng(0).standard_normal((n, COUNT))
    t0 = time.perf_counter()
    factor.solve(B[:, 0])
    out["solve_seconds"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    X = factor.solve(B)
    out["block_solve_seconds"] = time.perf_counter() - t0
    out["solve_residual"] = float(np.abs(K @ X - B).max())
    if reference is not None:
        if factor.backend == "superlu" and not Path(reference).exists():
            np.save(reference, X)
        elif Path(reference).exists():
            R = np.load(reference)
            out["max_rel_diff_vs_superlu"] = float(np.abs(X - R).max() / np.abs(R).max())
    ref = None
    for method in methods:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # LOBPCG's "not reaching the requested tolerance"
            seconds, lam, phi = _eigen(K, M, factor, method)
        f = np.sqrt(lam) / (2 * np.pi)
        ref = f if ref is None else ref
        res = np.linalg.norm(K @ phi - (M @ phi) * lam, axis=0) / np.linalg.norm(K @ phi, axis=0)
        out[method] = {"seconds": seconds, "max_rel_freq_diff_vs_first": float(np.abs(f / ref - 1).max()),
                       "max_rel_residual": float(res.max()), "peak_MiB": peak_mib()}
    out["peak_MiB"] = peak_mib()
    return out


def child(path: Path, backend: str, methods: list[str], reference: Path | None = None) -> dict:
    env = dict(os.environ, BLADECASE_FACTOR=backend)
    env.setdefault("OPENBLAS_NUM_THREADS", "1")
    ref = str(reference) if reference is not None else None
    code = (f"import json, sys; sys.path.insert(0, {str(Path(__file__).parent)!r}); import bench_solvers as b; "
            f"print('RESULT' + json.dumps(b.run_one({str(path)!r}, {methods!r}, {ref!r})))")
    proc = subprocess.run([sys.executable, "-W", "ignore", "-c", code], env=env, capture_output=True, text=True)
    rows = [r for r in proc.stdout.splitlines() if r.startswith("RESULT")]
    if proc.returncode or not rows:
        return {"backend": backend, "error": (proc.stderr.strip().splitlines() or ["?"])[-1]}
    return json.loads(rows[-1][len("RESULT"):])


def median_run(runs: list[dict], methods: list[str]) -> dict:
    """The medians of the figures of ``runs`` (one backend, one size); ``factor_range`` their min and max."""
    ok = [r for r in runs if "error" not in r]
    if not ok:
        return runs[-1]
    out = dict(ok[0], runs=len(ok), factor_range=[min(r["factor_seconds"] for r in ok),
                                                   max(r["factor_seconds"] for r in ok)])
    for key, value in ok[0].items():
        if isinstance(value, float):
            out[key] = statistics.median(r[key] for r in ok if key in r)
    for m in methods:
        out[m] = {k: statistics.median(r[m][k] for r in ok) for k in ok[0][m]}
    return out


def report(r: dict, methods: list[str]) -> None:
    if "error" in r:
        print(f"  {r['backend']:<8} error: {r['error']}")
        return
    spread = (f" ({r['factor_range'][0]:.2f}-{r['factor_range'][1]:.2f}, median of {r['runs']})"
              if r.get("runs", 1) > 1 else "")
    diff = f"   vs SuperLU {r['max_rel_diff_vs_superlu']:.1e}" if "max_rel_diff_vs_superlu" in r else ""
    print(f"  {r['backend']:<8} factor {r['factor_seconds']:7.2f} s{spread}  +{r['factor_peak_MiB']:5.0f} MiB peak "
          f"(+{r['factor_kept_MiB']:.0f} kept, ru_maxrss {r['factor_maxrss_MiB']:.0f})   solve "
          f"{r['solve_seconds']:.3f} s   20-block solve {r['block_solve_seconds']:.3f} s   "
          f"peak {r['peak_MiB']:.0f} MiB{diff}")
    for m in methods:
        e = r[m]
        print(f"  {'':<8} 20 modes {m:<7} {e['seconds']:7.2f} s   factor + modes "
              f"{r['factor_seconds'] + e['seconds']:7.2f} s   freq diff vs {methods[0]} "
              f"{e['max_rel_freq_diff_vs_first']:.1e}   residual {e['max_rel_residual']:.1e}")


def report_ratios(results: dict[str, dict]) -> None:
    """Each backend's figures against SuperLU's: SuperLU / backend (> 1: faster or leaner)."""
    base = results.get("superlu")
    if base is None or "error" in base:
        return
    for backend, r in results.items():
        if backend == "superlu" or "error" in r:
            continue
        ratios = "   ".join(f"{label} {base[key] / r[key]:.1f}x" for key, label in COMPARED.items())
        print(f"  {backend:<8} vs SuperLU (SuperLU / {backend}): {ratios}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", default=",".join(map(str, SIZES)), help="mesh sizes in m, comma-separated")
    parser.add_argument("--skip-110k", action="store_true", help="leave out the 1.4 mm (110k-dof) blade")
    parser.add_argument("--backends", default=None, help="comma-separated (default: every available backend)")
    parser.add_argument("--repeat", type=int, default=1, help="runs of each backend, interleaved (medians shown)")
    parser.add_argument("--eigen", action="store_true", help="also 20 modes by ARPACK and by block Lanczos")
    parser.add_argument("--lobpcg", action="store_true", help="with --eigen, also LOBPCG")
    parser.add_argument("--json", metavar="FILE", type=Path, help="also write the figures to FILE (JSON)")
    args = parser.parse_args(argv)

    from bladecase.linalg import available_backends

    sizes = [float(s) for s in args.sizes.split(",") if not (args.skip_110k and float(s) <= 0.0014)]
    backends = args.backends.split(",") if args.backends else sorted(available_backends(), key="superlu".__ne__)
    methods = (["arpack", "block"] + (["lobpcg"] if args.lobpcg else [])) if args.eigen else []
    print(f"bladecase sparse factorisation benchmark: {', '.join(backends)} on the blade's K")
    info = {"machine": machine(), "runs": [], "medians": []}
    with tempfile.TemporaryDirectory() as tmp:
        for size in sizes:
            n, path = save_model(size, Path(tmp))
            reference = Path(tmp) / f"X_{size:g}.npy"
            print(f"\nblade mesh size {size:g} m: {n} dofs")
            runs: dict[str, list[dict]] = {b: [] for b in backends}
            for _ in range(max(args.repeat, 1)):
                for backend in backends:
                    r = child(path, backend, methods, reference)
                    r["size"] = size
                    info["runs"].append(r)
                    runs[backend].append(r)
            results = {b: median_run(rs, methods) for b, rs in runs.items()}
            for r in results.values():
                report(r, methods)
                info["medians"].append(r)
            report_ratios(results)
            path.unlink()
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(info, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
