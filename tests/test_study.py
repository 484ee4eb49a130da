"""Study files: validation before any work, every error naming its key, nothing written on a bad study."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
from _studies import PLATE, ROOT, absolute, as_raw

from bladecase.cli import main
from bladecase.study.demo import demo_study, demo_text
from bladecase.study.schema import SCHEMA, StudyError, load_study, loads, validate


def raw_demo() -> dict:
    """The demo study as a plain dict (keys left at None removed, as a user would write it)."""
    return as_raw(copy.deepcopy(demo_study().config))


def test_demo_study_defaults():
    st = demo_study()
    assert st.name == "demo" and st.parametric
    assert st["contact"]["clearance"] == 1e-4
    assert st["reduction"] == {"method": "massless", "size": 8, "compare": [], "methods": [], "sizes": [],
                               "compare_periods": [0.9, 0.95, 0.99]}
    assert st["contact"]["model"] == "massless" and st["contact"]["face"] == "tip" and st["search"]["ipp"] == [1]
    assert st["output"]["frames"] == 40 and st["output"]["scale"] == "auto"
    # every schema key of the present sections has a value (defaults filled in)
    for section, keys in SCHEMA.items():
        if section == "mesh":
            continue
        assert set(keys) <= set(st[section]), section
    g = st.geometry()
    assert g.lean == 0.03 and g.contact_point == (0.0, 0.03, 0.15)
    assert "[geometry]" in demo_text()


def test_user_mesh_study_resolves_relative_to_its_file(tmp_path):
    st = loads(PLATE, base=ROOT)
    assert not st.parametric and st.mesh_path() == (ROOT / "meshes" / "plate.vtu").resolve()
    assert st.output_dir() == Path("results") / "plate"
    assert st.output_dir(tmp_path) == tmp_path
    f = tmp_path / "s.toml"
    f.write_text(absolute(PLATE))
    assert load_study(f).mesh_path().exists()


def _with(change) -> dict:
    raw = raw_demo()
    change(raw)
    return raw


BAD = [
    # (what the user did, edit of the demo study, words the message must contain)
    ("unknown section", lambda r: r.update(solver={"x": 1}), "[solver]"),
    ("unknown key", lambda r: r["contact"].update(gapp=1e-4), "[contact] gapp: unknown key"),
    ("negative clearance", lambda r: r["contact"].update(clearance=-1e-4), "[contact] clearance: must be > 0"),
    ("zero clearance", lambda r: r["contact"].update(clearance=0.0), "[contact] clearance"),
    ("clearance as string", lambda r: r["contact"].update(clearance="0.1 mm"),
     "[contact] clearance: expected a number"),
    ("missing clearance", lambda r: r["contact"].pop("clearance"), "[contact] clearance: required"),
    ("NaN size", lambda r: r["geometry"].update(size=float("nan")), "[geometry] size"),
    ("bool as integer", lambda r: r["reduction"].update(size=True), "[reduction] size: expected an integer"),
    ("bad method", lambda r: r["reduction"].update(method="pod"), "[reduction] method: must be one of"),
    ("bad compare", lambda r: r["reduction"].update(compare=[{"method": "modal"}]), "[reduction] compare"),
    ("bad periods", lambda r: r["search"].update(periods=[1.0, 0.9]), "[search] periods"),
    ("bad ipp", lambda r: r["search"].update(ipp=[0]), "[search] ipp"),
    ("bad unit", lambda r: r["search"].update(period_unit="ms"), "[search] period_unit"),
    ("bad format", lambda r: r["output"].update(formats=["gif", "avi"]), "[output] formats"),
    ("bad window", lambda r: r["output"].update(window=[10, 10]), "[output] window"),
    ("bad scale", lambda r: r["output"].update(scale="big"), "[output] scale"),
    ("orbit of unsearched ipp", lambda r: r["output"].update(orbits=[{"ipp": 3, "T": 0.95}]), "[output] orbits"),
    ("geometry value", lambda r: r["geometry"].update(span=-0.1), "[geometry] span"),
    ("geometry key", lambda r: r["geometry"].update(chord=0.05), "[geometry] chord: unknown key"),
    ("geometry kind", lambda r: r["geometry"].update(kind="disk"), "[geometry] kind"),
    ("half a material", lambda r: r["material"].update(E=1e11), "[material] nu, rho"),
    ("two contact pickers", lambda r: r["contact"].update(node=3, nearest=[0, 0, 0.15]), "[contact] nearest"),
    ("both geometry and mesh", lambda r: r.update(mesh={"path": "x.msh"}), "[geometry] / [mesh]"),
    ("neither geometry nor mesh", lambda r: r.pop("geometry"), "[geometry] / [mesh]"),
    ("section not a table", lambda r: r.update(fem=3), "[fem]: must be a table"),
]


@pytest.mark.parametrize("what, change, words", BAD, ids=[b[0] for b in BAD])
def test_bad_studies_name_the_key(what, change, words):
    with pytest.raises(StudyError) as err:
        validate(_with(change), source="<test>")
    assert words in str(err.value), str(err.value)


def test_invalid_toml():
    with pytest.raises(StudyError, match="not valid TOML"):
        loads("[contact\nclearance = 1", source="bad.toml")


def test_unreadable_study_file(tmp_path):
    with pytest.raises(StudyError, match="cannot read study file"):
        load_study(tmp_path / "missing.toml")


def _write(tmp_path, text: str) -> Path:
    f = tmp_path / "study.toml"
    f.write_text(text)
    return f


@pytest.mark.parametrize("edit, words", [
    (lambda t: t.replace("clearance = 1e-4", "clearance = -1e-4"), "[contact] clearance"),
    (lambda t: t.replace("meshes/plate.vtu", "meshes/nope.vtu"), "[mesh] path: no such file"),
    (lambda t: t.replace('mass = "lumped"', 'mass = "lumped"\nclamp = "hub"'), "[fem] clamp: the mesh"),
    (lambda t: t.replace("thickness = 0.002\n", ""), "[fem] thickness: required for a 2-D"),
    (lambda t: t.replace("clearance = 1e-4", 'clearance = 1e-4\ngroup = "tip"'), "[contact] group: group 'tip' has"),
    (lambda t: t.replace("clearance = 1e-4", 'clearance = 1e-4\nfarthest = [1, 0]\ngroup = "hub"'),
     "[contact] group: the mesh"),
    (lambda t: t.replace("size = 10", "size = 5000"), "[reduction]"),
])
def test_cli_run_fails_fast_and_writes_nothing(tmp_path, capsys, edit, words):
    text = edit(absolute(PLATE))
    out = tmp_path / "out"
    code = main(["run", str(_write(tmp_path, text)), "--out", str(out), "--quiet", "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2
    assert words in err, err
    assert "Traceback" not in err
    assert not out.exists() or not any(out.iterdir())  # nothing half-written, no staging left


def test_cli_demo_print_study(capsys):
    assert main(["demo", "--print-study"]) == 0
    text = capsys.readouterr().out
    assert loads(text).config == demo_study().config


@pytest.mark.parametrize("lines, expect", [
    ("", "contact"),                                   # the one-node group 'contact'
    ('node = 4', 4),
    ('farthest = [1, 0]', "max-x tip"),                # searches 'tip' by default, not the 'contact' group
    ('nearest = [0.0, 0.05]', "nearest all"),
    ('nearest = [0.0, 0.05]\ngroup = "tip"', "nearest tip"),
])
def test_contact_selectors(lines, expect):
    import numpy as np

    from bladecase.study import pipeline

    st = loads(PLATE.replace("clearance = 1e-4", "clearance = 1e-4\n" + lines), base=ROOT)
    mesh = pipeline.build_mesh(st)
    model = pipeline.build_model(st, mesh)
    node = pipeline.build_contact(st, model).node
    pts, tip = mesh.points, mesh.group("tip")
    free = np.unique(model.dofs.node[model.dofs.node >= 0])
    if expect == "contact":
        assert node == mesh.group("contact")[0]
    elif expect == "max-x tip":
        assert node in tip and pts[node, 0] == pts[tip, 0].max()
    elif expect == "nearest all":
        dist = np.linalg.norm(pts[free, :2] - [0.0, 0.05], axis=1)
        assert node == free[np.argmin(dist)] and pts[node, 1] < 0.09  # mid-span
    elif expect == "nearest tip":
        assert node in tip and pts[node, 1] == pytest.approx(0.1)
    else:
        assert node == expect


def test_readme_study_example_is_valid():
    import re

    text = (ROOT / "README.md").read_text()
    blocks = [b for b in re.findall(r"```toml\n(.*?)```", text, flags=re.S) if "[study]" in b]
    assert blocks, "README has no study example"
    for b in blocks:
        st = loads(b, base=ROOT)
        assert st.parametric or st.mesh_path().exists()
        if st.parametric:
            with pytest.raises(ValueError, match="no mesh file: its mesh is made by gmsh"):
                st.mesh_path()
