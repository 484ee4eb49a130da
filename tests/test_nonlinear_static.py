"""The geometrically nonlinear static state (``bladecase.fe.nonlinear_static``, ``spin(static="nonlinear")``).

* the tangent is the residual's Jacobian (central finite differences, relative 1e-6), in 3-D with a centrifugal and a
  dead load and in 2-D (plane stress, lumped mass); the batched kernel equals scikit-fem's ``@LinearForm`` /
  ``@BilinearForm`` of the same weak forms, and at rest the tangent is ``K``;
* a cantilever under a large tip load ``PL²/EI = 1`` against the elastica (solved here: tip deflection 0.30172 L,
  shortening 0.05643 L, as Mattiasson, Int. J. Numer. Meth. Eng. 17, 1981, tabulates; Bisshopp & Drucker,
  Q. Appl. Math. 3, 1945);
* a rotating cantilever about its nonlinear state against Hodges & Rutkowski's table (AIAA J. 19, 1981) and the
  Southwell coefficients of the first flapwise mode, ``ω² = ω₀² + (K₁ + K₂ R/L) Ω²`` with ``K₁ = 1.1933``,
  ``K₂ = 1.5709`` (Rayleigh's quotient of the clamped–free mode: ``tests/test_rotation.py``), chordwise one less;
* CalculiX (``ccx``, where installed) on the same 20-node hexahedral deck: its ``NLGEOM`` static step and
  ``PERTURBATION`` frequencies; its linear static step and perturbation rebuilt term by term.
"""

from __future__ import annotations

import math
import shutil

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.integrate import solve_bvp
from skfem import CellBasis, ElementTetP2, ElementVector, MeshTet, MeshTri

from bladecase.fe import Mesh, assemble
from bladecase.fe.nonlinear_static import StVenantKirchhoff, nonlinear_state, svk_forms
from bladecase.fe.rotation import RotationAxis, _operators, spin
from bladecase.linalg import lowest_modes, spd_factor

EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]
Z_AXIS = RotationAxis((0, 0, 0), (0, 0, 1))
HODGES = {0: 3.5160, 4: 5.5850, 12: 13.1702}  # Hodges & Rutkowski (1981), Table 1: first flapwise ω̄ at λ
K1, K2 = 1.1933, 1.5709


def strip(nx: int, ny: int, nz: int, length: float, width: float, thick: float, hub: float = 0.0,
          sweep_deg: float = 0.0) -> Mesh:
    """A structured 20-node hexahedral strip (VTK = C3D20 node order) from its root at ``(hub, 0, 0)`` along
    ``(cos s, 0, sin s)`` (``s`` the sweep out of the plane z = 0), ``width`` along y, ``thick`` along the normal."""
    size = (2 * nx + 1, 2 * ny + 1, 2 * nz + 1)
    cells = []
    for i, j, k in np.ndindex(nx, ny, nz):
        c = [(2 * i, 2 * j, 2 * k), (2 * i + 2, 2 * j, 2 * k), (2 * i + 2, 2 * j + 2, 2 * k), (2 * i, 2 * j + 2, 2 * k)]
        c += [(a, b, z + 2) for a, b, z in c]
        cells.append(c + [tuple(np.add(c[p], c[q]) // 2) for p, q in EDGES])
    used = sorted({n for cell in cells for n in cell})
    index = -np.ones(size, dtype=np.int64)
    for m, ijk in enumerate(used):
        index[ijk] = m
    g = np.array(used, dtype=float) / (np.array(size) - 1)
    s = math.radians(sweep_deg)
    along, normal = np.array([math.cos(s), 0, math.sin(s)]), np.array([-math.sin(s), 0, math.cos(s)])
    points = (np.array([hub, 0, 0]) + np.outer(g[:, 0] * length, along) + np.outer((g[:, 1] - 0.5) * width, [0, 1, 0])
              + np.outer((g[:, 2] - 0.5) * thick, normal))
    t = np.array([[index[c] for c in cell] for cell in cells])
    return Mesh(points, {"hexahedron20": t}, dim=3, groups={"root": np.flatnonzero(g[:, 0] == 0)})


def swept_strip(nx: int = 12, ny: int = 2):
    """A steel strip 200 × 20 × 3 mm on a 0.1 m hub, swept 30° out of its plane of rotation: the centrifugal load
    bends it (at 3000 rpm about z the linear state deflects the tip 118 mm, the nonlinear one 51 mm)."""
    return assemble(strip(nx, ny, 1, 0.2, 0.02, 0.003, hub=0.1, sweep_deg=30.0), "steel", order=2,
                    mass="consistent")


# ----------------------------------------------------------------------------- the tangent


def _smooth_state(model, angle: float = 0.4, seed: int = 0) -> np.ndarray:
    """A large displacement with a finite rotation (about y, through the root) and some stretch and bending."""
    x = model.dofs.coords
    c, s = math.cos(angle), math.sin(angle)
    rotated = x @ np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])[: model.dim, : model.dim].T if model.dim == 3 else \
        x[:, :2] @ np.array([[c, -s], [s, c]]).T
    u = (rotated - x[:, : model.dim])[np.arange(len(x)), model.dofs.direction]
    scale = float(np.abs(x).max())
    rng = np.random.default_rng(seed)
    return u * (x[:, 0] / scale) + 1e-5 * scale * rng.standard_normal(u.size)


def _plate_2d():
    t = MeshTri.init_tensor(np.linspace(0.05, 0.15, 7), np.linspace(0, 0.02, 3))
    points = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    mesh = Mesh(points, {"triangle": t.t.T.copy()}, dim=2, groups={"root": np.flatnonzero(np.isclose(t.p[0], 0.05))})
    return assemble(mesh, "steel", order=2, mass="lumped", thickness=0.002)


@pytest.mark.parametrize("case", ["3-D centrifugal + dead load", "2-D plane stress, lumped"])
def test_tangent_is_the_jacobian_of_the_residual(case):
    if case.startswith("3-D"):
        model, axis, speed = swept_strip(3, 1), RotationAxis((0.02, 0.01, 0), (0.1, 0.2, 1.0)), 400.0
    else:
        model, axis, speed = _plate_2d(), Z_AXIS, 900.0
    ops = _operators(model, axis)
    body = StVenantKirchhoff(model, ops.basis)
    rng = np.random.default_rng(1)
    dead = rng.standard_normal(model.n_dofs)
    w2 = speed * speed

    def residual(u):
        return body.forces(u) - w2 * (ops.f1 + ops.M_perp @ u) - dead

    assert abs(body.tangent(np.zeros(model.n_dofs)) - model.K).max() <= 1e-12 * abs(model.K).max()  # at rest: K
    u = _smooth_state(model)
    K, r = body.tangent(u, forces=True)
    assert np.allclose(r, body.forces(u), rtol=1e-12, atol=1e-12 * np.abs(r).max())
    J = K - w2 * ops.M_perp
    assert abs(J - J.T).max() <= 1e-12 * abs(J).max()
    for _ in range(2):
        v = rng.standard_normal(model.n_dofs)
        v *= 1e-6 * np.abs(u).max() / np.abs(v).max()
        fd = (residual(u + v) - residual(u - v)) / 2.0  # R is a cubic in u: exact but for h² R'''(v, v, v) / 6
        assert np.linalg.norm(fd - J @ v) <= 1e-6 * np.linalg.norm(J @ v)


def test_batched_kernel_is_scikit_fem_forms_and_K_at_rest():
    t = MeshTet.init_tensor(np.linspace(0, 0.1, 4), np.linspace(0, 0.02, 2), np.linspace(0, 0.01, 2))
    mesh = Mesh(t.p.T.copy(), {"tetra": t.t.T.copy()}, dim=3, groups={"root": np.flatnonzero(t.p[0] == 0)})
    model = assemble(mesh, "steel", order=2)
    body = StVenantKirchhoff(model)
    assert abs(body.tangent(np.zeros(model.n_dofs)) - model.K).max() <= 1e-12 * abs(model.K).max()
    vector = CellBasis(body.basis.mesh, ElementVector(ElementTetP2()), quadrature=body.basis.quadrature)
    lam, mu = model.material.lame()
    residual, tangent = svk_forms(lam, mu)
    u = _smooth_state(model, 0.6)
    full = np.zeros(vector.N)
    full[model.dofs.fe_index] = u
    field = vector.interpolate(full)
    free = model.dofs.fe_index
    r = residual.assemble(vector, u=field)[free]
    K = sp.csr_array(tangent.assemble(vector, u=field))[free][:, free]
    K_ours, r_ours = body.tangent(u, forces=True)
    assert np.allclose(r_ours, r, rtol=0, atol=1e-10 * np.abs(r).max())
    assert abs(K_ours - K).max() <= 1e-10 * abs(K).max()


# ----------------------------------------------------------------------------- large deflection: the elastica


def _elastica(load: float) -> tuple[float, float]:
    """Tip deflection and shortening (÷ L) of the inextensible cantilever under a tip load ``PL²/EI = load``:
    θ'' = −load cos θ, θ(0) = 0, θ'(1) = 0."""
    def f(s, y):
        return np.vstack([y[1], -load * np.cos(y[0]), np.sin(y[0]), 1 - np.cos(y[0])])

    s = np.linspace(0, 1, 101)
    guess = np.zeros((4, s.size))
    guess[0] = 0.4 * s
    sol = solve_bvp(f, lambda a, b: np.array([a[0], b[1], a[2], a[3]]), s, guess, tol=1e-10)
    assert sol.status == 0
    return float(sol.sol(1.0)[2]), float(sol.sol(1.0)[3])


def test_cantilever_under_a_large_tip_load_follows_the_elastica():
    deflection, shortening = _elastica(1.0)
    assert (deflection, shortening) == pytest.approx((0.30172, 0.05643), abs=1e-5)  # Mattiasson's table
    beam = assemble(strip(16, 1, 1, 1.0, 0.02, 0.02), "steel", order=2)
    tip = np.isclose(beam.dofs.coords[:, 0], 1.0)
    z = tip & (beam.dofs.direction == 2)
    P = beam.material.E * 0.02**4 / 12  # PL²/EI = 1
    load = np.where(z, P / z.sum(), 0.0)
    state = nonlinear_state(beam, load=load)
    w = state.displacement[z].mean()
    u = -state.displacement[tip & (beam.dofs.direction == 0)].mean()
    linear = spd_factor(beam.K).solve(load)[z].mean()  # this mesh's own linear deflection: 0.3297 L (1.1 % stiff)
    # the nonlinear deflection against the linear one: measured +0.08 % from the elastica's 0.30172 / (1/3),
    # the shortening (∝ deflection²) +0.5 %; as they are, -1.0 % and -1.7 % (the mesh's stiffness)
    assert w / linear == pytest.approx(deflection * 3, rel=3e-3)
    assert u / (3 * linear) ** 2 == pytest.approx(shortening, rel=1e-2)
    assert (w, u) == pytest.approx((deflection, shortening), rel=2.5e-2)
    assert w / linear < 0.92  # large deflection: 9.5 % below the linear solution
    assert state.residual <= 1e-6


# ----------------------------------------------------------------------------- a rotating cantilever


def _flap_chord(model, speed: float, static: str = "nonlinear") -> tuple[float, float]:
    """The first flapwise and chordwise angular frequencies about the ``static`` state (test_rotation's)."""
    from test_rotation import _flap_chord as flap_chord

    return flap_chord(model, speed, Z_AXIS, static=static)


@pytest.mark.parametrize("hub", [0.0, 0.5])
def test_rotating_cantilever_about_its_nonlinear_state(hub):
    """A 1 m steel beam 40 mm wide (y) and 20 mm thick (z) spun about z, root at ``hub`` (× L) from the axis."""
    beam = assemble(strip(20, 2, 1, 1.0, 0.04, 0.02, hub=hub), "steel", order=2)
    E, rho = beam.material.E, beam.material.rho
    scale = math.sqrt(rho * 12 / (E * 0.02**2))  # √(ρAL⁴/EI): λ = Ω · scale
    f0, c0 = _flap_chord(beam, 0.0, "linear")
    if hub == 0.0:  # measured -0.26 % and -0.39 % (-0.31 % at λ = 12 about the linear state)
        for lam in (4, 12):
            assert _flap_chord(beam, lam / scale)[0] / f0 == pytest.approx(HODGES[lam] / HODGES[0], rel=6e-3), lam
    omega = 0.3 / scale  # the Southwell (first-order) regime
    f, c = _flap_chord(beam, omega)
    # measured flapwise +0.38 % / +0.34 %, chordwise +1.5 % / +0.45 % (hub 0 / 0.5)
    assert (f * f - f0 * f0) / omega**2 == pytest.approx(K1 + K2 * hub, rel=1e-2)
    assert (c * c - c0 * c0) / omega**2 == pytest.approx(K1 + K2 * hub - 1.0, rel=3e-2)  # spin softening


# ----------------------------------------------------------------------------- spin(static=...)


def test_spin_nonlinear_auto_and_failures():
    model = swept_strip(8, 1)
    omega = 3000 * math.pi / 30
    linear = spin(model, omega, Z_AXIS, static="linear")
    state = spin(model, omega, Z_AXIS, static="nonlinear")
    assert state.static == "nonlinear" and state.iterations > 0 and state.load_steps >= 1
    assert 0.3 < np.abs(state.displacement).max() / np.abs(linear.displacement).max() < 0.5  # 50 mm, not 116 mm
    auto = spin(model, omega, Z_AXIS, static="auto")  # one second-order step moves this state by far more than 1 %
    assert auto.static == "nonlinear" and auto.second_order_change > 0.01
    assert np.allclose(auto.displacement, state.displacement, rtol=0, atol=1e-9)
    slow = spin(model, 30 * math.pi / 30, Z_AXIS, static="auto")  # 30 rpm: linear
    assert slow.static == "linear" and slow.second_order_change < 0.01
    with pytest.raises(ValueError, match="softening and stiffening must both be on"):
        spin(model, omega, Z_AXIS, static="nonlinear", softening=False)
    with pytest.raises(ValueError, match=r"did not converge: reached .* rpm\) of 314\.159 rad/s.*relative residual"):
        nonlinear_state(model, omega, Z_AXIS, max_iter=1)
    with pytest.raises(ValueError, match="needs a load"):
        nonlinear_state(model)


# ----------------------------------------------------------------------------- CalculiX


@pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX (ccx) is not installed (apt-get install "
                    "calculix-ccx)")
def test_calculix_nlgeom_and_its_linear_step_term_by_term(tmp_path):
    """The swept strip at 3000 rpm, the same 20-node hexahedra (27-point rule on both sides): CalculiX's ``NLGEOM``
    static step + ``PERTURBATION`` = ``static="nonlinear"`` (measured 4e-7: its printed digits); CalculiX's linear
    static step + ``PERTURBATION`` = ``K u = Ω² f₁`` (no load stiffness) then ``K_mat(F(u)) + K_geo(σ_lin(u)) −
    Ω² M⊥``: the material stiffness with the static state's deformation gradient, the geometric stiffness of the
    linear stress, spin softening (measured 2e-7); bladecase's ``"linear"`` is 3 to 72 % from CalculiX's linear run
    and 0.7 to 21 % from its ``NLGEOM`` run."""
    from bladecase.fe.calculix import run_calculix

    model = swept_strip()
    omega = 3000 * math.pi / 30

    def hz(K):
        K = sp.csr_array(0.5 * (K + K.T))
        return np.sqrt(lowest_modes(K, model.M, 4, factor=spd_factor(K))[0]) / (2 * math.pi)

    nlgeom = run_calculix(model, tmp_path, 4, name="strip", speed=omega, axis=Z_AXIS, nlgeom=True)
    state = spin(model, omega, Z_AXIS, static="nonlinear")
    assert hz(state.model.K) == pytest.approx(nlgeom, rel=1e-4)

    linear = run_calculix(model, tmp_path, 4, name="strip", speed=omega, axis=Z_AXIS)
    ops = _operators(model, Z_AXIS)
    u = spd_factor(model.K).solve(omega**2 * ops.f1)
    body = StVenantKirchhoff(model, ops.basis)
    # K_T(u) = K_mat(F) + K_geo(S(E(u))): its geometric stiffness swapped for the linear stress's
    rebuilt = body.tangent(u) - _geometric(body, u, green=True) + _geometric(body, u, green=False) \
        - omega**2 * ops.M_perp
    assert hz(rebuilt) == pytest.approx(linear, rel=1e-4)
    ours = hz(spin(model, omega, Z_AXIS, static="linear").model.K)
    assert np.abs(ours / linear - 1).max() > 0.05 and np.abs(ours / nlgeom - 1).max() > 0.05


def _geometric(body: StVenantKirchhoff, u: np.ndarray, green: bool) -> sp.csr_array:
    """``K_geo`` alone: ``∫ S : ∇δuᵀ∇v`` with St-Venant–Kirchhoff's ``S(E(u))`` or the linear ``σ = C ε(u)``."""
    from bladecase.fe.assembly import _gradients, _index_type

    basis, dim = body.basis, body.dim
    full = np.zeros(dim * basis.N)
    full[body.free] = u
    U = full.reshape(-1, dim)[basis.element_dofs.T]
    G = _gradients(basis, slice(None))
    H = np.einsum("eai,eakq->eikq", U, G)
    E = 0.5 * (H + H.transpose(0, 2, 1, 3)) + (0.5 * np.einsum("eikq,eilq->eklq", H, H) if green else 0.0)
    S = 2 * body.mu * E + body.lam * np.einsum("eiiq->eq", E)[:, None, None, :] * np.eye(dim)[None, :, :, None]
    data = np.einsum("eklq,eakq,eblq,eq->eab", S, G, G, basis.dx, optimize=True)
    ed = basis.element_dofs.T.astype(_index_type(basis.N))
    rows = np.broadcast_to(ed[:, :, None], data.shape).ravel()
    cols = np.broadcast_to(ed[:, None, :], data.shape).ravel()
    scalar = sp.coo_array((data.ravel(), (rows, cols)), shape=(basis.N, basis.N))
    return sp.csr_array(sp.kron(scalar, sp.eye_array(dim), format="csr")[body.free][:, body.free])
