"""The [rub] stage on a line of tip nodes (each its own contact, as the published Rotor 37 rub benchmark lists
them): weighted by tributary length, the contact selection checked before any factorisation."""

from __future__ import annotations

import csv

import numpy as np
import pytest
from test_rub_study import CASING, _study  # noqa: I001  (the demo blade under the 8-lobe casing)

from bladecase.study import run
from bladecase.study.keys import StudyError
from bladecase.study.schema import loads

#: 8 nodes of the demo blade's tip (26 nodes) nearest to 8 points evenly spread along its chord: no two of them
#: share a boundary facet, so they are a line, not a face.
LINE = [3, 95, 356, 355, 92, 359, 358, 4]

RUB = """
[rub]
speeds = [1450, 1650]
ratio = 0.005
revolutions = 4
window = 2
max_revolutions = 4
"""

FACE = 'face = "tip"                # the whole tip face rubs: its mean normal displacement meets the casing\n'
WEIGHTS = 'weights = "area"            # nodes weighted by their share of the face (converges under mesh refinement)\n'
STIFFNESS = ("casing_stiffness = 1e6      # N/m: a thin casing's local radial stiffness; the modes converge "
             "(docs/massless.md)\n")


def _line_study(nodes=LINE, stiffness: str | None = None) -> str:
    text = _study(CASING, RUB).replace(FACE, f"nodes = {list(nodes)}\n").replace(WEIGHTS, "")
    text = text.replace('formats = ["png", "vtu"]', 'formats = ["vtu"]').replace("scan = 6", "scan = 2")
    text = text.replace("periods = [0.95, 1.0001]", "periods = [0.99, 1.0001]")
    text += '\n[rotation]\nstatic = "linear"   # (the rub\'s centrifugal state: the quick one for a test)\n'
    return text if stiffness is None else text.replace(STIFFNESS, stiffness)


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    out = tmp_path_factory.mktemp("rub_line")
    return run(loads(_line_study(), source="<line>"), out, progress=False), out


def test_a_line_of_tip_nodes_rubs(result):
    res, out = result
    rows = list(csv.DictReader(open(out / "rub.csv")))
    assert [float(r["speed"]) for r in rows] == [1450.0, 1650.0]
    assert all(r["max_pressure_mpa"] == r["loaded_area_mm2"] == r["load_location"] == "" for r in rows)  # no area
    s = res.summary["rub"]
    assert s["model"]["contact_measure"] == "length" and s["model"]["face_area_mm2"] is None
    assert s["nodes"] == sorted(LINE)
    slow, fast = s["rows"]
    # past the crossing speed (1626 rpm, as with the whole tip face) the rub is far harder; measured (4 revolutions)
    # 0.046 mm, 21.5 N on 4 nodes at 1450 rpm and 0.70 mm, 60.7 N on 4 nodes at 1650 rpm
    assert 1450 < s["crossing"]["speed"] < 1650
    assert fast["tip_normal_displacement_mm"] > 5 * slow["tip_normal_displacement_mm"] > 0
    assert fast["total_force_n"] > 2 * slow["total_force_n"] > 0
    assert 0 < fast["nodes_touching"] <= len(LINE)
    nodes = list(csv.DictReader(open(out / "rub_nodes.csv")))
    assert len(nodes) == 2 * len(LINE) and all(r["contact_pressure_mpa"] == "" for r in nodes)
    text = (out / "report.md").read_text()
    assert "on the line of contact nodes" in text and "no contact pressure" in text
    assert "contact_pressure" not in __import__("meshio").read(out / "rub.vtu").point_data
    from bladecase.post.rub.plot import interaction_plot

    labels = [ax.get_ylabel() for ax in interaction_plot(s).axes]   # no pressure to draw: its panel left out
    assert "peak total contact force (N)" in labels and "peak contact pressure (MPa)" not in labels
    assert "rub: the 8 contact nodes are a line (they hold no facet of the body): each is weighted by its tributary " \
           "length" in (out / "run.log").read_text()


def test_the_casing_is_shared_by_tributary_length():
    """Each node of the line takes the casing's stiffness in proportion to half its distances to its neighbours
    along the line (computed here by sorting the nodes along the chord)."""
    from bladecase.study.rub.stage import _node_stiffness, check_rub_contact
    from bladecase.study.stages import build_contact, build_mesh, build_model

    study = loads(_line_study(), source="<line>")
    model = build_model(study, build_mesh(study))
    contact = build_contact(study, model)
    kind, lengths = check_rub_contact(study, model, contact)
    P = model.mesh.points[list(contact.nodes)]
    order = np.argsort(P[:, 1])           # the demo tip's chord runs mostly along y
    gaps = np.linalg.norm(np.diff(P[order], axis=0), axis=1)
    expected = np.empty(len(LINE))
    expected[order] = np.r_[gaps, 0] / 2 + np.r_[0, gaps] / 2
    assert kind == "length"
    np.testing.assert_allclose(lengths, expected, rtol=1e-12)
    k = _node_stiffness(study, model, contact, lengths)
    np.testing.assert_allclose(k, 1e6 * expected / expected.sum(), rtol=1e-12)


def _tip_and_one_more(node: int = 28) -> list[int]:
    """The demo blade's whole tip face and one node off it (node 28: on the blade's edge, 26 mm below the tip)."""
    from bladecase.study.stages import build_mesh

    mesh = build_mesh(loads(_line_study(), source="<line>"))
    assert mesh.points[node, 2] < 0.13
    return sorted(int(n) for n in mesh.groups["tip"]) + [node]


@pytest.mark.parametrize("nodes, stiffness, match", [
    (LINE, "casing_stiffness_per_area = 2e9\n",
     r"casing_stiffness_per_area: the 8 contact nodes are a line .* give casing_stiffness \(N/m in total: a line of "
     r"nodes shares it by each node's tributary length\)"),
    (None, None, r"\[contact\]: the contact nodes \[28\] hold no facet of the face with the others \(a mid-side "
                 r"node, or a node off the face\)"),
])
def test_an_invalid_selection_is_refused_before_any_factorisation(nodes, stiffness, match, monkeypatch):
    from bladecase.study.executor import SerialExecutor
    from bladecase.study.rub import stage
    from bladecase.study.stages import build_contact, build_mesh, build_model

    nodes = nodes or _tip_and_one_more()
    study = loads(_line_study(nodes), source="<line>")
    model = build_model(study, build_mesh(study))
    contact = build_contact(study, model)   # (a line's contact with a stiffness per area is refused already here)
    study = loads(_line_study(nodes, stiffness), source="<line>")

    def no_spin(*args, **kwargs):
        raise AssertionError("the centrifugal state was computed before the contact selection was checked")

    monkeypatch.setattr(stage, "spin", no_spin)
    with pytest.raises(StudyError, match=match):
        stage.rub_stage(study, model, contact, executor=SerialExecutor())


def test_the_run_checks_the_selection_before_the_modes(tmp_path, monkeypatch):
    """The whole run refuses an invalid selection while assembling, before the reduction and the mode search."""
    import importlib

    run_module = importlib.import_module("bladecase.study.run")

    def no_reference(*args, **kwargs):
        raise AssertionError("the FE modes were computed before the contact selection was checked")

    monkeypatch.setattr(run_module, "fe_reference", no_reference)
    with pytest.raises(StudyError, match=r"the contact nodes \[28\] hold no facet of the face"):
        run(loads(_line_study(_tip_and_one_more()), source="<line>"), tmp_path / "out", progress=False)
