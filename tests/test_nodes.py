"""The massless contact model with one contact per node: exact event-driven simulation against solve_ivp, energy,
the one-contact case, the complementarity problem, the reduced FE model's static compliance, the rub response."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import nnls

from bladecase.nsm import Damping, condense, simulate_massless
from bladecase.nsm.massless.nodes import NodalFlight, NodalSystem, Rub, lcp, simulate_nodes
from bladecase.nsm.massless.rub import rub_response, rub_sweep


def chain(casing=np.inf, masses=(1.0, 1.5, 0.7)) -> NodalSystem:
    """Three masses in a chain from a wall; massless contact points hang off masses 2 and 3 by springs and are
    coupled to each other (so the two contacts interact), condensed exactly."""
    K = np.zeros((5, 5))

    def spring(i, j, k):
        K[i, i] += k
        if j is not None:
            K[j, j] += k
            K[i, j] -= k
            K[j, i] -= k

    spring(0, None, 10.0), spring(0, 1, 8.0), spring(1, 2, 6.0), spring(1, 3, 20.0), spring(2, 4, 15.0)
    spring(3, 4, 5.0)
    i, c = [0, 1, 2], [3, 4]
    Kcc, Kci = K[np.ix_(c, c)], K[np.ix_(c, i)]
    S = K[np.ix_(i, i)] - Kci.T @ np.linalg.solve(Kcc, Kci)
    W = -Kci.T @ np.linalg.solve(Kcc, np.eye(2))
    return NodalSystem(np.diag(masses), S, W, np.linalg.inv(Kcc), gap=[0.2, 0.3], casing=casing)


def reference(s: NodalSystem, x0, v0, t_end, damping=None, rub=None):
    """solve_ivp (DOP853, rtol 1e-12) on ``M x'' + C x' + S x + W λ(x, t) = 0``, λ from the complementarity
    problem at every evaluation, restarted at every switch (events on ``λ_j − s_j``, which changes sign at each).

    The complementarity problem ``λ >= 0``, ``q + Hλ >= 0``, ``λᵀ(q + Hλ) = 0`` (``H`` positive definite: one
    solution) is solved here as the bound-constrained least squares ``min |Rλ + R⁻ᵀq|`` over ``λ >= 0``
    (``H = RᵀR``), with ``R`` and ``R⁻ᵀ`` computed once (tens of thousands of evaluations)."""
    fl = NodalFlight(s, damping, rub)
    Minv = np.linalg.inv(s.M)
    Cq = fl.Cq if fl.Cq is not None else np.zeros((s.n, s.n))
    C = s.M @ fl.phi @ Cq @ fl.phi.T @ s.M
    R = np.linalg.cholesky(s.H).T
    R_inv_t = np.linalg.inv(R).T
    none = np.zeros(s.m)

    def lam(t, x):
        q = fl.gap(t) - s.W.T @ x
        return none if np.all(q >= 0) else nnls(R, -(R_inv_t @ q), maxiter=50 * s.m)[0]

    def rhs(t, z):
        x, v = z[: s.n], z[s.n:]
        return np.concatenate((v, Minv @ (-s.S @ x - C @ v - s.W @ lam(t, x))))

    def event(j):
        def f(t, z):
            x = z[: s.n]
            mu = lam(t, x)
            return mu[j] - (fl.gap(t) - s.W.T @ x + s.H @ mu)[j]
        f.terminal = True
        return f

    events = [event(j) for j in range(s.m)]
    t, z, times = 0.0, np.r_[x0, v0], []
    while t < t_end:
        sol = solve_ivp(rhs, (t, t_end), z, method="DOP853", rtol=1e-12, atol=1e-14, events=events)
        z = sol.y[:, -1]
        if sol.status != 1:
            break
        t = min(e[0] for e in sol.t_events if e.size)
        times.append(t)
        step = solve_ivp(rhs, (t, t + 1e-9), z, method="DOP853", rtol=1e-12, atol=1e-14)  # off the surface
        z, t = step.y[:, -1], t + 1e-9
    return np.array(times), z


X0, V0 = np.array([0.5, -0.3, 0.8]), np.array([0.0, 1.0, -0.5])


@pytest.mark.parametrize("casing", [np.inf, 12.0], ids=["rigid", "compliant"])
def test_two_contacts_against_solve_ivp(casing):
    s = chain(casing)
    tr = simulate_nodes(s, X0, V0, 30.0)
    times, z = reference(s, X0, V0, 30.0)
    assert tr.switch_times.size == times.size >= 40
    assert np.abs(tr.switch_times - times).max() < 1e-9           # measured 1.4e-11 (rigid), 8.5e-11 (compliant)
    assert np.abs(np.r_[tr.x_end, tr.v_end] - z).max() < 1e-8       # measured 1e-10
    assert tr.active.any(axis=0).all() and (tr.active.sum(axis=1) == 2).any()   # both touch, sometimes together


@pytest.mark.parametrize("casing", [np.inf, 12.0], ids=["rigid", "compliant"])
def test_energy_is_conserved_over_thousands_of_switches(casing):
    s = chain(casing)
    tr = simulate_nodes(s, X0, V0, 2000.0)
    assert tr.switch_times.size > 2000
    e0 = s.energy(X0, V0)
    assert abs(s.energy(tr.x_end, tr.v_end) - e0) < 1e-11 * e0    # measured 6e-13 and 1.5e-12


def test_damped_rub_against_solve_ivp():
    s = chain(12.0)
    rub, damping = Rub(lobes=3, amplitude=0.28, speed=1.1, angles=[0.0, 0.7]), Damping(zeta=0.02)
    tr = simulate_nodes(s, np.zeros(3), np.zeros(3), 60.0, damping=damping, rub=rub)
    times, z = reference(s, np.zeros(3), np.zeros(3), 60.0, damping, rub)
    assert tr.switch_times.size == times.size >= 50
    assert np.abs(tr.switch_times - times).max() < 1e-9           # measured 4.7e-11
    assert np.abs(np.r_[tr.x_end, tr.v_end] - z).max() < 1e-8       # measured 5.5e-11


def test_one_contact_is_the_massless_model():
    rng = np.random.default_rng(0)
    A = rng.standard_normal((5, 5))
    K = A @ A.T + 5 * np.eye(5)
    one = condense(np.diag(np.r_[rng.uniform(1, 2, 4), 0.0]), K, np.r_[np.zeros(4), 1.0], gap=0.3)
    nodal = NodalSystem(one.M, one.S, one.w[:, None], np.array([[1 / one.kc]]), gap=[0.3])
    x0, v0 = 3 * rng.standard_normal(4), 3 * rng.standard_normal(4)
    a, b = simulate_massless(one, x0, v0, 50.0), simulate_nodes(nodal, x0, v0, 50.0)
    assert a.switch_times.size == b.switch_times.size > 0
    assert np.abs(a.switch_times - b.switch_times).max() < 1e-13    # measured 4.4e-16
    assert np.abs(a.x_end - b.x_end).max() < 1e-12 and np.abs(a.v_end - b.v_end).max() < 1e-12


def test_lcp_solves_the_complementarity_problem():
    rng = np.random.default_rng(1)
    for m in (1, 3, 26):
        A = rng.standard_normal((m, m))
        H = A @ A.T + 0.1 * np.eye(m)
        q = rng.standard_normal(m)
        lam = lcp(q, H)
        s = q + H @ lam
        scale = np.abs(q).max()
        assert lam.min() >= 0 and s.min() >= -1e-12 * scale and abs(lam @ s) < 1e-10 * scale * (1 + lam.max())


def test_bad_input_is_named():
    with pytest.raises(ValueError, match="clearance"):
        NodalSystem(np.eye(2), 2 * np.eye(2), np.eye(2), np.eye(2), gap=[1.0, -1.0])
    with pytest.raises(ValueError, match="same motion"):
        NodalSystem(np.eye(2), 2 * np.eye(2), np.ones((2, 2)), np.ones((2, 2)), gap=[1.0, 1.0])
    with pytest.raises(ValueError, match="one angle per contact node"):
        NodalFlight(chain(), rub=Rub(2, 0.1, 1.0, [0.0]))
    with pytest.raises(ValueError, match="window"):
        rub_response(chain(5.0), 1.0, 2, 0.1, [0.0, 0.1], revolutions=10, window=6)


def test_rub_response_and_sweep():
    s = chain(12.0)
    slow, fast = rub_sweep(s, [0.3, 0.9], lobes=3, amplitude=0.35, angles=[0.0, 0.7], damping=Damping(zeta=0.05),
                           revolutions=30, window=5)
    assert slow.settled and fast.settled
    assert slow.touching == (0, 1) and fast.touching == (0,)        # the farther node touches only at 0.3 rad/s
    assert (slow.contact_fraction > 0.1).all() and fast.contact_fraction[1] == 0
    np.testing.assert_allclose(slow.penetration, slow.peak_force / 12.0, rtol=1e-12)
    # a node reaches at most its clearance's lowest point plus the casing's yield: u <= d + a + λ/k
    assert np.all(slow.peak_displacement <= s.gap + 0.35 + slow.penetration + 1e-12)
    assert np.all(slow.peak_displacement >= s.gap - 0.35 - 1e-12)   # the touching nodes reach the casing


@pytest.fixture(scope="module")
def strip():
    from skfem import MeshTri

    from bladecase.fe import Mesh, assemble
    from bladecase.reduction import Contact

    t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5))
    p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    mesh = Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 0] == 0),
                                                       "tip": np.flatnonzero(p[:, 0] == 0.1)})
    model = assemble(mesh, "steel", order=1, thickness=0.002, mass="lumped")
    return model, Contact.face(model, "tip", (1.0, 0.0), 1e-4, weights="area")


@pytest.mark.parametrize("residual", [False, True], ids=["attachment vectors", "residual correction"])
def test_nodal_model_static_compliance_is_exact(strip, residual):
    import scipy.sparse.linalg as spla

    from bladecase.reduction.nodes import nodal_model

    model, contact = strip
    reduced = nodal_model(model, contact, 4, residual=residual)
    s = reduced.system
    W = contact.node_normal_map(model).T.toarray()
    exact = W.T @ spla.spsolve(model.K.tocsc(), W)            # every node's static compliance, the full model's
    model_compliance = s.flexibility + s.W.T @ np.linalg.solve(s.S, s.W)
    np.testing.assert_allclose(model_compliance, exact, rtol=1e-9, atol=1e-9 * np.abs(exact).max())
    assert s.n == (4 if residual else 4 + 5)
    # a force on one node: the nodes' static displacements from the expansion match the full model
    f = np.zeros(s.m)
    f[2] = 1.0
    q = np.linalg.solve(s.S, -s.W @ f)
    u = reduced.basis @ q + reduced.closed_shapes @ f
    np.testing.assert_allclose(W.T @ u, -exact @ f, rtol=1e-8, atol=1e-10 * np.abs(exact).max())


def test_one_node_nodal_model_is_the_massless_model(strip):
    from bladecase.reduction import Contact
    from bladecase.reduction.massless import massless_model
    from bladecase.reduction.nodes import nodal_model

    model, face = strip
    node = Contact(face.node, (1.0, 0.0), 1e-4, nodes=(face.node,))
    a = massless_model(model, Contact(face.node, (1.0, 0.0), 1e-4), 6).system
    b = nodal_model(model, node, 6).system
    assert b.m == 1 and b.n == a.n
    assert 1.0 / b.flexibility[0, 0] == pytest.approx(a.kc, rel=1e-12)
    np.testing.assert_allclose(np.sort(b.modes[0]), np.sort(a.open.omega), rtol=1e-10)
