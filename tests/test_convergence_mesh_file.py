"""``[convergence] meshes`` on a study that reads its own mesh file: the finer meshes split the file's cells.

Checked on the committed plate (``meshes/plate.vtu``, 988 triangles): the factors 1, 0.5, 0.33 make meshes split in
1, 2, 3 parts per edge and the order and Richardson estimate use the sizes 1, 1/2, 1/3 actually made (not 0.33); each
mesh is the study on that refined mesh by itself (f1 to 1e-9); the contact face (the group ``tip``) is carried (its
refined nodes are exactly the refined mesh's nodes on the tip line, the contact's weighted centroid unchanged); the
first frequency's extrapolation agrees with that of meshes split in 3, 4, 5, and the study's error covers it;
the report says how the meshes were made.
"""

from __future__ import annotations

import numpy as np
import pytest
from _studies import ROOT

from bladecase.fe import natural_frequencies, refine_mesh
from bladecase.study import run
from bladecase.study.convergence.stage import refined_mesh
from bladecase.study.schema import loads
from bladecase.study.stages import build_contact, build_mesh, build_model

PLATE = f"""
study = {{name = "plate_file"}}
mesh = {{path = "{ROOT / 'meshes' / 'plate.vtu'}"}}
fem = {{order = 1, thickness = 0.002, mass = "lumped"}}
reduction = {{method = "massless", size = 8}}
search = {{ipp = [1], periods = [0.95, 1.0], scan = 8}}
output = {{animate = 1, frames = 4, formats = [], reference = false}}
convergence = {{meshes = [1, 0.5, 0.33]}}
[contact]
clearance = 1e-4
model = "massless"
casing_stiffness = 1e6
face = "tip"
weights = "area"
normal = [0.0, 1.0]
"""


@pytest.fixture(scope="module")
def converged(tmp_path_factory):
    study = loads(PLATE)
    return study, run(study, tmp_path_factory.mktemp("conv-file"), progress=False)


def test_the_sizes_made_are_those_of_the_estimate(converged):
    study, result = converged
    c = result.summary["convergence"]
    assert c["refinement"] == "split" and c["requested"] == [1.0, 0.5, 0.33] and c["splits"] == [1, 2, 3]
    assert c["meshes"] == pytest.approx([1.0, 0.5, 1 / 3], rel=1e-15)
    assert c["dofs"][0] == result.summary["model"]["dofs"] < c["dofs"][1] < c["dofs"][2]
    quiet, mesh = refined_mesh(study, 0.33)
    model = build_model(quiet, mesh)
    assert model.n_dofs == c["dofs"][2]
    assert c["figures"]["f1_hz"]["values"][2] == pytest.approx(natural_frequencies(model, 1)[0], rel=1e-9)


def test_the_contact_face_is_carried(converged):
    study, _ = converged
    coarse = build_mesh(study)
    quiet, fine = refined_mesh(study, 0.5)
    tip_y = coarse.points[coarse.groups["tip"], 1].max()
    on_tip = np.flatnonzero(np.abs(fine.points[:, 1] - tip_y) < 1e-12)
    assert fine.groups["tip"].tolist() == on_tip.tolist() and on_tip.size == 2 * coarse.groups["tip"].size - 1
    centroid = []  # the contact: the face's nodes by their tributary lengths, whose centroid is the face's
    for s, m in ((study, coarse), (quiet, fine)):
        contact = build_contact(s, build_model(s, m))
        assert sorted(contact.nodes) == m.groups["tip"].tolist()
        w = np.asarray(contact.weights)
        assert w.sum() == pytest.approx(1.0, rel=1e-12)
        centroid.append(w @ m.points[list(contact.nodes)])
    assert np.allclose(centroid[0], centroid[1], rtol=0, atol=1e-12)


def test_the_extrapolation_agrees_with_finer_splits(converged):
    """f1 (linear triangles) over splits 1, 2, 3 extrapolates to within 3e-5 of the extrapolation over splits 3, 4, 5
    (measured 1591.738 and 1591.73 Hz; the ×1/4 mesh itself is still 1593.05), and the study's error covers it."""
    from bladecase.study.convergence.stage import richardson

    study, result = converged
    f = result.summary["convergence"]["figures"]["f1_hz"]
    coarse = build_mesh(study)
    fine = [natural_frequencies(build_model(study, refine_mesh(coarse, n)), 1)[0] for n in (4, 5)]
    far = richardson([1 / 3, 1 / 4, 1 / 5], [f["values"][2], *fine])
    assert f["order"] == pytest.approx(2.0, abs=0.2) and far["order"] == pytest.approx(2.0, abs=0.2)
    assert abs(f["extrapolated"] / far["extrapolated"] - 1) < 3e-5 < abs(fine[0] / far["extrapolated"] - 1)
    assert abs(f["values"][0] - far["extrapolated"]) <= f["error"] * f["extrapolated"]


def test_the_report_says_how_the_meshes_were_made(converged):
    from bladecase.post.report import report

    _, result = converged
    text = report(result.summary)
    assert "every cell edge split in 1, 2, 3 parts (sizes ×1, ×0.5, ×0.3333; asked ×1, ×0.5, ×0.33)" in text
