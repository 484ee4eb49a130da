"""The comparison stage of a study: every model of ``[reduction]`` (the main one, ``compare`` and the
methods × sizes grid) side by side against the FE model and the largest model (the reference) —
``comparison.csv``, the figures, the verdict (which model to use, or why none can be trusted) and sentences in
words on where the models disagree (:mod:`bladecase.post.comparison.compare`, :mod:`bladecase.post.comparison.table`,
:mod:`bladecase.post.comparison.plots`)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from ... import log
from ...io import save_figure
from ...post.comparison.compare import FEReference, ModelResult, choose_periods, largest_model
from ...post.comparison.diagnose import diagnose
from ...post.comparison.plots import convergence_plot, convergence_series, overlay_plot, spectral_plot
from ...post.comparison.table import (
    ENERGY_RTOL,
    FREQUENCY_RTOL,
    comparison_rows,
    comparison_verdict,
    write_comparison_csv,
)

#: Lowest FE modes computed for the MAC matching (more when the study asks for more frequencies).
FE_MODES = 12

#: Comparison figures and their file names.
FIGURES = {"overlay": "comparison_frequency_energy.png", "convergence": "comparison_convergence.png",
           "spectrum": "comparison_contact_spectrum.png"}

#: ``[reduction] compare_periods`` when the study does not set it (the schema fills it in): read as "not given",
#: the periods are then chosen inside the models' admissible arcs.
DEFAULT_PERIODS = (0.9, 0.95, 0.99)

#: Resolution of the comparison figures (10 × 5.5 in at most: 1100 × 605 px).
DPI = 110

#: Keys of :func:`compare_models`' result that go into ``summary.json["comparison"]``.
SUMMARY_KEYS = ("rows", "diagnostics", "figures", "verdict", "periods", "skipped")


def compare_models(fe: FEReference, entries: list[ModelResult], folder: Path, *, title: str = "",
                   figures: bool = True, fractions=None, energy_rtol: float = ENERGY_RTOL,
                   frequency_rtol: float = FREQUENCY_RTOL) -> dict:
    """Write ``comparison.csv`` and (``figures``: PNG) the comparison figures of ``entries`` against the FE
    model ``fe`` (:func:`~bladecase.post.comparison.compare.fe_reference`) and the largest model into ``folder``.

    ``fractions``: the periods (× FE T1) where every model's energy is read. Not given (``None`` or the schema's
    default :data:`DEFAULT_PERIODS`), or missing every admissible arc: chosen inside the models' common admissible
    range (:func:`~bladecase.post.comparison.compare.choose_periods`; the log says which and why).

    Returns ``{"csv", "figures", "rows", "diagnostics", "verdict", "periods", "skipped"}``: ``verdict`` —
    :func:`~bladecase.post.comparison.table.comparison_verdict` with the tolerances ``energy_rtol`` and
    ``frequency_rtol``; ``periods`` — :meth:`~bladecase.post.comparison.compare.PeriodChoice.to_dict`; ``skipped`` — the
    figures not drawn, each with the reason (also a sentence of ``diagnostics``); ``diagnostics`` — sentences,
    empty when the models agree. :func:`summary_section` is what ``summary.json`` keeps.
    """
    T1 = 1.0 / float(fe.frequencies[0])
    ref = largest_model(entries)
    given = None if fractions is None or tuple(float(f) for f in fractions) == DEFAULT_PERIODS else fractions
    choice = choose_periods(entries, T1, given=given, reference=ref and ref.name)
    if choice.source != "given":
        why = "compare_periods not given" if given is None else "compare_periods outside every arc"
        log.info("comparison: %s: %s", why, choice.words)
    if not choice.fractions:  # no admissible arc anywhere: the columns of the periods asked for, empty
        choice = replace(choice, fractions=tuple(fractions) if fractions is not None else DEFAULT_PERIODS)
    fracs = choice.fractions
    rows = comparison_rows(entries, fe, fractions=fracs, T1=T1, tol=energy_rtol, reference=ref and ref.name)
    write_comparison_csv(rows, folder / "comparison.csv")
    verdict = comparison_verdict(rows, energy_rtol=energy_rtol, frequency_rtol=frequency_rtol)
    log.info("comparison verdict: %s", verdict["sentence"])
    words = diagnose(rows, fe)
    skipped = {}
    if not convergence_series(rows)["change"]:
        skipped["convergence"] = ("no convergence figure: no method has two sizes with an admissible orbit at a "
                                  "comparison period")
    for line in words:
        log.info("comparison: %s", line)
    if not words:
        log.info("comparison: the %d models agree (frequencies, contact measures, energies at common periods)",
                 len(entries))
    out = {"csv": "comparison.csv", "figures": {}, "rows": rows, "diagnostics": words + list(skipped.values()),
           "verdict": verdict, "periods": choice.to_dict(), "skipped": skipped}
    if not figures:
        return out
    drawn = {"overlay": lambda: overlay_plot(entries, fe, title=f"{title}: nonsmooth modes of every model",
                                             periods=[f * T1 for f in fracs], reference=ref and ref.name),
             "spectrum": lambda: spectral_plot(entries, fe, title=f"{title}: contact spectral measure")}
    if "convergence" not in skipped:
        drawn["convergence"] = lambda: convergence_plot(rows, title=f"{title}: convergence with the model size",
                                                        tolerance=energy_rtol)
    for key in ("overlay", "convergence", "spectrum"):
        if key in drawn:
            save_figure(drawn[key](), folder / FIGURES[key], dpi=DPI)
            out["figures"][key] = FIGURES[key]
    return out


def summary_section(comparison: dict) -> dict:
    """The part of :func:`compare_models`' result that ``summary.json["comparison"]`` keeps (:data:`SUMMARY_KEYS`)."""
    return {k: comparison[k] for k in SUMMARY_KEYS if k in comparison}
