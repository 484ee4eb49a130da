"""A casing far softer than the blade at its contact: the log and the report give both stiffnesses (the closed
contact's and the blade's static one, 1/(wᵀK⁻¹w)) and say that the contact barely changes the modes, with the
bound on how far it can raise a frequency — which the nonsmooth modes found respect; a casing as stiff as the
blade is not called soft.  The casing-ring estimate against Roark's formula and a plane-stress FE ring."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from _studies import PLATE, ROOT
from scipy.sparse.linalg import spsolve

from bladecase.post.casing.words import weak_casing_words
from bladecase.post.report import report
from bladecase.reduction.casing import WEAK_CASING, frequency_rise_bound, ring_stiffness
from bladecase.study import run
from bladecase.study.schema import loads
from bladecase.study.stages import build_contact

OUTPUT = "[output]\nformats = []\nreference = false\nanimate = 0\n"


def _study(casing: float):
    text = (PLATE.replace("size = 10", "size = 4")
            .replace("clearance = 1e-4", f'clearance = 1e-4\nmodel = "massless"\ncasing_stiffness = {casing:g}')
            .replace('method = "modal"', 'method = "massless"'))
    return loads(text + OUTPUT, base=ROOT)


@pytest.fixture(scope="module")
def soft(tmp_path_factory):
    return run(_study(1e5), tmp_path_factory.mktemp("soft") / "out", progress=False)


def test_a_soft_casing_is_said_to_barely_change_the_modes(soft):
    result = soft
    c = result.summary["contact"]
    static, series = c["static_stiffness_n_per_m"], c["series_stiffness_n_per_m"]
    # the blade's static stiffness at the contact, by one direct sparse solve of the FE model: 1/(wᵀK⁻¹w)
    model = result.fe_model
    w = build_contact(_study(1e5), model).w(model)
    assert static == pytest.approx(1 / float(w @ spsolve(model.K.tocsc(), w)), rel=1e-8)
    ratio = series / static
    assert ratio < WEAK_CASING
    log = (result.directory / "run.log").read_text()
    report = (result.directory / "report.md").read_text()
    for text in (log, report):
        assert "the casing is far softer than the blade at its contact" in text
        assert f"{series:.4g} N/m" in text and f"= {static:.4g} N/m" in text and f"below {WEAK_CASING:g}" in text
        assert "the contact barely changes the modes" in text
    assert "**Soft casing:**" in report
    # the bound holds for the nonsmooth modes found: no admissible orbit above f1 × (1 + bound)
    f1 = result.summary["model"]["linear_frequencies_hz"][0]
    bound = frequency_rise_bound(series, static)
    tops = [a["f_hi"] for f in result.summary["families"] for a in f["admissible_arcs"]]
    assert tops and max(tops) <= f1 * (1 + bound)
    assert max(tops) > f1  # the band exists: narrow, not absent


def test_a_casing_as_stiff_as_the_blade_is_not_called_soft(soft):
    """The soft run's summary with a casing of a tenth of the blade's static stiffness: no such words."""
    summary = copy.deepcopy(soft.summary)
    c = summary["contact"]
    c["casing_stiffness_n_per_m"] = c["series_stiffness_n_per_m"] = 0.1 * c["static_stiffness_n_per_m"]
    assert "Soft casing" not in report(summary) and "far softer" not in report(summary)
    assert weak_casing_words(0.011 * 4e7, 4e7) is None and weak_casing_words(0.009 * 4e7, 4e7) is not None


def test_the_ring_estimate_is_roarks_and_refuses_bad_input():
    # Roark: a thin ring pinched by two opposite forces closes its diameter by 0.1488 F R³/(E I)
    E, R, h, b = 200e9, 0.45, 0.02, 0.1
    assert ring_stiffness(E, R, h, b) == pytest.approx(E * b * h**3 / 12 / (0.1488 * R**3), rel=2e-4)
    with pytest.raises(ValueError, match="thickness must be a finite number > 0, got -0.02"):
        ring_stiffness(E, R, -h, b)
    with pytest.raises(ValueError, match="thickness must be below its radius"):
        ring_stiffness(E, R, 0.5, b)


def test_the_ring_estimate_against_a_plane_stress_fe_ring():
    """A quarter of the ring (symmetry on both axes), 8-node quadrilaterals, the load spread over the top section:
    its diameter change against the thin-ring formula (the curved beam's shear and normal force add ~(h/R)²)."""
    from skfem import Basis, ElementQuad2, ElementVector, MeshQuad, asm, condense, solve
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    E, nu, R, h, b, F = 200e9, 0.3, 0.45, 0.02, 0.1, 1000.0
    m = MeshQuad.init_tensor(np.linspace(R - h / 2, R + h / 2, 5), np.linspace(0, np.pi / 2, 121))
    x, y = m.p[0] * np.cos(m.p[1]), m.p[0] * np.sin(m.p[1])  # (r, θ) → (x, y)
    basis = Basis(MeshQuad(np.vstack([x, y]), m.t), ElementVector(ElementQuad2()))
    lam, mu = lame_parameters(E, nu)
    K = asm(linear_elasticity(2 * lam * mu / (lam + 2 * mu), mu), basis) * b  # plane stress, width b
    dofs = basis.get_dofs(lambda p: np.isclose(p[1], 0.0))  # the section on the x axis: u_y = 0
    top = basis.get_dofs(lambda p: np.isclose(p[0], 0.0, atol=1e-12))  # the section on the y axis: u_x = 0
    fixed = np.concatenate([dofs.nodal["u^2"], dofs.facet.get("u^2", np.array([], int)),
                            top.nodal["u^1"], top.facet.get("u^1", np.array([], int))])
    load = np.concatenate([top.nodal["u^2"], top.facet.get("u^2", np.array([], int))])
    f = np.zeros(basis.N)
    f[load] = -F / 2 / load.size  # half the pinching force on the quarter, spread over the section
    u = solve(*condense(K, f, D=fixed))
    closure = 2 * -u[load].mean()
    assert F / closure == pytest.approx(ring_stiffness(E, R, h, b), rel=5e-3)  # measured: -0.3 %
