"""A comparison study: [reduction] methods × sizes through the same search, compared against the FE model
(bladecase/study/comparison/stage.py, bladecase/post/comparison/)."""

import json

import numpy as np
import pytest
from _studies import PLATE, ROOT

from bladecase.post.comparison.table import read_comparison_csv
from bladecase.study import run
from bladecase.study.schema import StudyError, loads

GRID = PLATE.replace('method = "modal"\nsize = 10\n', 'method = "modal"\nsize = 10\nmethods = ["modal", '
                     '"craig-bampton", "lanczos-si"]\nsizes = [6, 12]\n') + \
    '\n[output]\nreference = false\nformats = ["png"]\nanimate = 0\n'


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    return run(loads(GRID, base=ROOT), out=tmp_path_factory.mktemp("cmp") / "out", progress=False)


def test_grid_expands_to_every_model(result):
    names = list(result.models)
    assert names == ["modal-10", "modal-6", "modal-12", "craig-bampton-6", "craig-bampton-12", "lanczos-si-6",
                     "lanczos-si-12"]
    for m in result.models.values():
        assert m.build_s >= 0 and m.search_s >= 0 and m.reduced.n >= 6 and m.reduced.model is result.fe_model
    table = result.comparison  # a dict of columns for a notebook (no pandas needed)
    assert table["model"] == ["FE", *names] and len(table["impact_mass_kg"]) == len(names) + 1
    doc = json.loads((result.directory / "modes.json").read_text())
    assert [c["model"] for c in doc["compare"]] == names[1:]  # every model's families are kept


def test_comparison_table_figures_and_words(result):
    rows = read_comparison_csv(result.directory / "comparison.csv")
    assert [r["model"] for r in rows] == ["FE", *result.models]
    by = {r["model"]: r for r in rows}
    # modal models are the FE modes: every checked mode matched by shape; Lanczos-SI 6 has an artefact mode
    assert by["modal-12"]["modes_matched"] == by["modal-12"]["modes_checked"] and not by["modal-12"]["artefacts"]
    assert by["lanczos-si-6"]["artefacts"] >= 1
    # shift-invert Lanczos keeps the static compliance exactly; a truncated modal basis does not
    assert by["lanczos-si-12"]["static_compliance_kept"] == pytest.approx(1.0, rel=1e-8)
    assert by["modal-6"]["static_compliance_kept"] < 0.9
    words = result.summary["comparison"]["diagnostics"]
    assert any("impact mass differs" in w for w in words) and any("no FE counterpart" in w for w in words)
    for name in result.summary["files"]["comparison_figures"].values():
        assert (result.directory / name).stat().st_size > 10_000
    report = (result.directory / "report.md").read_text()
    assert "## Model comparison" in report and "| lanczos-si-6 | 6 |" in report and "nearest-frequency" not in report


@pytest.mark.parametrize("edit, match", [
    ('methods = ["modal", "magic"]', r"\[reduction\] methods: unknown method 'magic'"),
    ("sizes = [8, 8]", r"\[reduction\] sizes: sizes repeat"),
    ("sizes = [0]", r"\[reduction\] sizes: sizes must be integers with 1 <= size <= 6000, got 0"),
])
def test_grid_keys_are_checked(edit, match):
    with pytest.raises(StudyError, match=match):
        loads(PLATE.replace("[search]", edit + "\n[search]"), base=ROOT)  # the last keys of [reduction]


def test_face_weights_key():
    with pytest.raises(StudyError, match=r"\[contact\] weights: only with \[contact\] face"):
        loads(PLATE.replace("clearance = 1e-4", 'clearance = 1e-4\nweights = "area"'), base=ROOT)
    with pytest.raises(StudyError, match=r"\[contact\] weights"):
        loads(PLATE.replace("clearance = 1e-4", 'clearance = 1e-4\nface = "tip"\nweights = "mass"'), base=ROOT)
    study = loads(PLATE.replace("clearance = 1e-4", 'clearance = 1e-4\nface = "tip"\nweights = "area"'), base=ROOT)
    assert study["contact"]["weights"] == "area"


def test_reference_model_is_a_row_of_the_comparison(tmp_path):
    """The reference model of the verification (4 × the size, another method) goes through the same search
    and gets its row, its families in modes.json and its place in the report."""
    text = PLATE.replace('method = "modal"\nsize = 10\n', 'method = "modal"\nsize = 10\nmethods = ["lanczos-si"]\n'
                         'sizes = [6]\n') + '\n[output]\nformats = []\nanimate = 0\n'
    result = run(loads(text, base=ROOT), out=tmp_path / "out", progress=False)
    names = list(result.models)
    assert names == ["modal-10", "lanczos-si-6", "craig-bampton-40 (reference)"]
    ref = result.models["craig-bampton-40 (reference)"]
    assert ref.reduced.n == 42 and ref.search_s > 0  # 40 fixed-interface modes + the 2 contact dofs and ref.build_s > 0
    assert result.comparison["model"] == ["FE", *names]
    row = dict(zip(result.comparison, [c[-1] for c in result.comparison.values()]))
    # 40 Craig–Bampton dofs keep the plate's contact statics and first modes almost exactly
    assert row["static_compliance_kept"] == pytest.approx(1.0, abs=0.02)
    doc = json.loads((result.directory / "modes.json").read_text())
    assert [c["model"] for c in doc["compare"]] == names[1:]
    assert "craig-bampton-40 (reference)" in (result.directory / "report.md").read_text()


def test_the_grid_on_a_dask_local_cluster_gives_the_serial_results(result, tmp_path, dask_executor):
    """The models' searches shipped to a 2-worker Dask LocalCluster come back with the same families and arcs
    (records without their system, bound again on return); three models of the grid."""
    # no figures: the test is about the searches' results (the figures are checked on the serial grid)
    small = GRID.replace('methods = ["modal", "craig-bampton", "lanczos-si"]', 'methods = ["craig-bampton"]'
                         ).replace('formats = ["png"]', "formats = []")
    remote = run(loads(small, base=ROOT), out=tmp_path / "dask", progress=False, executor=dask_executor)
    assert list(remote.models) == ["modal-10", "craig-bampton-6", "craig-bampton-12"]
    for name, m in remote.models.items():
        mine = result.models[name]
        assert len(m.branches) == len(mine.branches), name
        arcs = [(a.T_lo, a.T_hi) for b in m.branches for a in b.arcs]
        assert np.allclose(arcs, [(a.T_lo, a.T_hi) for b in mine.branches for a in b.arcs], rtol=1e-12), name
        assert all(b.system is m.reduced.system for b in m.branches)


def test_comparison_periods_are_a_study_key(result, tmp_path):
    """[reduction] compare_periods: the energy columns at the asked periods (× FE T1), distinct near 1 — as long as
    one of them is inside an admissible arc; periods that miss every arc are replaced by periods inside the arcs
    (run.log says so)."""
    small = GRID.replace('methods = ["modal", "craig-bampton", "lanczos-si"]', 'methods = ["modal"]'
                         ).replace('formats = ["png"]', "formats = []")  # the columns only: no figures
    text = small.replace("sizes = [6, 12]\n", "sizes = [6]\ncompare_periods = [0.998, 0.99999889, 0.9999993]\n")
    other = run(loads(text, base=ROOT), out=tmp_path / "p", progress=False)
    cols = [c for c in other.comparison if c.startswith("energy_")]
    assert cols == ["energy_0.998T1_j", "energy_0.99999889T1_j", "energy_0.9999993T1_j"]
    assert all(e is not None for e in other.comparison["energy_0.998T1_j"][1:])  # 0.998 T1: in both models' arcs
    missed = run(loads(text.replace("0.998, ", "0.6, "), base=ROOT), out=tmp_path / "m", progress=False)
    cols = [c for c in missed.comparison if c.startswith("energy_")]
    assert "energy_0.6T1_j" not in cols and all(e is not None for c in cols for e in missed.comparison[c][1:])
    assert "comparison: compare_periods outside every arc: the compare_periods asked for (0.6, 0.99999889, " \
           "0.9999993 T1) miss every admissible arc" in (missed.directory / "run.log").read_text()
    with pytest.raises(StudyError, match=r"\[reduction\] compare_periods: periods repeat"):
        loads(GRID.replace("sizes = [6, 12]\n", "sizes = [6, 12]\ncompare_periods = [0.9, 0.9]\n"), base=ROOT)
