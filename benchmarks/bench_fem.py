"""Performance benchmark of the finite-element front end on a ~100k-dof 3-D blade.

Times, one run each (``time.perf_counter``), with the peak resident memory of
the process (``ru_maxrss``) after each stage:

(a) the mesh: ``bladecase.blade_mesh`` of a twisted, tapered NACA 0012 blade
    (span 100 mm, chord 40 → 30 mm, twist 30°, stagger 10°; ``--size`` 1.4 mm
    gives ~110k P2 dofs), or with ``--source plate`` a scikit-fem tensor
    tetrahedral mesh of a 100 × 40 × 4 mm plate (64 × 26 × 2 boxes, ~103k P2
    dofs; no gmsh);
(b) ``bladecase.assemble(mesh, Ti-6Al-4V, order=2)`` (stiffness, consistent
    mass, clamp at the ``root`` group / the ``x = 0`` face);
(c) ``bladecase.natural_frequencies(model, 20)``: sparse LDLᵀ of K
    (``bladecase.linalg.spd_factor``: SuperLU) and shift-invert Lanczos;
    ``--breakdown`` also times the factorisation on its own
    (``bladecase.fe.stiffness_factor``, an extra factorisation), reports its
    fill-in, and times (c') the eigen-solution reusing that factor.

Target: (b) + (c) under 60 s on a 2-core machine.  The script never fails on
a time (exit status 0); ``--json FILE`` writes every figure to ``FILE``.

Run::

    cd /work/main && .venv/bin/python benchmarks/bench_fem.py [--source blade|plate]
        [--size 0.0014] [--order 2] [--mass consistent] [--count 20] [--breakdown] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import resource
import sys
import time
from pathlib import Path

import numpy as np
from bench_core import fmt_time, line, machine, verdict

import bladecase
from bladecase.fe import Mesh, stiffness_factor

#: Target: assembly + eigen-solution in under this many seconds (2-core machine).
TARGET_SECONDS = 60.0


def peak_mb() -> float:
    """Peak resident memory of this process so far (MiB; Linux reports KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def plate_mesh() -> Mesh:
    """scikit-fem tensor tetrahedral mesh of a 100 × 40 × 4 mm plate, group ``root`` at ``x = 0``."""
    from skfem import MeshTet

    m = MeshTet.init_tensor(np.linspace(0, 0.1, 65), np.linspace(0, 0.04, 27), np.linspace(0, 0.004, 3))
    p = m.p.T.copy()
    return Mesh(points=p, cells={"tetra": m.t.T.copy()}, dim=3,
                groups={"root": np.flatnonzero(p[:, 0] < 1e-12)}, source="skfem tensor plate 64x26x2")


def blade(size: float) -> Mesh:
    geometry = bladecase.BladeGeometry(span=0.1, root_chord=0.04, tip_chord=0.03, naca="0012",
                                       twist_deg=30.0, stagger_deg=10.0)
    return bladecase.blade_mesh(geometry, size=size, order=1)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--source", choices=("blade", "plate"), default="blade",
                        help="gmsh NACA blade (default) or skfem tensor plate")
    parser.add_argument("--size", type=float, default=0.0014, help="blade mesh size in m (default 0.0014)")
    parser.add_argument("--order", type=int, choices=(1, 2), default=2, help="element order (default 2)")
    parser.add_argument("--mass", choices=("consistent", "lumped"), default="consistent")
    parser.add_argument("--count", type=int, default=20, help="number of frequencies (default 20)")
    parser.add_argument("--breakdown", action="store_true", help="also time the factorisation of K alone")
    parser.add_argument("--json", metavar="FILE", type=Path, help="also write the figures to FILE (JSON)")
    args = parser.parse_args(argv)

    print("bladecase FE benchmark: assembly and lowest natural frequencies of a 3-D blade")
    info = {"machine": machine()}

    print("\n(a) mesh")
    t0 = time.perf_counter()
    mesh = blade(args.size) if args.source == "blade" else plate_mesh()
    t_mesh = time.perf_counter() - t0
    n_cells = len(mesh.cells[mesh.body_type])
    line("source", mesh.source if args.source == "plate" else f"blade_mesh(NACA 0012 blade, size={args.size:g} m)")
    line("nodes / cells", f"{mesh.points.shape[0]} / {n_cells} {mesh.body_type}")
    line("time", fmt_time(t_mesh))
    line("peak memory", f"{peak_mb():.0f} MiB")

    print(f"\n(b) assemble(order={args.order}, mass={args.mass!r}, clamp='root'), Ti-6Al-4V")
    t0 = time.perf_counter()
    model = bladecase.assemble(mesh, "Ti-6Al-4V", order=args.order, mass=args.mass, clamp="root")
    t_asm = time.perf_counter() - t0
    line("free dofs", f"{model.n_dofs}  ({model.clamped.size} clamped nodes)")
    line("nnz(K) / nnz(M)", f"{model.K.nnz} / {model.M.nnz}")
    line("mass (kg)", f"{model.total_mass:.6g}")
    line("time", fmt_time(t_asm))
    line("peak memory", f"{peak_mb():.0f} MiB")
    info["mesh"] = {"source": args.source, "nodes": int(mesh.points.shape[0]), "cells": n_cells,
                    "seconds": t_mesh}
    info["assemble"] = {"order": args.order, "mass": args.mass, "dofs": model.n_dofs, "nnz_K": int(model.K.nnz),
                        "seconds": t_asm, "peak_MiB": peak_mb()}

    if args.breakdown:
        print("\n(c0) factorisation of K alone (bladecase.fe.stiffness_factor)")
        t0 = time.perf_counter()
        factor = stiffness_factor(model)
        t_lu = time.perf_counter() - t0
        fill, backend = factor.fill, factor.backend
        t0 = time.perf_counter()
        factor.solve(np.ones(model.n_dofs))
        t_solve = time.perf_counter() - t0
        line("backend", backend)
        line("time / fill nnz(L+U)", f"{fmt_time(t_lu)} / {fill} ({fill / model.K.nnz:.1f} x nnz(K))")
        line("one solve", fmt_time(t_solve))
        print(f"\n(c') natural_frequencies(model, {args.count}, factor=...) reusing it")
        t0 = time.perf_counter()
        bladecase.natural_frequencies(model, args.count, factor=factor)
        t_reuse = time.perf_counter() - t0
        del factor
        line("time", fmt_time(t_reuse))
        line("peak memory", f"{peak_mb():.0f} MiB")
        info["factorisation"] = {"backend": backend, "seconds": t_lu, "fill": int(fill),
                                 "solve_seconds": t_solve, "eigen_reusing_seconds": t_reuse}

    print(f"\n(c) natural_frequencies(model, {args.count})")
    t0 = time.perf_counter()
    f = bladecase.natural_frequencies(model, args.count)
    t_eig = time.perf_counter() - t0
    line("time", fmt_time(t_eig))
    line("peak memory", f"{peak_mb():.0f} MiB")
    print("  frequencies (Hz):")
    for i in range(0, f.size, 5):
        print("    " + "  ".join(f"{x:10.2f}" for x in f[i:i + 5]))
    info["eigen"] = {"count": args.count, "seconds": t_eig, "frequencies_Hz": f.tolist(), "peak_MiB": peak_mb()}

    total = t_asm + t_eig
    print("\nSummary")
    line("assembly + eigen-solution", f"{fmt_time(total)}  (target < {TARGET_SECONDS:g} s on 2 cores: "
         f"{verdict(total < TARGET_SECONDS)})")
    line("with meshing", fmt_time(total + t_mesh))
    line("peak memory (ru_maxrss)", f"{peak_mb():.0f} MiB")
    info["total_seconds"] = total
    info["peak_MiB"] = peak_mb()
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(info, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
