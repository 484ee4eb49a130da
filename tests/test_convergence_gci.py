"""The mesh error of ``[convergence]`` is the grid convergence index (GCI): Roache's safety factor 1.25 on the
distance from the Richardson extrapolation where three meshes establish the observed order, 3 on the range of the
values where they do not (oscillating, changes that do not shrink, an order out of range).

Checked against the worked example of Celik et al. (2008, J. Fluids Eng. 130, 078001, Table 1: three 2-D grids of
18 000, 8 000 and 4 500 cells, r21 = 1.5, r32 = 4/3, φ = 6.063, 5.972, 5.863 → p = 1.53, φ_ext = 6.1685,
e_ext = 1.7 %, GCI_fine = 2.2 %), against closed forms for each case where the order is not established, and in the
report's words.
"""

from __future__ import annotations

import pytest

from bladecase.post.convergence.report import convergence_report
from bladecase.study.convergence.stage import (
    ORDER_RANGE,
    SAFETY,
    SAFETY_UNESTABLISHED,
    estimate_words,
    richardson,
)


def test_celik_et_al_worked_example():
    """Celik et al.'s Table 1 to its printed digits; our error on the finest grid is 1.25 e_ext."""
    h = [1.5 * 4 / 3, 1.5, 1.0]
    phi = [5.863, 5.972, 6.063]
    r = richardson(h, phi, study_h=1.0)
    assert round(r["order"], 2) == 1.53 and round(r["extrapolated"], 4) == 6.1685
    e_ext = abs(r["extrapolated"] - phi[-1]) / r["extrapolated"]
    gci_fine = SAFETY * abs(phi[-1] - phi[-2]) / phi[-1] / (1.5 ** r["order"] - 1)
    assert round(100 * e_ext, 1) == 1.7 and round(100 * gci_fine, 1) == 2.2
    assert r["error"] == pytest.approx(SAFETY * e_ext, rel=1e-12)
    assert r["safety"] == SAFETY and r["regime"] == "asymptotic" and r["monotone"]


@pytest.mark.parametrize("values, regime, words", [
    ([10.0, 10.4, 10.1], "oscillating", "not monotone"),
    ([10.0, 10.1, 10.5], "not shrinking", "the changes do not shrink with the mesh"),
    ([1.0, 1.5, 1.5001], "order out of range", f"outside {ORDER_RANGE[0]:g}–{ORDER_RANGE[1]:g}"),
    ([1.0 + x ** 0.3 for x in (1.0, 0.7, 0.5)], "order out of range", "observed order 0.3 outside"),
])
def test_an_order_not_established_takes_three_times_the_range(values, regime, words):
    """No extrapolation; the error is 3 × (max − min over the meshes) / |finest value|, said with the reason."""
    r = richardson([1.0, 0.7, 0.5], values)
    assert r["regime"] == regime and r["safety"] == SAFETY_UNESTABLISHED == 3.0 and r["extrapolated"] is None
    assert r["error"] == pytest.approx(3.0 * (max(values) - min(values)) / abs(values[-1]), rel=1e-12)
    assert r["monotone"] == (regime != "oscillating")
    assert words in estimate_words(r) and estimate_words(r).endswith("3 × the range over the meshes")


def test_an_established_order_keeps_roaches_125():
    """f = 2 − h²: order 2, extrapolation 2, error of the study's mesh 1.25 × |f(1) − 2| / 2."""
    r = richardson([1.0, 0.7, 0.5], [2 - x ** 2 for x in (1.0, 0.7, 0.5)])
    assert r["order"] == pytest.approx(2.0, rel=1e-9) and r["extrapolated"] == pytest.approx(2.0, rel=1e-12)
    assert r["error"] == pytest.approx(1.25 * 1.0 / 2.0, rel=1e-9) and estimate_words(r) == ""


def test_the_report_says_which_rule_and_why():
    """Every figure whose order is not established says why next to its error, flagged or not; the header states
    both rules."""
    h = [1.0, 0.7, 0.5]
    figures = {"f1_hz": ([210.5, 212.479, 213.094], "Hz"), "contact_fraction": ([0.18125, 0.18458, 0.18457], ""),
               "energy_j": ([1.0, 1.0001, 1.00005], "J")}
    section = {"meshes": h, "dofs": [1, 2, 3], "ratio": None, "ipp": 1, "flag": 0.02, "flagged": [],
               "figures": {k: {"words": k, "unit": u, "values": v, **richardson(h, v)} for k, (v, u) in
                           figures.items()}}
    section["flagged"] = [k for k, f in section["figures"].items() if f["flag"]]
    lines = convergence_report(section)
    text = "\n".join(lines)
    assert "1.25 ×" in text and "3 × the range of the values over the meshes" in text
    row = {k: next(line for line in lines if line.startswith(f"| {k}")) for k in figures}
    assert row["f1_hz"].endswith("| 1.7 % |")  # order established: no words
    assert row["contact_fraction"].endswith("**5.4 %** (not monotone) |")
    assert row["energy_j"].endswith("| 0.03 % (not monotone) |")  # not flagged, still said
