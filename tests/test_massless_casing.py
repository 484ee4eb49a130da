"""A compliant casing in series with the massless contact (``Contact.with_casing``, ``[contact] casing_stiffness``).

The casing is a spring ``k`` between the contact and the rigid casing at ``d``: the closed phase's stiffness is the
contact dofs' ``k_c`` in series with ``k``, both switches stay at ``ŵᵀx = d``, and the contact moves ``λ / k``
beyond ``d``. Checked: the series law on the bilinear oscillator (exact, 1e-15) and its closed-form period–energy
relation (1e-10); the FE expansion puts the contact at ``d + λ/k`` (1e-10); energy over 1000 contact phases (1e-10);
convergence of the strip's nonsmooth mode under reduced-model (1e-4) and mesh refinement (observed order > 1,
< 0.1 % between the two finest meshes), where the rigid casing has no admissible orbit at the same periods;
Newton's law, the schema and the files refuse or keep the casing as documented.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_massless import bilinear_period
from test_massless_fe import strip

import bladecase as bc
from bladecase.nsm import condense, series_stiffness, simulate_massless
from bladecase.nsm.massless.orbits import follow_from_grazing, orbits_at_period, smoothest
from bladecase.reduction import load_reduced, save_reduced
from bladecase.study.schema import StudyError, validate


def two_dof(k2: float, casing: float = float("inf")):
    """Mass 1 on spring 1 to the wall, spring ``k2`` to a massless contact point at gap 1, against ``casing``."""
    return condense(np.diag([1.0, 0.0]), np.array([[1 + k2, -k2], [-k2, k2]]), np.array([0.0, 1.0]), 1.0, casing)


def test_series_law_and_the_bilinear_closed_form():
    """k2 = 3 against a casing of 6 is the bilinear oscillator with k2 = 2: the same branch, to 1e-10."""
    s = two_dof(3.0, 6.0)
    assert s.kc == pytest.approx(2.0, rel=1e-15) and s.casing == 6.0 and s.kc_structure == pytest.approx(3.0, rel=1e-14)
    assert repr(s) == "MasslessSystem(n=1, gap=1, kc=2, casing=6)"
    assert two_dof(3.0).kc == 3.0 and series_stiffness(3.0, float("inf")) == 3.0
    orbits = follow_from_grazing(s, T_min=np.pi + np.pi / np.sqrt(3.0) + 0.1, ds=0.02)
    assert len(orbits) > 20
    for o in orbits[1:]:
        assert o.admissible and o.T == pytest.approx(bilinear_period(o.energy, k2=2.0), rel=1e-10)
    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="casing stiffness must be > 0"):
            series_stiffness(3.0, bad)


def test_energy_with_a_casing_is_conserved_over_1000_contact_phases():
    s = bc.bar(20, 0.5, casing=2.0)
    x0 = -2 * s.gap * np.linalg.solve(s.S, s.w) / (s.w @ np.linalg.solve(s.S, s.w))
    traj = simulate_massless(s, x0, np.zeros(s.n), t_end=1e9, max_switches=2000)
    assert traj.phases.count("closed") >= 1000
    E0 = s.energy(x0, np.zeros(s.n))
    assert abs(s.energy(traj.x_end, traj.v_end) / E0 - 1) < 1e-10


@pytest.fixture(scope="module")
def plate():
    model, _ = strip(41, 9, order=2)
    return model, bc.Contact.face(model, "tip", (0.0, 1.0), 1e-4, weights="area")


def test_the_expanded_contact_sits_lambda_over_k_beyond_the_gap(plate):
    model, face = plate
    r = bc.reduce(model, face.with_casing(1e6), "massless", 8)
    s, w = r.system, face.w(model)
    q = 3 * np.linalg.solve(s.S + s.kc * np.outer(s.w, s.w), s.kc * s.gap * s.w)  # a closed-phase state
    lam = r.multiplier(q)
    assert lam > 0 and w @ r.free_dofs(q) == pytest.approx(s.gap + lam / 1e6, rel=1e-10)
    rigid = bc.reduce(model, face, "massless", 8)
    assert rigid.system.kc > 1e3 * s.kc and s.kc == pytest.approx(series_stiffness(rigid.system.kc, 1e6), rel=1e-12)


def backbone_energy(system, ratio: float):
    """Energy of the backbone's orbit at ``ratio·T1`` (the smoothest admissible one; None when none is)."""
    T1 = 2 * np.pi / system.open.omega[0]
    proved = [o for o in orbits_at_period(system, ratio * T1, samples=200) if o.admissible]
    o = smoothest(proved, modes=min(10, system.n // 2))
    return None if o is None else o.energy


def test_the_mode_converges_with_the_reduced_size(plate):
    """Against a 1e6 N/m casing the strip's mode at 0.99 and 0.95 T1 settles to 1e-4 from size 4 on (measured
    changes 8 → 32 below 2e-5); against the rigid casing the same orbits are not admissible at 0.95 T1."""
    model, face = plate
    factor = bc.fe.stiffness_factor(model)
    systems = [bc.reduce(model, face.with_casing(1e6), "massless", n, factor=factor).system for n in (4, 8, 16, 32)]
    for ratio in (0.99, 0.95):
        E = [backbone_energy(system, ratio) for system in systems]
        assert None not in E
        assert max(abs(e / E[-1] - 1) for e in E) < 1e-4
        assert max(abs(e / E[-1] - 1) for e in E[1:]) < 2e-5
    assert backbone_energy(bc.reduce(model, face, "massless", 16, factor=factor).system, 0.95) is None


def test_the_mode_converges_under_mesh_refinement():
    """P2 strip, 21 × 5 → 41 × 9 → 81 × 17 nodes, size 12, casing 1e6 N/m: the energy at 0.99 T1 changes by
    2.6e-3, 7.8e-4, 2.9e-4 (relative; observed order 1.5–1.8) — below 0.1 % between the two finest meshes."""
    E = []
    for nx, ny in ((11, 3), (21, 5), (41, 9), (81, 17)):
        model, _ = strip(nx, ny, order=2)
        face = bc.Contact.face(model, "tip", (0.0, 1.0), 1e-4, weights="area").with_casing(1e6)
        E.append(backbone_energy(bc.reduce(model, face, "massless", 12).system, 0.99))
    d = np.abs(np.diff(E))
    assert np.all(np.diff(E) < 0) and np.all(d[1:] < d[:-1])  # monotone, differences shrinking
    orders = np.log2(d[:-1] / d[1:])  # h halves
    assert np.all(orders > 1.2), orders
    assert d[-1] / E[-1] < 1e-3


def test_newton_and_the_study_refuse_a_compliant_casing(plate):
    model, face = plate
    with pytest.raises(ValueError, match="needs a rigid casing, got casing stiffness 1e\\+06 N/m"):
        bc.reduce(model, face.with_casing(1e6), "lanczos-si", 8)
    with pytest.raises(ValueError, match="needs a rigid casing"):
        face.with_casing(1e6).system(model)
    with pytest.raises(ValueError, match="Newton's impact law needs a rigid casing"):
        bc.bar(10, 0.5, contact="newton", casing=1.0)
    for bad in (0, -5.0, "stiff", float("nan")):
        with pytest.raises(ValueError, match="casing stiffness must be a number > 0"):
            face.with_casing(bad)
    plate_geometry = {"kind": "plate", "span": 0.1, "chord": 0.02}
    with pytest.raises(StudyError, match="casing_stiffness: a compliant casing needs model = 'massless'"):
        validate({"geometry": plate_geometry, "contact": {"clearance": 1e-4, "casing_stiffness": 1e6}})
    with pytest.raises(StudyError, match=r"\[contact\] casing_stiffness: must be > 0 \(N/m\)"):
        validate({"geometry": plate_geometry, "contact": {"clearance": 1e-4, "casing_stiffness": -1.0}})


def test_reduced_model_file_keeps_the_casing(plate, tmp_path):
    model, face = plate
    r = bc.reduce(model, face.with_casing(2.5e6), "massless", 6)
    save_reduced(r, tmp_path / "r.npz")
    back = load_reduced(tmp_path / "r.npz")
    assert back.contact.casing == 2.5e6 and back.system.casing == 2.5e6 and back.system.kc == r.system.kc
    rigid = bc.reduce(model, face, "massless", 6)
    save_reduced(rigid, tmp_path / "rigid.npz")
    assert np.isinf(load_reduced(tmp_path / "rigid.npz").system.casing)


def test_a_family_ending_in_an_internal_resonance_is_named():
    """The bar (n = 20) against a casing of 1: the energy of its first mode grows ~1e7-fold towards f = 0.2735, where
    99.9 % of it sits in mode 5 (2.184, 7.98 × the orbit's frequency): the 8:1 resonance, named in the report. The
    bilinear oscillator's energy also grows without bound (towards its high-energy limit), but in its own mode:
    no resonance."""
    from bladecase.post.report import _resonance_words
    from bladecase.study.documents import family_summary

    s = bc.bar(20, 0.5, casing=1.0)
    T1 = 2 * np.pi / s.open.omega[0]
    (fam,) = bc.nonsmooth_mode(s, 1, (0.85 * T1, 1.001 * T1))
    res = family_summary(fam)["resonance"]
    assert res["mode"] == 5 and res["ratio"] == pytest.approx(7.98, abs=0.02) and res["share"] > 0.99
    assert res["growth"] > 1e6 and res["frequency_hz"] == pytest.approx(0.2735, abs=1e-3)
    words = _resonance_words(0, family_summary(fam))
    assert "ends in an internal resonance" in words and "mode 5" in words and "the 8:1 resonance" in words
    s2 = two_dof(3.0, 6.0)
    (fam2,) = bc.nonsmooth_mode(s2, 1, (np.pi + np.pi / np.sqrt(3.0) + 0.05, 2 * np.pi + 0.01))
    assert family_summary(fam2)["resonance"] is None


def test_the_animation_says_contact_for_the_massless_model_and_impact_for_newton():
    from bladecase.post.outputs.animation import _massless

    s = two_dof(3.0, 6.0)
    (fam,) = bc.nonsmooth_mode(s, 1, (5.0, 2 * np.pi + 0.01))
    assert _massless(fam.orbits[1])
    assert not _massless(bc.orbit_1ipp(bc.chain(2, k=1.0, m=0.5, gap=1.0), 6.0))


@pytest.mark.parametrize("casing", [1e5, 1e7])
def test_a_soft_casing_on_a_stiff_plate_still_grows_its_mode(casing):
    """A casing far softer than the blade (the plate's static stiffness at its contact: 2.3e7 N/m) puts the
    closing residual's root within 1e-7 of its pole at half the linear period: the branch's first point is then
    bracketed beside the pole (before, Newton from T1/2 went astray and the branch was the grazing orbit alone —
    no family at all in a study)."""
    import sys

    sys.path.insert(0, str(Path(__file__).parent))
    from test_verdict import MASSLESS_PLATE

    from bladecase.nsm.massless.orbits import follow_from_grazing
    from bladecase.study.schema import loads
    from bladecase.study.stages import build_contact, build_mesh, build_model, build_reduced

    study = loads(MASSLESS_PLATE.replace("[contact]\n", f"[contact]\ncasing_stiffness = {casing}\n"), source="<p>")
    model = build_model(study, build_mesh(study))
    s = build_reduced(study, model, build_contact(study, model)).system
    T1 = 2 * np.pi / s.open.omega[0]
    branch = follow_from_grazing(s, 0.8 * T1, max_points=60)
    assert len(branch) == 60                                   # measured before the fix: 1 (the grazing orbit)
    assert all(o.T <= T1 * (1 + 1e-9) for o in branch) and branch[-1].T < branch[0].T
    assert abs(branch[0].T / T1 - 1) < 1e-5                     # it starts at grazing


def test_the_massless_model_brings_its_reduction_and_mass_by_default():
    """[contact] model = "massless" alone: the massless reduction and the lumped mass are its defaults; a study that
    sets them otherwise is still refused, naming the key."""
    from _studies import PLATE, absolute

    text = absolute(PLATE).replace('method = "modal"\nsize = 10\n', "size = 10\n").replace(
        'mass = "lumped"\n', "").replace("clearance = 1e-4", 'clearance = 1e-4\nmodel = "massless"')
    from bladecase.study.schema import loads

    s = loads(text.replace("ipp = [1]\n", "ipp = [1]\n"))
    assert s["reduction"]["method"] == "massless" and s["fem"]["mass"] == "lumped"
    with pytest.raises(StudyError, match=r"\[fem\] mass: the massless contact model moves lumped masses"):
        loads(text.replace("[fem]\n", '[fem]\nmass = "consistent"\n'))
    with pytest.raises(StudyError, match=r"\[reduction\] method: the massless contact model needs a massless method"):
        loads(text.replace("size = 10\n", 'size = 10\nmethod = "modal"\n'))
