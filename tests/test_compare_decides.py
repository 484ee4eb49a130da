"""Comparisons that decide (bladecase/study/comparison/stage.py, bladecase/post/comparison/): periods chosen inside the
models' admissible arcs, a verdict that names the model to use or says why none can be trusted, one readable
overlay figure, no convergence figure without data, observed orders only where sizes converge monotonically, units
in the headers of comparison.csv.

Two studies, each run once:

* ``plate_doc`` — the documented user-mesh example of docs/study.md as a new user runs it (default
  ``compare_periods``; its reference model craig-bampton-40 is compared too): the arcs of modal-10 and of the
  reference meet at one computed period only, 0.98734 T1, where their energies are 0.2605 and 0.2175 J (20 % apart,
  measured); lanczos-si-6's only arc is elsewhere (0.8768 T1);
* ``converging`` — the committed P1 plate (tests/_studies.py) with the massless contact model on its tip face
  (area weights, casing 1e6 N/m, chordwise normal), massless 4, 8 and 16: the energies at the five periods spread
  over the common arc (0.958–0.995 T1) agree to 5.5e-4 (massless-4) and 4.5e-4 (massless-8) of massless-16's,
  the frequencies to 1e-11 (measured).
"""

from __future__ import annotations

import re
import struct
from pathlib import Path

import numpy as np
import pytest
from _studies import PLATE, ROOT

import bladecase as bc
from bladecase.fe import stiffness_factor
from bladecase.post.comparison import table
from bladecase.post.comparison.compare import ModelResult, fe_reference
from bladecase.post.comparison.plots import observed_order, overlay_plot
from bladecase.post.comparison.table import read_comparison_csv
from bladecase.reduction import Contact, reduce
from bladecase.study import run
from bladecase.study.comparison.stage import compare_models
from bladecase.study.schema import loads


def energy_columns(row: dict) -> list[str]:
    return [k for k in row if k.startswith("energy_")]


def documented_plate() -> str:
    """The user-mesh study of docs/study.md, as printed there (its first ```toml block after the heading)."""
    page = (ROOT / "docs" / "study.md").read_text(encoding="utf-8")
    body = page[page.index("### A user-mesh study"):]
    return re.search(r"```toml\n(.*?)```", body, flags=re.S).group(1)


def png_size(path: Path) -> tuple[int, int]:
    """(width, height) in pixels, from the PNG header (IHDR)."""
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR"
    return struct.unpack(">II", head[16:24])


@pytest.fixture(scope="module")
def plate_doc(tmp_path_factory):
    text = documented_plate().replace('animate = 1', 'animate = 0').replace(
        'formats = ["gif", "vtu", "png"]', 'formats = ["png"]')  # no orbit animated: the comparison is the subject
    return run(loads(text, base=ROOT), out=tmp_path_factory.mktemp("doc") / "out", progress=False)


CONVERGING = PLATE.replace(
    "clearance = 1e-4", 'clearance = 1e-4\nface = "tip"\nweights = "area"\nmodel = "massless"\n'
    "casing_stiffness = 1e6\nnormal = [1.0, 0.0]").replace(
    'method = "modal"\nsize = 10\n', 'method = "massless"\nsize = 4\nmethods = ["massless"]\nsizes = [4, 8, 16]\n'
).replace("periods = [0.5, 0.9999]", 'periods = [0.95, 1.0001]\nperiod_unit = "T1"\nscan = 6') + \
    '\n[output]\nreference = false\nformats = ["png"]\nanimate = 0\n'


@pytest.fixture(scope="module")
def converging(tmp_path_factory):
    return run(loads(CONVERGING, base=ROOT), out=tmp_path_factory.mktemp("conv") / "out", progress=False)


# --------------------------------------------------------------------------- 1. periods inside the arcs


def test_the_documented_example_gets_energies_with_the_default_periods(plate_doc):
    """compare_periods not given: the periods are where the models' arcs meet, so the energy columns have numbers
    (the default 0.9, 0.95, 0.99 T1 miss every arc of this plate); run.log says how they were chosen."""
    rows = read_comparison_csv(plate_doc.directory / "comparison.csv")
    by = {r["model"]: r for r in rows}
    (col,) = energy_columns(rows[0])  # one computed period in common: 0.98734 T1
    assert col.startswith("energy_0.98733") and col.endswith("T1_j")
    assert by["modal-10"][col] == pytest.approx(0.2605, rel=1e-3)
    assert by["craig-bampton-40 (reference)"][col] == pytest.approx(0.2175, rel=1e-3)
    assert by["lanczos-si-6"][col] is None  # its only arc is elsewhere
    log = (plate_doc.directory / "run.log").read_text()
    assert ("comparison: compare_periods not given: 1 period inside 0.98734 T1, where the admissible arcs of "
            "modal-10 and craig-bampton-40 (reference) overlap (lanczos-si-6 has no admissible arc there)") in log


def test_converging_models_are_compared_inside_their_common_arc(converging):
    rows = converging.summary["comparison"]["rows"]
    cols = energy_columns(rows[0])
    assert len(cols) == 5 and all(r[c] is not None for r in rows[1:] for c in cols)
    f = [float(c.removeprefix("energy_").removesuffix("T1_j")) for c in cols]
    assert 0.95 < f[0] < f[-1] < 1.0001 and np.all(np.diff(f) > 0)


# --------------------------------------------------------------------------- 2. a verdict that decides


def test_the_verdict_names_the_model_and_size_to_use(converging):
    report = (converging.directory / "report.md").read_text()
    section = report[report.index("## Model comparison"):]
    first = section.split("\n")[2]  # the section opens with the verdict
    assert first.startswith("**Verdict:** Use massless-4: within 0.055 % of the reference massless-16 from size 4 "
                            "(energies at 5 periods, 0.958–0.995 T1, within 0.055 %;")
    assert first.endswith("tolerances 1 % and 0.1 %).")
    rows = read_comparison_csv(converging.directory / "comparison.csv")
    v = table.comparison_verdict(rows)  # the same verdict from the CSV alone
    assert (v["decision"], v["model"], v["method"], v["size"], v["reference"]) == (
        "use", "massless-4", "massless", 4, "massless-16")
    # independent: the largest relative energy difference from massless-16 over the five periods
    cols = energy_columns(rows[0])
    by = {r["model"]: r for r in rows}
    dev = max(abs(by["massless-4"][c] / by["massless-16"][c] - 1) for c in cols)
    assert v["energy_deviation"] == pytest.approx(max(dev, by["massless-8"]["ref_energy_deviation"]), rel=1e-12)
    assert 1e-4 < dev < 1e-3 and v["frequency_deviation"] < 1e-9


def test_the_verdict_says_why_no_model_can_be_trusted(plate_doc):
    report = (plate_doc.directory / "report.md").read_text()
    section = report[report.index("## Model comparison"):]
    assert section.split("\n")[2] == (
        "**Verdict:** No model can be trusted here, because the models disagree with the reference craig-bampton-40 "
        "(reference) in energy: the closest, modal-10, is 20 % off (tolerance 1 %).")
    v = table.comparison_verdict(read_comparison_csv(plate_doc.directory / "comparison.csv"))
    assert v["decision"] == "none" and v["reasons"] == ["disagree"] and v["model"] is None


def test_every_reason_for_no_model_comes_from_the_data():
    """Built rows: the reference without an arc, arcs that do not overlap, sizes that do not converge."""
    def row(name, size, dofs, arcs, energies, ref=0, df=0.0):
        return {"model": name, "method": name.rsplit("-", 1)[0], "size": size, "dofs": dofs, "admissible_arcs": arcs,
                "is_reference": ref, "ref_frequency_deviation": df,
                **{f"energy_{p}T1_j": e for p, e in zip((0.9, 0.95), energies)}}

    no_arc = [row("modal-8", 8, 8, 2, (1.0, 2.0)), row("modal-32", 32, 32, 0, (None, None), ref=1)]
    v = table.comparison_verdict(no_arc)
    assert v["reasons"] == ["reference_no_arc"] and "the reference modal-32 (32 dofs, the largest model) has no " \
        "admissible arc" in v["sentence"]
    apart = [row("modal-8", 8, 8, 1, (1.0, None)), row("cb-8", 8, 10, 1, (None, 2.0), ref=1)]
    assert table.comparison_verdict(apart)["reasons"] == ["arcs_disjoint"]
    wobbly = [row("modal-8", 8, 8, 1, (1.02, 2.0)), row("modal-16", 16, 16, 1, (1.05, 2.0)),
              row("modal-24", 24, 24, 1, (1.03, 2.0)), row("modal-32", 32, 32, 1, (1.0, 2.0), ref=1)]
    v = table.comparison_verdict(wobbly)
    assert v["reasons"] == ["disagree", "not_monotone"]
    assert "modal does not converge monotonically with size: its energies are 2 % at 8, 5 % at 16, 3 % at 24 off " \
           "the reference" in v["sentence"]
    off = [row("modal-8", 8, 8, 1, (1.0, 2.0), df=0.02), row("modal-32", 32, 32, 1, (1.0, 2.0), ref=1)]
    v = table.comparison_verdict(off)
    assert v["reasons"] == ["frequencies_off"]
    assert "the linear frequencies are 2 % off (tolerance 0.1 %" in v["sentence"]
    agree = [r | {"energy_0.9T1_j": 1.0} for r in wobbly]
    assert table.comparison_verdict(agree)["sentence"].startswith("use modal-8: within 0 % of the reference modal-32")


# --------------------------------------------------------------------------- 3. readable figures


@pytest.fixture(scope="module")
def strip():
    """The committed P1 plate (1084 free dofs) with a tip contact: 12 FE modes and reduced models on demand."""
    model = bc.assemble(bc.load_mesh(ROOT / "meshes" / "plate.msh"), "Ti-6Al-4V", order=1, thickness=0.002)
    contact, factor = Contact(int(model.mesh.group("contact")[0]), [0.0, 1.0], 1e-4), stiffness_factor(model)
    return model, contact, factor, fe_reference(model, contact, 12, factor=factor)


def test_one_overlay_for_a_grid_of_twelve_models(strip, tmp_path):
    """Twelve models (3 methods × 4 sizes): one pair of axes, a legend of methods, sizes and kinds of marks — not
    one entry per model — in a PNG of at most 2000 px a side; the 1-ipp backbone of each model, 0.5 to 0.999 T1."""
    model, contact, factor, fe = strip
    T = np.linspace(0.5, 0.999, 60) / fe.frequencies[0]
    entries = []
    for method in ("modal", "craig-bampton", "lanczos-si"):
        for size in (4, 6, 8, 12):
            r = reduce(model, contact, method, size, factor=factor)
            entries.append(ModelResult(r, [bc.backbone(r.system, T)], 0.0, 0.0))
    out = compare_models(fe, entries, tmp_path, title="strip")
    w, h = png_size(tmp_path / out["figures"]["overlay"])
    assert w <= 2000 and h <= 2000
    fig_legend = [t.get_text() for t in overlay_plot(entries, fe).axes[0].get_legend().get_texts()]
    assert fig_legend[:7] == ["modal", "craig-bampton", "lanczos-si", "size 4", "size 6", "size 8", "size 12"]
    assert not any(e.name in t for e in entries if e.name != "craig-bampton-12" for t in fig_legend)
    assert len(fig_legend) <= 12


def test_no_convergence_figure_without_data(strip, tmp_path):
    """Two sizes of one method but no admissible orbit anywhere: the convergence figure is not drawn (no empty
    axes), and the diagnostics say why."""
    model, contact, factor, fe = strip
    entries = [ModelResult(reduce(model, contact, "modal", n, factor=factor), [], 0.0, 0.0) for n in (4, 8)]
    out = compare_models(fe, entries, tmp_path, title="strip")
    assert "convergence" not in out["figures"] and not (tmp_path / "comparison_convergence.png").exists()
    assert set(out["figures"]) == {"overlay", "spectrum"}
    reason = ("no convergence figure: no method has two sizes with an admissible orbit at a comparison period")
    assert out["skipped"] == {"convergence": reason} and reason in out["diagnostics"]
    assert out["verdict"]["reasons"] == ["no_arcs"]


def test_the_convergence_figure_when_it_has_data(converging):
    figures = converging.summary["files"]["comparison_figures"]
    assert set(figures) == {"overlay", "convergence", "spectrum"}
    for name in figures.values():
        w, h = png_size(converging.directory / name)
        assert w <= 2000 and h <= 2000


# --------------------------------------------------------------------------- 4. observed orders


def test_orders_only_where_three_sizes_converge_monotonically():
    s = [8, 16, 32, 36]
    # like the demo's massless energies at 0.99 T1 (sizes 8, 16, 32, 36): up, down, up — a fit through all the
    # changes gives 6.8 here
    wobbly = [1.150587e-2, 1.1508546e-2, 1.1508532e-2, 1.1508547e-2]
    growing = [1.0, 1.01, 1.03]  # the change grows: the fit gave a negative order
    assert observed_order(s, wobbly) is None and observed_order([8, 16, 32], growing) is None
    assert table.convergence_order(s, wobbly) == (None, "not monotone")
    assert table.convergence_order([8, 16, 32], growing) == (None, "not monotone")
    p, words = table.convergence_order([8, 16, 32], [2 + 5 * x**-2.0 for x in (8, 16, 32)])
    assert p == pytest.approx(2.0, abs=1e-12) and words == "order 2"
    # a flip at the small sizes, then three sizes converging: the order of the three largest
    tail = [1.5, 1.2, 1.3 - 0.1, 1.3 - 0.05, 1.3 - 0.025]
    assert table.convergence_order([4, 8, 16, 32, 64], tail)[0] == pytest.approx(1.0, abs=1e-12)
    assert table.convergence_order([8, 16], [1.0, 2.0]) == (None, "fewer than 3 sizes")
    assert table.convergence_order([8, 16, 32], [1.0, 1.0, 1.0]) == (None, "no change")


def test_the_rows_say_not_monotone_instead_of_a_number(converging):
    orders = {r["observed_order"] for r in converging.summary["comparison"]["rows"][1:]}
    assert len(orders) == 1
    (order,) = orders
    assert order == "not monotone" or float(order) > 0


# --------------------------------------------------------------------------- 5. comparison.csv


DIMENSIONLESS = {"model", "method", "size", "contact_model", "dofs", "modes_checked", "modes_matched",
                 "max_frequency_error", "artefacts", "artefact_modes", "unchecked_modes", "impact_mass_kept",
                 "static_compliance_kept", "families", "families_with_arcs", "admissible_arcs", "is_reference",
                 "ref_energy_deviation", "ref_frequency_deviation", "convergence", "convergence_delta",
                 "observed_order"}


def test_the_csv_headers_carry_their_units(plate_doc, converging):
    for result in (plate_doc, converging):
        header = (result.directory / "comparison.csv").read_text().split("\n")[0].split(",")
        units = [h for h in header if h not in DIMENSIONLESS]
        assert all(re.search(r"_(hz|s|j|kg|m_per_n|n_per_m)$", h) for h in units), units
        assert {"impact_mass_kg", "static_compliance_m_per_n", "contact_stiffness_n_per_m", "T1_s", "build_s",
                "search_s", "frequencies_hz"} <= set(header)
        assert all(h.endswith("T1_j") for h in header if h.startswith("energy_"))
    fe = read_comparison_csv(converging.directory / "comparison.csv")[0]
    assert fe["model"] == "FE" and fe["contact_model"] is None  # no search ran on the FE model: no contact model


# --------------------------------------------------------------------------- 6. speed


# --------------------------------------------------------------------------- the summary (run.py keeps it)


def test_the_summary_carries_the_verdict_and_the_periods(plate_doc, converging):
    v = converging.summary["comparison"]["verdict"]
    assert (v["decision"], v["model"], v["size"], v["energy_rtol"], v["frequency_rtol"]) == (
        "use", "massless-4", 4, 0.01, 0.001)
    assert v["sentence"].startswith("use massless-4: within 0.055 % of the reference massless-16 from size 4")
    periods = converging.summary["comparison"]["periods"]
    assert periods["source"] == "intersection" and len(periods["fractions"]) == 5
    assert periods["words"].startswith("5 periods spread inside the intersection of the admissible arcs of "
                                       "massless-4, massless-8 and massless-16")
    v = plate_doc.summary["comparison"]["verdict"]
    assert v["decision"] == "none" and v["reasons"] == ["disagree"]
    assert plate_doc.summary["comparison"]["periods"]["source"] == "overlap"
