"""A k-ipp search whose period range holds a great many resonances of the contact is announced, or refused with
the range that would do, before it starts (a Craig–Bampton model of a contact face went past 300 s and 23 GB)."""

from __future__ import annotations

import re

import numpy as np
import pytest

import bladecase as bc
from bladecase.study import stages
from bladecase.study.demo import demo_text
from bladecase.study.keys import StudyError
from bladecase.study.schema import loads
from bladecase.study.stages import RESONANCE_SECONDS, SEARCH_REFUSE_S, SEARCH_WARN_S, _check_resonances, resonance_count


def _range(system, lo=0.9, hi=0.9999):
    T1 = 2 * np.pi / system.spectrum.omega[0]
    return lo * T1, hi * T1


def test_the_resonances_are_counted_one_by_one():
    system = bc.chain(50, k=1.0, m=1 / 50, gap=1.0)
    T_range = _range(system)
    brute = sum(1 for w in system.spectrum.contact_modes[0] for m in range(1, 200)
                if T_range[0] < 2 * np.pi * m / w <= T_range[1])
    assert resonance_count(system, T_range) == brute == 203  # the figure bench_search prints for chain50


def test_a_long_search_is_announced_and_a_runaway_one_refused_with_the_range_that_would_do(caplog):
    quick = bc.chain(50, k=1.0, m=1 / 50, gap=1.0)
    slow = bc.chain(100, k=1.0, m=1 / 100, gap=1.0)
    with caplog.at_level("WARNING", logger="bladecase"):
        _check_resonances(quick, 2, _range(quick), "chain 50")
        assert not caplog.text
        _check_resonances(slow, 2, _range(slow), "chain 100")
    est = RESONANCE_SECONDS * resonance_count(slow, _range(slow)) * 100
    assert SEARCH_WARN_S < est < SEARCH_REFUSE_S
    assert re.search(rf"chain 100: 2-ipp search: the contact sees modes up to \d+ × the lowest frequency .* "
                     rf"\d+ resonances T = 2πm/ω_j lie in the period range .* estimated {est / 60:.1f} min on 100 "
                     r"dofs; [\d.]+ % of the contact's inverse mass .* \(a narrower \[search\] periods shortens it\)",
                     caplog.text)

    runaway = bc.chain(300, k=1.0, m=1 / 300, gap=1.0)
    text = demo_text().replace('model = "massless"', 'model = "newton"').replace("casing_stiffness = 1e6 ",
                                                                                 "# casing_stiffness = 1e6 ")
    text = text.replace('method = "massless" ', 'method = "lanczos-si" ').replace("ipp = [1] ", "ipp = [2] ")
    study = loads(text, source="<guard>")
    with pytest.raises(StudyError, match=r"\[search\] periods: 2-ipp search: .* estimated \d+ min on 300 dofs, with "
                                         r"thousands of families .*valid: a range estimated within 30 min") as err:
        stages.search(study, runaway)  # refused before any search
    lo, hi = (float(x) for x in re.search(r"\(from (\S+) s: up to (\S+) s\)", str(err.value)).groups())
    unit = stages.period_unit(study, runaway)[0]
    assert lo == pytest.approx(study["search"]["periods"][0] * unit, rel=1e-5)
    within = RESONANCE_SECONDS * resonance_count(runaway, (lo, hi)) * 300
    beyond = RESONANCE_SECONDS * resonance_count(runaway, (lo, hi * 1.001)) * 300
    assert within <= SEARCH_REFUSE_S < beyond
    assert "massless contact model" in str(err.value)


def test_the_warning_says_how_much_of_the_contacts_inverse_mass_the_stiff_modes_carry(caplog):
    """A model whose contact sees stiff local modes (a Craig–Bampton contact face): the warning gives the share of
    ``Σ b_j² = wᵀM⁻¹w`` in the modes above STIFF_RATIO × the lowest frequency, computed from the model."""
    omega = np.array([1.0, 2.0, 5e4, 8e4])
    b = np.array([1.0, 1.0, 1.0, 2.0])  # above 100 × ω₁: (1 + 4) / (1 + 1 + 1 + 4) = 71.4 %
    system = bc.LinearSystem(np.eye(4), np.diag(omega**2), b, 1.0)
    with caplog.at_level("WARNING", logger="bladecase"):
        _check_resonances(system, 2, _range(system), "face")
    assert stages.STIFF_RATIO == 100
    assert ("estimated 1.7 min on 4 dofs; 71.4 % of the contact's inverse mass wᵀM⁻¹w (what an impact excites) lies in "
            "its 2 modes above 100 × the lowest frequency (a narrower [search] periods shortens it)") in caplog.text
    caplog.clear()
    soft = bc.LinearSystem(np.eye(4), np.diag([1.0, 4.0, 2500.0, 9000.0]), b, 1.0)  # none above 100 × ω₁: no share
    with caplog.at_level("WARNING", logger="bladecase"):
        _check_resonances(soft, 2, _range(soft, 0.01, 0.9999), "soft")
    assert "inverse mass" not in caplog.text


def test_the_inverse_mass_of_a_contact_face_grows_like_one_over_the_element_length():
    """Why the warning names the face's local modes, and why the documentation sends a face to the massless contact
    model: Newton's law acts on the layer of elements at the face, so the face mean's inverse mass ``wᵀM⁻¹w`` doubles
    with each halving of the element length normal to the face (observed order -1 within 1 %; the strip of the
    documentation's Craig–Bampton case, 150 × 30 × 6 mm steel, 4 × 4 face nodes)."""
    from skfem import MeshTet

    from bladecase.fe import Mesh, assemble
    from bladecase.reduction import Contact
    from bladecase.reduction.methods.common import constraint

    inverse = []
    for nx in (16, 31, 61):
        m = MeshTet.init_tensor(np.linspace(0, 0.15, nx), np.linspace(-0.015, 0.015, 4), np.linspace(-0.003, 0.003, 4))
        p = m.p.T.copy()
        mesh = Mesh(p, {"tetra": m.t.T.copy()}, dim=3, groups={"root": np.flatnonzero(p[:, 0] == 0),
                                                               "tip": np.flatnonzero(np.isclose(p[:, 0], 0.15))})
        model = assemble(mesh, "steel", mass="lumped")
        w = constraint(model, Contact.face(model, "tip", (0.0, 0.0, 1.0), 1e-4))
        inverse.append(float(w @ (w / model.M.diagonal())))
    orders = np.log2(np.array(inverse[1:]) / inverse[:-1])
    assert inverse[0] == pytest.approx(1.881e3, rel=1e-3)  # 1/kg
    assert np.allclose(orders, 1.0, atol=0.01), orders
