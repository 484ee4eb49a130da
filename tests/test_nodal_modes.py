"""Nonsmooth modes of the massless model with one contact per node (``bladecase.nsm.massless.nodal_modes``).

The references are independent of the shooting code: the one-contact massless model's closed forms (m = 1),
the exact event-driven simulator (orbits re-simulated for 50 periods; a central-difference monodromy) and, on the
demo blade, a richer reduced model (size 20) into which an orbit of the size-8 model is projected.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.linalg as sla

from bladecase.nsm import condense
from bladecase.nsm.massless.branches import massless_mode, massless_orbit_at
from bladecase.nsm.massless.nodal_modes import (
    NodalFamily,
    NodalOrbit,
    flow_map,
    grazing_orbit,
    nodal_family,
    nodal_orbit,
    transfer_state,
)
from bladecase.nsm.massless.nodes import NodalFlight, NodalSystem, simulate_nodes
from bladecase.nsm.massless.orbits import follow_from_grazing


def chain(masses=(2.0, 1.5, 0.7), casing=np.inf) -> NodalSystem:
    """``tests/test_nodes.py``'s chain (three masses from a wall, two coupled massless contact points off masses
    2 and 3, clearances 0.2 and 0.3), here with a heavier first mass by default: ω₂/ω₁ = 2.49 and ω₃/ω₁ = 3.71
    keep the low-order internal resonances (3:1, 4:1) away from the first 15 % of the family (with masses
    (1, 1.5, 0.7), ω₂/ω₁ = 3.02: a 3:1 resonance 0.8 % above grazing)."""
    from test_nodes import chain as nodes_chain

    return nodes_chain(casing, masses)


def energy_norm(s: NodalSystem, x, v) -> float:
    """``√(vᵀMv + xᵀSx)``: the norm of the open-phase energy coordinates."""
    return float(np.sqrt(v @ s.M @ v + x @ s.S @ x))


def returns(orbit: NodalOrbit, periods: int) -> float:
    """Relative state error of the orbit re-simulated by ``simulate_nodes`` for ``periods`` periods."""
    s = orbit.system
    tr = simulate_nodes(s, orbit.x0, orbit.v0, periods * orbit.T)
    return energy_norm(s, tr.x_end - orbit.x0, tr.v_end - orbit.v0) / energy_norm(s, orbit.x0, orbit.v0)


def fd_monodromy(orbit: NodalOrbit, eps: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """``(fd, exact)``: the one-period map's Jacobian by central differences of ``simulate_nodes`` and the
    orbit's monodromy (``monodromy_xv``), both in the open-phase energy coordinates ``(Ωq, p)`` computed here
    (balanced across modes)."""
    s = orbit.system
    w2, phi = sla.eigh(s.S, s.M)
    om = np.sqrt(w2)
    n = s.n
    D = np.r_[om, np.ones(n)]
    y0 = D * np.r_[phi.T @ s.M @ orbit.x0, phi.T @ s.M @ orbit.v0]
    h = eps * np.linalg.norm(y0)

    flight = NodalFlight(s)  # the simulator's phases, cached across the runs

    def period_map(y):
        tr = simulate_nodes(s, phi @ (y[:n] / om), phi @ y[n:], orbit.T, flight=flight)
        return D * np.r_[phi.T @ s.M @ tr.x_end, phi.T @ s.M @ tr.v_end]

    J = np.column_stack([(period_map(y0 + h * e) - period_map(y0 - h * e)) / (2 * h) for e in np.eye(2 * n)])
    S2 = sla.block_diag(phi.T @ s.M, phi.T @ s.M)
    P = sla.block_diag(phi, phi)
    exact = D[:, None] * (S2 @ orbit.monodromy_xv() @ P) / D[None, :]
    return J, exact


# ----------------------------------------------------------------------------- m = 1: the massless model


def one_contact(casing):
    """A 3-mass chain whose last mass hangs a massless contact point by a spring of 15 (clearance 0.3), as the
    one-contact model (``condense``) and as a nodal system with one node."""
    K = np.zeros((4, 4))
    for i, j, k in ((0, None, 10.0), (0, 1, 8.0), (1, 2, 6.0), (2, 3, 15.0)):
        K[i, i] += k
        if j is not None:
            K[j, j] += k
            K[i, j] -= k
            K[j, i] -= k
    one = condense(np.diag([2.0, 1.5, 0.7, 0.0]), K, np.array([0.0, 0.0, 0.0, 1.0]), gap=0.3, casing=casing)
    nodal = NodalSystem(one.M, one.S, one.w[:, None], np.array([[1 / 15.0]]), gap=[0.3], casing=casing)
    return one, nodal


@pytest.mark.parametrize("casing", [np.inf, 5.0], ids=["rigid", "compliant"])
def test_one_contact_family_is_the_massless_models(casing):
    """Every orbit of the nodal family down to 0.93 T₁ has the energy of the one-contact model's symmetric
    one-phase orbit of the same period (closed forms, ``follow_from_grazing`` + ``massless_orbit_at``)."""
    one, nodal = one_contact(casing)
    T1 = 2 * np.pi / nodal.modes[0][0]
    fam = nodal_family(nodal, 0, freq_ratio=1 / 0.93)
    ref = follow_from_grazing(one, 0.93 * T1)
    compared = []
    for o in fam.orbits[1:]:
        if not 0.93 * T1 < o.T < (1 - 1e-5) * T1:
            continue
        at = [r for r in massless_orbit_at(one, ref, o.T) if r.admissible]
        assert at, f"no admissible one-contact orbit at T = {o.T}"
        compared.append(min(abs(r.energy / o.energy - 1) for r in at))
    assert len(compared) >= 7                       # measured 8 (rigid), 9 (compliant) periods
    assert max(compared) < 1e-8                     # measured 6.7e-15 (rigid), 1.0e-14 (compliant)
    assert fam.T[-1] < 0.93 * T1


def test_one_contact_at_the_massless_modes_periods():
    """The other way round: nodal orbits solved at the periods of ``massless_mode``'s orbits (``at_period``)."""
    one, nodal = one_contact(np.inf)
    T1 = 2 * np.pi / nodal.modes[0][0]
    branch = massless_mode(one, (0.95 * T1, T1))
    fam = nodal_family(nodal, 0, freq_ratio=1 / 0.94)
    picks = [o for o in branch.orbits if o.T < (1 - 1e-4) * T1][::2]
    assert len(picks) >= 3                          # measured 4 (T/T₁ = 0.99990 … 0.9601)
    for o in picks:
        (nod,) = fam.at_period(o.T)
        assert nod.T == pytest.approx(o.T, rel=1e-14)
        assert nod.energy == pytest.approx(o.energy, rel=1e-8)   # measured <= 9.6e-14


# ----------------------------------------------------------------------------- two contacts: the chain


@pytest.mark.parametrize("method", ["energy", "arclength"])
@pytest.mark.parametrize("casing", [np.inf, 12.0], ids=["rigid", "compliant"])
def test_chain_family_comes_back_after_50_periods(casing, method):
    s = chain(casing=casing)
    fam = nodal_family(s, 0, method=method, freq_ratio=1.15, ds_max=0.2 if method == "arclength" else None)
    assert isinstance(fam, NodalFamily) and len(fam.orbits) >= 8    # measured 10 to 15
    assert fam.frequency[-1] / fam.frequency[0] >= 1.15
    assert max(o.residual for o in fam.orbits) < 1e-12              # measured 3.7e-15 to 9.8e-14
    # every orbit re-simulated by the exact simulator for 50 periods comes back to itself
    errors = [returns(o, 50) for o in fam.orbits[1:]]
    assert max(errors) < 1e-8                                       # measured 5.9e-13 to 1.1e-12
    # energy monotone along the family (arclength does not impose it)
    assert np.all(np.diff(fam.energy) > 0)
    # the phase sequence changes: node 1 alone first, then both nodes
    touching = [tuple(o.touching.tolist()) for o in fam.orbits]
    assert touching[0] == (False, False) and touching[1] == (True, False) and touching[-1] == (True, True)
    assert any(i >= 2 for i in fam.changes)                         # measured: orbit 6 to 9
    assert {len(o.sequence) for o in fam.orbits} >= {1, 3, 5}       # phases per period: 1, 3, then 5
    # contact fractions and forces are consistent with the sequence
    last = fam.orbits[-1]
    assert np.all(last.contact_fraction > 0) and np.all(last.peak_force > 0)
    assert fam.orbits[1].peak_force[1] == 0 and fam.orbits[1].contact_fraction[1] == 0


def test_chain_peaks_against_the_sampled_orbit():
    """Peak forces and displacements (signals, polished) against a dense sample of the simulated orbit: never
    below it, and above it by less than the sample's own error."""
    s = chain(casing=12.0)
    o = nodal_family(s, 0, freq_ratio=1.15).orbits[-1]
    t = np.linspace(0.0, o.T, 20001)
    tr = simulate_nodes(s, o.x0, o.v0, o.T)
    x, _ = tr.state(t)
    lam = s.forces(x)
    u = s.W.T @ x - s.flexibility @ lam                             # the nodes' normal displacements
    assert np.all(o.peak_force >= lam.max(axis=1) - 1e-12)
    assert np.allclose(o.peak_force, lam.max(axis=1), rtol=1e-8)    # measured 7e-16
    assert np.all(o.peak_displacement >= u.max(axis=1) - 1e-12)
    assert np.allclose(o.peak_displacement, u.max(axis=1), rtol=1e-8)  # measured 2e-16
    assert np.allclose(o.penetration, lam.max(axis=1) / s.casing, rtol=1e-8)


# ----------------------------------------------------------------------------- Floquet


@pytest.mark.parametrize("casing", [np.inf, 12.0], ids=["rigid", "compliant"])
def test_monodromy_against_finite_differences_of_the_simulator(casing):
    fam = nodal_family(chain(casing=casing), 0, freq_ratio=1.15)
    for o in fam.orbits[1::3]:
        fd, exact = fd_monodromy(o)
        assert np.linalg.norm(fd - exact) / np.linalg.norm(exact) < 1e-6      # measured 2.1e-10 to 4.5e-10
        assert abs(np.linalg.det(o.monodromy) - 1) < 1e-10                    # symplectic; measured <= 7.5e-15
        # the trivial pair, split off exactly (time shift, energy direction)
        assert np.abs(o.multipliers[:2] - 1).max() < 1e-8                     # measured <= 2.9e-15
        # a plain eigensolver splits the Jordan block at 1 by ~√ε
        raw = np.linalg.eigvals(o.monodromy)
        near = np.sort(np.abs(raw - 1))[:2]
        assert near.max() < 1e-6                                              # measured 4e-9 to 4.3e-8
        # the non-trivial multipliers are the finite-difference monodromy's other eigenvalues
        mu_fd = np.linalg.eigvals(fd)
        mu_fd = mu_fd[np.argsort(np.abs(mu_fd - 1))[2:]]
        for mu in o.nontrivial_multipliers:
            assert np.abs(mu_fd - mu).min() < 1e-6                            # measured <= 2.6e-10
        assert o.stable()                                                     # this stretch is stable


def test_flow_map_jacobian_is_the_simulators():
    s = chain()
    rng = np.random.default_rng(3)
    q0, p0 = rng.standard_normal(3) * 0.3, rng.standard_normal(3) * 0.3
    qT, pT, J = flow_map(s, q0, p0, 7.0)
    g = grazing_orbit(s)
    phi = g._shooter.flight.phi
    tr = simulate_nodes(s, phi @ q0, phi @ p0, 7.0)
    assert tr.switch_times.size >= 4
    assert np.allclose(phi @ qT, tr.x_end, rtol=0, atol=1e-13) and np.allclose(phi @ pT, tr.v_end, rtol=0, atol=1e-13)
    h = 1e-6
    for i in range(6):
        dz = np.zeros(6)
        dz[i] = h
        a = flow_map(s, q0 + dz[:3], p0 + dz[3:], 7.0)
        b = flow_map(s, q0 - dz[:3], p0 - dz[3:], 7.0)
        col = np.r_[a[0] - b[0], a[1] - b[1]] / (2 * h)
        assert np.abs(col - J[:, i]).max() < 1e-6 * max(1.0, np.abs(J).max())   # measured ~1e-10


# ----------------------------------------------------------------------------- single orbits, failures


def test_orbit_at_period_and_at_energy_agree():
    s = chain(casing=12.0)
    fam = nodal_family(s, 0, freq_ratio=1.15)
    o = fam.orbits[5]
    by_T = nodal_orbit(s, fam.orbits[4], T=o.T)
    by_E = nodal_orbit(s, fam.orbits[6], energy=o.energy)
    for p in (by_T, by_E):
        assert p.T == pytest.approx(o.T, rel=1e-10) and p.energy == pytest.approx(o.energy, rel=1e-10)
        assert np.allclose(p.q0, o.q0, atol=1e-9 * np.abs(o.q0).max())
    (at,) = fam.at_energy(0.5 * (fam.energy[5] + fam.energy[6]))
    assert fam.T[6] < at.T < fam.T[5]


def test_bilinear_oscillator_closed_form():
    """One dof, k₁ = 1, a massless contact point on a spring k₂: period ``2(π − arccos(d/A)) + 2 arccos(·)/ω_c``."""
    for k2 in (0.5, 3.0):
        s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), np.array([[1 / k2]]), gap=[1.0])
        fam = nodal_family(s, 0, freq_ratio=1.2)
        for o in fam.orbits[1:]:
            E, wc = o.energy, np.sqrt(1 + k2)
            A = np.sqrt(2 * E)                               # open-side amplitude (x = −A at t = 0)
            v2 = 2 * E - 1.0                                  # speed² at the clearance x = 1
            xe = k2 / (1 + k2)                                # the closed phase's equilibrium
            B = np.sqrt((1 - xe) ** 2 + v2 / wc**2)
            T = 2 * (np.pi - np.arccos(1 / A)) + 2 * np.arccos((1 - xe) / B) / wc
            assert o.T == pytest.approx(T, rel=1e-12)         # measured 2e-15


def test_failures_are_named():
    s = NodalSystem(np.eye(2), np.diag([1.0, 4.0]), np.array([[1.0], [0.0]]), np.eye(1), gap=[1.0])
    with pytest.raises(ValueError, match="no contact reached"):
        grazing_orbit(s, mode=1)
    with pytest.raises(ValueError, match="mode must be"):
        nodal_family(s, mode=2)
    with pytest.raises(ValueError, match="method must be"):
        nodal_family(s, method="newton")
    with pytest.raises(ValueError, match="freq_ratio"):
        nodal_family(s, freq_ratio=0.9)
    with pytest.raises(ValueError, match="exactly one of T and energy"):
        nodal_orbit(s, grazing_orbit(s))
    # the bilinear oscillator's periods lie in (π + π/√2, 2π]: none at T = 4
    one = NodalSystem(np.eye(1), np.eye(1), np.eye(1), np.eye(1), gap=[1.0])
    with pytest.raises(ValueError, match=r"Newton did not converge at T = [0-9.]+ s: closing residual"):
        nodal_orbit(one, ([-2.0], [0.0], 5.8), T=4.0)


def test_records_are_plain_data():
    fam = nodal_family(chain(), 0, freq_ratio=1.05)
    data = json.loads(json.dumps(fam.to_dict()))
    assert len(data["orbits"]) == len(fam.orbits) and data["orbits"][-1]["T"] == fam.T[-1]
    assert "NodalFamily(mode 0" in repr(fam) and "nodes touch" in repr(fam.orbits[-1])


# ----------------------------------------------------------------------------- the demo blade


@pytest.fixture(scope="module")
def blade():
    from bladecase.reduction.nodes import nodal_model
    from bladecase.study.demo import demo_study
    from bladecase.study.stages import build_contact, build_mesh, build_model

    study = demo_study()
    model = build_model(study, build_mesh(study))
    contact = build_contact(study, model)
    red = nodal_model(model, contact, 8)
    fam = nodal_family(red.system, 0, freq_ratio=1.02)
    return model, contact, red, fam


def test_demo_blade_family(blade):
    _, _, red, fam = blade
    s = red.system
    assert s.n == 34 and s.m == 26
    assert fam.linear_frequency == pytest.approx(210.4997, abs=1e-3)
    assert fam.frequency[-1] / fam.linear_frequency >= 1.02              # measured 1.0208 (214.87 Hz)
    assert max(o.residual for o in fam.orbits) < 1e-10                   # measured 9.7e-14
    assert np.all(np.diff(fam.energy) > 0) and np.all(np.diff(fam.frequency) > 0)
    counts = [int(o.touching.sum()) for o in fam.orbits]
    assert counts[0] == 0 and counts[1] >= 1 and counts[-1] >= 15        # measured 0, 3, …, 17 of 26
    assert len(fam.changes) >= 5                                         # measured 10
    last = fam.orbits[-1]
    assert last.max_tip > s.gap.max() and np.all(last.penetration <= last.max_tip)
    assert all(o.stable() for o in fam.orbits)                           # measured max |μ| = 1 + 6.5e-12
    assert np.abs(last.multipliers[:2] - 1).max() < 1e-8                 # measured 2.3e-11


def test_demo_blade_monodromy_against_finite_differences(blade):
    _, _, _, fam = blade
    o = fam.orbits[len(fam.orbits) // 2]
    fd, exact = fd_monodromy(o)
    assert np.linalg.norm(fd - exact) / np.linalg.norm(exact) < 1e-6      # measured 3.7e-8 (all 68 columns)


def test_demo_blade_orbit_in_a_richer_model(blade):
    """The last orbit (214.9 Hz) expanded to the free dofs and projected onto ``nodal_model(…, 20)``, simulated
    there. Measured relative state error after 1, 5, 20 periods: 3.1e-3, 3.3e-3, 3.2e-3 (a figure, not a
    convergence claim; over the 20 orbits of the family: 2.6e-5 to 9.2e-3, no growth over 20 periods); the
    contact nodes' peak normal displacements over the first period agree to 5.4e-4 (family: <= 5.4e-4)."""
    from bladecase.reduction.nodes import nodal_model

    model, contact, red, fam = blade
    rich = nodal_model(model, contact, 20)
    sr = rich.system
    o = fam.orbits[-1]
    xr, vr = transfer_state(red, rich, o.x0, o.v0)
    assert sr.energy(xr, vr) == pytest.approx(o.energy, rel=1e-3)       # measured 1.3e-10
    tr = simulate_nodes(sr, xr, vr, 20 * o.T)
    size = energy_norm(sr, xr, vr)
    errors = []
    for k in (1, 5, 20):
        x, v = tr.state(k * o.T)
        errors.append(energy_norm(sr, x[:, 0] - xr, v[:, 0] - vr) / size)
    assert max(errors) < 0.05                                            # measured 3.3e-3
    # the nodes' normal displacements (normal map of the expanded free dofs) over one period, both models
    N = contact.node_normal_map(model)
    t = np.linspace(0.0, o.T, 1201)
    X8, _ = o.state(t)
    Xr, _ = tr.state(t)
    peak8 = (N @ np.column_stack([red.free_dofs(X8[:, k]) for k in range(t.size)])).max(axis=1)
    peakr = (N @ np.column_stack([rich.free_dofs(Xr[:, k]) for k in range(t.size)])).max(axis=1)
    assert np.abs(peakr / peak8 - 1).max() < 0.02                        # measured 5.4e-4
    # the orbit's own peak displacements (signals) are the expanded model's, up to the sample
    assert np.all(o.peak_displacement >= peak8 - 1e-12)
    assert np.abs(o.peak_displacement / peak8 - 1).max() < 1e-3          # measured 1.3e-5 (the sample's error)
