"""The comparison table of a comparison study: one flat row per model, its CSV, the convergence per method
(:func:`convergence_verdict`, :func:`convergence_order`) and :func:`comparison_verdict` — which model to use, or
why none can be trusted; why the models disagree, in words, is :func:`bladecase.post.comparison.diagnose.diagnose`.

Rows hold only text, integers, floats and ``None`` (an empty CSV cell), so they round-trip through
:func:`write_comparison_csv` / :func:`read_comparison_csv`, and the diagnosis works on either. The analysis
behind each column is in :mod:`.compare`; the figures in :mod:`.plots`.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ...checks import integer, positive
from ...io import atomic_path
from .compare import (
    MAC_THRESHOLD,
    ContactSpectrum,
    FEReference,
    ModelResult,
    ModeMatch,
    arc_energies,
    choose_periods,
    contact_spectrum,
    kept_fraction,
    largest_model,
    model_matches,
)

__all__ = ["ENERGY_RTOL", "FREQUENCY_RTOL", "comparison_rows", "comparison_verdict", "convergence_order",
           "convergence_verdict", "energy_column", "energy_columns", "energy_label", "observed_order",
           "period_labels", "read_comparison_csv", "write_comparison_csv"]

#: Tolerances of :func:`comparison_verdict`: energies at the comparison periods (relative), linear frequencies.
ENERGY_RTOL = 0.01
FREQUENCY_RTOL = 1e-3

_STR = ("model", "method", "contact_model", "frequencies_hz", "artefact_modes", "convergence", "observed_order")
_INT = ("size", "dofs", "modes_checked", "modes_matched", "artefacts", "unchecked_modes", "families",
        "families_with_arcs", "admissible_arcs", "is_reference")
#: Columns before the energies; a unit suffix on each dimensional one (``_hz``, ``_s``, ``_kg``, ``_m_per_n``,
#: ``_n_per_m``; the energies ``_j``), none on the dimensionless ones (counts, ``_kept`` ratios, relative errors).
_HEAD = ("model", "method", "size", "contact_model", "dofs", "build_s", "search_s", "frequencies_hz",
         "modes_checked", "modes_matched", "max_frequency_error", "artefacts", "artefact_modes", "unchecked_modes",
         "impact_mass_kg", "impact_mass_kept", "static_compliance_m_per_n", "static_compliance_kept",
         "contact_stiffness_n_per_m", "families", "families_with_arcs", "admissible_arcs", "T1_s")
_TAIL = ("is_reference", "ref_energy_deviation", "ref_frequency_deviation", "convergence", "convergence_delta",
         "observed_order")


def energy_column(fraction: float) -> str:
    """The column of the energy (J) at ``fraction`` × T1, e.g. ``"energy_0.95T1_j"`` (10 significant digits:
    periods next to grazing, 0.99999889 and 0.9999993, keep their own columns).

    >>> energy_column(0.95), energy_column(0.99999889)
    ('energy_0.95T1_j', 'energy_0.99999889T1_j')
    """
    return f"energy_{float(fraction):.10g}T1_j"


def energy_columns(row: dict) -> list[str]:
    """The energy columns of a row (or of a table's first row), in order."""
    return [k for k in (row or {}) if k.startswith("energy_")]


def energy_label(column: str) -> str:
    """``"0.95 T1"`` for the column ``"energy_0.95T1_j"`` (also the unit-less ``"energy_0.95T1"`` of older tables).

    >>> energy_label("energy_0.95T1_j"), energy_label("energy_0.95T1")
    ('0.95 T1', '0.95 T1')
    """
    return column.removeprefix("energy_").removesuffix("_j").replace("T1", " T1")


def period_labels(columns: Sequence[str]) -> dict[str, str]:
    """Short labels of energy columns: the fewest digits (3 to 10) that keep them apart and each within 1 % of its
    distance from T1.

    >>> list(period_labels(["energy_0.9581040547T1_j", "energy_0.9674133729T1_j"]).values())
    ['0.9581 T1', '0.9674 T1']
    >>> list(period_labels(["energy_0.99999889T1_j", "energy_0.9999993T1_j"]).values())
    ['0.9999989 T1', '0.9999993 T1']
    >>> list(period_labels(["energy_0.9999T1_j"]).values()), list(period_labels(["energy_0.9873396985T1_j"]).values())
    (['0.9999 T1'], ['0.9873 T1'])
    """
    f = [float(energy_label(c).removesuffix(" T1")) for c in columns]

    def fits(d: int) -> bool:  # distinct, and each within 1 % of its distance from T1 (0.9999 is not "1")
        return len({f"{x:.{d}g}" for x in f}) == len(set(f)) and all(
            abs(float(f"{x:.{d}g}") - x) <= 0.01 * max(abs(1 - x), 1e-9) for x in f)

    digits = next((d for d in range(3, 11) if fits(d)), 10)
    return {c: f"{x:.{digits}g} T1" for c, x in zip(columns, f)}


def _none(x) -> float | None:
    return None if x is None or not math.isfinite(float(x)) else float(x)


def _spectral_columns(spec: ContactSpectrum, fe_spec: ContactSpectrum | None) -> dict:
    return {"impact_mass_kg": spec.impact_mass, "static_compliance_m_per_n": spec.static_compliance,
            "contact_stiffness_n_per_m": spec.kc,
            "impact_mass_kept": kept_fraction(spec.impact_mass, fe_spec and fe_spec.impact_mass),
            "static_compliance_kept": kept_fraction(spec.static_compliance, fe_spec and fe_spec.static_compliance)}


def _mode_columns(matches: list[ModeMatch] | None, modes: int) -> dict:
    if matches is None:
        return {}
    listed = [m for m in matches if m.index < modes]
    errs = [abs(m.relative_error) for m in listed if m.relative_error is not None]
    bad = [m for m in matches if m.artefact]
    return {"frequencies_hz": "; ".join(m.describe() for m in listed), "modes_checked": len(listed),
            "modes_matched": sum(m.matched for m in listed), "max_frequency_error": max(errs) if errs else None,
            "artefacts": len(bad),
            "artefact_modes": ", ".join(f"{m.index + 1} ({m.frequency:.6g} Hz)" for m in bad) or None,
            "unchecked_modes": sum(m.beyond_fe for m in listed)}


def _model_row(entry: ModelResult, matches: list[ModeMatch] | None, fe_spec, periods: np.ndarray,
               columns: list[str], modes: int) -> dict:
    r = entry.reduced
    spec = contact_spectrum(r)
    row = {"model": entry.name, "method": r.method, "size": r.size, "contact_model": spec.contact_model,
           "dofs": r.n, "build_s": _none(entry.build_s), "search_s": _none(entry.search_s),
           "families": len(entry.branches), "families_with_arcs": sum(1 for b in entry.branches if b.arcs),
           "admissible_arcs": sum(len(b.arcs) for b in entry.branches)}
    if matches is None:
        row["frequencies_hz"] = "; ".join(f"{f:.6g} Hz" for f in spec.frequencies[:modes])
    row |= _spectral_columns(spec, fe_spec) | _mode_columns(matches, modes)
    for col, E in zip(columns, arc_energies(entry.branches, periods)):
        row[col] = float(E[0]) if E.size else None
    return row


def _frequency_deviation(entry: ModelResult, matches, ref: ModelResult, ref_matches, modes: int) -> float | None:
    """Largest ``|f/f_ref − 1|`` over the model's lowest ``modes`` modes that share an FE counterpart (by MAC) with a
    mode of the reference; without FE matches, over the lowest modes by index."""
    if matches is not None and ref_matches is not None:
        mine = {m.fe_index: m.frequency for m in matches if m.matched and m.index < modes}
        theirs = {m.fe_index: m.frequency for m in ref_matches if m.matched}
        pairs = [(mine[j], theirs[j]) for j in mine if j in theirs]
    else:
        f, g = entry.reduced.system.spectrum.frequencies, ref.reduced.system.spectrum.frequencies
        pairs = list(zip(f[:modes], g[:modes]))
    devs = [abs(a / b - 1) for a, b in pairs if a is not None and b]
    return max(devs) if devs else None


def _energy_deviation(row: dict, ref: dict, columns: Sequence[str]) -> float | None:
    devs = [abs(row[c] / ref[c] - 1) for c in columns if row.get(c) is not None and ref.get(c)]
    return max(devs) if devs else None


def comparison_rows(entries: Sequence[ModelResult], fe: FEReference | None = None, *,
                    fractions: Sequence[float] | None = None, T1: float | None = None, modes: int = 8,
                    threshold: float = MAC_THRESHOLD, tol: float = 0.01, reference: str | None = None) -> list[dict]:
    """One flat row (str, int, float or None) per model, after an ``"FE"`` row when ``fe`` is given.

    Columns: ``model`` (name), ``method``, ``size``, ``contact_model`` (none on the FE row: no search ran on it),
    ``dofs`` (reduced), ``build_s``, ``search_s``; ``frequencies_hz`` (the lowest ``modes`` reduced modes, each
    with its FE counterpart by MAC, or "no FE counterpart"), ``modes_checked``, ``modes_matched``,
    ``max_frequency_error`` (|f/f_FE − 1|, matched pairs only), ``artefacts`` / ``artefact_modes`` (modes in the FE
    range with no counterpart, 1-based), ``unchecked_modes`` (above the FE modes computed); ``impact_mass_kg``,
    ``static_compliance_m_per_n``, their ``_kept`` fractions of the FE value and ``contact_stiffness_n_per_m``
    (:func:`contact_spectrum`); ``families``, ``families_with_arcs``, ``admissible_arcs``; ``T1_s`` and
    ``energy_<f>T1_j`` — the lowest admissible energy at ``f × T1`` on the model's admissible arcs
    (:func:`arc_energies`), blank when none; ``is_reference`` (1 on the reference model: ``reference``, default
    the largest, :func:`~.compare.largest_model`), ``ref_energy_deviation`` (largest ``|E/E_ref − 1|`` over the
    periods where both have an orbit) and ``ref_frequency_deviation`` (largest ``|f/f_ref − 1|`` over the lowest
    ``modes`` modes matched to the same FE mode as one of the reference's); ``convergence`` and
    ``convergence_delta`` (:func:`convergence_verdict`, one per method, on each of its rows) and
    ``observed_order`` (:func:`convergence_order` over the method's sizes: a number, or ``"not monotone"``).

    ``fractions``: the periods (× T1) where the energies are read; ``None``: chosen inside the models' common
    admissible range (:func:`~.compare.choose_periods`). ``T1``: the common reference period (default: FE mode 1,
    else the first model's first contact mode).
    """
    entries = list(entries)
    bad = [type(e).__name__ for e in entries if not isinstance(e, ModelResult)]
    if bad:
        raise ValueError(f"entries must be ModelResult objects, got {bad[0]}")
    modes = integer("modes", modes, 1)
    if T1 is None:
        if fe is None and not entries:
            raise ValueError("no model and no FE reference: give T1 (the reference period)")
        first = None if fe is not None else contact_spectrum(entries[0].reduced)
        T1 = 1.0 / float(fe.frequencies[0]) if first is None else 2 * np.pi / float(first.omega[first.b2 > 0][0])
    T1 = positive("T1", T1)
    names = [e.name for e in entries]
    if len(set(names)) != len(names) or (fe is not None and "FE" in names):
        raise ValueError(f"model names must be unique, got {names}: give ModelResult(name=...)")
    ref = next((e for e in entries if e.name == reference), None) if reference is not None else \
        largest_model(entries)
    if reference is not None and ref is None:
        raise ValueError(f"reference {reference!r} is not one of the models {names}")
    if fractions is None:
        fractions = choose_periods(entries, T1, reference=ref and ref.name).fractions
    fractions = [positive("period fraction", f) for f in fractions]
    columns = list(dict.fromkeys(energy_column(f) for f in fractions))
    if len(columns) != len(fractions):
        raise ValueError(f"period fractions must differ in their first 10 digits, got {list(fractions)}")
    periods = T1 * np.asarray(fractions)
    fe_spec = None if fe is None else contact_spectrum(fe)
    rows = []
    if fe is not None:
        rows.append({"model": "FE", "method": "fe", "dofs": fe.n_dofs, "contact_model": None,
                     "frequencies_hz": "; ".join(f"{f:.6g} Hz" for f in fe.frequencies[:modes]),
                     **_spectral_columns(fe_spec, fe_spec), "is_reference": 0})
    matches = [None if fe is None else model_matches(e.reduced, fe, modes=modes, threshold=threshold)
               for e in entries]
    mine = [_model_row(e, m, fe_spec, periods, columns, modes) for e, m in zip(entries, matches)]
    if ref is not None:
        k = entries.index(ref)
        for e, m, row in zip(entries, matches, mine):
            row["is_reference"] = int(e is ref)
            row["ref_energy_deviation"] = _energy_deviation(row, mine[k], columns)
            row["ref_frequency_deviation"] = _frequency_deviation(e, m, ref, matches[k], modes)
    rows += mine
    for r in rows:
        r["T1_s"] = T1
    _add_convergence(rows, columns, tol)
    order = [*_HEAD, *columns, *_TAIL]
    return [{k: r.get(k) for k in order} for r in rows]


def _pct(x: float) -> str:
    return f"{100 * x:.0f}" if 100 * x >= 10 else f"{100 * x:.2g}"


def convergence_verdict(previous: dict, last: dict, columns: Sequence[str],
                        tol: float = 0.01) -> tuple[str, float | None]:
    """Verdict from the energies ``columns`` of two rows (the two largest sizes of one method), and ``Δ``.

    ``Δ`` = the largest ``|E_last − E_previous| / E_last`` over the periods where both have an admissible orbit.
    ``"converged (<1 %)"`` when ``Δ < tol``, ``"not converged (Δ = 37 %)"`` otherwise; an admissible orbit at a
    period in one size only is not converged; ``"n/a"`` when no period has an orbit in either.

    >>> convergence_verdict({"E": 3.0}, {"E": 4.0}, ["E"])
    ('not converged (Δ = 25 %)', 0.25)
    >>> convergence_verdict({"E": 1.0, "F": 2.0}, {"E": 1.005, "F": 2.0}, ["E", "F"])[0]
    'converged (<1 %)'
    >>> convergence_verdict({"E": None}, {"E": None}, ["E"])
    ('n/a', None)
    """
    pairs = [(previous.get(c), last.get(c)) for c in columns]
    lonely = [c for c, (a, b) in zip(columns, pairs) if (a is None) != (b is None)]
    deltas = [abs(b - a) / abs(b) for a, b in pairs if a is not None and b is not None]
    if lonely:
        return f"not converged (admissible orbits at {energy_label(lonely[0])} in one size only)", None
    if not deltas:
        return "n/a", None
    delta = max(deltas)
    return (f"converged (<{_pct(tol)} %)" if delta < tol else f"not converged (Δ = {_pct(delta)} %)"), delta


def convergence_order(sizes, values, *, rtol: float = 1e-12) -> tuple[float | None, str]:
    """Observed order ``p`` of ``values`` against ``sizes`` (``E(s) ≈ E∞ + C s^-p``), and its words.

    Only where the sizes converge monotonically: the changes ``E_{i+1} − E_i`` between consecutive sizes keep
    their sign and shrink, over (at least) the three largest sizes; ``p`` is then minus the least-squares slope of
    ``log|E_{i+1} − E_i|`` against ``log s_{i+1}`` over that trailing monotone run (exact for sizes in geometric
    progression). Otherwise no number: ``"not monotone"``; ``"no change"`` when the last changes are round-off
    (below ``rtol`` × the values); ``"fewer than 3 sizes"``.

    >>> s = [8.0, 16.0, 32.0, 64.0]
    >>> p, words = convergence_order(s, [2.0 + 5.0 * x**-1.5 for x in s]); round(p, 12), words
    (1.5, 'order 1.5')
    >>> convergence_order([8, 16, 32], [1.0, 1.2, 1.1])   # the change flips sign: no order
    (None, 'not monotone')
    >>> convergence_order([8, 16, 32], [1.0, 1.01, 1.03])   # the change grows
    (None, 'not monotone')
    """
    s, v = np.asarray(sizes, float), np.asarray(values, float)
    ok = np.isfinite(s) & np.isfinite(v)
    order = np.argsort(s[ok], kind="stable")
    s, v = s[ok][order], v[ok][order]
    if np.unique(s).size != s.size:
        raise ValueError(f"sizes repeat: {s.tolist()}")
    if s.size < 3:
        return None, "fewer than 3 sizes"
    d = np.diff(v)
    if np.all(np.abs(d[-2:]) <= rtol * np.abs(v).max()):
        return None, "no change"
    start = d.size - 1
    while start >= 1 and d[start - 1] * d[start] > 0 and abs(d[start]) < abs(d[start - 1]):
        start -= 1
    if d.size - start < 2:
        return None, "not monotone"
    p = float(-np.polyfit(np.log(s[1:][start:]), np.log(np.abs(d[start:])), 1)[0])
    return p, f"order {p:.2g}"


def observed_order(sizes, values) -> float | None:
    """The observed order of :func:`convergence_order`, ``None`` where it has none (not monotone, fewer than three
    sizes, no change).

    >>> s = np.array([8.0, 16.0, 32.0, 64.0])
    >>> round(observed_order(s, 2.0 + 5.0 * s**-1.5), 12), observed_order(s[:3], [1.0, 1.2, 1.1])
    (1.5, None)
    """
    return convergence_order(sizes, values)[0]


def _method_order(mine: list[dict], columns: Sequence[str]) -> str | None:
    """``observed_order`` of a method's rows (sorted by size): the smallest order over the periods, ``"not
    monotone"`` if any period is not, ``None`` with fewer than three sizes at every period."""
    found = []
    for c in columns:
        pts = [(r["size"], r[c]) for r in mine if r.get(c) is not None]
        if len(pts) >= 3:
            found.append(convergence_order(*zip(*pts)))
    if not found:
        return None
    if any(w == "not monotone" for _, w in found):
        return "not monotone"
    orders = [p for p, _ in found if p is not None]
    return f"{min(orders):.2g}" if orders else "no change"


def _add_convergence(rows: list[dict], columns: list[str], tol: float) -> None:
    for method in {r["method"] for r in rows}:
        mine = sorted((r for r in rows if r["method"] == method and r.get("size") is not None),
                      key=lambda r: r["size"])
        verdict, delta = convergence_verdict(mine[-2], mine[-1], columns, tol) if len(mine) >= 2 else ("n/a", None)
        order = _method_order(mine, columns)
        for r in rows:
            if r["method"] == method and method != "fe":
                r["convergence"], r["convergence_delta"], r["observed_order"] = verdict, delta, order


# ----------------------------------------------------------------------------- the verdict


def _size_words(r: dict) -> str:
    return "exact" if r.get("size") is None else str(r["size"])


def _check(r: dict, ref: dict, columns: list[str], energy_rtol: float, frequency_rtol: float) -> dict:
    """How a model compares with the reference: deviations, periods missing or extra, and whether it is within."""
    at_ref = [c for c in columns if ref.get(c) is not None]
    missing = [c for c in at_ref if r.get(c) is None]
    extra = [c for c in columns if ref.get(c) is None and r.get(c) is not None]
    dE = _energy_deviation(r, ref, at_ref)
    dF = r.get("ref_frequency_deviation")
    ok = (bool(at_ref) and not missing and not extra and dE is not None and dE <= energy_rtol
          and dF is not None and dF <= frequency_rtol)
    return {"row": r, "dE": dE, "dF": dF, "missing": missing, "extra": extra, "ok": ok}


def comparison_verdict(rows: Sequence[dict], *, energy_rtol: float = ENERGY_RTOL,
                       frequency_rtol: float = FREQUENCY_RTOL) -> dict:
    """Which model to use, from the rows of :func:`comparison_rows` (or :func:`read_comparison_csv`).

    A model is *within* the reference (the row with ``is_reference``, else the one of most dofs) when, at every
    comparison period where the reference has an admissible orbit, it has one too with an energy within
    ``energy_rtol`` of the reference's (and none where the reference has none), and its linear frequencies are
    within ``frequency_rtol`` of the reference's (``ref_frequency_deviation``). Per method, the model to use is its
    smallest size from which every larger size (but the reference) is within; over the methods, the one of fewest
    dofs: ``decision = "use"``. Otherwise ``decision = "none"``, with the reasons computed from the rows (codes in
    ``reasons``): ``one_model``, ``no_arcs`` (no model found an admissible arc), ``reference_no_arc``,
    ``reference_no_orbit`` (none at the comparison periods), ``arcs_disjoint`` (no period where two models have
    an orbit), ``disagree`` (by how much, the closest model named), ``frequencies_off``, ``not_monotone`` (a
    method's deviation does not shrink with size), ``energies_scatter`` (the energies of three models or more at
    a period spread by more than 10 × ``energy_rtol``).

    Returns ``{"decision", "model", "method", "size", "reference", "energy_rtol", "frequency_rtol",
    "energy_deviation", "frequency_deviation", "periods", "reasons", "sentence"}``.

    >>> rows = [{"model": m, "method": "modal", "size": s, "dofs": s, "is_reference": int(s == 32),
    ...          "admissible_arcs": 1, "ref_frequency_deviation": 0.0, "energy_0.9T1_j": e} for m, s, e in
    ...         (("modal-8", 8, 1.2), ("modal-16", 16, 1.004), ("modal-32", 32, 1.0))]
    >>> from textwrap import fill
    >>> print(fill(comparison_verdict(rows)["sentence"], 110))
    use modal-16: within 0.4 % of the reference modal-32 from size 16 (energies at 1 period, 0.9 T1, within 0.4 %;
    linear frequencies within 0 %; tolerances 1 % and 0.1 %)
    >>> rows[0]["energy_0.9T1_j"], rows[1]["energy_0.9T1_j"] = 1.05, 1.08
    >>> v = comparison_verdict(rows); v["decision"], v["reasons"]
    ('none', ['disagree', 'not_monotone'])
    >>> print(fill(v["sentence"], 110))
    no model can be trusted here, because the models disagree with the reference modal-32 in energy: the closest,
    modal-8, is 5 % off (tolerance 1 %); modal does not converge monotonically with size: its energies are 5 % at
    8, 8 % at 16 off the reference
    """
    rows = list(rows)
    models = [r for r in rows if r.get("method") != "fe"]
    columns = energy_columns(rows[0] if rows else {})
    ref = next((r for r in models if r.get("is_reference")), None)
    if ref is None and models:
        ref = max(reversed(models), key=lambda r: r.get("dofs") or 0)
    labels = list(period_labels(columns).values())
    out = {"decision": "none", "model": None, "method": None, "size": None, "reference": ref and ref["model"],
           "energy_rtol": energy_rtol, "frequency_rtol": frequency_rtol, "energy_deviation": None,
           "frequency_deviation": None, "periods": labels, "reasons": [], "sentence": ""}
    why: list[tuple[str, str]] = []
    others = [r for r in models if r is not ref]
    if not others:
        why.append(("one_model", "only one model was compared"))
    elif all(not r.get("admissible_arcs") for r in models):
        why.append(("no_arcs", "no model found an admissible arc in the search range"))
    elif not ref.get("admissible_arcs"):
        why.append(("reference_no_arc", f"the reference {ref['model']} ({ref.get('dofs')} dofs, the largest model) "
                                        "has no admissible arc, so nothing confirms the smaller models' arcs"))
    elif all(ref.get(c) is None for c in columns):
        why.append(("reference_no_orbit", f"the reference {ref['model']} has no admissible orbit at the comparison "
                                          f"periods ({', '.join(labels) or 'none'})"))
    checks = [] if why else [_check(r, ref, columns, energy_rtol, frequency_rtol) for r in others]
    best = _pick(checks, ref) if checks else None
    if best is not None:
        chosen, group = best
        r = chosen["row"]
        dE = max(c["dE"] for c in group)
        dF = max(c["dF"] for c in group)
        at = [c for c in columns if ref.get(c) is not None]
        span = _span_words(at)
        out |= {"decision": "use", "model": r["model"], "method": r["method"], "size": r.get("size"),
                "energy_deviation": dE, "frequency_deviation": dF}
        since = "" if r.get("size") is None else f" from size {r['size']}"
        out["sentence"] = (f"use {r['model']}: within {_pct(dE)} % of the reference {ref['model']}{since} (energies "
                           f"at {len(at)} period{'s' if len(at) > 1 else ''}, {span}, within {_pct(dE)} %; linear "
                           f"frequencies within {_pct(dF)} %; tolerances {_pct(energy_rtol)} % and "
                           f"{_pct(frequency_rtol)} %)")
        return out
    if checks:
        why += _disagreement(checks, ref, columns, models, energy_rtol, frequency_rtol)
    out["reasons"] = [code for code, _ in why]
    out["sentence"] = "no model can be trusted here, because " + "; ".join(text for _, text in why)
    return out


def _span_words(columns: Sequence[str]) -> str:
    """``"0.958–0.995 T1"``: the first and last comparison periods, with the digits that tell them apart."""
    f = [float(energy_label(c).removesuffix(" T1")) for c in columns]
    if len(f) == 1:
        return f"{f[0]:.6g} T1"
    digits = next((d for d in range(3, 11) if f"{f[0]:.{d}g}" != f"{f[-1]:.{d}g}"), 10)
    return f"{f[0]:.{digits}g}–{f[-1]:.{digits}g} T1"


def _pick(checks: list[dict], ref: dict) -> tuple[dict, list[dict]] | None:
    """Per method, the smallest size from which every larger one is within; the candidate of fewest dofs."""
    found = []
    for method in dict.fromkeys(c["row"]["method"] for c in checks):
        mine = sorted((c for c in checks if c["row"]["method"] == method),
                      key=lambda c: (c["row"].get("size") is None, c["row"].get("size") or 0))
        for i, c in enumerate(mine):
            if all(x["ok"] for x in mine[i:]):
                found.append((c, mine[i:]))
                break
    if not found:
        return None
    return min(found, key=lambda f: (f[0]["row"].get("dofs") or 0, f[0]["dE"]))


def _disagreement(checks: list[dict], ref: dict, columns: list[str], models: list[dict], energy_rtol: float,
                  frequency_rtol: float) -> list[tuple[str, str]]:
    why = []
    shared = [c for c in columns if sum(r.get(c) is not None for r in models) >= 2]
    comparable = [c for c in checks if c["dE"] is not None and not c["missing"] and not c["extra"]]
    if not shared:
        why.append(("arcs_disjoint", "the models' admissible arcs do not overlap: no comparison period has an "
                                     "admissible orbit in two models"))
    elif not comparable:
        why.append(("disagree", f"no other model has admissible orbits at exactly the periods where the reference "
                                f"{ref['model']} has them"))
    else:
        close = min(comparable, key=lambda c: c["dE"])
        if close["dE"] > energy_rtol:
            why.append(("disagree", f"the models disagree with the reference {ref['model']} in energy: the closest, "
                                    f"{close['row']['model']}, is {_pct(close['dE'])} % off (tolerance "
                                    f"{_pct(energy_rtol)} %)"))
        else:
            within = [c for c in comparable if c["dE"] <= energy_rtol]
            c = min(within, key=lambda c: float("inf") if c["dF"] is None else c["dF"])
            f = "cannot be paired with the reference's" if c["dF"] is None else f"are {_pct(c['dF'])} % off"
            why.append(("frequencies_off", f"{_names([x['row']['model'] for x in within])} "
                                           f"{'is' if len(within) == 1 else 'are'} within {_pct(energy_rtol)} % of "
                                           f"the reference {ref['model']} in energy, but the linear frequencies {f} "
                                           f"(tolerance {_pct(frequency_rtol)} %; {c['row']['model']})"))
    for method in dict.fromkeys(c["row"]["method"] for c in checks):
        mine = sorted((c for c in checks if c["row"]["method"] == method and c["dE"] is not None
                       and c["row"].get("size") is not None), key=lambda c: c["row"]["size"])
        if any(b["dE"] >= a["dE"] for a, b in zip(mine, mine[1:])):
            steps = ", ".join(f"{_pct(c['dE'])} % at {c['row']['size']}" for c in mine)
            why.append(("not_monotone", f"{method} does not converge monotonically with size: its energies are "
                                        f"{steps} off the reference"))
    worst = None
    for c in columns:
        vals = [r[c] for r in models if r.get(c) is not None and r[c] > 0]
        if len(vals) >= 3 and max(vals) / min(vals) - 1 > 10 * energy_rtol:  # two: "disagree" says it
            if worst is None or max(vals) / min(vals) > worst[1] / worst[0]:
                worst = (min(vals), max(vals), c)
    if worst is not None:
        lo, hi, c = worst
        why.append(("energies_scatter", f"energies at {period_labels(columns)[c]} scatter from {lo:.3g} to "
                                        f"{hi:.3g} J across the models ({times(hi / lo)})"))
    return why


def _names(names) -> str:
    names = list(names)
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


def write_comparison_csv(rows: Sequence[dict], path) -> Path:
    """Write ``rows`` (:func:`comparison_rows`) as CSV, atomically: one header, ``None`` as an empty cell,
    floats in full precision (:func:`read_comparison_csv` gives the rows back)."""
    rows = list(rows)
    if not rows:
        raise ValueError("no rows to write: comparison_rows gave an empty table")
    header = list(rows[0])
    with atomic_path(path) as tmp, open(tmp, "w", newline="", encoding="utf-8") as fh:
        out = csv.writer(fh)
        out.writerow(header)
        for r in rows:
            out.writerow(["" if r.get(k) is None else repr(r[k]) if isinstance(r[k], float) else r[k]
                          for k in header])
    return Path(path)


def read_comparison_csv(path) -> list[dict]:
    """The rows of a comparison CSV, typed back (text, int, float; empty cells ``None``)."""
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))

    def typed(key: str, text: str):
        if text == "":
            return None
        return text if key in _STR else int(text) if key in _INT else float(text)

    return [{k: typed(k, v) for k, v in r.items()} for r in rows]


def times(ratio: float) -> str:
    """A ratio in words: ``"12×"``, ``"2.5×"``."""
    return f"{ratio:.0f}×" if ratio >= 10 else f"{ratio:.2g}×"
