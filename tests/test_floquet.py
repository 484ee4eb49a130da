"""Floquet stability of periodic orbits with impacts (``bladecase.nsm.floquet``, theory §6).

The reference is the event-driven simulator (``bladecase.simulate``), never the module's own formulas.
A well-posed finite-difference monodromy: the post-impact state at ``t = 0`` lies ON the obstacle, so half of
the perturbations of the contact position would start beyond it, and at the fixed time ``T`` a perturbed
trajectory has or has not yet had its k-th impact (the state jumps there).  So the map is taken between two
instants in the MIDDLE of a flight: ``z(τ₀) ↦ z(τ₀ + T)``, ``τ₀ = t₁/2``.  Every perturbation is admissible
there, every perturbed trajectory has exactly k impacts in between, and the map is smooth; the change of
impact times is inside the simulated map.  Its Jacobian is ``E(τ₀) · monodromy · E(τ₀)⁻¹``, with the flight
``E(τ) = expm(Aτ)`` of the first-order system (scipy, independent of the modal code).  Central differences with
step ``1e-6·max|z|``: measured agreement 2e-10 to 2e-9 (relative, Frobenius), asserted 1e-6.
"""

from __future__ import annotations

import importlib.util
import pickle
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla
from _util import dense, fd_flow_map, stacked

import bladecase as bc
from bladecase.nsm import Branch
from bladecase.nsm.floquet import FLOQUET_TOL, Floquet, branch_stability, floquet, stable_arcs

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "fig11_stability.py"


@pytest.fixture(scope="module")
def chain5() -> bc.LinearSystem:
    return bc.chain(5, k=1.0, m=0.2, gap=1.0)


def _orbit(system, k: int, T: float, t1: float | None) -> bc.PeriodicOrbit:
    """The 1-ipp orbit of period T, or the admissible 2-ipp orbit of period T whose t₁ is nearest ``t1``."""
    if k == 1:
        return bc.orbit_1ipp(system, T)
    orbits = [o for o in bc.orbits_kipp(system, T, k) if o.admissible and o.repeats == 1]
    o = min(orbits, key=lambda o: abs(o.impact_times[0] - t1))
    assert abs(o.impact_times[0] - t1) < 1e-3, o.impact_times
    return o


def _state_matrix(system) -> np.ndarray:
    M, K = dense(system.M), dense(system.K)
    n = M.shape[0]
    return np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), np.zeros((n, n))]])


def _fd_map(system, orbit, eps: float = 1e-6) -> tuple[np.ndarray, float]:
    """Central-difference Jacobian of ``z(τ₀) ↦ z(τ₀ + T)`` by simulation (module docstring)."""
    tau0 = 0.5 * float(orbit.impact_times[0])
    return fd_flow_map(system, stacked(*orbit.state(tau0)), orbit.T, orbit.k, eps), tau0


# (system fixture, k, T, t₁ of the 2-ipp orbit, stable?) — admissible orbits, measured verdicts in the comments
CASES = [
    ("two_dof", 1, 6.6, None, False),     # flip -1.150
    ("two_dof", 1, 7.0, None, True),
    ("two_dof", 2, 11.0, 4.1473, True),
    ("two_dof", 2, 13.5, 6.0829, False),  # flip -7.02 (the paper's 2-ipp mode)
    ("chain5", 1, 6.0, None, False),      # complex quadruplet, |μ| = 1.225
    ("chain5", 1, 5.3, None, False),      # flip -1.11
    ("chain5", 2, 8.0, 1.0470, False),    # flip -1.30
    ("chain5", 2, 8.0, 1.3936, False),    # real 2.79
    ("random_sys", 1, 1.6102, None, True),  # non-diagonal M, generic w (Moreau's law)
    ("random_sys", 1, 1.9153, None, False),  # flip -1.66
]


@pytest.mark.parametrize("name,k,T,t1,stable", CASES, ids=[f"{c[0]}-{c[1]}ipp-T{c[2]}-{c[3]}" for c in CASES])
def test_monodromy_matches_finite_differences_of_the_simulator(request, name, k, T, t1, stable):
    system = request.getfixturevalue(name)
    orbit = _orbit(system, k, T, t1)
    assert orbit.admissible and orbit.k == k
    fl = floquet(orbit)
    J, tau0 = _fd_map(system, orbit)
    E = sla.expm(_state_matrix(system) * tau0)
    ref = E @ fl.monodromy @ np.linalg.inv(E)
    err = np.linalg.norm(J - ref) / np.linalg.norm(ref)
    assert err <= 1e-6, err
    # the verdict, from the simulator alone: the largest |eigenvalue| of the finite-difference map
    mu_fd = np.linalg.eigvals(J)
    mu_fd = mu_fd[np.argsort(np.abs(mu_fd - 1))[2:]]  # the finite differences split the Jordan pair at 1 by ~1e-5
    assert fl.stable is stable
    assert np.abs(mu_fd).max() == pytest.approx(fl.max_modulus, rel=1e-6)
    for mu in fl.nontrivial:  # every non-trivial multiplier is an eigenvalue of the simulated map (rel 1e-6)
        assert np.abs(mu_fd - mu).min() <= 1e-6 * max(1.0, abs(mu)), mu


def _structure_orbits(two_dof, chain5, random_sys):
    systems = {"two_dof": two_dof, "chain5": chain5, "random_sys": random_sys}
    return [_orbit(systems[c[0]], c[1], c[2], c[3]) for c in CASES]


def test_det_one_trivial_pair_reciprocal_pairs_symplectic(two_dof, chain5, random_sys):
    for orbit in _structure_orbits(two_dof, chain5, random_sys):
        s = orbit.system
        fl = floquet(orbit)
        assert isinstance(fl, Floquet) and fl.tol == FLOQUET_TOL
        Y = fl.monodromy
        n = s.n
        assert Y.shape == (2 * n, 2 * n) and fl.multipliers.shape == (2 * n,)
        assert abs(np.linalg.det(Y) - 1) <= 1e-9, np.linalg.det(Y)
        # the two trivial multipliers: exactly at 1 (split off structurally, to round-off) ...
        assert len(fl.trivial) == 2 and np.abs(fl.multipliers[list(fl.trivial)] - 1).max() <= 1e-9
        # ... and a plain eigensolver finds the double (Jordan) multiplier 1 within ~√ε
        assert np.sort(np.abs(np.linalg.eigvals(Y) - 1))[1] <= 1e-6
        # flow direction fixed, energy gradient a fixed left vector (rel 1e-9)
        x0, v0 = (z[:, 0] for z in orbit.state(0.0))
        M, K = dense(s.M), dense(s.K)
        f = np.concatenate([v0, -np.linalg.solve(M, K @ x0)])
        e = np.concatenate([K @ x0, M @ v0])
        scale = np.linalg.norm(Y, 2)
        assert np.linalg.norm(Y @ f - f) <= 1e-9 * scale * np.linalg.norm(f)
        assert np.linalg.norm(e @ Y - e) <= 1e-9 * scale * np.linalg.norm(e)
        # symplectic in (x, Mv): PᵀJP = J, hence reciprocal pairs
        P = sla.block_diag(np.eye(n), M) @ Y @ sla.block_diag(np.eye(n), np.linalg.inv(M))
        Jm = np.block([[np.zeros((n, n)), np.eye(n)], [-np.eye(n), np.zeros((n, n))]])
        assert np.abs(P.T @ Jm @ P - Jm).max() <= 1e-9 * scale**2
        nt = fl.nontrivial
        for mu in nt:
            assert np.abs(nt - 1 / mu).min() <= 1e-8 * max(abs(mu), 1 / abs(mu)), mu
        # sorted by modulus, descending; max_modulus and the verdict agree with the multipliers
        assert np.all(np.diff(np.abs(fl.multipliers)) <= 1e-12)
        assert fl.max_modulus == pytest.approx(np.abs(nt).max(), rel=1e-15)
        assert fl.stable is bool(fl.max_modulus <= 1 + FLOQUET_TOL)
        assert fl.verdict.startswith("linearly stable" if fl.stable else "unstable")


def test_saltation_matrix_is_the_theory_formula(random_sys):
    """One impact per period: monodromy = S · E(T), and S is theory §6's general formula
    ``D + (F(z⁺) - D F(z⁻)) ∇hᵀ / (∇hᵀ F(z⁻))`` evaluated densely (non-diagonal M, generic w)."""
    s = random_sys
    orbit = bc.orbit_1ipp(s, 1.6102)
    M, K, w = dense(s.M), dense(s.K), s.w
    n = s.n
    x, vp = (z[:, 0] for z in orbit.state(0.0))
    Minv_w = np.linalg.solve(M, w)
    R = np.eye(n) - 2 * np.outer(Minv_w, w) / (w @ Minv_w)
    vm = R @ vp  # R² = I
    acc = -np.linalg.solve(M, K @ x)
    D = sla.block_diag(np.eye(n), R)
    F_minus, F_plus = np.concatenate([vm, acc]), np.concatenate([vp, acc])
    grad_h = np.concatenate([w, np.zeros(n)])
    S = D + np.outer(F_plus - D @ F_minus, grad_h) / (grad_h @ F_minus)
    expected = S @ sla.expm(_state_matrix(s) * orbit.T)
    Y = floquet(orbit).monodromy
    assert np.abs(Y - expected).max() <= 1e-10 * np.abs(expected).max()
    # the closed form of the module docstring: [[R, 0], [(2α/(μu)) M⁻¹w wᵀ, R]]
    mu, u, alpha = w @ Minv_w, w @ vm, w @ acc
    closed = np.block([[R, np.zeros((n, n))], [2 * alpha / (mu * u) * np.outer(Minv_w, w), R]])
    np.testing.assert_allclose(S, closed, rtol=0, atol=1e-12 * np.abs(closed).max())


def test_flip_multiplier_predicts_the_divergence_of_the_simulation(two_dof):
    """The issue: admissible 1-ipp orbits of the paper's 2-dof chain are unstable by a flip; a 1e-9 perturbation
    reaches O(1) after ~ln(1e8)/ln|μ| impacts.  On the Poincaré section (post-impact states) the component of
    the deviation along the flip eigenvector is multiplied by μ at each impact (the time shift has no component
    there: its left eigenvector is orthogonal to the flow direction)."""
    orbit = bc.orbit_1ipp(two_dof, 6.6)
    assert orbit.admissible
    fl = floquet(orbit)
    mu = complex(fl.nontrivial[0])
    assert abs(mu.imag) == 0 and mu.real == pytest.approx(-1.149875, abs=1e-6) and not fl.stable
    assert fl.verdict == "unstable: a multiplier -1.15 (flip) leaves the unit circle"
    vals, left, right = sla.eig(fl.monodromy, left=True, right=True)
    j = int(np.argmin(np.abs(vals - mu)))
    ell, r = left[:, j].real, right[:, j].real
    ell /= ell @ r
    x0, v0 = (z[:, 0] for z in orbit.state(0.0))
    z_star = stacked(x0, v0)
    x = x0.copy()
    x[0] += 1e-9  # the contact position stays at d: a state on the section
    tr = bc.simulate(two_dof, x, v0, 200.5 * orbit.T)
    dev = np.vstack([tr.x, tr.v]) - z_star[:, None]
    c = ell @ dev
    c0 = ell @ (stacked(x, v0) - z_star)
    N = np.arange(1, 91)
    # linear regime (deviation <= 3e-4): c_N = μᴺ c₀ within 1 %, alternating in sign (a flip)
    np.testing.assert_allclose(c[:90] / (mu.real**N * c0), 1.0, rtol=1e-2, atol=0)
    assert np.all(np.sign(c[1:90]) == -np.sign(c[:89]))
    # O(1) reached when predicted: first impact with |δz| >= 0.1 |z*|, within 10 %
    rel = np.linalg.norm(dev, axis=0) / np.linalg.norm(z_star)
    n_sim = int(np.argmax(rel >= 0.1)) + 1
    n_pred = np.log(0.1 * np.linalg.norm(z_star) / (abs(c0) * np.linalg.norm(r))) / np.log(abs(mu))
    assert rel.max() >= 0.1 and abs(n_sim - n_pred) <= 0.1 * n_pred, (n_sim, n_pred)
    assert 100 < n_sim < 200


def test_floquet_is_a_frozen_record(two_dof):
    fl = floquet(bc.orbit_1ipp(two_dof, 7.0), tol=1e-8)
    assert fl.tol == 1e-8 and fl.verdict == "linearly stable: all multipliers on the unit circle within 1e-08"
    with pytest.raises(AttributeError):
        fl.stable = False


def test_one_degree_of_freedom_has_only_the_trivial_pair():
    fl = floquet(bc.orbit_1ipp(bc.chain(1, k=1.0, m=1.0, gap=1.0), 4.0))
    assert fl.monodromy.shape == (2, 2) and fl.trivial == (0, 1) and fl.stable
    assert np.isnan(fl.max_modulus) and fl.nontrivial.size == 0
    np.testing.assert_allclose(fl.multipliers, [1.0, 1.0], rtol=0, atol=1e-12)


# --- orbits that give their own monodromy (the massless contact model) ------


class _GivenMonodromy:
    def __init__(self, Y):
        self._Y = Y

    def monodromy(self):
        return self._Y


def test_an_orbit_with_its_own_monodromy(two_dof, chain5):
    for orbit in (bc.orbit_1ipp(two_dof, 6.6), _orbit(chain5, 2, 8.0, 1.0470), bc.orbit_1ipp(two_dof, 7.0)):
        ref = floquet(orbit)
        fl = floquet(_GivenMonodromy(ref.monodromy))  # trivial pair found from Y alone (SVD of Y - I)
        assert fl.stable is ref.stable and fl.verdict == ref.verdict
        np.testing.assert_allclose(fl.multipliers, ref.multipliers, rtol=0, atol=1e-9 * max(1, ref.max_modulus))
        assert np.abs(fl.multipliers[list(fl.trivial)] - 1).max() <= 1e-9


def test_a_monodromy_without_the_trivial_pair_is_refused():
    c, s = np.cos(0.3), np.sin(0.3)
    rot = np.array([[c, s], [-s, c]])
    with pytest.raises(ValueError, match="trivial multipliers at 1"):
        floquet(_GivenMonodromy(sla.block_diag(rot, rot)))
    with pytest.raises(ValueError, match=r"\(2n, 2n\)"):
        floquet(_GivenMonodromy(np.eye(3)))


# --- bad input ----------------------------------------------------------------


def test_bad_input_raises_value_error(two_dof):
    orbit = bc.orbit_1ipp(two_dof, 7.0)
    for tol in (0.0, -1e-6, float("nan"), 1.0, "x"):
        with pytest.raises(ValueError, match="tol must be"):
            floquet(orbit, tol)
    with pytest.raises(ValueError, match="got None"):
        floquet(None)
    with pytest.raises(ValueError, match="PeriodicOrbit"):
        floquet(object())
    with pytest.raises(ValueError, match="not bound"):
        floquet(pickle.loads(pickle.dumps(orbit)))
    grazing = bc.make_orbit(two_dof, 6.0, [6.0], [0.0], certify=False)
    with pytest.raises(ValueError, match="grazing"):
        floquet(grazing)


# --- branches -------------------------------------------------------------------


def test_branch_stability_and_stable_arcs(two_dof):
    T1 = float(two_dof.spectrum.periods[0])
    periods = np.concatenate([np.linspace(5.7, 7.15, 30), [T1]])  # the last one is resonant: no orbit
    branch = bc.backbone(two_dof, periods)
    assert branch.orbits[-1] is None
    stab = branch_stability(branch)
    assert isinstance(stab, np.ma.MaskedArray) and stab.dtype == bool and stab.shape == (31,)
    assert stab.mask.tolist() == [False] * 30 + [True]
    expected = [floquet(o).stable for o in branch.orbits[:30]]
    assert stab[:30].tolist() == expected
    assert 0 < sum(expected) < 30  # stable and unstable points on this arc
    arcs = stable_arcs(branch, stability=stab)
    assert arcs == stable_arcs(branch) and len(arcs) >= 2
    good = np.array([o is not None and o.admissible for o in branch.orbits]) & np.ma.filled(stab, False)
    covered = np.zeros(31, dtype=bool)
    for a, b in arcs:
        assert a <= b and good[a: b + 1].all()
        assert (a == 0 or not good[a - 1]) and (b == 30 or not good[b + 1])  # maximal
        covered[a: b + 1] = True
    assert np.array_equal(covered, good)
    with pytest.raises(ValueError, match="entries"):
        stable_arcs(branch, stability=stab[:5])
    # the form Branch.stable has once orbits carry their stability: True/False/None objects (None: not stable)
    objects = np.array([None if m else bool(v) for v, m in zip(stab.data, stab.mask)], dtype=object)
    a, b = arcs[0]
    objects[a] = None
    expected = ([(a + 1, b)] if b > a else []) + arcs[1:]
    assert stable_arcs(branch, stability=objects) == expected


def test_branch_stability_masks_orbits_without_multipliers(two_dof, caplog):
    grazing = bc.make_orbit(two_dof, 6.0, [6.0], [0.0], certify=False)
    branch = Branch(two_dof, 1, [bc.orbit_1ipp(two_dof, 6.6), grazing, bc.orbit_1ipp(two_dof, 7.0), grazing], [])
    with caplog.at_level("WARNING", logger="bladecase"):
        stab = branch_stability(branch)
    assert stab.mask.tolist() == [False, True, False, True] and stab.tolist() == [False, None, True, None]
    (record,) = [r for r in caplog.records if "stability" in r.getMessage()]  # one line for the branch
    assert "2 point(s)" in record.getMessage() and "grazing" in record.getMessage()


def test_the_paper_two_ipp_mode_is_stable_near_1_and_unstable_near_2(two_dof):
    """The 2-ipp mode of the paper's Figs. 2–4 (a curve branch): linearly stable from ① (T = 13.3287, the
    1-ipp orbit of period T/2 seen twice) to T ≈ 13.43, then flip-unstable up to ② (T → 5T₂, where the
    impulses vanish and the saltation matrices blow up: |μ| > 1e3)."""
    (mode,) = [f for f in bc.nonsmooth_mode(two_dof, 2, (13.2, 13.75), scan=2) if f.arcs]
    stab = branch_stability(mode)
    assert not stab.mask.any()
    (arc,) = mode.arcs
    adm = [i for i in range(arc.start, arc.stop + 1)]
    T = mode.T
    assert all(stab[i] for i in adm if T[i] <= 13.43) and not any(stab[i] for i in adm if T[i] >= 13.54)
    assert stable_arcs(mode, stability=stab) == [(arc.start, max(i for i in adm if T[i] <= 13.43))]
    worst = floquet(mode.orbits[arc.stop])
    assert worst.max_modulus > 1e3 and worst.verdict.endswith("(flip) leaves the unit circle")


# --- the example's orbits (examples/fig11_stability.py) -------------------------


@pytest.fixture(scope="module")
def fig11():
    spec = importlib.util.spec_from_file_location("bladecase_example_fig11_stability", EXAMPLE)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_example_picks_a_stable_and_an_unstable_admissible_orbit(fig11, two_dof):
    stable, unstable = fig11.pick_orbits(two_dof, 60)
    fs, fu = floquet(stable), floquet(unstable)
    assert stable.admissible and unstable.admissible and stable.k == unstable.k == 1
    assert fs.stable and not fu.stable and fu.verdict.endswith("(flip) leaves the unit circle")
    assert abs(stable.T - unstable.T) < 0.2 and abs(stable.energy - unstable.energy) < 0.1 * unstable.energy
    # by simulation (relative perturbation 1e-6, 300 flights): the stable orbit's deviation stays within
    # 10× the perturbation, the unstable one's exceeds 1e4× it
    for orbit, bound in ((stable, 1e-5), (unstable, None)):
        tr, z0, dz0 = fig11.perturbed_run(orbit, 300, size=1e-6)
        dist = np.linalg.norm(np.vstack([tr.x, tr.v]) - z0[:, None], axis=0) / np.linalg.norm(z0)
        if bound is not None:
            assert dist.max() <= bound, dist.max()
        else:
            assert dist.max() >= 1e-2, dist.max()
    # the section's energy bound holds every simulated point (energy conservation)
    tr, _, _ = fig11.perturbed_run(unstable, 300)
    xs, vs = fig11.section_points(tr, two_dof)
    bx, bv = fig11.energy_bound(two_dof, unstable.energy)
    assert np.abs(vs).max() <= np.abs(bv).max() * (1 + 1e-3)
    assert bx.min() - 1e-6 <= xs.min() and xs.max() <= bx.max() + 1e-6


def test_frequency_energy_plot_styles_stable_and_unstable_arcs():
    from bladecase.nsm import backbone, chain
    from bladecase.post.plots import frequency_energy

    branch = backbone(chain(2, k=1.0, m=0.5, gap=1.0), np.linspace(6.0, 7.0, 41))
    labels = frequency_energy([branch], stability=True).axes[0].get_legend_handles_labels()[1]
    # the flip window [6.487, 6.664] lies inside the admissible arc: both styles are drawn and labelled
    assert "1 ipp, admissible, stable (Floquet)" in labels and "1 ipp, admissible, unstable (Floquet)" in labels
    st = branch.stability()
    assert not st[(branch.T > 6.52) & (branch.T < 6.63)].any() and st[branch.T < 6.45].all()
