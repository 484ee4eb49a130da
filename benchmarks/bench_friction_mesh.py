"""The mesh error of the friction-damping figures: the demo blade's first mode with stick–slip friction (μ = 0.15,
all tip nodes, 1650 rpm, casing at rest, 0.5 % damping) at 1.5 × each mesh's own grazing amplitude, on meshes whose
element sizes are the demo study's ``[geometry] size`` and ``tip_size`` times each factor (as
``bladecase.study.convergence.stage.scaled_study`` scales them).

Each mesh is built as the rub study builds it (``bench_rub.at_speed``: the centrifugal state at the speed, the nodal
model with one contact per tip node, the casing's stiffness shared by the nodes' areas; a finer mesh has more tip
nodes), its friction as ``bench_friction_damping.blade`` builds it. Per mesh: dofs, tip (contact) nodes ``m``, the
open-phase f1 and f2/f1 (mode 2 lies near 4·f1: the orbit's 4th harmonic drives it), the grazing amplitude (with the
hot gap at its node and the mode's normal displacement there), the normal force the first mode held at the amplitude
puts on the casing; the extended periodic motion concept (EPMC, ``coulomb_mode``) at ``--amplitude`` × grazing:
f(a), f(a)/f1 − 1, ζ, ζκ (kinetic factor), ζ − 0.005 and friction's own damping ratio on the orbit (its work over a
period over ``2ω∫x'ᵀMx' dt``). Then, for each figure, the observed order, the Richardson extrapolation and the error
of the study's mesh (factor 1) by ``richardson`` (the grid convergence index of the convergence stage: 1.25 × the
distance from the extrapolation when the order is established, else 3 × the range over the meshes), over ``h`` = the
factors (as the convergence stage reads them) and, as a check, over ``h = (dofs₁/dofs)^(1/3)`` (gmsh's meshes refine
less than the factors say: 0.8 → 0.86, 0.64 → 0.75). ``--higher 0.05`` damps the modes above the first 5 %
(the first's 0.5 % kept): the 4:1 internal resonance with mode 2 taken out.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_friction_mesh.py                       # 1, 0.8, 0.64: 34 s
    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_friction_mesh.py --factors 1 0.8 0.64 0.512 0.4096
    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_friction_mesh.py --factors 1 0.8 0.64 0.512 0.4096 --higher 0.05

``--json FILE`` keeps each mesh's row as soon as it is done and reuses the rows already there (same speed,
amplitude and ``--higher``).

Figures (amplitude 1.5 × each mesh's grazing; a busy two-core machine, one BLAS thread; build + EPMC per mesh):

======  =====  ===  =========  =======  =========  =========  =========  =========  =========  =======  =======
factor  dofs   m    f1 open    f2/f1    grazing    f(a) Hz    ζ(a)       ζκ         friction   f2/f(a)  s
======  =====  ===  =========  =======  =========  =========  =========  =========  =========  =======  =======
1       5787   26   216.90909  4.00801  8.5163e-5  217.30126  0.0053044  0.0053292  2.4197e-4  4.00078  1 + 5
0.8     8958   36   218.50918  4.02173  9.0266e-5  218.86715  0.0052402  0.0052491  2.2144e-4  4.01515  2 + 7
0.64    13683  42   219.15657  4.02481  9.2721e-5  219.51054  0.0052356  0.0052428  2.2152e-4  4.01832  4 + 9
0.512   21420  59   219.57482  4.03021  9.4548e-5  219.92393  0.0052310  0.0052360  2.2313e-4  4.02381  6 + 13
0.4096  34635  76   219.76867  4.03361  9.5685e-5  220.11335  0.0052277  0.0052316  2.2251e-4  4.02729  12 + 20
======  =====  ===  =========  =======  =========  =========  =========  =========  =========  =======  =======

0.32768: 59976 dofs, 112 tip nodes, f1 219.83103 Hz, f2/f1 4.03494, grazing 9.62158e-5 (28.5 s to build); EPMC
f = 220.17310 Hz, ζ = 0.0052256, ζκ = 0.0052292, friction's own 2.2133e-4, f2/f(a) 4.02867, 70 phases (32 s).
Over the three finest of the six: f1 order 5.1, extrapolated 219.861 Hz, the demo mesh's error 1.7 %; ζ order 2.0,
0.0052219, 2.0 %; ζ − 0.005 order 1.7, 2.206e-4, 47 %; friction's own not established (not shrinking), 28 %.
(Before the fix of a stick–slip switch this mesh's EPMC did not finish: its first flight switched 2341 times in
300 s at t = 0.49854 T1 without advancing — a sliding node's slip signal reaching 0 falling, the nodes decided
together keeping every code, the signal left 4e-18 of its size above 0.)

The error of the study's mesh (``richardson``, h = the factors; "—": the order not established, 3 × the range):

======================  =========================================  =========================================
figure                  meshes 1, 0.8, 0.64: order, f₀, error      meshes 1 … 0.4096 (the three finest)
======================  =========================================  =========================================
f1 open                 4.06, 219.597 Hz, 1.53 %                   3.45, 219.936 Hz, 1.72 %
f2/f1                   6.69, 4.0257, 0.55 %                       2.06, 4.0394, 0.97 %
grazing amplitude       3.28, 9.500e-5, 12.9 %                     2.12, 9.756e-5, 15.9 %
f(a)                    3.99, 219.959 Hz, 1.51 %                   3.50, 220.274 Hz, 1.69 %
f(a)/f1 − 1             — (order 8.9), 35.8 %                      0.69, 1.439e-3, 32.1 %
ζ(a)                    — (order 12), 3.95 %                       1.45, 0.0052189, 2.05 %
ζκ                      — (order 11), 4.95 %                       2.03, 0.0052241, 2.51 %
friction's own ratio    — (oscillating), 27.8 %                    — (oscillating), 27.7 %
ζ(a) − 0.005            — (order 12), 87.7 %                       1.45, 2.189e-4, 48.9 %
f2/f(a)                 6.77, 4.0192, 0.57 %                       2.03, 4.0334, 1.01 %
======================  =========================================  =========================================

What they say. The frequencies converge from below at an established order (3.5–4): f1 and f(a) of the study's mesh
are 1.4 % low (219.94 / 220.27 Hz extrapolated), error estimate 1.5–1.7 %. The grazing amplitude is 10–13 % low
(error estimate 13–16 %): the hot gap at the grazing node (a corner of the tip, the same point on every mesh) is the
cold 0.5 mm less the centrifugal growth, 134.4 → 141.2 → 144.3 → 146.6 → 147.9 μm (the growth, ~0.36 mm, converging
slowly, order ~2, and the gap its small remainder), with the mode's normal displacement there 1.578 → 1.546. The
damping figures jump at the first refinement and then drift: ζ(a) − 0.005 is 3.04e-4 on the study's mesh, 2.40,
2.36, 2.31, 2.28e-4 after (−21 %, then −1.4…−2 % a step; extrapolated 2.19e-4: the study's mesh ~+39 %); ζ(a) itself
is 1.6 % high. Friction's own ratio is 2.42e-4 on the study's mesh and 2.214–2.231e-4 (±0.4 %, oscillating) on the
four finer: +9 %. The 4:1 internal resonance moves with the mesh: f2/f(a) = 4.0008 on the study's mesh (mode 2
within 0.02 % of the orbit's 4th harmonic), 4.015, 4.018, 4.024, 4.027 on the finer ones, 4.033 extrapolated; the
part of ζ − 0.005 that is not friction's (mode 2's damping, pumped) falls 6.2e-5 → 1.9, 1.4, 0.8, 0.5e-5, κ 1.0047 →
1.0008. With ``--higher 0.05`` (mode 2 not resonating, κ ≤ 1.0001) friction's own ratio is 3.030e-4, 2.474, 2.431,
2.383, 2.347e-4: monotone, order 1.35, extrapolated 2.246e-4, the study's mesh +35 % (error estimate 44 %); ζ(a)
0.0053018 → 0.0052328 (order 1.31, 1.9 %). So the jump at the first refinement is not the internal resonance: with
0.5 % on mode 2 the two effects (friction's part falling with the mesh, mode 2 detuning from 4:1) partly cancel in
friction's own ratio, and its +9 % is that coincidence, not a small mesh error. Nor is it the total normal load: the
first mode held at 1.5 × grazing presses 5, 7, 8, 11, 14 nodes (6.5–9.0 % of the tip's area) with 2.185, 2.114,
2.218, 2.224, 2.253 N in all (within 3 %); but on the study's mesh half of it (1.10 N) sits on one node of 3.3 % of
the tip's area, tangentially stiff, where on the meshes 0.8 and 0.64 the most loaded node carries 0.57 and 0.51 N:
how the load is shared among the tip's nodes is what the coarse mesh gets wrong. With h from the dofs the orders
rise (f1: 6.1 over 1, 0.8, 0.64; 5.4 over the three finest) and the errors move by at most 0.5 points, except
f(a)/f1 − 1 (27 % instead of 32 %) and ζ − 0.005 (47 % instead of 49 %); over 1, 0.8, 0.64 alone, f2/f1 and f2/f(a)
lose their order (order 10: 1.3 % instead of 0.55 %).

At 3 × grazing (``--amplitude 3``; 25, 39, 48, 104 s an EPMC): f(a) 219.82019, 221.15017, 221.87218, 222.40703 Hz;
ζ(a) 0.0094978, 0.0087857, 0.0087122, 0.0085762; κ 1.0445, 1.0787, 1.0784, 1.0768; friction's own ratio 3.897e-3,
2.730e-3, 2.669e-3, 2.554e-3; f2/f(a) 3.955, 3.974, 3.976, 3.979 (meshes 1, 0.8, 0.64, 0.512). The study's mesh is
again the outlier (friction's own ratio +43 % over the mesh 0.8's, ζ(a) +8 %), and the finer meshes are not in the
asymptotic range (the changes from 0.64 to 0.512 larger than from 0.8 to 0.64: no order; error estimates 3 × the
range: ζ 32 %, friction's own 158 %); f(a) order 1.34, 223.94 Hz extrapolated, 2.3 %. The mesh 0.4096 at 3 ×: its
EPMC not reached (stopped after 11 min inside the solve's flights, the 0.512's took 104 s).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from dataclasses import replace
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from threadpoolctl import threadpool_limits  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from bench_friction_damping import DAMPING, MU, friction_ratio  # noqa: E402
from bench_rub import at_speed, demo  # noqa: E402
from test_rub_study import CASING, _study  # noqa: E402

from bladecase.nsm import Damping  # noqa: E402
from bladecase.nsm.massless.friction_modes_coulomb import coulomb_mode  # noqa: E402
from bladecase.nsm.massless.friction_modes_phase import kinetic_factor  # noqa: E402
from bladecase.nsm.massless.nodal_system import lcp  # noqa: E402
from bladecase.reduction.nodal_friction import nodal_friction  # noqa: E402
from bladecase.study.convergence.stage import estimate_words, richardson, scaled_study  # noqa: E402
from bladecase.study.rub import stage  # noqa: E402
from bladecase.study.schema import loads  # noqa: E402

#: The figures compared: key → (words, format).
FIGURES = {
    "f1_hz": ("f1 open (Hz)", ".5f"),
    "f2_over_f1": ("f2/f1 open", ".5f"),
    "gap_um": ("hot gap, grazing node (um)", ".4f"),
    "reach": ("its normal disp. in mode 1", ".5f"),
    "grazing": ("grazing amplitude", ".6g"),
    "f_hz": ("EPMC f(a) (Hz)", ".5f"),
    "stiffening": ("f(a)/f1 - 1", ".4e"),
    "zeta": ("zeta(a)", ".7f"),
    "zeta_kappa": ("zeta*kappa", ".7f"),
    "friction": ("friction's own ratio", ".4e"),
    "zeta_minus": ("zeta(a) - 0.005", ".4e"),
    "f2_over_f": ("f2/f(a)", ".5f"),
    "past_area": ("area past its gap (lin.)", ".4%"),
    "force_n": ("normal force, mode 1 (N)", ".5f"),
}


def mesh(factor: float, rpm: float, amplitude: float, higher: float | None = None) -> dict:
    """One mesh's row: its nodal model at ``rpm`` (all tip nodes) and the EPMC at ``amplitude`` × grazing (the modes
    above the first damped ``higher`` when given, else as the first)."""
    t0 = time.perf_counter()
    study, model, contact = demo(mesh=factor)
    g, scaled = study["geometry"], scaled_study(loads(_study(CASING, ""), source="<bench>"), factor)["geometry"]
    # the same sizes as the convergence stage's own scaling
    assert np.isclose(g["size"], scaled["size"], rtol=1e-5) and np.isclose(g["tip_size"], scaled["tip_size"],
                                                                           rtol=1e-5), (g, scaled)
    reduced, _, _ = at_speed(study, model, contact, rpm)
    axis = stage._axis(study)
    fr = replace(nodal_friction(reduced, MU, axis.origin, axis.direction), model="coulomb")
    s = reduced.system
    omega, phi = s.modes
    reach = np.abs(s.W.T @ phi[:, 0])  # each node's normal displacement in the first open mode, per unit amplitude
    grazing = float(np.min(s.gap / reach))
    build = time.perf_counter() - t0
    # the nodes the first open mode at the amplitude would push past their gaps, and their share of the tip's area;
    # the normal forces there with the other modes held (the contact problem at that turning point)
    past = amplitude * grazing * reach > s.gap
    k = np.asarray(s.casing, dtype=float)
    toward = np.sign((s.W.T @ phi[:, 0])[np.argmin(s.gap / reach)]) * (s.W.T @ phi[:, 0])
    lam = lcp(s.gap - amplitude * grazing * toward, s.H)
    row = {"factor": factor, "dofs": int(model.n_dofs), "n": int(s.n), "m": int(s.m),
           "f1_hz": float(omega[0] / 2 / np.pi), "f2_over_f1": float(omega[1] / omega[0]), "grazing": grazing,
           "build_s": build, "past": int(past.sum()), "past_area": float(k[past].sum() / k.sum()),
           "gap_um": float(1e6 * s.gap[np.argmin(s.gap / reach)]), "reach": float(reach[np.argmin(s.gap / reach)]),
           "force_n": float(lam.sum()), "pressed": int(np.count_nonzero(lam > 0))}
    print(f"mesh x{factor:g} (size {g['size']:.6g}, tip_size {g['tip_size']:.6g}): {row['dofs']} dofs, nodal model "
          f"n = {s.n}, {s.m} tip (contact) nodes, f1 open {row['f1_hz']:.5f} Hz, f2 {omega[1] / 2 / np.pi:.4f} Hz "
          f"= {row['f2_over_f1']:.5f} f1, grazing amplitude {grazing:.6g} (the hot gap at the grazing node "
          f"{row['gap_um']:.3f} um) ({build:.1f} s to build); the first open "
          f"mode at {amplitude:g} x grazing pushes {row['past']} nodes past their gaps ({row['past_area']:.2%} of "
          f"the tip's area), held there: {row['force_n']:.4f} N on {row['pressed']} nodes", flush=True)
    t = time.perf_counter()
    damping = DAMPING if higher is None else Damping(zeta=(DAMPING.zeta,) + (higher,) * (s.n - 1))
    m = coulomb_mode(s, fr, amplitude * grazing, damping=damping, guess=None)
    a1, kap = kinetic_factor(m)
    zf = friction_ratio(m.orbit, 0.0, m.period, m.frequency)
    row.update(f_hz=float(m.frequency / 2 / np.pi), stiffening=float(m.frequency / omega[0] - 1),
               zeta=float(m.zeta), kappa=float(kap), a1=float(a1),
               zeta_kappa=float(m.zeta * kap), friction=float(zf), zeta_minus=float(m.zeta - DAMPING.zeta),
               f2_over_f=float(omega[1] / m.frequency), epmc_s=time.perf_counter() - t,
               phases=int(m.orbit.starts.size))
    print(f"   EPMC at {amplitude:g} x grazing: f = {row['f_hz']:.5f} Hz, zeta {m.zeta:.7f}, kappa {kap:.5f}: "
          f"zeta*kappa {row['zeta_kappa']:.7f}; friction's own ratio {zf:.4e}; f2/f(a) {row['f2_over_f']:.5f}; "
          f"{row['phases']} phases ({row['epmc_s']:.0f} s)", flush=True)
    return row


def richardson_table(h: list[float], rows: list[dict], label: str) -> None:
    """Each figure's order, extrapolation and the error of the study's mesh (``h = 1``) by ``richardson`` (the three
    finest meshes), and the changes from mesh to mesh."""
    print(f"\nRichardson, h = {label}: {', '.join(f'{x:.4g}' for x in h)} (the study's mesh: h = 1; the three finest "
          "give the order):")
    print(f"{'figure':24} {'h = 1':>13} {'order':>6} {'extrapolated':>13} {'error':>8}  order established?; "
          "changes mesh to mesh")
    for k, (words, f) in FIGURES.items():
        values = [r.get(k) for r in rows]
        r = richardson(h, values, study_h=1.0)
        if r["error"] is None:
            continue
        order = "-" if r["order"] is None else f"{r['order']:.2f}"
        ext = "-" if r["extrapolated"] is None else format(r["extrapolated"], f)
        how = estimate_words(r) or "yes: 1.25 × the distance from the extrapolation"
        changes = ", ".join(f"{c:+.3g}" for c in np.diff(values))
        print(f"{words:24} {values[0]:13{f}} {order:>6} {ext:>13} {r['error']:8.2%}  {how}; {changes}", flush=True)


def table(rows: list[dict]) -> None:
    """Per mesh, then the Richardson table over the factors (as the convergence stage reads them) and, as a check of
    how far the unstructured meshes are from the factors' refinement, over ``h = (dofs₁/dofs)^(1/3)``."""
    rows = sorted(rows, key=lambda r: -r["factor"])
    print("\nper mesh:")
    print(f"{'factor':>7} {'h dofs':>7} {'dofs':>7} {'m':>3} {'build s':>8} {'EPMC s':>7} " +
          " ".join(f"{k:>12}" for k in FIGURES), flush=True)
    for r in rows:
        h = (rows[0]["dofs"] / r["dofs"]) ** (1 / 3)
        print(f"{r['factor']:7g} {h:7.4f} {r['dofs']:7d} {r['m']:3d} {r['build_s']:8.1f} "
              f"{r.get('epmc_s', np.nan):7.0f} " + " ".join(f"{r.get(k, np.nan):12{f}}" for k, (_, f) in
                                                            FIGURES.items()))
    if len(rows) < 3:
        print("(fewer than three meshes: no order)")
        return
    if rows[0]["factor"] != 1.0:
        print("(no mesh of factor 1: the error is the coarsest mesh's)")
    richardson_table([r["factor"] / rows[0]["factor"] for r in rows], rows, "the factors")
    richardson_table([(rows[0]["dofs"] / r["dofs"]) ** (1 / 3) for r in rows], rows, "(dofs1/dofs)^(1/3)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--factors", type=float, nargs="+", default=[1.0, 0.8, 0.64])
    ap.add_argument("--amplitude", type=float, default=1.5, help="the EPMC's amplitude, times each mesh's grazing")
    ap.add_argument("--rpm", type=float, default=1650.0)
    ap.add_argument("--higher", type=float, default=None,
                    help="the damping ratio of the modes above the first (default: 0.5 %%, as the first)")
    ap.add_argument("--json", type=Path, default=None, help="keep each mesh's row here; reuse the rows already there")
    a = ap.parse_args()
    t0 = time.perf_counter()
    done: dict[float, dict] = {}
    if a.json is not None and a.json.exists():
        for r in json.loads(a.json.read_text()):
            if (r.get("rpm"), r.get("amplitude"), r.get("higher")) == (a.rpm, a.amplitude, a.higher):
                done[float(r["factor"])] = r
    with threadpool_limits(limits=1, user_api="blas"):
        for factor in a.factors:
            if factor in done:
                print(f"mesh x{factor:g}: from {a.json}", flush=True)
                continue
            done[factor] = {**mesh(factor, a.rpm, a.amplitude, a.higher), "rpm": a.rpm, "amplitude": a.amplitude,
                            "higher": a.higher}
            if a.json is not None:  # the other settings' rows kept
                old = json.loads(a.json.read_text()) if a.json.exists() else []
                keep = [r for r in old if (r.get("rpm"), r.get("amplitude"), r.get("higher"), r.get("factor"))
                        != (a.rpm, a.amplitude, a.higher, factor)]
                a.json.write_text(json.dumps(keep + [done[factor]], indent=1))
    higher = "" if a.higher is None else f" (modes 2 and above: {a.higher:.1%})"
    print(f"\nthe demo blade at {a.rpm:g} rpm, all tip nodes, mu = {MU}, stick–slip, casing at rest, "
          f"{DAMPING.zeta:.1%} damping{higher}; EPMC at {a.amplitude:g} x each mesh's grazing amplitude")
    table([done[f] for f in a.factors])
    print(f"\n{time.perf_counter() - t0:.1f} s in all", flush=True)


if __name__ == "__main__":
    main()
