"""``[contact] friction = {model = "coulomb"}`` in a study: the keys, and the rub stage of the demo blade with the
stick–slip model — at an engine speed it is the rotation model's rub, figure for figure, and the log, summary,
rub.csv and report say the assumption and each speed's share of contact time in stick."""

from __future__ import annotations

import logging

import pytest
from test_friction_study import RUB, _wear_study
from test_rub_study import _study

from bladecase.study.keys import StudyError
from bladecase.study.schema import loads


@pytest.fixture(scope="module")
def blade():
    from bladecase.study.stages import build_mesh, build_model

    study = loads(_study(rub=RUB), source="<coulomb>")
    return build_model(study, build_mesh(study))


def _stage(blade, folder=None, **contact):
    from bladecase.study.executor import SerialExecutor
    from bladecase.study.rub.stage import rub_stage
    from bladecase.study.stages import build_contact

    study = loads(_study(rub=RUB, **contact), source="<coulomb>")
    return rub_stage(study, blade, build_contact(study, blade), executor=SerialExecutor(), folder=folder,
                     figures=False)


def test_coulomb_keys():
    study = loads(_study(rub=RUB, friction='{mu = 0.15, model = "coulomb"}'), source="<coulomb>")
    assert study["contact"]["friction"] == {"mu": 0.15, "model": "coulomb"}
    with pytest.raises(StudyError, match="model must be 'rotation' or 'coulomb', got 'stick'"):
        loads(_study(rub=RUB, friction='{mu = 0.15, model = "stick"}'), source="<coulomb>")
    with pytest.raises(StudyError, match=r'model = "coulomb" \(stick–slip\) is not run with a \[casing\] abradable'):
        loads(_wear_study(friction='{mu = 0.15, model = "coulomb"}'), source="<coulomb>")


def test_coulomb_at_engine_speed_is_the_rotation_model(blade, tmp_path, caplog):
    """The demo blade at 1650 rpm, μ = 0.15: the tip slides at ΩR ≈ 78 m/s, 40 times its fastest tangential
    vibration; the stick–slip rub never sticks and gives the rotation model's figures to 1e-9 (the energy of the last
    revolution, the peaks, the switches); the log, the summary, rub.csv and the report say the model and the share of
    contact time in stick."""
    rotation = _stage(blade, friction='{mu = 0.15, model = "rotation"}')
    with caplog.at_level(logging.INFO, logger="bladecase"):
        coulomb = _stage(blade, folder=tmp_path, friction='{mu = 0.15, model = "coulomb"}')
    r, c = rotation["friction"]["speeds"][0], coulomb["friction"]["speeds"][0]
    for key in ("casing_input_j", "friction_work_j", "damping_j", "stored_change_j"):
        assert c[key] == pytest.approx(r[key], rel=1e-9), key
    assert c["sliding_ratio"] == pytest.approx(r["sliding_ratio"], rel=5e-3)   # sampled maxima, on other grids
    assert abs(c["balance_residual"]) < 1e-9 and c["stick_share"] == 0.0 and r["stick_share"] is None
    for key in ("tip_normal_displacement_mm", "max_node_force_n", "contact_fraction", "switches"):
        assert coulomb["rows"][0][key] == pytest.approx(rotation["rows"][0][key], rel=1e-9), key
    f = coulomb["friction"]
    assert f["model"] == "coulomb" and "stick–slip" in f["assumption"] and f["sticking"] == []
    assert any("stick–slip (model 'coulomb')" in m for m in caplog.messages)
    assert any("of its contact time sticking" in m for m in caplog.messages)
    header, line = (tmp_path / "rub.csv").read_text().splitlines()[:2]
    cells = dict(zip(header.split(","), line.split(",")))
    assert float(cells["stick_share"]) == 0.0
    from bladecase.post.rub.report import rub_report

    text = "\n".join(rub_report(coulomb))
    assert "stick–slip (model 'coulomb')" in text and "share of contact time a node spends sticking" in text
    assert "The sliding is dominated by the rotation" not in text


def test_demo_blade_against_a_casing_at_rest_sticks(blade):
    """The demo blade's tip (26 contact nodes, their normal and tangential compliances from the FE model) released
    from its first mode against a casing at rest: the nodes stick at each reversal of their sliding, the coupled nodes
    changing together (a node's change moves its neighbours' sliding velocities); the energy balance closes to 1e-9
    and Coulomb's law holds all along."""
    from dataclasses import replace

    import numpy as np

    from bladecase.nsm import Damping
    from bladecase.nsm.massless.friction_coulomb import CODES, simulate_coulomb
    from bladecase.nsm.massless.friction_coulomb_rub import coulomb_energy, stick_share
    from bladecase.reduction.nodal_friction import nodal_friction
    from bladecase.reduction.nodes import nodal_model
    from bladecase.study.stages import build_contact

    study = loads(_study(rub=RUB), source="<coulomb>")
    reduced = nodal_model(blade, build_contact(study, blade), 8, residual=True)
    axis = study.config["rotation"]["axis"]
    f = replace(nodal_friction(reduced, 0.15, axis["origin"], axis["direction"]), model="coulomb")
    s = reduced.system
    x0 = s.modes[1][:, 0].copy()
    x0 *= 1.5 * np.min(s.gap / np.abs(s.W.T @ x0)) * np.sign((s.W.T @ x0).sum())
    period = 2 * np.pi / s.modes[0][0]
    tr = simulate_coulomb(s, f, x0, np.zeros(s.n), 2 * period, damping=Damping(zeta=0.005), sliding=0.0)
    share = stick_share(tr, 0.0, 2 * period)
    assert tr.complete and share.max() > 0.005
    e = coulomb_energy(tr, 0.0, 2 * period)
    assert abs(e.relative) < 1e-9 and e.friction < 0 < e.damping
    t = np.union1d(np.linspace(0.0, 2 * period, 2001), np.minimum(tr.starts + 1e-12 * period, 2 * period))
    codes = tr.codes[np.searchsorted(tr.starts, t, side="right") - 1].T
    _, _, lam, tau, _, zd = tr.sample(t)
    top = lam.max()
    # within round-off of the coupled compliances' solves (5e-8 of the largest force measured)
    assert np.all(lam >= -1e-9 * top) and np.all(np.abs(tau) <= 0.15 * lam + 1e-7 * top)
    slide = (codes == CODES["slip+"]) | (codes == CODES["slip-"])
    sigma = np.where(codes == CODES["slip+"], 1.0, -1.0)
    assert np.all(-sigma[slide] * zd[slide] >= -1e-9 * np.abs(zd).max())
    assert np.all(np.abs(zd[codes == CODES["stick"]]) <= 1e-9 * np.abs(zd).max())
