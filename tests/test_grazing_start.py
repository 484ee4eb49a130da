"""The first point of a massless one-phase branch, next to grazing (``orbits._grazing_start``).

Next to grazing the closing residual is, to leading order, ``r/d = κβ / (δ + β(1 + κ)) - 1`` (``δ = α - π/ω``,
``κ = k b²/ω²`` the contact's share of the mode's stiffness): its root at ``δ = -β``, its pole ``κβ`` away. A soft
casing or a contact that barely moves with the mode makes ``κ`` small; the bracketing on a fixed grid around the
pole then picked another mode's pole or could not reach ``|r| <= 1e-8 d`` at the contact half-times it tried, and
refused valid studies ("no grazing orbit found from the linear mode") — or took a root beside another mode's pole
and followed a family that is not the mode's (a mode share of 1e-33). Measured before the fix on the cases below:
refused (the soft ones), a wrong family (the axial tip face of the order-2 strip at sizes 3 to 8).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from skfem import MeshTri

import bladecase as bc
from bladecase.nsm.massless.model import simulate_massless
from bladecase.nsm.massless.orbits import closing_residual, contact_share, follow_from_grazing


def strip_system(face: str, casing: float | None, method: str, size: int, order: int = 1, nx: int = 20,
                 ny: int = 4):
    """The steel strip of ``test_hardening_cli`` (0.1 m × 0.02 m × 2 mm, clamped at x = 0, lumped mass), a massless
    face contact (area weights, clearance 0.1 mm) on its tip face (``"tip"``, normal +x: along the span) or its top
    face (``"top"``, normal +y: the bending direction)."""
    t = MeshTri.init_tensor(np.linspace(0, 0.1, nx + 1), np.linspace(0, 0.02, ny + 1)).oriented()
    p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    mesh = bc.Mesh(p, {"triangle": t.t.T}, dim=2, groups={
        "root": np.flatnonzero(p[:, 0] == 0), "tip": np.flatnonzero(np.isclose(p[:, 0], 0.1)),
        "top": np.flatnonzero(np.isclose(p[:, 1], 0.02))}, source="strip")
    model = bc.assemble(mesh, "steel", order=order, thickness=0.002, mass="lumped")
    contact = bc.Contact.face(model, face, (1.0, 0.0) if face == "tip" else (0.0, 1.0), 1e-4, weights="area")
    return bc.reduce(model, contact if casing is None else contact.with_casing(casing), method, size).system


def plate_system(casing: float):
    """``test_verdict.MASSLESS_PLATE`` (the committed plate, its contact node, a 4-mode massless model) against a
    compliant casing."""
    sys.path.insert(0, str(Path(__file__).parent))
    from test_verdict import MASSLESS_PLATE

    from bladecase.study.schema import loads
    from bladecase.study.stages import build_contact, build_mesh, build_model, build_reduced

    study = loads(MASSLESS_PLATE.replace("[contact]\n", f"[contact]\ncasing_stiffness = {casing}\n"), source="<p>")
    model = build_model(study, build_mesh(study))
    return build_reduced(study, model, build_contact(study, model)).system


FOUND = {  # refused before the fix; κ: the contact's share of mode 1's stiffness
    "strip top face, 1e3 N/m, massless 8": lambda: strip_system("top", 1e3, "massless", 8),  # κ = 1.6e-4
    "strip top face, 1e3 N/m, massless-lanczos 7": lambda: strip_system("top", 1e3, "massless-lanczos", 7),
    "strip tip face, 1e8 N/m, massless 4": lambda: strip_system("tip", 1e8, "massless", 4),  # κ = 1.9e-5
    "plate node, 1e3 N/m, massless 4": lambda: plate_system(1e3),  # κ = 9.4e-6
}


@pytest.mark.parametrize("case", list(FOUND))
def test_a_soft_contact_grows_its_mode_from_grazing(case):
    s = FOUND[case]()
    w, b, d = s.open.omega[0], s.open.b[0], s.gap
    T1, kappa = 2 * np.pi / w, contact_share(s)
    assert kappa == pytest.approx(s.kc * b**2 / w**2, rel=1e-14) and 5e-6 < kappa < 2e-4

    branch = follow_from_grazing(s, 0.9 * T1, max_points=40)
    assert len(branch) == 40                                   # before: ValueError, no grazing orbit found
    start = branch[0]
    assert abs(start.T / T1 - 1) < 1e-9                        # grazing: the linear period ...
    assert start.energy == pytest.approx(0.5 * w**2 * (d / b) ** 2, rel=1e-3)   # ... and energy E_g
    assert 0.5 * w**2 * start.a[0] ** 2 / start.energy > 0.999  # mode 1's orbit, not another mode's
    assert start.contact_time / start.T < 0.01                 # in contact for less than 1 % of the period
    assert abs(closing_residual(s, start.alpha, start.beta)[1]) <= 1e-8 * d
    assert all(o.admissible for o in branch)                   # proved, the switch's residual allowed for
    assert branch[-1].beta > 2 * start.beta and branch[-1].T <= start.T * (1 + 1e-12)

    # the closed-form structure the start is bracketed from (leading order in β): the root at δ = α - π/ω = -β,
    # r = +d and -d/2 at δ = -β(1 + κ/2) and -β(1 - κ) — between the pole and the root, and beyond the root
    beta = start.beta
    assert abs(start.alpha - (np.pi / w - beta)) <= 1e-3 * kappa * beta     # measured: <= 1.5e-4 κβ
    for delta, r_d in ((-beta * (1 + kappa / 2), 1.0), (-beta * (1 - kappa), -0.5)):
        assert closing_residual(s, np.pi / w + delta, beta)[1] / d == pytest.approx(r_d, abs=0.15)  # <= 0.093

    # the exact event-driven simulator comes back to the start, and to an orbit further on, after one period
    for orbit in (start, branch[-1]):
        run = simulate_massless(s, orbit.x_mid_open, np.zeros(s.n), orbit.T)
        scale = np.abs(orbit.x_mid_open).max()
        assert np.abs(run.x_end - orbit.x_mid_open).max() <= 1e-6 * scale
        assert np.abs(run.v_end).max() * orbit.T <= 1e-6 * scale
        assert sum(p == "closed" for p in run.phases) == 1


@pytest.mark.parametrize("size", [2, 4])
def test_a_mode_the_contact_hardly_sees_is_refused_in_its_numbers(size):
    """The strip's tip face pushed along the span by its first bending mode (order 2, rigid casing): the contact's
    participation is a mesh asymmetry, 4e-8 of the axial mode's, κ = 5.8e-7. Before: size 2 refused without a
    reason, size 4 followed a family of another mode (mode share 1e-33) as if it were mode 1's."""
    s = strip_system("tip", None, "massless", size, order=2)
    w, b = s.open.omega[0], s.open.b[0]
    kappa = contact_share(s)
    assert kappa < 2e-6
    with pytest.raises(ValueError) as err:
        follow_from_grazing(s, 0.9 * 2 * np.pi / w, max_points=10)
    msg = str(err.value)
    assert f"open-phase mode 1 ({w / 2 / np.pi:.6g} Hz): the contact hardly sees it" in msg
    assert f"b = {b:.3g} is {abs(b) / np.abs(s.open.b).max():.1e} of the largest" in msg
    assert f"κ = k b²/ω² = {kappa:.2e}" in msg and "resolving it needs κ >= 2e-06" in msg
    assert f"grazing takes the energy {0.5 * w**2 * (s.gap / b) ** 2:.3g}" in msg
    best = int(np.argmax(s.kc * s.open.b**2 / s.open.omega**2))
    assert best > 0 and f"the contact sees mode {best + 1} ({s.open.omega[best] / 2 / np.pi:.6g} Hz) most" in msg
