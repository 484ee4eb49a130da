"""A rotating cantilever against published and closed-form values: the flapwise frequencies of Hodges &
Rutkowski's table (AIAA J. 19, 1981; also Wright et al., J. Appl. Mech. 49, 1982), the Southwell coefficients
of the first flapwise mode with and without a hub (Rayleigh's quotient of the exact non-rotating mode, computed
here), the chordwise mode (spin softening: one less), and the static centrifugal elongation of a bar."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad
from skfem import MeshTet

from bladecase.fe import Mesh, assemble
from bladecase.fe.rotation import RotationAxis, spin, to_rad_s
from bladecase.linalg import lowest_modes

L, H, C = 1.0, 0.02, 0.04  # a 1 m steel beam, 20 mm thick (z, flapwise) and 40 mm wide (y, chordwise)
Z_AXIS = RotationAxis((0, 0, 0), (0, 0, 1))  # flap: motion along z (the axis); chord: along y (in the plane)


def _beam(hub: float = 0.0, nx: int = 20):
    # centred on the axis (the published beams' centroidal line meets the axis)
    m = MeshTet.init_tensor(np.linspace(0, L, nx + 1), np.linspace(-C / 2, C / 2, 3), np.linspace(-H / 2, H / 2, 3))
    p = m.p.T.copy()
    p[:, 0] += hub
    mesh = Mesh(p, {"tetra": m.t.T.copy()}, dim=3, groups={"root": np.flatnonzero(np.isclose(m.p[0], 0))})
    return assemble(mesh, "steel", order=2, mass="consistent")


@pytest.fixture(scope="module")
def beam():
    return _beam(nx=40)


def _scale(model) -> float:
    """``sqrt(ρ A L⁴ / E I)`` of flapwise bending: ω̄ = ω · scale, λ = Ω · scale."""
    E, rho = model.material.E, model.material.rho
    return np.sqrt(rho * C * H * L**4 / (E * C * H**3 / 12))


def _flap_chord(model, speed: float, axis=Z_AXIS, **spin_options) -> tuple[float, float]:
    """The first flapwise (z) and chordwise (y) angular frequencies at ``speed`` (``spin_options``, e.g. ``static``,
    passed to :func:`spin`)."""
    state = spin(model, speed, axis, **spin_options)
    lam, phi = lowest_modes(state.model.K, state.model.M, 3, factor=state.factor)
    d = model.dofs.direction
    share = np.array([[np.sum(phi[d == c, j] ** 2) / np.sum(phi[:, j] ** 2) for j in range(3)] for c in (1, 2)])
    chord, flap = int(np.argmax(share[0])), int(np.argmax(share[1]))
    assert share[1, flap] > 0.9 and share[0, chord] > 0.9 and flap != chord
    return float(np.sqrt(lam[flap])), float(np.sqrt(lam[chord]))


def _rayleigh_southwell() -> tuple[float, float]:
    """``(K1, K2)`` of ``ω² = ω₀² + (K1 + K2 R/L) Ω²`` for the first flapwise mode, by Rayleigh's quotient of the
    exact clamped–free mode: K1 = ∫(1 − ξ²)/2 φ'² / ∫φ², K2 = ∫(1 − ξ) φ'² / ∫φ²."""
    beta = 1.875104068711961
    s = (np.cosh(beta) + np.cos(beta)) / (np.sinh(beta) + np.sin(beta))

    def phi(x):
        return np.cosh(beta * x) - np.cos(beta * x) - s * (np.sinh(beta * x) - np.sin(beta * x))

    def dphi(x):
        return beta * (np.sinh(beta * x) + np.sin(beta * x) - s * (np.cosh(beta * x) - np.cos(beta * x)))

    norm = quad(lambda x: phi(x) ** 2, 0, 1)[0]
    k1 = quad(lambda x: 0.5 * (1 - x * x) * dphi(x) ** 2, 0, 1)[0] / norm
    k2 = quad(lambda x: (1 - x) * dphi(x) ** 2, 0, 1)[0] / norm
    return k1, k2


def test_southwell_constants_by_rayleigh_are_the_published_ones():
    k1, k2 = _rayleigh_southwell()
    assert k1 == pytest.approx(1.1933, abs=2e-4) and k2 == pytest.approx(1.5709, abs=2e-4)


# Hodges & Rutkowski (1981), Table 1: first flapwise ω̄ of a uniform rotating cantilever at λ = 0, 1, 2, 4, 8, 12
HODGES = {0: 3.5160, 1: 3.6816, 2: 4.1373, 4: 5.5850, 8: 9.2568, 12: 13.1702}


def test_flapwise_frequencies_follow_the_published_table(beam):
    scale = _scale(beam)
    w0 = _flap_chord(beam, 0.0)[0]
    for lam in (1, 2, 4, 8, 12):
        w = _flap_chord(beam, lam / scale)[0]
        # ratios to the model's own ω₀: the FE model's 0.25 % stiffness at rest cancels
        assert w / w0 == pytest.approx(HODGES[lam] / HODGES[0], rel=2e-3), lam


@pytest.mark.parametrize("hub", [0.0, 0.5])
def test_southwell_coefficients_flapwise_and_chordwise(hub):
    model = beam_ = _beam(hub)
    k1, k2 = _rayleigh_southwell()
    omega = 0.3 / _scale(beam_)  # λ = 0.3: the Southwell (first-order) regime
    f0, c0 = _flap_chord(model, 0.0)
    f, c = _flap_chord(model, omega)
    flap = (f * f - f0 * f0) / omega**2
    chord = (c * c - c0 * c0) / omega**2
    assert flap == pytest.approx(k1 + k2 * hub / L, rel=1e-2)
    assert chord == pytest.approx(k1 + k2 * hub / L - 1.0, rel=3e-2, abs=5e-3)  # spin softening: one less


def test_static_centrifugal_elongation_of_a_bar(beam):
    """u(x) = ρ Ω² (L² x / 2 − x³ / 6) / E along a bar from the axis (no spin softening in the static solve: the
    closed form), compared between x = 0.4 and 0.8 L, away from the clamp's local stiffening."""
    omega = 200.0
    state = spin(beam, omega, Z_AXIS, softening=False)
    x = beam.mesh.points[:, 0]
    u = state.nodal_displacement()

    def exact(x):
        return beam.material.rho * omega**2 * (L * L * x / 2 - x**3 / 6) / beam.material.E

    stretch = u[np.isclose(x, 0.8 * L), 0].mean() - u[np.isclose(x, 0.4 * L), 0].mean()
    assert stretch == pytest.approx(exact(0.8 * L) - exact(0.4 * L), rel=2e-3)
    tip = np.isclose(x, L)
    # no flapwise bending but the tetrahedra's own asymmetry (their diagonals couple stretch and bending: 0.6 %)
    assert abs(u[tip, 2].mean()) < 1e-2 * exact(L)


def test_at_rest_and_symmetry(beam):
    rest = spin(beam, 0.0, Z_AXIS)
    assert rest.model is beam and not rest.displacement.any()
    state = spin(beam, 100.0, Z_AXIS)
    K = state.model.K
    assert abs(K - K.T).max() <= 1e-12 * abs(K).max()
    assert (state.model.M != beam.M).nnz == 0


def test_speed_units_and_bad_input(beam):
    assert to_rad_s(60, "rpm") == pytest.approx(2 * np.pi)
    with pytest.raises(ValueError, match="speed unit must be one of"):
        to_rad_s(1, "rps")
    with pytest.raises(ValueError, match="speed must be >= 0, got -1"):
        spin(beam, -1)
    with pytest.raises(ValueError, match="direction must be 2 or 3 finite numbers, not all zero"):
        RotationAxis((0, 0, 0), (0, 0, 0))
    with pytest.raises(ValueError, match="the blade is unstable"):  # an axis along the beam: spin softening only
        spin(beam, 2000.0, RotationAxis((0, 0, 0), (1, 0, 0)))


def test_campbell_tracks_modes_through_a_crossing_by_shape():
    """The flapwise mode (lowest at rest) stiffens past the chordwise one near λ = 5: followed by shape, each keeps
    its identity (ranking by frequency would swap them); its frequencies are the flap/chord ones of the model."""
    from bladecase.fe.campbell import campbell

    model = _beam(nx=20)
    scale = _scale(model)
    speeds = np.linspace(0, 8, 9) / scale
    c = campbell(model, speeds, Z_AXIS, count=2, engine_orders=[1, 2, 3])
    flap, chord = c.frequencies[:, 0], c.frequencies[:, 1]
    assert flap[0] < chord[0] and flap[-1] > chord[-1]  # they cross
    top_flap, top_chord = _flap_chord(model, speeds[-1])
    assert flap[-1] == pytest.approx(top_flap / (2 * np.pi), rel=1e-9)
    assert chord[-1] == pytest.approx(top_chord / (2 * np.pi), rel=1e-9)
    assert c.link_mac.min() > 0.99 and not c.uncertain_links
    assert (c.rank[-1] == [1, 0]).all()
    d = c.to_dict()
    assert d["frequencies_hz"][-1] == sorted(d["frequencies_hz"][-1]) and d["tracked_mode"][-1] == [1, 0]
    assert {(x["mode"], x["engine_order"]) for x in c.crossings} >= {(0, 2), (1, 2)}
    # every crossing lies on its engine-order line and on the mode's piecewise-linear curve
    for x in c.crossings:
        assert x["frequency_hz"] == pytest.approx(x["engine_order"] * x["speed_rad_s"] / (2 * np.pi))
        assert x["frequency_hz"] == pytest.approx(np.interp(x["speed_rad_s"], speeds, c.frequencies[:, x["mode"]]))
