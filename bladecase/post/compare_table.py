"""The comparison table of a comparison study (issue 12): one flat row per model, its CSV, the convergence verdict
per method, and :func:`diagnose` — why the models disagree, in words.

Rows hold only text, integers, floats and ``None`` (an empty CSV cell), so they round-trip through
:func:`write_comparison_csv` / :func:`read_comparison_csv` and :func:`diagnose` works on either. The analysis
behind each column is in :mod:`.compare`; the figures in :mod:`.compare_plots`.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..checks import integer, positive
from ..io import atomic_path
from .compare import (
    MAC_THRESHOLD,
    ContactSpectrum,
    FEReference,
    ModelResult,
    ModeMatch,
    arc_energies,
    contact_spectrum,
    kept_fraction,
    model_matches,
)

__all__ = ["comparison_rows", "convergence_verdict", "diagnose", "energy_column", "read_comparison_csv",
           "write_comparison_csv"]



_STR = ("model", "method", "contact_model", "frequencies_hz", "artefact_modes", "convergence")
_INT = ("size", "dofs", "modes_checked", "modes_matched", "artefacts", "unchecked_modes", "families",
        "families_with_arcs", "admissible_arcs")
_HEAD = ("model", "method", "size", "contact_model", "dofs", "build_s", "search_s", "frequencies_hz",
         "modes_checked", "modes_matched", "max_frequency_error", "artefacts", "artefact_modes", "unchecked_modes",
         "impact_mass", "impact_mass_kept", "static_compliance", "static_compliance_kept", "contact_stiffness",
         "families", "families_with_arcs", "admissible_arcs", "T1_s")
_TAIL = ("convergence", "convergence_delta")


def energy_column(fraction: float) -> str:
    """The column of the energy at ``fraction`` × T1, e.g. ``"energy_0.95T1"`` (10 significant digits: periods
    next to grazing, 0.99999889 and 0.9999993, keep their own columns).

    >>> energy_column(0.95), energy_column(0.99999889)
    ('energy_0.95T1', 'energy_0.99999889T1')
    """
    return f"energy_{float(fraction):.10g}T1"


def _none(x) -> float | None:
    return None if x is None or not math.isfinite(float(x)) else float(x)


def _spectral_columns(spec: ContactSpectrum, fe_spec: ContactSpectrum | None) -> dict:
    return {"impact_mass": spec.impact_mass, "static_compliance": spec.static_compliance, "contact_stiffness": spec.kc,
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


def _model_row(entry: ModelResult, fe: FEReference | None, fe_spec, periods: np.ndarray, columns: list[str],
               modes: int, threshold: float) -> dict:
    r = entry.reduced
    spec = contact_spectrum(r)
    row = {"model": entry.name, "method": r.method, "size": r.size, "contact_model": spec.contact_model,
           "dofs": r.n, "build_s": _none(entry.build_s), "search_s": _none(entry.search_s),
           "families": len(entry.branches), "families_with_arcs": sum(1 for b in entry.branches if b.arcs),
           "admissible_arcs": sum(len(b.arcs) for b in entry.branches)}
    if fe is None:
        row["frequencies_hz"] = "; ".join(f"{f:.6g} Hz" for f in spec.frequencies[:modes])
    row |= _spectral_columns(spec, fe_spec) | _mode_columns(fe and model_matches(r, fe, modes=modes,
                                                                                 threshold=threshold), modes)
    for col, E in zip(columns, arc_energies(entry.branches, periods)):
        row[col] = float(E[0]) if E.size else None
    return row


def comparison_rows(entries: Sequence[ModelResult], fe: FEReference | None = None, *,
                    fractions: Sequence[float] = (0.9, 0.95, 0.99), T1: float | None = None, modes: int = 8,
                    threshold: float = MAC_THRESHOLD, tol: float = 0.01) -> list[dict]:
    """One flat row (str, int, float or None) per model, after an ``"FE"`` row when ``fe`` is given.

    Columns: ``model`` (name), ``method``, ``size``, ``contact_model``, ``dofs`` (reduced), ``build_s``,
    ``search_s``; ``frequencies_hz`` (the lowest ``modes`` reduced modes, each with its FE counterpart by MAC, or
    "no FE counterpart"), ``modes_checked``, ``modes_matched``, ``max_frequency_error`` (|f/f_FE − 1|, matched
    pairs only), ``artefacts`` / ``artefact_modes`` (modes in the FE range with no counterpart, 1-based),
    ``unchecked_modes`` (above the FE modes computed); ``impact_mass``, ``static_compliance``, their ``_kept``
    fractions of the FE value and ``contact_stiffness`` (:func:`contact_spectrum`); ``families``,
    ``families_with_arcs``, ``admissible_arcs``; ``T1_s`` and ``energy_<f>T1`` — the lowest admissible energy at
    ``f × T1`` on the model's admissible arcs (:func:`arc_energies`), blank when none; ``convergence`` and
    ``convergence_delta`` (:func:`convergence_verdict`, one per method, on each of its rows).

    ``T1``: the common reference period (default: FE mode 1, else the first model's first contact mode).
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
    fractions = [positive("period fraction", f) for f in fractions]
    columns = [energy_column(f) for f in fractions]
    periods = T1 * np.asarray(fractions)
    fe_spec = None if fe is None else contact_spectrum(fe)
    rows = []
    if fe is not None:
        rows.append({"model": "FE", "method": "fe", "dofs": fe.n_dofs, "contact_model": "newton",
                     "frequencies_hz": "; ".join(f"{f:.6g} Hz" for f in fe.frequencies[:modes]),
                     **_spectral_columns(fe_spec, fe_spec)})
    rows += [_model_row(e, fe, fe_spec, periods, columns, modes, threshold) for e in entries]
    names = [r["model"] for r in rows]
    if len(set(names)) != len(names):
        raise ValueError(f"model names must be unique, got {names}: give ModelResult(name=...)")
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
        where = lonely[0].removeprefix("energy_").replace("T1", " T1")
        return f"not converged (admissible orbits at {where} in one size only)", None
    if not deltas:
        return "n/a", None
    delta = max(deltas)
    return (f"converged (<{_pct(tol)} %)" if delta < tol else f"not converged (Δ = {_pct(delta)} %)"), delta


def _add_convergence(rows: list[dict], columns: list[str], tol: float) -> None:
    for method in {r["method"] for r in rows}:
        mine = sorted((r for r in rows if r["method"] == method and r.get("size") is not None),
                      key=lambda r: r["size"])
        verdict, delta = convergence_verdict(mine[-2], mine[-1], columns, tol) if len(mine) >= 2 else ("n/a", None)
        for r in rows:
            if r["method"] == method and method != "fe":
                r["convergence"], r["convergence_delta"] = verdict, delta


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


# ----------------------------------------------------------------------------- the diagnostics


def _times(ratio: float) -> str:
    return f"{ratio:.0f}×" if ratio >= 10 else f"{ratio:.2g}×"


def _count(n: int, noun: str) -> str:
    return f"{n} {noun if n == 1 else noun[:-1] + 'ies' if noun.endswith('y') else noun + 's'}"


def _at(column: str) -> str:
    return column.removeprefix("energy_").replace("T1", " T1")


def _spread(models: list[dict], key: str, label: str, factor: float, fe_row: dict | None) -> list[str]:
    vals = [(r[key], r["model"]) for r in models if r.get(key) is not None and r[key] > 0]
    if len(vals) < 2 or max(vals)[0] < factor * min(vals)[0]:
        return []
    (hi, a), (lo, b) = max(vals), min(vals)
    fe = f"; FE: {fe_row[key]:.3g}" if fe_row and fe_row.get(key) is not None else ""
    return [f"{label} differs {_times(hi / lo)} between {a} ({hi:.3g}) and {b} ({lo:.3g}{fe})"]


def _kept(models: list[dict], factor: float, compliance_rtol: float, fe_row: dict | None) -> list[str]:
    off = sorted((r["impact_mass_kept"], r["model"]) for r in models
                 if r.get("impact_mass_kept") is not None and not 1 / factor < r["impact_mass_kept"] < factor)
    out = []
    if off:
        fe = f" {fe_row['impact_mass']:.3g}" if fe_row and fe_row.get("impact_mass") is not None else ""
        span = " to ".join(dict.fromkeys(f"{_times(max(k, 1 / k))} ({n})" for k, n in (off[0], off[-1])))
        more = "above" if off[-1][0] > 1 else "below"
        out.append(f"impact mass 1/Σb² is {span} {more} the FE value{fe}"
                   + (f" in {len(off)} models" if len(off) > 1 else "")
                   + (": their modes miss most of the FE's Σb² (the contact node's own inertia)"
                      if off[0][0] > 1 else ""))
    comp = [(r["static_compliance_kept"], r["model"]) for r in models
            if r.get("static_compliance_kept") is not None and abs(r["static_compliance_kept"] - 1) > compliance_rtol]
    if comp:
        out.append(", ".join(n for _, n in comp) + f" keep{'s' if len(comp) == 1 else ''} "
                   + ", ".join(f"{c:.0%}" for c, _ in comp) + " of the FE static compliance at the contact")
    return out


def _findings(models: list[dict], error: float) -> list[str]:
    if models and all(r.get("admissible_arcs") == 0 for r in models):
        # the massless contact model searches one contact phase per period: only the periods can be widened
        massless = all(r.get("contact_model") == "massless" for r in models)
        out = [f"no model found an admissible arc: widen the search ({'periods' if massless else 'periods, ipp'}) "
               "or check the contact point"]
    else:
        out = [f"{r['model']} found no admissible arc" + (f" ({_count(r['families'], 'family')})"
                                                          if r.get("families") else "")
               for r in models if r.get("admissible_arcs") == 0]
    for r in models:
        if r.get("artefacts"):
            out.append(f"{r['model']}: {_count(r['artefacts'], 'mode')} with no FE counterpart, artefacts of the "
                       f"reduction: {r['artefact_modes']}")
        if r.get("max_frequency_error") is not None and r["max_frequency_error"] > error:
            out.append(f"{r['model']}: matched frequencies up to {r['max_frequency_error']:.1%} off the FE ones")
    return out


def _energies(models: list[dict], factor: float) -> list[str]:
    out = []
    for col in [k for k in (models[0] if models else {}) if k.startswith("energy_")]:
        vals = [(r[col], r["model"]) for r in models if r.get(col) is not None]
        if vals and len(vals) < len(models):
            names = [n for _, n in vals]
            out.append(f"at {_at(col)} only {', '.join(names)} {'has' if len(names) == 1 else 'have'} "
                       "an admissible orbit")
        if len(vals) >= 2 and max(vals)[0] >= factor * min(vals)[0]:
            (hi, a), (lo, b) = max(vals), min(vals)
            out.append(f"energies at {_at(col)} differ {_times(hi / lo)} across models ({lo:.3g} for {b} to "
                       f"{hi:.3g} for {a})")
    return out


def _convergence(models: list[dict]) -> list[str]:
    out = []
    for method in dict.fromkeys(r["method"] for r in models):
        mine = sorted((r for r in models if r["method"] == method and r.get("size") is not None),
                      key=lambda r: r["size"])
        if len(mine) >= 2 and str(mine[-1].get("convergence", "")).startswith("not converged"):
            out.append(f"{method} is {mine[-1]['convergence']} between sizes {mine[-2]['size']} and "
                       f"{mine[-1]['size']}")
    return out


def _weak_modes(fe: FEReference, weak: float, count: int) -> list[str]:
    motion = fe.contact_motion[:count]
    low = np.flatnonzero(motion < weak)
    if low.size == 0:
        return []
    b2 = fe.b[low] ** 2
    which = " and ".join(str(j + 1) for j in low)
    return [f"mode{'s' if low.size > 1 else ''} {which} barely move{'' if low.size > 1 else 's'} the contact node: "
            f"b² = {', '.join(f'{x:.2g}' for x in b2)} (contact motion {', '.join(f'{x:.1%}' for x in motion[low])} "
            "of the mode's largest); try another contact point or normal"]


def diagnose(rows: Sequence[dict], fe: FEReference | None = None, *, factor: float = 10.0, weak: float = 0.1,
             weak_modes: int = 6, error: float = 0.01, compliance_rtol: float = 0.2) -> list[str]:
    """Sentences, in words, on where the models of a comparison disagree or find nothing (empty: they agree).

    From the rows of :func:`comparison_rows` (or :func:`read_comparison_csv`): impact mass, static compliance or
    energies at a common period that differ ``factor``× or more between models; a model whose impact mass is
    ``factor``× off the FE value or whose static compliance is off by more than ``compliance_rtol``; models that
    found no admissible arc, or periods where only some have an admissible orbit; artefact modes; matched
    frequencies more than ``error`` off; methods not converged between their two largest sizes. With ``fe``:
    the lowest ``weak_modes`` FE modes that barely move the contact — their :attr:`FEReference.contact_motion`
    (contact displacement over the mode's largest) below ``weak`` (the contact sits near their node line, or the
    normal is orthogonal to their motion there).

    >>> rows = [{"model": "modal-10", "method": "modal", "size": 10, "impact_mass": 2e-3, "admissible_arcs": 92},
    ...         {"model": "lanczos-si-6", "method": "lanczos-si", "size": 6, "impact_mass": 2e-5,
    ...          "admissible_arcs": 0, "families": 12}]
    >>> print(*diagnose(rows), sep="\\n")
    impact mass differs 100× between modal-10 (0.002) and lanczos-si-6 (2e-05)
    lanczos-si-6 found no admissible arc (12 families)
    """
    factor = positive("factor", factor)
    rows = list(rows)
    models = [r for r in rows if r.get("method") != "fe"]
    fe_row = next((r for r in rows if r.get("method") == "fe"), None)
    out = _spread(models, "impact_mass", "impact mass", factor, fe_row)
    out += _spread(models, "static_compliance", "static compliance", factor, fe_row)
    out += _kept(models, factor, compliance_rtol, fe_row) + _findings(models, error) + _energies(models, factor)
    out += _convergence(models)
    if fe is not None:
        out += _weak_modes(fe, weak, integer("weak_modes", weak_modes, 1))
    return out
