"""Node selection by coordinates (issue 15): rules, messages, clamps of meshes without groups, Nastran PIDs."""

import meshio
import numpy as np
import pytest
from test_fe_elements import WEDGES, box, split

from bladecase.fe import assemble, load_mesh, natural_frequencies
from bladecase.fe.mesh import Mesh, from_meshio
from bladecase.fe.select import TOL_FRACTION, select_nodes


@pytest.fixture(scope="module")
def bar() -> Mesh:
    """8 × 2 × 2 hexahedra on [0, 0.08] × [0, 0.01] × [0, 0.01] (edges 10 mm and 5 mm)."""
    return from_meshio(box((0.08, 0.01, 0.01), (8, 2, 2), "hexahedron"), source="bar")


def test_rules_select_what_they_say(bar):
    x = bar.points
    np.testing.assert_array_equal(select_nodes(bar, {"plane": [0, 0, 0, 1, 0, 0]}), np.flatnonzero(x[:, 0] == 0))
    tilted = select_nodes(bar, {"plane": [0.04, 0, 0, -2, 0, 0], "tol": 0.0101})  # normal of any length
    np.testing.assert_array_equal(tilted, np.flatnonzero(np.abs(x[:, 0] - 0.04) < 0.0101))
    assert len(tilted) == 27
    inside = select_nodes(bar, {"box": [[0.015, 0.0, 0.0], [0.05, 0.005, 0.01]]})
    np.testing.assert_array_equal(inside, np.flatnonzero((x[:, 0] > 0.015) & (x[:, 0] < 0.051) & (x[:, 1] < 0.006)))
    assert len(inside) == 24  # bounds included: x = 0.02 … 0.05, y = 0, 0.005
    ball = select_nodes(bar, {"sphere": [0.08, 0.005, 0.005, 0.0051]})
    np.testing.assert_array_equal(ball, np.flatnonzero(np.linalg.norm(x - [0.08, 0.005, 0.005], axis=1) <= 0.0051))
    assert len(ball) == 5  # the tip face's centre and its 4 edge midpoints
    (one,) = select_nodes(bar, {"nearest": [0.1, 0.02, -0.01]})
    assert x[one].tolist() == [0.08, 0.01, 0.0]
    assert select_nodes(bar, {"plane": [0, 0, 0, 1, 0, 0]}).dtype == np.int64


def test_default_tolerance_is_a_fraction_of_the_shortest_edge(bar):
    near = {"plane": [0.9 * TOL_FRACTION * 0.005, 0, 0, 1, 0, 0]}
    assert len(select_nodes(bar, near)) == 9
    far = {"plane": [1.1 * TOL_FRACTION * 0.005, 0, 0, 1, 0, 0]}
    with pytest.raises(ValueError, match=r"selects no node of mesh bar \(tol 5e-06\): its bounding box is "
                                         r"\[\[0, 0, 0\], \[0.08, 0.01, 0.01\]\], the nearest node \(0 at \[0, 0, 0\]\)"
                                         r" is 5.5e-06 away"):
        select_nodes(bar, far)


@pytest.mark.parametrize("spec, message", [
    ({"plane": [0, 0, 0, 0, 0, 0]}, r"normal \(the last 3 values\) must not be zero"),
    ({"plane": [0, 0, 1, 0]}, r"plane = \[0, 0, 1, 0\] must be 6 finite numbers \[x0, y0, z0, nx, ny, nz\]"),
    ({"box": [[1, 0, 0], [0, 1, 1]]}, r"min <= max"),
    ({"box": [0, 0, 0, 1, 1]}, r"box = \[0, 0, 0, 1, 1\] must be 6 finite numbers"),
    ({"sphere": [0, 0, 0, -1]}, r"radius must be >= 0, got -1"),
    ({"sphere": [0, 0, "x", 1]}, r"sphere = \[0, 0, 'x', 1\] must be 4 finite numbers"),
    ({"nearest": [0, 0, float("nan")]}, r"nearest = \[0, 0, nan\] must be 3 finite"),
    ({"nearest": [0, 0, 0], "tol": 1}, r"tol does not apply to nearest"),
    ({"plane": [0, 0, 0, 1, 0, 0], "tol": -1}, r"tol = -1 must be a finite length >= 0"),
    ({"plane": [0, 0, 0, 1, 0, 0], "box": [[0, 0, 0], [1, 1, 1]]}, r"exactly one of plane, box, sphere, nearest, got "
                                                                    r"plane, box"),
    ({"tol": 1}, r"exactly one of .*got none"),
    ({"cylinder": [0, 0, 0, 1]}, r"unknown key 'cylinder'; valid: one of plane, box, sphere, nearest, and tol"),
    (3, r"clamp must be a group name or a dict with one of plane, box, sphere, nearest \(and tol\), got 3"),
    ("casing", r"no group 'casing'"),
])
def test_bad_selections_name_the_value(bar, spec, message):
    with pytest.raises(ValueError, match=message):
        select_nodes(bar, spec, what="clamp")


def test_planar_selections_accept_two_coordinates():
    strip = from_meshio(box((0.1, 0.01), (10, 2), "quad"), source="strip")
    np.testing.assert_array_equal(select_nodes(strip, {"plane": [0, 0, 1, 0]}), [0, 1, 2])
    np.testing.assert_array_equal(select_nodes(strip, {"box": [[0.095, 0], [0.1, 0.01]]}), [30, 31, 32])
    assert select_nodes(strip, {"nearest": [0.2, 0.02]}).tolist() == [32]
    assert select_nodes(strip, {"sphere": [0.1, 0.005, 1e-4]}).tolist() == [31]


def test_clamp_by_coordinates_equals_clamp_by_group(bar):
    root = np.flatnonzero(bar.points[:, 0] == 0)
    grouped = Mesh(bar.points, bar.cells, 3, {"root": root}, source="bar")
    f_group = natural_frequencies(assemble(grouped, "steel", order=2), 3)
    by_plane = assemble(bar, "steel", order=2, clamp={"plane": [0, 0, 0, 1, 0, 0]})
    np.testing.assert_array_equal(by_plane.clamped, root)
    np.testing.assert_allclose(natural_frequencies(by_plane, 3), f_group, rtol=1e-12)
    with pytest.raises(ValueError, match=r"clamp \{'box': .*\} selects every node of the body of mesh bar \(81 "):
        assemble(bar, "steel", order=1, clamp={"box": [[-1, -1, -1], [1, 1, 1]]})
    with pytest.raises(ValueError, match=r"clamp \{'plane': .*\} selects no node of mesh bar"):
        assemble(bar, "steel", order=1, clamp={"plane": [-1, 0, 0, 1, 0, 0]})


def test_nastran_property_ids_become_groups(tmp_path):
    """meshio writes Nastran bulk data with the element property ids; they come back as ``pid_<id>`` groups."""
    hexa = box((0.04, 0.01, 0.01), (4, 1, 1), "hexahedron")
    pid = np.array([1, 1, 2, 2])
    m = meshio.Mesh(hexa.points, hexa.cells, cell_data={"nastran:ref": [pid]})
    meshio.write(tmp_path / "bar.bdf", m, file_format="nastran")
    mesh = load_mesh(tmp_path / "bar.bdf", require=("pid_1", "pid_2"))
    assert mesh.body_type == "hexahedron" and len(mesh.points) == 20
    np.testing.assert_allclose(mesh.points, hexa.points, atol=1e-9)
    np.testing.assert_array_equal(mesh.group("pid_1"), np.unique(hexa.cells[0].data[:2]))
    np.testing.assert_array_equal(mesh.group("pid_2"), np.unique(hexa.cells[0].data[2:]))
    wedges = split(hexa, WEDGES)
    meshio.write(tmp_path / "w.nas", wedges, file_format="nastran")
    assert load_mesh(tmp_path / "w.nas").body_type == "wedge"


def test_a_study_clamps_by_coordinates(tmp_path):
    """[fem] clamp = {plane = ...} on a mesh without a root group gives the frequencies of the group clamp."""
    from _studies import PLATE, ROOT

    from bladecase.study import run
    from bladecase.study.schema import StudyError, loads

    base = PLATE + '\n[output]\nformats = []\nanimate = 0\nreference = false\n'
    by_group = run(loads(base, base=ROOT), out=tmp_path / "a", progress=False)
    text = base.replace("thickness = 0.002", 'thickness = 0.002\nclamp = {plane = [0, 0, 0, 0, 1, 0]}')
    by_plane = run(loads(text, base=ROOT), out=tmp_path / "b", progress=False)
    fa, fb = (r.summary["model"]["linear_frequencies_hz"] for r in (by_group, by_plane))
    assert by_plane.summary["model"]["clamped_nodes"] == by_group.summary["model"]["clamped_nodes"]
    assert np.allclose(fa, fb, rtol=1e-12)
    with pytest.raises(StudyError, match=r"\[fem\] clamp: must hold exactly one of plane, box, sphere"):
        loads(base.replace("thickness = 0.002", 'thickness = 0.002\nclamp = {plane = [0, 0, 0, 0, 1, 0], '
                           'box = [[0, 0], [1, 1]]}'), base=ROOT)
    bad = base.replace("thickness = 0.002", 'thickness = 0.002\nclamp = {plane = [0, 5, 0, 0, 1, 0]}')
    with pytest.raises(StudyError, match=r"\[fem\] clamp .* selects no node of mesh"):
        run(loads(bad, base=ROOT), out=tmp_path / "c", progress=False)


def test_a_study_takes_its_contact_face_by_coordinates():
    """[contact] face = {plane = ...} selects the same nodes as the plate's 'tip' group: the same constraint."""
    from _studies import PLATE, ROOT

    from bladecase.study.schema import StudyError, loads
    from bladecase.study.stages import build_contact, build_mesh, build_model

    def contact(face):
        text = PLATE.replace("clearance = 1e-4", f"clearance = 1e-4\nface = {face}\nweights = \"area\"")
        study = loads(text, base=ROOT)
        model = build_model(study, build_mesh(study))
        return build_contact(study, model).w(model)

    w_group, w_plane = contact('"tip"'), contact("{plane = [0, 0.1, 0, 0, 1, 0]}")
    assert np.count_nonzero(w_group) > 2 and np.allclose(w_group, w_plane, rtol=0, atol=1e-15)
    with pytest.raises(StudyError, match=r"\[contact\] face .*selects no node"):
        contact("{plane = [0, 0.5, 0, 0, 1, 0]}")
