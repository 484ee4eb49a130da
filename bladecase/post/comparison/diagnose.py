"""Why the models of a comparison disagree, in words: :func:`diagnose` reads the rows of
:func:`bladecase.post.comparison.table.comparison_rows` (or of their CSV) and names the cause its columns show —
impact masses or static compliances far apart, modes the contact barely sees, energies that do not converge."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...checks import integer, positive
from .compare import FEReference
from .table import energy_columns, period_labels, times

__all__ = ["diagnose"]


def _count(n: int, noun: str) -> str:
    return f"{n} {noun if n == 1 else noun[:-1] + 'ies' if noun.endswith('y') else noun + 's'}"


def _spread(models: list[dict], key: str, label: str, factor: float, fe_row: dict | None) -> list[str]:
    vals = [(r[key], r["model"]) for r in models if r.get(key) is not None and r[key] > 0]
    if len(vals) < 2 or max(vals)[0] < factor * min(vals)[0]:
        return []
    (hi, a), (lo, b) = max(vals), min(vals)
    fe = f"; FE: {fe_row[key]:.3g}" if fe_row and fe_row.get(key) is not None else ""
    return [f"{label} differs {times(hi / lo)} between {a} ({hi:.3g}) and {b} ({lo:.3g}{fe})"]


def _kept(models: list[dict], factor: float, compliance_rtol: float, fe_row: dict | None) -> list[str]:
    off = sorted((r["impact_mass_kept"], r["model"]) for r in models
                 if r.get("impact_mass_kept") is not None and not 1 / factor < r["impact_mass_kept"] < factor)
    out = []
    if off:
        fe = f" {fe_row['impact_mass_kg']:.3g}" if fe_row and fe_row.get("impact_mass_kg") is not None else ""
        span = " to ".join(dict.fromkeys(f"{times(max(k, 1 / k))} ({n})" for k, n in (off[0], off[-1])))
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
    columns = energy_columns(models[0] if models else {})
    short = period_labels(columns)
    for col in columns:
        vals = [(r[col], r["model"]) for r in models if r.get(col) is not None]
        if vals and len(vals) < len(models):
            names = [n for _, n in vals]
            out.append(f"at {short[col]} only {', '.join(names)} {'has' if len(names) == 1 else 'have'} "
                       "an admissible orbit")
        if len(vals) >= 2 and max(vals)[0] >= factor * min(vals)[0]:
            (hi, a), (lo, b) = max(vals), min(vals)
            out.append(f"energies at {short[col]} differ {times(hi / lo)} across models ({lo:.3g} for {b} to "
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

    >>> rows = [{"model": "modal-10", "method": "modal", "size": 10, "impact_mass_kg": 2e-3, "admissible_arcs": 92},
    ...         {"model": "lanczos-si-6", "method": "lanczos-si", "size": 6, "impact_mass_kg": 2e-5,
    ...          "admissible_arcs": 0, "families": 12}]
    >>> print(*diagnose(rows), sep="\\n")
    impact mass differs 100× between modal-10 (0.002) and lanczos-si-6 (2e-05)
    lanczos-si-6 found no admissible arc (12 families)
    """
    factor = positive("factor", factor)
    rows = list(rows)
    models = [r for r in rows if r.get("method") != "fe"]
    fe_row = next((r for r in rows if r.get("method") == "fe"), None)
    out = _spread(models, "impact_mass_kg", "impact mass", factor, fe_row)
    out += _spread(models, "static_compliance_m_per_n", "static compliance", factor, fe_row)
    out += _kept(models, factor, compliance_rtol, fe_row) + _findings(models, error) + _energies(models, factor)
    out += _convergence(models)
    if fe is not None:
        out += _weak_modes(fe, weak, integer("weak_modes", weak_modes, 1))
    return out
