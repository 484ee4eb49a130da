"""The comparison study's analysis and figures (bladecase.post.comparison.compare, comparison.table, comparison.plots).

Reference model: the committed plane-stress plate ``meshes/plate.msh`` (P1, 1084 free dofs, Ti-6Al-4V, 2 mm,
root clamped at y = 0), contact at its ``contact`` node on the tip (x = 5 mm, y = 100 mm) with the casing normal
``+y`` (along the span) and a 0.1 mm clearance; 12 FE modes (1610 Hz … 85.9 kHz). Independent references are
numpy/scipy only (dense solves of the 1084-dof matrices).

Measured on this model (tolerances keep a margin of 10–100 unless said):

* modal-8 against FE: MAC 1 − 1e-15, frequency errors <= 3e-15;
* lanczos-si-6: modes 1–4 match FE 1–4 (MAC >= 0.9988, error <= 2.6e-3); mode 5 (39157 Hz) has best MAC 0.67
  (FE 6 at 37996 Hz, 3 % away in frequency; index pairing would give FE 5): an artefact; mode 6 (181 kHz) is
  above the FE modes computed;
* exact FE impact mass ``1/(wᵀM⁻¹w)`` = 2.68e-6 kg and static compliance ``wᵀK⁻¹w`` = 4.41e-8 m/N, to 1e-15
  of dense solves; the modal model keeps 2672× (4 modes), 417× (16), 94× (64) … 1 (all 1084 modes, 1e-10) of
  the impact mass and 71 % … 100 % of the compliance; shift-invert Lanczos keeps the compliance to 1e-12, the
  massless model (lumped plate) to 3e-13 (6 modes) and 5e-12 (exact);
* mode 1 (in-plane bending) moves the contact along the span by 6.7 % of its largest dof displacement.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import bladecase as bc
from bladecase.fe import stiffness_factor
from bladecase.post.comparison.compare import (
    ModelResult,
    arc_energies,
    contact_spectrum,
    fe_reference,
    kept_fraction,
    mac_matrix,
    match_modes,
    model_matches,
)
from bladecase.post.comparison.diagnose import diagnose
from bladecase.post.comparison.plots import MARKERS, convergence_plot, observed_order, overlay_plot, spectral_plot
from bladecase.post.comparison.table import (
    comparison_rows,
    convergence_verdict,
    energy_column,
    read_comparison_csv,
    write_comparison_csv,
)
from bladecase.reduction import Contact, reduce

MESHES = Path(__file__).resolve().parent.parent / "meshes"
GAP = 1e-4
FE_MODES = 12


# --------------------------------------------------------------------------- fixtures


def load_plate(mass: str = "consistent"):
    plate = bc.assemble(bc.load_mesh(MESHES / "plate.msh"), "Ti-6Al-4V", order=1, thickness=0.002, mass=mass)
    return plate, Contact(int(plate.mesh.group("contact")[0]), [0.0, 1.0], GAP), stiffness_factor(plate)


@pytest.fixture(scope="module")
def plate():
    return load_plate()


@pytest.fixture(scope="module")
def fe(plate):
    model, contact, factor = plate
    return fe_reference(model, contact, FE_MODES, factor=factor)


@pytest.fixture(scope="module")
def models(plate, fe):
    """modal-4, modal-8, lanczos-si-6, each with its 1-ipp scan from 0.5 to 0.999 T1."""
    model, contact, factor = plate
    T = np.linspace(0.5, 0.999, 120) / fe.frequencies[0]
    out = {}
    for method, size in (("modal", 4), ("modal", 8), ("lanczos-si", 6)):
        r = reduce(model, contact, method, size, factor=factor)
        out[f"{method}-{size}"] = ModelResult(r, [bc.backbone(r.system, T)], build_s=0.01, search_s=0.1)
    return out


# --------------------------------------------------------------------------- mode matching


def test_modal_modes_are_the_fe_modes(plate, fe):
    model, contact, factor = plate
    matches = model_matches(reduce(model, contact, "modal", 8, factor=factor), fe)
    assert [m.fe_index for m in matches] == list(range(8))
    assert min(m.mac for m in matches) > 1 - 1e-10
    assert max(abs(m.relative_error) for m in matches) < 1e-10
    assert not any(m.artefact or m.beyond_fe for m in matches)


def test_a_lanczos_ritz_artefact_is_never_paired_with_an_fe_mode(plate, fe):
    model, contact, factor = plate
    r = reduce(model, contact, "lanczos-si", 6, factor=factor)
    matches = model_matches(r, fe)
    assert [m.fe_index for m in matches[:4]] == [0, 1, 2, 3]
    assert min(m.mac for m in matches[:4]) > 0.99
    art = matches[4]
    assert art.fe_index is None and art.artefact and art.relative_error is None
    # what index or nearest-frequency pairing would have done: FE 5, or FE 6 at 3 % — both wrong
    assert abs(art.frequency / fe.frequencies[5] - 1) < 0.05
    # independent: the Ritz vector mixes FE modes (dense M), no single one reaches 0.9
    psi = r.basis @ r.system.spectrum.phi[:, 4]
    Md = model.M.toarray()
    mac = (fe.modes.T @ Md @ psi) ** 2 / ((psi @ Md @ psi) * np.einsum("ij,ij->j", fe.modes, Md @ fe.modes))
    assert mac.max() < 0.9 and np.sort(mac)[-2] > 0.05 and mac.sum() <= 1 + 1e-12
    assert art.mac == pytest.approx(mac.max(), rel=1e-10)
    assert "no FE counterpart" in art.describe()
    assert matches[5].beyond_fe and not matches[5].artefact and matches[5].frequency > fe.frequencies[-1]


def test_mac_only_multiplies_by_m(plate, fe):
    """A LinearOperator (no entries to densify) gives the same MAC as the sparse matrix."""
    model, contact, factor = plate
    psi = reduce(model, contact, "craig-bampton", 6, factor=factor).basis
    ref = mac_matrix(fe.modes, model.M, psi)
    assert np.abs(mac_matrix(fe.modes, spla.aslinearoperator(model.M), psi) - ref).max() < 1e-14
    assert ref.min() >= 0 and ref.max() <= 1 + 1e-12


def test_repeated_frequencies_match_through_their_span():
    m = np.array([1.0, 2.0, 3.0, 4.0])
    M = sp.diags_array(m, format="csr")
    fe_modes = np.diag(1 / np.sqrt(m))  # M-orthonormal, frequencies 1, 2, 2, 3
    a, b = fe_modes[:, 1], fe_modes[:, 2]
    red = np.c_[(a + b) / np.sqrt(2), (a - b) / np.sqrt(2), fe_modes[:, 0]]
    assert mac_matrix(fe_modes, M, red)[1:3, :2] == pytest.approx(0.5)
    got = match_modes(fe_modes, M, red, fe_frequencies=[1.0, 2.0, 2.0, 3.0], frequencies=[2.0, 2.0, 1.0])
    assert sorted(m.fe_index for m in got[:2]) == [1, 2] and got[2].fe_index == 0
    assert min(m.mac for m in got) == pytest.approx(1.0, abs=1e-12)
    alone = match_modes(fe_modes, M, red)  # without frequencies there is no cluster: 0.5 < 0.9
    assert [m.fe_index for m in alone] == [None, None, 0]


def test_match_modes_rejects_bad_input():
    with pytest.raises(ValueError, match=r"threshold must be a MAC in \(0.5, 1\]"):
        match_modes(np.eye(2), np.eye(2), np.eye(2), threshold=0.5)
    with pytest.raises(ValueError, match="must be"):
        match_modes(np.eye(3), np.eye(2), np.eye(2))
    with pytest.raises(ValueError, match="frequencies must have one entry per mode"):
        match_modes(np.eye(2), np.eye(2), np.eye(2), frequencies=[1.0])


# --------------------------------------------------------------------------- contact spectral data


def test_fe_contact_measures_are_exact(plate, fe):
    model, contact, _ = plate
    w = contact.w(model)
    assert fe.impact_mass == pytest.approx(1 / (w @ np.linalg.solve(model.M.toarray(), w)), rel=1e-12)
    assert fe.static_compliance == pytest.approx(w @ np.linalg.solve(model.K.toarray(), w), rel=1e-12)
    assert np.allclose(fe.b, w @ fe.modes)


def test_modal_impact_mass_converges_to_the_fe_value(plate, fe):
    model, contact, factor = plate
    kept_mass, kept_compliance = [], []
    for size in (4, 16, 64, model.n_dofs):
        s = contact_spectrum(reduce(model, contact, "modal", size, factor=factor))
        kept_mass.append(kept_fraction(s.impact_mass, fe.impact_mass))
        kept_compliance.append(kept_fraction(s.static_compliance, fe.static_compliance))
    assert np.all(np.diff(kept_mass) < 0) and kept_mass[0] > 1000  # the node's own inertia is missed
    assert kept_mass[-1] == pytest.approx(1.0, abs=1e-8)
    assert np.all(np.diff(kept_compliance) > 0) and kept_compliance[-1] == pytest.approx(1.0, abs=1e-8)


def test_shift_invert_lanczos_and_massless_keep_the_static_compliance(plate, fe):
    model, contact, factor = plate
    s = contact_spectrum(reduce(model, contact, "lanczos-si", 6, factor=factor))
    assert s.static_compliance == pytest.approx(fe.static_compliance, rel=1e-10)  # moment Σb²/ω² is matched
    lumped, contact_l, factor_l = load_plate("lumped")
    ref = fe_reference(lumped, contact_l, 4, factor=factor_l)
    (c,) = np.flatnonzero(contact_l.w(lumped))
    for size in (6, None):
        m = contact_spectrum(reduce(lumped, contact_l, "massless", size, factor=factor_l))
        assert m.contact_model == "massless" and m.impact_mass is None
        assert m.kc == pytest.approx(lumped.K[c, c], rel=1e-12)  # one contact dof: k_c = K_cc
        assert m.static_compliance == pytest.approx(ref.static_compliance, rel=1e-10)


def test_contact_spectrum_of_a_bare_spectrum_and_bad_input(plate):
    model, contact, factor = plate
    system = reduce(model, contact, "modal", 5, factor=factor).system
    s = contact_spectrum(system.spectrum)
    assert s.impact_mass == pytest.approx(1 / np.sum(system.w**2), rel=1e-12)  # M_r = I
    m = contact_spectrum(system.spectrum, kc=2.0)
    assert m.static_compliance == pytest.approx(0.5 + s.static_compliance, rel=1e-14)
    with pytest.raises(ValueError, match="contact_spectrum takes"):
        contact_spectrum(np.eye(2))
    with pytest.raises(ValueError, match="kc must be"):
        contact_spectrum(system.spectrum, kc=-1.0)
    assert kept_fraction(1.0, 0.0) is None and kept_fraction(float("nan"), 1.0) is None


# --------------------------------------------------------------------------- energies on admissible arcs


def test_arc_energies_interpolate_on_admissible_arcs_only(two_dof):
    T = np.linspace(4.0, 12.0, 161)
    bb = bc.backbone(two_dof, T)
    arc = max(bb.arcs, key=lambda a: a.stop - a.start)
    i = arc.start + 3
    mid = 0.5 * (T[i] + T[i + 1])
    (at_point,), (between,) = arc_energies([bb], [T[i], mid])
    assert at_point == bb.energy[i]
    assert between == pytest.approx(np.sqrt(bb.energy[i] * bb.energy[i + 1]), rel=1e-14)
    (exact,) = [o.energy for o in bb.orbit_at(mid) if o.admissible]
    assert between == pytest.approx(exact, rel=1e-2)  # close to the re-solved orbit (3.5e-3: ΔT = T/100)
    outside = np.flatnonzero(~bb.admissible)[0]
    assert arc_energies([bb], [T[outside]])[0].size == 0  # never on a non-admissible stretch
    assert [e.size for e in arc_energies([bb, bb], [mid, 100.0])] == [2, 0]


# --------------------------------------------------------------------------- the table


def test_rows_have_the_columns_and_round_trip_through_csv(models, fe, tmp_path):
    rows = comparison_rows(list(models.values()), fe, fractions=(0.9, 0.95, 0.99))
    assert [r["model"] for r in rows] == ["FE", "modal-4", "modal-8", "lanczos-si-6"]
    by = {r["model"]: r for r in rows}
    energy = [energy_column(f) for f in (0.9, 0.95, 0.99)]
    assert energy == ["energy_0.9T1_j", "energy_0.95T1_j", "energy_0.99T1_j"]  # J: every dimensional column has
    assert list(rows[0]) == [                                                      # its unit in its name
        "model", "method", "size", "contact_model", "dofs", "build_s", "search_s", "frequencies_hz", "modes_checked",
        "modes_matched", "max_frequency_error", "artefacts", "artefact_modes", "unchecked_modes", "impact_mass_kg",
        "impact_mass_kept", "static_compliance_m_per_n", "static_compliance_kept", "contact_stiffness_n_per_m",
        "families", "families_with_arcs", "admissible_arcs", "T1_s", *energy, "is_reference", "ref_energy_deviation",
        "ref_frequency_deviation", "convergence", "convergence_delta", "observed_order"]
    assert by["FE"]["contact_model"] is None  # no search ran on the FE model: it has no contact model
    assert all(list(r) == list(rows[0]) for r in rows)
    assert by["FE"]["dofs"] == 1084 and by["FE"]["impact_mass_kept"] == 1.0
    assert by["modal-8"]["dofs"] == 8 and by["modal-8"]["modes_matched"] == 8 and by["modal-8"]["artefacts"] == 0
    li = by["lanczos-si-6"]
    assert li["artefacts"] == 1 and li["artefact_modes"].startswith("5 (39156") and li["unchecked_modes"] == 1
    assert li["impact_mass_kept"] == pytest.approx(li["impact_mass_kg"] / fe.impact_mass, rel=1e-14)
    # the reference is the largest model (modal-8: 8 dofs); lanczos-si-6's modes 1–4 are FE modes 1–4, 2.6e-3 off
    assert [r["is_reference"] for r in rows] == [0, 0, 1, 0] and by["modal-8"]["ref_frequency_deviation"] == 0
    assert 1e-3 < li["ref_frequency_deviation"] < 3e-3 and by["modal-4"]["ref_frequency_deviation"] < 1e-10
    assert li["static_compliance_kept"] == pytest.approx(1.0, abs=1e-10)
    for name, entry in models.items():
        assert by[name]["admissible_arcs"] == sum(len(b.arcs) for b in entry.branches)
        expect = arc_energies(entry.branches, np.array([0.9, 0.95, 0.99]) / fe.frequencies[0])
        assert [by[name][c] for c in energy] == [e.min() if e.size else None for e in expect]
    assert all(r["T1_s"] == 1 / fe.frequencies[0] for r in rows)
    path = write_comparison_csv(rows, tmp_path / "comparison.csv")
    assert read_comparison_csv(path) == rows
    assert path.read_text().count("\n") == len(rows) + 1


def test_convergence_verdicts():
    assert convergence_verdict({"E": 0.63}, {"E": 1.0}, ["E"]) == ("not converged (Δ = 37 %)", pytest.approx(0.37))
    assert convergence_verdict({"E": 0.995}, {"E": 1.0}, ["E"])[0] == "converged (<1 %)"
    assert convergence_verdict({"E": None}, {"E": None}, ["E"]) == ("n/a", None)
    assert convergence_verdict({"E": 1.0}, {"E": None}, ["E"])[0].startswith("not converged (admissible orbits")


def test_rows_give_each_method_the_verdict_of_its_two_largest_sizes(models, fe):
    rows = comparison_rows(list(models.values()), fe, fractions=(0.999,))
    by = {r["model"]: r for r in rows}
    want = convergence_verdict(by["modal-4"], by["modal-8"], [energy_column(0.999)])
    assert by["modal-4"]["convergence"] == by["modal-8"]["convergence"] == want[0]
    assert by["lanczos-si-6"]["convergence"] == "n/a" and by["FE"]["convergence"] is None


def test_bad_rows_input(models):
    with pytest.raises(ValueError, match="ModelResult"):
        comparison_rows([object()])
    entry = models["modal-4"]
    with pytest.raises(ValueError, match="model names must be unique"):
        comparison_rows([entry, entry])
    with pytest.raises(ValueError, match="give T1"):
        comparison_rows([])


# --------------------------------------------------------------------------- diagnostics


def test_diagnose_says_why_models_disagree(models, fe):
    rows = comparison_rows(list(models.values()), fe)
    lines = diagnose(rows, fe)
    by = {r["model"]: r for r in rows}
    ratio = by["modal-4"]["impact_mass_kg"] / by["lanczos-si-6"]["impact_mass_kg"]
    assert ratio > 50
    assert f"impact mass differs {ratio:.0f}× between modal-4" in lines[0] and "lanczos-si-6" in lines[0]
    assert any(s.startswith("lanczos-si-6: 1 mode with no FE counterpart") for s in lines)
    (weak,) = [s for s in lines if "barely moves" in s]
    # independent: mode 1 bends the plate in-plane; along the span the tip moves by x·θ only
    phi = fe.modes[:, 0]
    motion = abs(contact_weight := fe.w @ phi) / np.abs(phi).max()
    assert motion < 0.1 and weak.startswith(f"mode 1 barely moves the contact node: b² = {contact_weight**2:.2g}")
    assert "try another contact point or normal" in weak


def test_diagnose_on_rows_built_to_disagree_and_to_agree():
    base = {"method": "modal", "impact_mass_kg": 1e-3, "static_compliance_m_per_n": 4e-8, "admissible_arcs": 3,
            "energy_0.95T1_j": 1e-6}
    agree = [base | {"model": "modal-8", "size": 8}, base | {"model": "modal-16", "size": 16}]
    assert diagnose(agree) == []
    disagree = [agree[0], base | {"model": "cb-8", "method": "craig-bampton", "size": 8, "impact_mass_kg": 1e-5,
                                  "energy_0.95T1_j": 1.2e-5},
                base | {"model": "lanczos-si-6", "method": "lanczos-si", "size": 6, "admissible_arcs": 0,
                        "families": 285, "energy_0.95T1_j": None}]
    lines = diagnose(disagree)
    assert "impact mass differs 100× between modal-8 (0.001) and cb-8 (1e-05)" in lines
    assert "lanczos-si-6 found no admissible arc (285 families)" in lines
    assert "at 0.95 T1 only modal-8, cb-8 have an admissible orbit" in lines
    assert any(s.startswith("energies at 0.95 T1 differ 12× across models") for s in lines)
    nothing = diagnose([r | {"admissible_arcs": 0} for r in agree])
    assert nothing[0].startswith("no model found an admissible arc")


# --------------------------------------------------------------------------- figures


def test_overlay_puts_every_model_on_one_pair_of_axes(models, fe):
    """One colour per method, one line style per size, the reference (the largest model) thicker; a legend of a
    fixed number of entries (methods, sizes, kinds of marks), never one per model."""
    entries = list(models.values())
    T1 = 1 / fe.frequencies[0]
    fig = overlay_plot(entries, fe, periods=[0.95 * T1])
    (ax,) = fig.axes
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert ax.get_xlabel() == "frequency 1/T (Hz)" and ax.get_ylabel() == "energy E (J)"
    assert labels[:5] == ["modal", "lanczos-si", "size 4", "size 6", "size 8"]
    assert labels[5] == "thick: the reference (modal-8)"
    assert labels[-2:] == ["linear frequencies (FE)", "comparison periods (1/T)"]
    assert tuple(fig.get_size_inches()) == (10.0, 5.5)
    arcs = [ln for ln in ax.lines if ln.get_color() not in ("k", "0.5")]  # not the vertical lines
    assert {ln.get_color() for ln in arcs} == {"C0", "C1"}  # modal, lanczos-si
    widths = {ln.get_linewidth() for ln in arcs if ln.get_marker() in ("None", None, "")}
    assert len(widths) == 2 and max(widths) > min(widths) + 1  # the reference thicker
    styles = {str(ln.get_linestyle()) for ln in arcs
              if ln.get_marker() in ("None", None, "") and ln.get_color() == "C0"}
    assert len(styles) == 2  # modal-4, modal-8
    # every arc a marker when a "pixel" is huge; curves (arcs of >= 2 points) when it is 0
    big = overlay_plot(entries, fe, min_px=1e9).axes[0]
    dots = [ln for ln in big.lines if ln.get_marker() not in ("None", None, "")]
    assert sum(len(ln.get_xdata()) for ln in dots) == sum(len(b.arcs) for e in entries for b in e.branches)
    small = overlay_plot(entries, fe, min_px=0.0, nonadmissible=True).axes[0]
    assert "non-admissible orbits" in [t.get_text() for t in small.get_legend().get_texts()]
    dots = [ln for ln in small.lines if ln.get_marker() in MARKERS]  # arcs of one computed point only
    assert sum(len(ln.get_xdata()) for ln in dots) == sum(a.stop == a.start for e in entries for b in e.branches
                                                          for a in b.arcs)
    assert [t.get_text().strip() for t in ax.texts] == ["1"]  # FE mode 1 is the only one in range


def test_convergence_plot_reports_the_observed_order():
    """Top: the distance from the reference; bottom: the change from the previous size, with the observed order
    only where three sizes converge monotonically."""
    rows = [{"method": "modal", "size": s, "dofs": s, "energy_0.95T1_j": 2.0 + 5.0 * s**-2.0,
             "energy_0.99T1_j": None} for s in (8, 16, 32, 64)]
    rows += [{"method": "lanczos-si", "size": s, "dofs": s, "energy_0.95T1_j": e, "energy_0.99T1_j": None}
             for s, e in ((6, 2.1), (12, 2.3), (24, 2.2))]
    fig = convergence_plot(rows, tolerance=0.01)
    top, bottom = fig.axes
    assert top.get_legend_handles_labels()[1] == ["modal, 0.95 T1", "lanczos-si, 0.95 T1", "tolerance 1 %"]
    assert bottom.get_legend_handles_labels()[1] == ["modal, 0.95 T1: order 2", "lanczos-si, 0.95 T1: not monotone"]
    assert top.get_xscale() == top.get_yscale() == bottom.get_yscale() == "log"
    assert top.get_shared_x_axes().joined(top, bottom)
    (modal, _, _) = top.lines  # every modal size but the reference (modal-64), distance from it
    assert modal.get_xdata().tolist() == [8, 16, 32]
    assert np.allclose(modal.get_ydata(), [abs((2 + 5 * s**-2.0) / (2 + 5 * 64**-2.0) - 1) for s in (8, 16, 32)])
    assert observed_order([8, 16, 32], [1.0, 1.0, 1.0]) is None and observed_order([8, 16], [1, 2]) is None


def test_spectral_plot_shows_fe_each_model_and_the_artefacts(models, fe):
    fig = spectral_plot(list(models.values()), fe)
    (ax,) = fig.axes
    labels = ax.get_legend_handles_labels()[1]
    assert labels[0].startswith(f"FE ({FE_MODES} lowest modes")
    assert [lab.split(" (")[0] for lab in labels[1:4]] == list(models)
    assert labels[-1] == "hollow: no FE counterpart (artefact)"
    assert len(ax.lines[0].get_xdata()) == FE_MODES
    assert ax.get_xscale() == ax.get_yscale() == "log"
    assert ax.get_xlabel() == "linear frequency ω_j/2π (Hz)" and ax.get_ylabel().endswith("(1/kg)")
