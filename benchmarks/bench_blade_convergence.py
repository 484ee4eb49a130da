"""Does the demo blade's massless nonsmooth mode converge? Three meshes × reduced sizes 8, 16, 32, 64.

For three mesh sizes of the demo blade (its ``[geometry] size`` and ``tip_size`` scaled by 1.4, 1, 0.7) the demo
study (massless contact on the area-weighted tip face, ``[search] ipp = [1]``, periods [0.95, 1.0001] T1) is run as
a comparison study, ``[reduction] sizes = [8, 16, 32, 64]``, through ``bladecase.study.run`` (one FE model per
mesh, reused by every size; ``comparison.csv`` and ``comparison_convergence.png`` in ``<out>/mesh_x<scale>/``).
With ``--exact`` the exact massless condensation (``size=None``, interior at most ``MASSLESS_DENSE_LIMIT`` dofs:
the coarsest mesh only) is added, searched in the same period window — off by default: its dense phases take 18 s
and each closing residual 1-5 s at 3091 interior dofs, so its search did not end within 5 min of CPU.

Printed per mesh, one row per model: reduced dofs, first frequency, contact stiffness k_c, static compliance
wᵀK⁻¹w, grazing energy E_g = ½ω₁²(d/b₁)², number of admissible arcs, the grazing arc (T/T1), the lowest
admissible energy at three common periods inside every grazing arc, as E/E_g − 1 (the part that is not the
linear mode's; every one-phase orbit of the period is found by a scan of the contact time), the number of
one-phase orbits at the middle period, and the branch's orbit at 0.999, 0.99, 0.97 T1 (energy, admissible or
not). Then the relative changes between successive sizes and between meshes (largest size), the observed order
where three values are monotone, and the verdict against the convergence goal: < 1 % change between the two finest.
Newton's law on the tip node (lanczos-si, same sizes, 1 ipp) follows for contrast. T1: each mesh's FE period.

Run: OPENBLAS_NUM_THREADS=1 nice .venv/bin/python benchmarks/bench_blade_convergence.py [--quick] [--out DIR]
     [--exact] [--no-newton]       (about a minute; --quick: meshes ×1.4, ×1, sizes 8, 16)
"""

from __future__ import annotations

import argparse
import json
import time
import warnings
from pathlib import Path

import numpy as np
from scipy.linalg import LinAlgWarning
from scipy.optimize import brentq

import bladecase as bc
from bladecase.nsm import MASSLESS_DENSE_LIMIT
from bladecase.nsm.massless.orbits import SymmetricOrbit, closing_residual, orbit_at_period
from bladecase.post.comparison.compare import ModelResult, contact_spectrum
from bladecase.post.comparison.table import convergence_verdict
from bladecase.study import demo_study, stages
from bladecase.study.run import run
from bladecase.study.schema import validate

MESHES = (1.4, 1.0, 0.7)
SIZES = (8, 16, 32, 64)
#: Periods (× T1) of the branch's orbit shown whether admissible or not (below the grazing arcs).
BELOW = (0.999, 0.99, 0.97)
GOAL = 0.01


def scaled_study(scale: float, sizes: tuple[int, ...], contact_model: str = "massless"):
    """The demo study (massless or Newton variant) with its mesh sizes × ``scale``, a comparison grid over
    ``sizes``, no animation and no reference check (the comparison is what is measured)."""
    st = demo_study(contact_model)
    raw = {sec: {k: v for k, v in keys.items() if v is not None} for sec, keys in st.config.items()}
    raw["study"]["name"] = f"demo-{contact_model}-x{scale:g}"
    raw["geometry"]["size"] *= scale
    raw["geometry"]["tip_size"] *= scale
    raw["reduction"]["size"] = sizes[0]
    raw["reduction"]["sizes"] = list(sizes)
    if contact_model == "newton":
        raw["search"]["ipp"] = [1]
    raw["output"].update(animate=0, reference=False, formats=["png"])
    return validate(raw, source=f"<demo {contact_model} × {scale:g}>")


def grazing_energy(system) -> float:
    """Energy of the first linear mode whose contact displacement just reaches the gap: ½ ω₁² (d / b₁)²."""
    sp = system.spectrum
    return 0.5 * (sp.omega[0] * system.gap / sp.b[0]) ** 2


def orbits_at(branch, T: float) -> list:
    """The branch's orbits of period ``T``: ``Branch.orbit_at`` (Newton) or, massless,
    ``bladecase.nsm.massless.orbits.orbit_at_period`` from the interpolated contact half-time of each pair of
    neighbours that brackets ``T``."""
    system = branch.system
    if getattr(system, "contact_model", "newton") != "massless":
        return branch.orbit_at(T)
    out = []
    for o1, o2 in zip(branch.orbits[:-1], branch.orbits[1:]):
        if o1 is None or o2 is None or o1.T == o2.T or not min(o1.T, o2.T) <= T <= max(o1.T, o2.T):
            continue
        s = (T - o1.T) / (o2.T - o1.T)
        orbit = orbit_at_period(system, T, (1 - s) * o1.beta + s * o2.beta)
        out += [] if orbit is None else [orbit]
    return out


def scan_orbits(system, T: float, count: int = 400, top: float = 0.05) -> list:
    """Every one-contact-phase orbit of period ``T`` with contact half-time ``β`` in [1e-9 T, ``top`` T]: sign
    changes of the closing residual on a geometric grid of ``count`` values of β, each refined by ``brentq`` and
    kept when the residual vanishes there (a sign change across a pole of the residual — an internal resonance —
    is dropped). Independent of how densely the continuation sampled the branch: along the blade's branch the
    period zig-zags within 1e-5 T1 of grazing, and admissible orbits between two computed points of larger
    period are missed by interpolation."""
    def r(beta: float) -> float:
        return closing_residual(system, T / 2 - beta, beta)[1]

    grid = np.geomspace(1e-9 * T, top * T, count)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LinAlgWarning)  # exactly on a pole of the residual: NaN, skipped
        vals = np.array([r(b) for b in grid])
    out = []
    for lo, hi, rlo, rhi in zip(grid[:-1], grid[1:], vals[:-1], vals[1:]):
        if not np.sign(rlo) * np.sign(rhi) < 0:
            continue
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", LinAlgWarning)
                beta = brentq(r, lo, hi, xtol=1e-16 * T, rtol=1e-14)
        except ValueError:  # NaN inside the bracket: a pole hit exactly
            continue
        a, res = closing_residual(system, T / 2 - beta, beta)
        if abs(res) <= 1e-8 * system.gap:
            out.append(SymmetricOrbit(system, T / 2 - beta, beta, a))
    return out


def lowest_orbit(branches, T: float, admissible_only: bool):
    """The lowest-energy orbit of period ``T`` on the branches (admissible ones only, or any), or ``None``."""
    orbits = [o for b in branches for o in orbits_at(b, T) if o.admissible or not admissible_only]
    return min(orbits, key=lambda o: o.energy, default=None)


def grazing_arc(branches, T1: float) -> tuple[float, float] | None:
    """The admissible arc that reaches highest in T (the one grown from grazing), as (T_lo, T_hi) / T1."""
    arcs = [(a.T_lo / T1, a.T_hi / T1) for b in branches for a in b.arcs]
    return max(arcs, key=lambda a: a[1], default=None)


def measures(entry: ModelResult, T1: float) -> dict:
    """Size-independent record of one model (everything but the energies at the common periods)."""
    r, br = entry.reduced, entry.branches
    spec = contact_spectrum(r)
    rec = {"model": entry.name or f"{r.method}-{r.size}", "size": r.size, "dofs": r.n,
           "f1_hz": float(spec.omega[0] / (2 * np.pi)), "static_compliance": spec.static_compliance,
           "arcs": sum(len(b.arcs) for b in br), "graze_arc": grazing_arc(br, T1),
           "search_s": entry.search_s, "T1_s": T1}
    if getattr(r.system, "contact_model", "newton") == "massless":
        rec |= {"kc": r.system.kc, "E_graze": grazing_energy(r.system)}
    else:
        rec |= {"impact_mass": spec.impact_mass}
    for x in BELOW:
        o = lowest_orbit(br, x * T1, admissible_only=False)
        rec[f"E_{x:g}"] = None if o is None else (float(o.energy), bool(o.admissible))
    return rec


def exact_entry(res, study) -> ModelResult | None:
    """The exact massless condensation of the run's FE model, searched like the others; ``None`` when too large."""
    model = res.fe_model
    contact = next(iter(res.models.values())).reduced.contact
    n_interior = model.n_dofs - int(np.count_nonzero(contact.w(model)))
    if n_interior > MASSLESS_DENSE_LIMIT:
        return None
    t0 = time.perf_counter()
    exact = bc.reduce(model, contact, "massless", None)
    t1 = time.perf_counter()
    found = stages.search(study, exact.system, unit=res.summary["search"]["period_unit_s"], label="exact")
    return ModelResult(exact, found, t1 - t0, time.perf_counter() - t1, "massless-exact")


def run_mesh(scale: float, sizes, out: Path, contact_model: str, exact: bool) -> list[tuple[ModelResult, dict]]:
    """One mesh: the comparison study through ``bladecase.study.run`` (+ the exact model); entries and records."""
    study = scaled_study(scale, sizes, contact_model)
    t0 = time.perf_counter()
    res = run(study, out / f"{contact_model}_x{scale:g}", progress=False)
    T1 = res.comparison["T1_s"][0]
    entries = list(res.models.values())
    extra = exact_entry(res, study) if exact and contact_model == "massless" else None
    entries += [extra] if extra is not None else []
    recs = [measures(e, T1) for e in entries]
    for rec in recs:
        rec["fe_dofs"] = res.fe_model.n_dofs
    print(f"  {contact_model}, mesh × {scale:g}: {res.fe_model}, T1 = {T1 * 1e3:.6f} ms, "
          f"{time.perf_counter() - t0:.0f} s (run {res.summary['timings_s']['total']:.0f} s)", flush=True)
    return list(zip(entries, recs))


def common_periods(table: dict, count: int = 3) -> list[float]:
    """``count`` periods (× T1) inside the grazing arc of every model of every mesh (evenly inside the narrowest)."""
    lo = max(rec["graze_arc"][0] for rows in table.values() for _, rec in rows if rec["graze_arc"])
    return [1 - (1 - lo) * f for f in np.linspace(0.8, 0.2, count)]


def add_energies(table: dict, periods: list[float]) -> None:
    """``E_<x>``: the lowest admissible one-phase energy at ``x`` T1 (:func:`scan_orbits`; ``None``: none there),
    ``n_<x>``: how many one-phase orbits (admissible or not) that period has."""
    for rows in table.values():
        for entry, rec in rows:
            for x in periods:
                found = scan_orbits(entry.reduced.system, x * rec["T1_s"])
                ok = [o.energy for o in found if o.admissible]
                rec[f"E_{x:.8f}"] = float(min(ok)) if ok else None
                rec[f"n_{x:.8f}"] = (len(ok), len(found))


# ----------------------------------------------------------------------------- printing


def rel(a, b) -> float | None:
    """|b/a − 1|, ``None`` when either is missing."""
    return None if a is None or b is None or a == 0 else abs(b / a - 1)


def order(q: list[float], h: list[float]) -> float | None:
    """Observed order p of three values on grids ``h``: (q1−q2)/(q2−q3) = (h1^p−h2^p)/(h2^p−h3^p); ``None`` when
    the differences change sign (not monotone), are at round-off (below 1e-8 relative) or no p in (0.05, 10) fits."""
    d1, d2 = q[0] - q[1], q[1] - q[2]
    if min(abs(d1), abs(d2)) <= 1e-8 * abs(q[1]) or (d1 > 0) != (d2 > 0):
        return None
    ratio = d1 / d2

    def f(p: float) -> float:
        return (h[0] ** p - h[1] ** p) / (h[1] ** p - h[2] ** p) - ratio

    try:
        return brentq(f, 0.05, 10.0)
    except ValueError:
        return None


def fmt(x, spec: str = ".6g") -> str:
    if x is None:
        return "—"
    if isinstance(x, tuple) and len(x) == 2 and isinstance(x[1], bool):
        return f"{x[0]:.4g}{'' if x[1] else ' (not adm.)'}"
    if isinstance(x, tuple):
        return f"[{x[0]:.7f}, {x[1]:.7f}]"
    return format(x, spec) if isinstance(x, float) else str(x)


def excess(rec: dict, key: str) -> float | None:
    """E/E_g − 1 at one common period (the part of the energy that is not the grazing linear mode's)."""
    return None if rec.get(key) is None else rec[key] / rec["E_graze"] - 1


def print_mesh(scale: float, rows, periods: list[float]) -> None:
    """The massless table of one mesh, then the successive relative changes and observed orders over sizes."""
    keys = [f"E_{x:.8f}" for x in periods]
    print(f"\nmassless, tip face (area weights), mesh × {scale:g} ({rows[0][1]['fe_dofs']} FE dofs)")
    head = ["model", "dofs", "f1 (Hz)", "k_c (N/m)", "wᵀK⁻¹w (m/N)", "E_g (J)", "arcs", "grazing arc / T1",
            *[f"E/E_g−1 @{x:.7f}" for x in periods], "orbits adm/all @mid", *[f"E @{x:g} (J)" for x in BELOW]]
    print(" | ".join(head))
    for _, r in rows:
        cells = [r["model"], r["dofs"], fmt(r["f1_hz"], ".7g"), fmt(r["kc"], ".5g"), fmt(r["static_compliance"], ".7g"),
                 fmt(r["E_graze"], ".7g"), r["arcs"], fmt(r["graze_arc"]), *[fmt(excess(r, k), ".4g") for k in keys],
                 "{}/{}".format(*r[f"n_{periods[len(periods) // 2]:.8f}"]), *[fmt(r[f"E_{x:g}"]) for x in BELOW]]
        print(" | ".join(map(str, cells)))
    sized = [r for _, r in rows if r["size"] is not None]
    print("  relative change between successive sizes:")
    quantities = {"f1": lambda r: r["f1_hz"], "E_g": lambda r: r["E_graze"],
                  "arc width": lambda r: 1 - r["graze_arc"][0] if r["graze_arc"] else None,
                  **{f"E @{x:.7f}": (lambda r, k=k: r[k]) for x, k in zip(periods, keys)},
                  **{f"E−E_g @{x:.7f}": (lambda r, k=k: None if r[k] is None else r[k] - r["E_graze"])
                     for x, k in zip(periods, keys)}}
    for name, get in quantities.items():
        vals = [get(r) for r in sized]
        steps = [rel(a, b) for a, b in zip(vals[:-1], vals[1:])]
        orders = [order(vals[i:i + 3], [1 / s["size"] for s in sized[i:i + 3]]) if None not in vals[i:i + 3]
                  else None for i in range(len(vals) - 2)]
        print(f"    {name:>22}: " + ", ".join(f"{a['size']}→{b['size']}: {fmt(s, '.2e')}"
                                             for a, b, s in zip(sized[:-1], sized[1:], steps))
              + "; observed order " + (", ".join(fmt(p, ".2f") for p in orders) or "—"))
    verdict, delta = convergence_verdict(sized[-2], sized[-1], keys, GOAL)
    print(f"  verdict (energies at the common periods, sizes {sized[-2]['size']} → {sized[-1]['size']}): {verdict}"
          + ("" if delta is None else f" (Δ = {delta:.2e})"))


def print_meshes(table: dict, periods: list[float]) -> dict:
    """Across meshes: the largest size of each mesh side by side, relative changes, observed order in h."""
    scales = sorted(table, reverse=True)
    finest = {s: max((r for _, r in table[s] if r["size"] is not None), key=lambda r: r["size"]) for s in scales}
    keys = [f"E_{x:.8f}" for x in periods]
    quantities = {"f1 (Hz)": lambda r: r["f1_hz"], "k_c (N/m)": lambda r: r["kc"],
                  "wᵀK⁻¹w (m/N)": lambda r: r["static_compliance"], "E_g (J)": lambda r: r["E_graze"],
                  "grazing arc width / T1": lambda r: 1 - r["graze_arc"][0] if r["graze_arc"] else None,
                  **{f"E @{x:.7f} T1 (J)": (lambda r, k=k: r[k]) for x, k in zip(periods, keys)},
                  **{f"E/E_g−1 @{x:.7f} T1": (lambda r, k=k: excess(r, k)) for x, k in zip(periods, keys)},
                  **{f"E @{x:g} T1 (J)": (lambda r, x=x: None if r[f"E_{x:g}"] is None else r[f"E_{x:g}"][0])
                     for x in BELOW}}
    size = finest[scales[0]]["size"]
    print(f"\nacross meshes (massless-{size} of each; h = mesh scale "
          + ", ".join(f"{s:g} ({finest[s]['fe_dofs']} FE dofs)" for s in scales) + ")")
    print(" | ".join(["quantity", *[f"× {s:g}" for s in scales], *[f"Δ ×{a:g}→×{b:g}" for a, b in
                                                                    zip(scales[:-1], scales[1:])], "order"]))
    out = {}
    for name, get in quantities.items():
        vals = [get(finest[s]) for s in scales]
        steps = [rel(a, b) for a, b in zip(vals[:-1], vals[1:])]
        p = order(vals, scales) if len(vals) == 3 and None not in vals else None
        out[name] = {"values": vals, "changes": steps, "order": p}
        print(" | ".join([name, *[fmt(v, ".7g") for v in vals], *[fmt(s, ".2e") for s in steps], fmt(p, ".2f")]))
    last = out[f"E @{periods[len(periods) // 2]:.7f} T1 (J)"]["changes"][-1]
    ok = all(v["changes"][-1] is not None and v["changes"][-1] < GOAL for k, v in out.items()
             if k.startswith("E @") and "T1 (J)" in k and not any(k == f"E @{x:g} T1 (J)" for x in BELOW))
    print(f"  verdict across meshes (energies at the common periods, two finest meshes): "
          f"{'converged (<1 %)' if ok else 'NOT converged'}; middle period: {fmt(last, '.2e')}")
    return out


def print_newton(scale: float, rows) -> None:
    """The Newton contrast of one mesh: tip node, lanczos-si sizes."""
    print(f"\nNewton's law, tip node (lanczos-si), mesh × {scale:g} ({rows[0][1]['fe_dofs']} FE dofs)")
    print(" | ".join(["model", "dofs", "f1 (Hz)", "impact mass 1/Σb² (kg)", "wᵀK⁻¹w (m/N)", "arcs",
                      "highest arc / T1", *[f"E @{x:g} (J)" for x in BELOW]]))
    for _, r in rows:
        print(" | ".join(map(str, [r["model"], r["dofs"], fmt(r["f1_hz"], ".7g"), fmt(r["impact_mass"], ".4g"),
                                   fmt(r["static_compliance"], ".7g"), r["arcs"], fmt(r["graze_arc"]),
                                   *[fmt(r[f"E_{x:g}"]) for x in BELOW]])))
    ims = [r["impact_mass"] for _, r in rows]
    print("  impact mass, successive sizes: " + ", ".join(f"×{a / b:.3g}" for a, b in zip(ims[:-1], ims[1:]))
          + " (it falls with the size: the tip node's own inertia, ever smaller)")


def figure(table: dict, periods: list[float], path: Path) -> None:
    """Arc width and energy excess against the reduced size, one line per mesh."""
    from bladecase.post.plots import new_figure

    fig = new_figure(figsize=(10, 4), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    key = f"E_{periods[len(periods) // 2]:.8f}"
    for s in sorted(table, reverse=True):
        rows = [r for _, r in table[s] if r["size"] is not None]
        n = [r["size"] for r in rows]
        ax1.semilogy(n, [1 - r["graze_arc"][0] if r["graze_arc"] else np.nan for r in rows], "o-",
                     label=f"mesh × {s:g}")
        ax2.semilogy(n, [abs(excess(r, key)) if r.get(key) is not None else np.nan for r in rows], "o-",
                     label=f"mesh × {s:g}")
    for ax in (ax1, ax2):
        ax.set_xscale("log", base=2)
        ax.set_xlabel("reduced size (massless modes)")
        ax.legend()
    ax1.set_ylabel("grazing arc width (1 − T_lo/T1)")
    ax2.set_ylabel(f"|E/E_g − 1| at {periods[len(periods) // 2]:.7f} T1")
    fig.suptitle("demo blade, massless tip face: the one-contact-phase mode near grazing")
    fig.savefig(path, dpi=110)


def jsonable(table: dict) -> dict:
    return {f"x{s:g}": [r for _, r in rows] for s, rows in table.items()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="meshes ×1.4, ×1, sizes 8, 16")
    ap.add_argument("--out", default="results/blade_convergence", help="folder of the studies and figures")
    ap.add_argument("--exact", action="store_true", help="add the exact massless condensation where small enough")
    ap.add_argument("--no-newton", action="store_true", help="skip the Newton contrast")
    a = ap.parse_args()
    meshes, sizes = ((1.4, 1.0), (8, 16)) if a.quick else (MESHES, SIZES)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    print(f"demo blade, massless tip face: meshes × {meshes}, sizes {sizes}; studies in {out}/", flush=True)
    table = {s: run_mesh(s, sizes, out, "massless", a.exact) for s in meshes}
    periods = common_periods(table)
    add_energies(table, periods)
    print(f"common periods inside every grazing arc: {', '.join(f'{x:.8f}' for x in periods)} T1 "
          "(each mesh's FE T1)")
    for s in meshes:
        print_mesh(s, [r for r in table[s]], periods)
    across = print_meshes(table, periods) if len(meshes) == 3 else {}
    figure(table, periods, out / "blade_convergence.png")
    newton = {}
    if not a.no_newton:
        newton = {s: run_mesh(s, sizes, out, "newton", False) for s in meshes}
        for s in meshes:
            print_newton(s, newton[s])
    doc = {"meshes": list(meshes), "sizes": list(sizes), "common_periods_T1": periods, "massless": jsonable(table),
           "across_meshes": across, "newton": jsonable(newton)}
    (out / "blade_convergence.json").write_text(json.dumps(doc, indent=1, default=float))
    print(f"\nfigures: {out}/<model>_x<scale>/comparison_convergence.png, {out}/blade_convergence.png; "
          f"numbers: {out}/blade_convergence.json; total {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
