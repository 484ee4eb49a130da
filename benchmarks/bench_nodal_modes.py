"""Nonsmooth modes with one contact per tip node (``bladecase.nsm.massless.nodal_modes``): times and figures.

1. The 2-contact chain's family (``tests/test_nodal_modes.py``'s chain, rigid and compliant casing) and the demo
   blade's (``nodal_model(model, contact, 8)``: 34 interior dofs, 26 tip nodes), timed: the blade's to 2 % above
   f₁ (what the test runs) and on to where it stops (an internal resonance).
2. Side by side with the face-mean contact model (``massless_model(model, contact, 8).system``, one constraint:
   the face's mean normal displacement) — its first nonsmooth mode by ``massless_mode``: frequency against energy
   along both, and at a few energies the largest penetration over the 26 tip nodes (each orbit expanded to the
   free dofs, ``reduced.free_dofs``, then ``contact.node_normal_map(model)`` against
   ``contact.node_clearances(model)[0]``, sampled at 2001 instants per period).

Run: .venv/bin/python benchmarks/bench_nodal_modes.py          (about half a minute on an idle 2-core machine)
"""

from __future__ import annotations

import os
import time

import numpy as np

from bladecase.nsm.massless.branches import massless_mode
from bladecase.nsm.massless.follow import solve_at_period
from bladecase.nsm.massless.nodal_modes import nodal_family
from bladecase.nsm.massless.nodes import NodalSystem
from bladecase.reduction.massless import massless_model
from bladecase.reduction.nodes import nodal_model
from bladecase.study.demo import demo_study
from bladecase.study.stages import build_contact, build_mesh, build_model


def chain(casing=np.inf) -> NodalSystem:
    """``tests/test_nodal_modes.py``'s chain: masses (2, 1.5, 0.7), two coupled massless contact points."""
    K = np.zeros((5, 5))
    for i, j, k in ((0, None, 10.0), (0, 1, 8.0), (1, 2, 6.0), (1, 3, 20.0), (2, 4, 15.0), (3, 4, 5.0)):
        K[i, i] += k
        if j is not None:
            K[j, j] += k
            K[i, j] -= k
            K[j, i] -= k
    i, c = [0, 1, 2], [3, 4]
    Kcc, Kci = K[np.ix_(c, c)], K[np.ix_(c, i)]
    return NodalSystem(np.diag([2.0, 1.5, 0.7]), K[np.ix_(i, i)] - Kci.T @ np.linalg.solve(Kcc, Kci),
                       -Kci.T @ np.linalg.inv(Kcc), np.linalg.inv(Kcc), gap=[0.2, 0.3], casing=casing)


def timed(f, *args, **kw):
    t = time.perf_counter()
    out = f(*args, **kw)
    return out, time.perf_counter() - t


def penetration(reduced, orbit, N, d, samples: int = 2001) -> float:
    """Largest ``ν_j·u_j − d_j`` over the tip nodes and one period of ``orbit`` (expanded to the free dofs)."""
    t = np.linspace(0.0, orbit.T, samples)
    X, _ = orbit.state(t)
    U = np.column_stack([reduced.free_dofs(X[:, k]) for k in range(t.size)])
    return float(((N @ U) - d[:, None]).max())


def at_energy(orbits, E: float):
    """The face-mean branch's orbits just below and above ``E`` in energy (the branch's energy increases)."""
    Es = np.array([o.energy for o in orbits])
    i = int(np.clip(np.searchsorted(Es, E), 1, len(orbits) - 1))
    return orbits[i - 1], orbits[i]


def face_at_energy(system, orbits, E: float):
    """The face-mean orbit of energy ``E``: secant on the period between its neighbours on the branch, each
    orbit solved at its period (``solve_at_period``, same phase pattern); the nearest neighbour if that fails;
    ``None`` outside the branch's energies."""
    if not orbits[0].energy <= E <= orbits[-1].energy:
        return None
    a, b = at_energy(orbits, E)
    if a.first != b.first or a.durations.size != b.durations.size:
        return min((a, b), key=lambda o: abs(o.energy - E))
    for _ in range(8):
        if abs(b.energy / E - 1) < 1e-10 or b.energy == a.energy:
            break
        T = b.T + (E - b.energy) * (b.T - a.T) / (b.energy - a.energy)
        o = solve_at_period(system, b.first, b.durations, T)
        if o is None:
            break
        a, b = b, o
    return min((a, b), key=lambda o: abs(o.energy - E))


def main() -> None:
    print(f"load average at start: {os.getloadavg()[0]:.2f} (2-core machine; times are wall-clock)")
    print("\n== 2-contact chain (masses 2, 1.5, 0.7; clearances 0.2, 0.3) to 15 % above f1")
    for casing in (np.inf, 12.0):
        for method in ("energy", "arclength"):
            fam, dt = timed(nodal_family, chain(casing), 0, method=method, freq_ratio=1.15,
                            ds_max=0.2 if method == "arclength" else None)
            print(f"  casing {casing:>4}: {method:9s} {dt * 1e3:7.1f} ms, {len(fam.orbits):3d} orbits, "
                  f"touching changes at {fam.changes}, max residual {max(o.residual for o in fam.orbits):.1e}")

    study = demo_study()
    model = build_model(study, build_mesh(study))
    contact = build_contact(study, model)
    red, dt_red = timed(nodal_model, model, contact, 8)
    s = red.system
    print(f"\n== demo blade, nodal model: {red} ({dt_red:.2f} s)")
    fam2, dt2 = timed(nodal_family, s, 0, freq_ratio=1.02)
    print(f"  to 2 % above f1:   {dt2:6.2f} s, {len(fam2.orbits)} orbits; {fam2.stop}")
    fam, dt = timed(nodal_family, s, 0)
    print(f"  to where it stops: {dt:6.2f} s, {len(fam.orbits)} orbits; {fam.stop}")
    mu = max(o.max_modulus for o in fam.orbits)
    print(f"  max closing residual {max(o.residual for o in fam.orbits):.1e}; stable: "
          f"{sum(o.stable() for o in fam.orbits)}/{len(fam.orbits)}; max |μ| {mu:.6f}")

    face, dt_face = timed(massless_model, model, contact, 8)
    T1 = 2 * np.pi / face.system.open.omega[0]
    branch, dt_b = timed(massless_mode, face.system, (T1 / 1.05, T1))
    fo = list(branch.orbits)
    print(f"\n== demo blade, face-mean model: {face} ({dt_face:.2f} s); massless_mode in (T1/1.05, T1): "
          f"{dt_b:.2f} s, {len(fo)} orbits, {fo[0].frequency:.4f} → {fo[-1].frequency:.4f} Hz, "
          f"E {fo[0].energy * 1e3:.4f} → {fo[-1].energy * 1e3:.4f} mJ")

    print("\n== frequency against energy (every 2nd nodal orbit; the face-mean orbit of the same energy)")
    print(f"  {'E (mJ)':>9} {'f nodal (Hz)':>13} {'touch':>6} {'f face (Hz)':>12}")
    for o in fam.orbits[::2]:
        a = face_at_energy(face.system, fo, o.energy)
        f_face = ("   (linear) " + f"{fo[0].frequency:.4f}"[-9:]) if o.energy < fo[0].energy else \
            (f"{a.frequency:12.4f}" if a is not None else f"{'—':>12}")
        print(f"  {o.energy * 1e3:9.4f} {o.frequency:13.4f} {int(o.touching.sum()):4d}/26 {f_face}")

    N = contact.node_normal_map(model)
    d = contact.node_clearances(model)[0]
    print("\n== largest penetration over the 26 tip nodes (µm) at a few energies")
    print(f"  {'E (mJ)':>9} {'nodal':>8} {'(signals)':>10} {'nodal f':>9} {'face-mean':>10} {'face f':>9} "
          f"{'face E':>9}")
    E_lo, E_hi = fam.orbits[1].energy, fam.orbits[-1].energy
    shape = N @ (face.basis @ face.system.open.phi[:, 0])  # the nodes' normal displacements, first open mode
    for E in np.sort(np.r_[np.geomspace(E_lo, E_hi, 6), fo[0].energy * 1.05]):
        o = fam.at_energy(E)[0] if E < E_hi else fam.orbits[-1]
        a = face_at_energy(face.system, fo, E)
        pn = penetration(red, o, N, d)
        face_cells = (f"{penetration(face, a, N, d) * 1e6:10.2f} {a.frequency:9.3f} {a.energy * 1e3:9.4f}"
                      if a is not None else f"{'—':>30}")
        if E < fo[0].energy:  # the face-mean model is still linear: its first mode scaled to E
            amp = np.sqrt(2 * E) / face.system.open.omega[0]
            pl = max(float((amp * shape - d).max()), float((-amp * shape - d).max()))
            face_cells = f"{pl * 1e6:10.2f} {fo[0].frequency:9.3f} {'linear':>9}"
        print(f"  {E * 1e3:9.4f} {pn * 1e6:8.2f} {o.penetration.max() * 1e6:10.2f} {o.frequency:9.3f} {face_cells}")


if __name__ == "__main__":
    main()
