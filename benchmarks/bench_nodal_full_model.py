"""Held-out check: the demo's every-node orbit flown in the full FE model, by code independent of the tool's
simulators and reduced models.

The tool (``[contact] points = "nodes"``, the demo study) animates one orbit of the nonsmooth mode with every tip
node a massless contact and stores in ``summary.json["files"]["nodal_animations"][0]`` its own re-simulation error
(``verification.return_error``, its 8-mode nodal model) and its estimate of the drift in the FE model
(``full_model_check.drift``: nested Krylov extensions of the nodal model, 32/64/128 dofs).  This script:

1. runs the tool on the demo study with ``points = "nodes"`` (or reads ``--summary`` of such a run);
2. takes the FE model (the tool's assembly: free-dof ``K``, the lumped masses with the contact dofs' mass moved off
   them, each tip node's normal, clearance and casing stiffness) and rebuilds the animated orbit from the tool's
   nodal family (the orbit whose period is the summary's);
3. independently of the tool: factorises ``K`` with SciPy's SuperLU, computes the ``N`` lowest modes of the full
   massless structure (ARPACK shift-invert on ``(K, M)``; ``M`` is zero on the contact dofs, so every mode has the
   contact dofs statically condensed exactly) and adds the exact static correction of the contact forces
   (mode-acceleration: ``K⁻¹W − ΦΩ⁻²ΦᵀW`` from 26 sparse solves) — i.e. every open mode of the full model below
   the ``N``-th, the rest responding statically; ``N`` is raised (default 50, 100, 200, 400) to show the figure has
   converged;
4. flies the orbit's state (the middle of its open phase, expanded to the mesh and projected on the modes) for one
   period: each phase is a closed-form modal flight of its own stiffness (``Ω² + B_A C_A⁻¹B_Aᵀ``, ``C_A`` the
   closed nodes' residual flexibility plus the casing's compliance), each node's signal (its gap while open, its
   force while closed) sampled at 8 points per period of the phase's fastest mode and every sign change bisected to
   machine precision;
5. prints the return error ``‖z(T) − z(0)‖/‖z(0)‖`` in the tool's energy norm (``uᵀKu + u̇ᵀMu̇``, both states open),
   the energy conservation, the switches, the touching nodes against the tool's, and the goal: within ×2 the tool's
   full-model drift, and at most 5e-3.

Run (about a minute on a loaded 2-core machine):

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_nodal_full_model.py [--summary RUN/summary.json]
        [--modes 50 100 200 400]
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from bladecase.nsm.massless.nodal_modes import nodal_family
from bladecase.reduction.nodes import nodal_model
from bladecase.study.demo import demo_text
from bladecase.study.reference import open_start
from bladecase.study.schema import loads
from bladecase.study.stages import build_contact, build_mesh, build_model

GOAL_FACTOR, GOAL_MAX = 2.0, 5e-3


def study_text() -> str:
    """The demo study with ``[contact] points = "nodes"`` (VTK output only: the animation is what is checked)."""
    text = re.sub(r'(?m)^model = "massless".*$', 'model = "massless"\npoints = "nodes"', demo_text())
    return re.sub(r"(?m)^formats = .*$", 'formats = ["vtu"]', text)


def tool_summary(path: str | None) -> dict:
    """The tool's ``summary.json``: read, or from a fresh ``bladecase run`` of :func:`study_text`."""
    if path is None:
        out = Path(tempfile.mkdtemp(prefix="bench_nodal_full_"))
        (out / "study.toml").write_text(study_text())
        t = time.perf_counter()
        subprocess.run([sys.executable, "-m", "bladecase", "run", "--quiet", "--no-progress", "--out",
                        str(out / "run"), str(out / "study.toml")], check=True)
        print(f"tool run: {time.perf_counter() - t:.1f} s -> {out / 'run'}")
        path = out / "run" / "summary.json"
    return json.loads(Path(path).read_text())


# ----------------------------------------------------------------------------- the independent full model


class FullModel:
    """The FE model's lowest ``N`` massless-structure modes with the exact static correction of the nodes' forces."""

    def __init__(self, K, masses, N_map, gap, casing, count: int, lu=None):
        self.K = sp.csc_array(K)
        self.masses = np.asarray(masses, dtype=float)
        self.lu = lu if lu is not None else spla.splu(self.K)
        Wf = N_map.T.toarray()  # (n, m): each node's normal on the free dofs
        op = spla.LinearOperator(self.K.shape, matvec=self.lu.solve, dtype=float)
        lam, Phi = spla.eigsh(self.K, k=count, M=sp.diags_array(self.masses), sigma=0.0, OPinv=op, which="LM")
        order = np.argsort(lam)
        lam, Phi = lam[order], Phi[:, order]
        Phi /= np.sqrt(np.einsum("ik,i,ik->k", Phi, self.masses, Phi))
        self.orthonormality = float(np.abs(Phi.T @ (self.masses[:, None] * Phi) - np.eye(count)).max())
        self.Phi, self.om2 = Phi, lam
        self.B = Phi.T @ Wf  # (N, m)
        KinvW = self.lu.solve(Wf)
        self.Hr = Wf.T @ KinvW - self.B.T @ (self.B / lam[:, None])  # the residual flexibility at the nodes
        self.Hr = 0.5 * (self.Hr + self.Hr.T)
        self.d = np.asarray(gap, dtype=float)
        k = np.asarray(casing, dtype=float)
        self.soft = np.where(np.isfinite(k), 1.0 / np.where(np.isfinite(k), k, 1.0), 0.0)

    def project(self, u, v):
        """Modal coordinates of an open state of the free dofs, and the relative energy-norm residual."""
        Mu, Mv = self.masses * u, self.masses * v
        q, p = self.Phi.T @ Mu, self.Phi.T @ Mv
        r = u - self.Phi @ q
        rv = v - self.Phi @ p
        res = np.sqrt((r @ (self.K @ r) + rv @ (self.masses * rv)) / (u @ (self.K @ u) + v @ Mv))
        return q, p, float(res)

    def phase(self, A):
        """The flight and the signals of the phase with closed set ``A`` (boolean, ``(m,)``)."""
        a = np.flatnonzero(A)
        n = self.om2.size
        if a.size == 0:
            w, U, qs = np.sqrt(self.om2), None, np.zeros(n)
            G, s0 = -self.B.T, self.d.copy()  # open signal −p_j = d_j − B_jᵀq (>= 0 valid)
        else:
            Ba = self.B[:, a]
            Ci = np.linalg.inv(np.diag(self.soft[a]) + self.Hr[np.ix_(a, a)])
            KA = np.diag(self.om2) + Ba @ Ci @ Ba.T
            KA = 0.5 * (KA + KA.T)
            qs = np.linalg.solve(KA, Ba @ (Ci @ self.d[a]))
            w2, U = sla.eigh(KA)
            w = np.sqrt(w2)
            L = Ci @ Ba.T  # λ_A = L q − Ci d_A
            G = -(self.B.T - self.Hr[:, a] @ L)
            s0 = -(self.Hr[:, a] @ (Ci @ self.d[a]) - self.d)
            G[a], s0[a] = L, -(Ci @ self.d[a])
        scale = np.where(A, 1.0, 1.0 / self.d)  # signals made O(1): forces in N, gaps in clearances
        return {"w": w, "U": U, "qs": qs, "G": G * scale[:, None], "s0": s0 * scale, "A": A.copy()}

    def forces(self, ph, q):
        a = np.flatnonzero(ph["A"])
        lam = np.zeros(self.d.size)
        if a.size:
            lam[a] = (ph["G"] @ q + ph["s0"])[a]
        return lam

    def energy(self, ph, q, p) -> float:
        lam = self.forces(ph, q)
        C = self.Hr + np.diag(self.soft)
        return float(0.5 * p @ p + 0.5 * q @ (self.om2 * q) + 0.5 * lam @ C @ lam)


def _coords(ph, q, p):
    y = q - ph["qs"]
    return (y, p) if ph["U"] is None else (ph["U"].T @ y, ph["U"].T @ p)


def _state(ph, eta, deta, t):
    """``q, p`` at the times ``t`` (array) after the phase start, from its eigen-coordinates."""
    w = ph["w"][:, None]
    c, s = np.cos(w * t), np.sin(w * t)
    e, de = eta[:, None] * c + (deta / ph["w"])[:, None] * s, -(eta * ph["w"])[:, None] * s + deta[:, None] * c
    if ph["U"] is not None:
        e, de = ph["U"] @ e, ph["U"] @ de
    return e + ph["qs"][:, None], de


def _signals(ph, eta, deta, t):
    q, _ = _state(ph, eta, deta, np.atleast_1d(t))
    return ph["G"] @ q + ph["s0"][:, None]


def fly(full: FullModel, q0, p0, T: float, samples_per_period: int = 8):
    """One period of exact event-driven flight from an open state: ``(q, p)`` at ``T``, the switch times and nodes,
    the set of nodes that touched, the largest relative energy change at the switches."""
    m = full.d.size
    A = np.zeros(m, dtype=bool)
    t, q, p = 0.0, np.asarray(q0, float), np.asarray(p0, float)
    switches, touched = [], np.zeros(m, dtype=bool)
    fresh = np.zeros(m, dtype=bool)  # nodes that just switched: their signal starts at 0
    ph = full.phase(A)
    E0 = full.energy(ph, q, p)
    e_err = 0.0
    while True:
        ph = full.phase(A)
        eta, deta = _coords(ph, q, p)
        s_now = _signals(ph, eta, deta, 0.0)[:, 0]
        bad = (~fresh) & (s_now < -1e-9)
        if bad.any():  # a node the switch made inconsistent switches at the same instant
            A ^= bad
            fresh |= bad
            switches.append((t, tuple(np.flatnonzero(bad))))
            touched |= A
            continue
        horizon = T - t
        dt = 2 * np.pi / ph["w"].max() / samples_per_period
        n = max(int(np.ceil(horizon / dt)), 2) + 1
        hit = None
        for lo in range(0, n, 2000):
            ts = np.linspace(0.0, horizon, n)[lo:lo + 2001]
            S = _signals(ph, eta, deta, ts)
            valid = S > 0
            for j in range(m):
                if fresh[j]:  # wait until the just-switched node's signal is valid
                    first = np.flatnonzero(valid[j])
                    if not first.size:
                        continue
                    cand = np.flatnonzero(~valid[j, first[0]:]) + first[0]
                else:
                    cand = np.flatnonzero(~valid[j])
                if cand.size and (hit is None or ts[cand[0]] < hit[0]):
                    k = cand[0]
                    hit = (ts[k], ts[k - 1], j) if k > 0 else (ts[k], ts[k], j)
            if hit is not None:
                break
            fresh &= ~(valid.any(axis=1))  # a fresh node that became valid is an ordinary node now
        if hit is None:
            q, p = (z[:, 0] for z in _state(ph, eta, deta, np.array([horizon])))
            return q, p, switches, touched, e_err, E0
        hi, lo_t, j = hit
        lo_t = max(lo_t, 0.0)
        while True:  # bisection to machine precision on node j's signal
            mid = 0.5 * (lo_t + hi)
            if not lo_t < mid < hi:
                break
            if _signals(ph, eta, deta, mid)[j, 0] > 0:
                lo_t = mid
            else:
                hi = mid
        q, p = (z[:, 0] for z in _state(ph, eta, deta, np.array([hi])))
        t += hi
        E_before = full.energy(ph, q, p)
        A[j] = ~A[j]
        fresh = np.zeros(m, dtype=bool)
        fresh[j] = True
        touched |= A
        switches.append((t, (j,)))
        e_err = max(e_err, abs(full.energy(full.phase(A), q, p) - E_before) / E0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--summary", help="summary.json of a run of the demo with points = 'nodes' (default: run it)")
    ap.add_argument("--modes", type=int, nargs="+", default=[50, 100, 200, 400])
    args = ap.parse_args()
    summary = tool_summary(args.summary)
    anim = summary["files"]["nodal_animations"][0]
    nm = summary["nodal_modes"]
    tool_err, tool_full = anim["verification"]["return_error"], anim["full_model_check"]
    print(f"tool: animated every-node orbit T = {anim['T']:.12g} s ({anim['frequency_hz']:.4f} Hz), "
          f"E = {anim['energy_j']:.6g} J, {anim['nodes_touching']} nodes touching")
    print(f"tool: re-simulation in its own {nm['reduced_dofs']}-dof model: return error {tool_err:.2e} "
          f"({anim['verification']['switches']} switches)")
    print(f"tool: FE-model drift estimate (Krylov extensions {tool_full['dofs']} dofs): "
          f"{', '.join(f'{x:.4e}' for x in tool_full['drifts'])} -> {tool_full['drift']:.4e} "
          f"(bound {tool_full['bound']:.1e})")

    t0 = time.perf_counter()
    study = loads(study_text())
    model = build_model(study, build_mesh(study))
    contact = build_contact(study, model)
    nodal = nodal_model(model, contact, study["reduction"]["size"] or 8, residual=True)
    cap = max(nm["face_mean"]["energy_j"]) if nm.get("face_mean") else None
    fam = nodal_family(nodal.system, 0, through_resonances=True, energy_max=cap)
    orbit = min(fam.orbits, key=lambda o: abs(o.T - anim["T"]))
    print(f"FE model: {model.n_dofs} free dofs, {nodal.system.m} contact nodes; tool's orbit rebuilt at "
          f"T = {orbit.T:.12g} s (|ΔT|/T = {abs(orbit.T / anim['T'] - 1):.1e}), E = {orbit.energy:.6g} J "
          f"({time.perf_counter() - t0:.1f} s)")
    ts = open_start(orbit)
    x_r, v_r = (z[:, 0] for z in orbit.state(np.array([ts])))
    u0, v0 = nodal.basis @ x_r, nodal.basis @ v_r  # an open state: no closed-node correction
    labels = np.array(nodal.system.nodes)
    tool_nodes = set(int(x) for x in anim["touching_nodes"].split())

    t1 = time.perf_counter()
    lu = spla.splu(sp.csc_array(model.K))
    top = max(args.modes)
    base = FullModel(model.K, nodal.masses, nodal.normal_map, nodal.system.gap, nodal.system.casing, top, lu)
    f_top = np.sqrt(base.om2[-1]) / (2 * np.pi)
    print(f"full model: SuperLU of K + {top} modes by ARPACK shift-invert ({time.perf_counter() - t1:.1f} s); "
          f"modes 1-4 {np.sqrt(base.om2[:4]) / (2 * np.pi)} Hz, mode {top} {f_top:.4g} Hz; "
          f"M-orthonormality {base.orthonormality:.1e}")
    A = np.asarray(orbit.active)
    edges = [k for k in range(len(A)) if np.any(A[k] != A[k - 1])]  # phase starts that are switches
    tool_times = np.sort(np.mod(np.asarray(orbit.starts)[edges] - ts, orbit.T))
    print(f"{'N':>5} {'f_N Hz':>10} {'proj.res':>9} {'E0 J':>10} {'return err':>11} {'E drift':>9} {'E jump':>8} "
          f"{'switches':>8} {'max dt/T':>9} {'touching':>8}  nodes (vs tool)")
    results = []
    for N in sorted(args.modes):
        fm = base if N == top else _truncate(base, N, model.K, lu, nodal)
        q0, p0, res = fm.project(u0, v0)
        t2 = time.perf_counter()
        qT, pT, sw, touched, e_err, E0 = fly(fm, q0, p0, orbit.T)
        dq, dp = qT - q0, pT - p0
        err = np.sqrt((dq @ (fm.om2 * dq) + dp @ dp) / (q0 @ (fm.om2 * q0) + p0 @ p0))
        ph = fm.phase(np.zeros(fm.d.size, dtype=bool))
        e_drift = abs(fm.energy(ph, qT, pT) / E0 - 1)
        nodes = set(int(x) for x in labels[touched])
        diff = "same" if nodes == tool_nodes else f"+{sorted(nodes - tool_nodes)} -{sorted(tool_nodes - nodes)}"
        mine = np.sort([t for t, _ in sw])
        shift = (f"{np.abs(mine - tool_times).max() / orbit.T:9.1e}" if mine.size == tool_times.size
                 else f"{'n/a':>9}")
        print(f"{N:5d} {np.sqrt(fm.om2[-1]) / (2 * np.pi):10.4g} {res:9.1e} {E0:10.6g} {err:11.4e} {e_drift:9.1e} "
              f"{e_err:8.1e} {len(sw):8d} {shift} {touched.sum():8d}  {diff} ({time.perf_counter() - t2:.1f} s)")
        results.append((N, err, len(sw), nodes))
    N, err, nsw, nodes = results[-1]
    ratio = err / tool_full["drift"]
    print(f"\nfull-model return error (N = {N}): {err:.4e}; tool's FE-model estimate {tool_full['drift']:.4e}: "
          f"ratio {ratio:.3f}; tool's own re-simulation {tool_err:.1e}")
    print(f"switches {nsw} (tool's orbit: {anim['verification']['expected']}); touching nodes: {len(nodes)} "
          f"{'= the tool' if nodes == tool_nodes else '!= the tool'} ({' '.join(str(x) for x in sorted(nodes))})")
    if len(results) > 1:
        print(f"change of the return error from N = {results[-2][0]} to {N}: {abs(err - results[-2][1]):.1e}")
    met = (1 / GOAL_FACTOR <= ratio <= GOAL_FACTOR) and err <= GOAL_MAX
    print(f"goal (within x{GOAL_FACTOR:g} the tool's reported FE-model drift, and <= {GOAL_MAX:g}): "
          f"{'MET' if met else 'NOT MET'}")


def _truncate(base: FullModel, N: int, K, lu, nodal) -> FullModel:
    """``base`` cut to its ``N`` lowest modes, the static correction recomputed for them."""
    fm = FullModel.__new__(FullModel)
    fm.K, fm.masses, fm.lu = base.K, base.masses, lu
    fm.Phi, fm.om2 = base.Phi[:, :N], base.om2[:N]
    fm.orthonormality = base.orthonormality
    Wf = nodal.normal_map.T.toarray()
    fm.B = fm.Phi.T @ Wf
    fm.Hr = Wf.T @ lu.solve(Wf) - fm.B.T @ (fm.B / fm.om2[:, None])
    fm.Hr = 0.5 * (fm.Hr + fm.Hr.T)
    fm.d, fm.soft = base.d, base.soft
    return fm


if __name__ == "__main__":
    main()
