"""The static centrifugal state of a blade that deflects: linear, second-order and geometrically nonlinear, against
CalculiX's linear and ``NLGEOM`` static steps (each followed by a ``PERTURBATION`` frequency step).

The demo blade (span 150 mm, leaned 30 mm, twisted 40°; P2 tetrahedra = C3D10, Ti-6Al-4V, consistent mass) on a
0.25 m hub spinning about the x axis.  At each speed (default 5000 and 10 000 rpm): f1–f4, the tip's closure along
the casing normal (the demo's contact, the tip face's mean radial displacement), the largest displacement and the
wall time of ``bladecase.fe.rotation.spin`` with ``static`` = ``"linear"``, ``"second-order"``, ``"nonlinear"``,
``"auto"``; where ``ccx`` is installed, CalculiX's linear and ``NLGEOM`` runs of the same mesh (their wall time: the
``ccx`` process, static and frequency steps), the frequencies in per cent of CalculiX ``NLGEOM``'s, and CalculiX's
linear run rebuilt term by term (``--terms``): its static step ``K u = Ω² f₁`` (no load stiffness), its
perturbation stiffness ``K_mat(F(u)) + K_geo(σ_lin(u)) − Ω² M⊥`` (the material stiffness with the static state's
deformation gradient, the geometric stiffness of the linear stress, spin softening).  Finally the lumped mass of
the demo study against the consistent one (the nonlinear state).

    .venv/bin/python benchmarks/bench_nlgeom.py [--rpm 5000 10000] [--terms] [--no-ccx]
"""

from __future__ import annotations

import argparse
import math
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from bladecase.fe import assemble
from bladecase.fe.calculix import run_calculix
from bladecase.fe.nonlinear_static import StVenantKirchhoff
from bladecase.fe.rotation import RotationAxis, _operators, spin
from bladecase.linalg import lowest_modes, spd_factor
from bladecase.study.demo import demo_text
from bladecase.study.schema import loads
from bladecase.study.stages import build_contact, build_mesh

AXIS = RotationAxis((0, 0, -0.25), (1, 0, 0))
STATES = ("linear", "second-order", "nonlinear", "auto")


def frequencies(K, M, count: int = 4) -> np.ndarray:
    K = sp.csr_array(0.5 * (K + K.T))
    return np.sqrt(lowest_modes(K, M, count, factor=spd_factor(K, "K"))[0]) / (2 * math.pi)


class LinearStress(StVenantKirchhoff):
    """The tangent with the linear stress ``σ = C ε(u)`` in place of St-Venant–Kirchhoff's ``S(E(u))``: the material
    stiffness with ``F(u)`` plus the geometric stiffness of the linear stress."""

    def _kinematics(self, U, cells):
        G, F, _ = super()._kinematics(U, cells)
        H = F.copy()
        for i in range(self.dim):
            H[:, i, i, :] -= 1.0
        eps = 0.5 * (H + H.transpose(0, 2, 1, 3))
        S = 2.0 * self.mu * eps
        trace = np.einsum("eiiq->eq", eps)
        for i in range(self.dim):
            S[:, i, i, :] += self.lam * trace
        return G, F, S


def percent(a, b) -> str:
    return "  ".join(f"{x:+7.3f} %" for x in 100 * (np.asarray(a) / np.asarray(b) - 1))


def terms(model, omega: float, ccx_linear) -> None:
    """CalculiX's linear static + perturbation rebuilt term by term (module docstring)."""
    ops = _operators(model, AXIS)
    w2 = omega * omega
    soft = spd_factor(sp.csr_array(model.K - w2 * ops.M_perp)).solve(w2 * ops.f1)
    hard = spd_factor(model.K).solve(w2 * ops.f1)
    linear = LinearStress(model, ops.basis)
    rows = [("bladecase 'linear': (K − Ω²M⊥)u = Ω²f₁, K + K_σ − Ω²M⊥", soft, "sigma"),
            ("static without load stiffness: K u = Ω²f₁, K + K_σ − Ω²M⊥", hard, "sigma"),
            ("K u = Ω²f₁, K_mat(F) + K_geo(σ_lin) − Ω²M⊥", hard, "F"),
            ("K u = Ω²f₁, K_mat(F) + K_geo(σ_lin) (no spin softening)", hard, "F-nosoft"),
            ("(K − Ω²M⊥)u = Ω²f₁, K_mat(F) + K_geo(σ_lin) − Ω²M⊥", soft, "F")]
    print("  CalculiX linear step rebuilt (f1..f4 against CalculiX linear):")
    for words, u, kind in rows:
        if kind == "sigma":
            K = model.K + ops.stress_stiffness(u) - w2 * ops.M_perp
        else:
            K = linear.tangent(u) - (0.0 if kind == "F-nosoft" else w2) * ops.M_perp
        print(f"    {words:62s} {percent(frequencies(K, model.M), ccx_linear)}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rpm", type=float, nargs="+", default=[5000.0, 10000.0])
    parser.add_argument("--terms", action="store_true", help="rebuild CalculiX's linear run term by term")
    parser.add_argument("--no-ccx", action="store_true")
    args = parser.parse_args()
    study = loads(demo_text(), source="demo")
    mesh = build_mesh(study)
    model = assemble(mesh, "Ti-6Al-4V", order=2, mass="consistent", clamp="root")
    lumped = assemble(mesh, "Ti-6Al-4V", order=2, mass="lumped", clamp="root")
    w = build_contact(study, model).w(model)
    ccx = shutil.which("ccx") is not None and not args.no_ccx
    print(f"demo blade: {model.n_dofs} dofs (P2 tetrahedra = C3D10, consistent mass), hub 0.25 m, axis x; "
          f"CalculiX: {'ccx ' + shutil.which('ccx') if ccx else 'not run'}")
    for rpm in args.rpm:
        omega = rpm * 2 * math.pi / 60
        print(f"\n{rpm:.0f} rpm ({omega:.1f} rad/s)")
        rows = {}
        for static in STATES:
            t0 = time.perf_counter()
            state = spin(model, omega, AXIS, static=static)
            seconds = time.perf_counter() - t0
            f = np.sqrt(lowest_modes(state.model.K, state.model.M, 4, factor=state.factor)[0]) / (2 * math.pi)
            rows[static] = (f, seconds, state)
        reference = None
        if ccx:
            with tempfile.TemporaryDirectory() as tmp:
                for nlgeom in (False, True):
                    t0 = time.perf_counter()
                    f = run_calculix(model, Path(tmp), 4, name="blade", speed=omega, axis=AXIS, nlgeom=nlgeom)
                    rows["CalculiX NLGEOM" if nlgeom else "CalculiX linear"] = (f, time.perf_counter() - t0, None)
            reference = rows["CalculiX NLGEOM"][0]
        print(f"  {'state':16s} {'closure':>8s} {'max |u|':>8s} {'iter':>5s} {'time':>7s}   "
              f"{'f1':>8s} {'f2':>8s} {'f3':>8s} {'f4':>8s} Hz" + ("   vs CalculiX NLGEOM" if ccx else ""))
        for name, (f, seconds, state) in rows.items():
            closure = f"{w @ state.displacement * 1e3:7.2f}" if state is not None else "      -"
            peak = f"{np.abs(state.displacement).max() * 1e3:7.2f}" if state is not None else "      -"
            label = name if state is None or name == state.static else f"{name}->{state.static}"
            its = str(state.iterations) if state is not None else "-"
            print(f"  {label:16s} {closure:>8s} {peak:>8s} {its:>5s} {seconds:6.2f}s   "
                  + " ".join(f"{x:8.2f}" for x in f) + (f"   {percent(f, reference)}" if ccx else ""))
        if ccx:
            print(f"  bladecase 'linear' vs CalculiX linear: {percent(rows['linear'][0], rows['CalculiX linear'][0])}")
            if args.terms:
                terms(model, omega, rows["CalculiX linear"][0])
        state = spin(lumped, omega, AXIS, static="nonlinear")
        f = np.sqrt(lowest_modes(state.model.K, state.model.M, 4, factor=state.factor)[0]) / (2 * math.pi)
        print(f"  lumped mass (HRZ: M, M⊥, f₁ lumped), nonlinear: {percent(f, rows['nonlinear'][0])} against the "
              f"consistent mass; closure {w @ state.displacement * 1e3:.2f} mm")


if __name__ == "__main__":
    main()
