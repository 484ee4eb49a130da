"""The demo blade's first nonsmooth mode against a compliant casing: does it converge?

The massless contact on the area-weighted tip face (the demo's) in series with a casing of stiffness ``k_casing``
(``[contact] casing_stiffness``; ``inf`` = rigid). For each casing stiffness, each mesh (the demo's ``[geometry]
size`` and ``tip_size`` scaled by 1.4, 1, 0.7 — and 0.5, 0.35 with ``--fine``) and each reduced size (massless
method, 8, 16, 32, 64): the first open frequency f₁, the grazing energy ``E_g = ½ω₁²(d/b₁)²`` and, at the periods
``T/T₁`` of ``--ratios``, the energy of the backbone's orbit: the smoothest one-phase orbit of that period
(``smoothest`` of every orbit ``orbits_at_period`` finds, bladecase.nsm.massless.orbits; admissible ones first),
so that a narrow internal-resonance tongue elsewhere on the branch does not hide it; whether it is admissible
(proved), and its contact fraction of the period. Then the relative changes between the two largest sizes (per
mesh) and between the two finest meshes (largest size), of admissible orbits only, with the observed order
where three meshes are monotone, and the verdict against the convergence goal: < 1 % between the two finest.

Run: OPENBLAS_NUM_THREADS=1 nice .venv/bin/python benchmarks/bench_blade_casing.py [--fine] [--quick]
     [--casing 1e6,inf] [--ratios 0.995,0.99,0.98] [--scales 0.7,0.5,0.35,0.25] [--json FILE]
     (default: casings 1e6 and inf, meshes ×1.4, ×1, ×0.7, sizes 8–64: about 3 min; --fine adds the 22k- and
     51k-dof meshes, about 10 min more; --quick: meshes ×1.4, ×1 and sizes 8, 16)
"""

from __future__ import annotations

import argparse
import json
import time
import warnings

import numpy as np
from scipy.linalg import LinAlgWarning

import bladecase as bc
from bladecase.fe import stiffness_factor
from bladecase.nsm import series_stiffness
from bladecase.nsm.massless.orbits import orbits_at_period, smoothest
from bladecase.post.comparison.plots import observed_order as observed_order_of
from bladecase.study import demo_study, stages

GOAL = 0.01


def demo_model(scale: float):
    """The demo blade's FE model and tip-face contact with the mesh sizes × ``scale``."""
    st = demo_study()
    st.config["geometry"]["size"] *= scale
    st.config["geometry"]["tip_size"] *= scale
    model = stages.build_model(st, stages.build_mesh(st))
    return model, stages.build_contact(st, model).with_casing(float("inf"))  # the casing is applied per row


def measure(system, ratios) -> dict:
    """f₁, E_g and the backbone orbit at each ``T/T₁`` of ``ratios``."""
    sp = system.spectrum
    T1 = 2 * np.pi / sp.omega[0]
    Eg = 0.5 * (sp.omega[0] * system.gap / sp.b[0]) ** 2
    rec = {"f1": sp.omega[0] / (2 * np.pi), "Eg": Eg, "kc": system.kc, "points": []}
    for x in ratios:
        found = orbits_at_period(system, x * T1, samples=400)
        proved = [o for o in found if o.admissible]  # the backbone's orbit is admissible where one is
        o = smoothest(proved or found, modes=min(10, system.n // 2))
        rec["points"].append(None if o is None else
                             {"E": o.energy, "E/Eg": o.energy / Eg, "admissible": bool(o.admissible),
                              "contact": 2 * o.beta / o.T})
    return rec


def rel(a, b) -> float:
    return abs(b / a - 1) if a and b and np.isfinite(a) and np.isfinite(b) else float("nan")


def observed_order(q, h) -> float:
    """Order p of values ``q`` on meshes of sizes ``h`` (the library's, in the resolution ``1/h``); NaN unless the
    changes keep their sign and shrink."""
    d = np.diff(q)
    if not np.all(np.isfinite(d)) or np.any(d[1:] * d[:-1] <= 0) or np.any(np.abs(d[1:]) >= np.abs(d[:-1])):
        return float("nan")
    p = observed_order_of(1 / np.asarray(h, dtype=float), q)
    return float("nan") if p is None else p


def value(rec, i, key):
    """The measure of an ADMISSIBLE backbone orbit (NaN: no orbit, or not admissible — nothing to converge)."""
    p = rec["points"][i]
    return float("nan") if p is None or not p["admissible"] else p[key]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fine", action="store_true")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--scales", help="mesh scales instead of the defaults, e.g. 0.7,0.5,0.35,0.25")
    ap.add_argument("--casing", default="1e6,inf")
    ap.add_argument("--ratios", default="0.995,0.99,0.98")
    ap.add_argument("--json")
    args = ap.parse_args()
    warnings.simplefilter("ignore", LinAlgWarning)
    scales = (1.4, 1.0) if args.quick else (1.4, 1.0, 0.7) + ((0.5, 0.35) if args.fine else ())
    if args.scales:
        scales = tuple(float(x) for x in args.scales.split(","))
    sizes = (8, 16) if args.quick else (8, 16, 32, 64)
    casings = [float(x) for x in args.casing.split(",")]
    ratios = [float(x) for x in args.ratios.split(",")]
    t0 = time.perf_counter()
    table = {}
    for scale in scales:
        tm = time.perf_counter()
        model, contact = demo_model(scale)
        factor = stiffness_factor(model)
        reduced = {n: bc.reduce(model, contact, "massless", n, factor=factor).system for n in sizes}
        print(f"mesh ×{scale:g}: {model.n_dofs} dofs (model and reductions {time.perf_counter() - tm:.0f} s)",
              flush=True)
        for kp in casings:
            for n, s in reduced.items():
                s = bc.nsm.MasslessSystem(s.M, s.S, s.w, series_stiffness(s.kc, kp), s.gap, casing=kp)
                rec = measure(s, ratios)
                table[(kp, scale, n)] = rec | {"dofs": model.n_dofs}
                cells = "  ".join("—" if p is None else f"{p['E/Eg']:.6f} {'adm' if p['admissible'] else 'NOT'} "
                                  f"{p['contact']:.3f}" for p in rec["points"])
                print(f"  casing {kp:<6g} size {n:3d}: f1 {rec['f1']:.4f} Hz  E_g {rec['Eg']:.6g} J  "
                      f"E/E_g, proved?, contact/T at T/T1 = {ratios}: {cells}", flush=True)
    print("\nconvergence (relative changes; E = E/E_g × E_g)")
    top = sizes[-1]
    h = [s for s in scales]
    verdicts = {}
    for kp in casings:
        print(f"casing {kp:g} N/m:")
        for i, x in enumerate(ratios):
            for key in ("E/Eg", "E"):
                q = [value(table[(kp, sc, top)], i, key) for sc in scales]
                within = [rel(value(table[(kp, sc, sizes[-2])], i, key), value(table[(kp, sc, top)], i, key))
                          for sc in scales]
                meshes = [rel(q[j], q[j + 1]) for j in range(len(q) - 1)]
                order = observed_order(q[-3:], h[-3:]) if len(q) >= 3 else float("nan")
                ok = np.isfinite(meshes[-1]) and meshes[-1] < GOAL
                verdicts[(kp, x, key)] = ok
                print(f"  T = {x} T1, {key:5s}: sizes {sizes[-2]}→{top}: "
                      + ", ".join(f"{c:.1e}" for c in within)
                      + "; meshes: " + ", ".join(f"{c:.2%}" for c in meshes)
                      + f"; order {order:.2f}; " + ("< 1 % between the two finest: REACHED" if ok else
                                                    "< 1 % between the two finest: NOT reached"))
        for key in ("f1", "Eg"):
            q = [table[(kp, sc, top)][key] for sc in scales]
            print(f"  {key}: " + ", ".join(f"{v:.6g}" for v in q) + "; meshes: "
                  + ", ".join(f"{rel(q[j], q[j + 1]):.2%}" for j in range(len(q) - 1))
                  + (f"; order {observed_order(q[-3:], h[-3:]):.2f}" if len(q) >= 3 else ""))
    print(f"\ntotal {time.perf_counter() - t0:.0f} s")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({f"{k[0]:g}/{k[1]:g}/{k[2]}": v for k, v in table.items()}, fh, indent=1)


if __name__ == "__main__":
    main()
