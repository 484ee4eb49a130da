"""The comparison stage of a study: every model of ``[reduction]`` (the main one, ``compare`` and the
methods × sizes grid) side by side against the FE model — ``comparison.csv``, three figures and sentences in
words on where the models disagree (:mod:`bladecase.post.compare`, :mod:`bladecase.post.compare_table`,
:mod:`bladecase.post.compare_plots`)."""

from __future__ import annotations

from pathlib import Path

from .. import log
from ..post.compare import FEReference, ModelResult
from ..post.compare_plots import convergence_plot, overlay_plot, spectral_plot
from ..post.compare_table import comparison_rows, diagnose, write_comparison_csv

#: Lowest FE modes computed for the MAC matching (more when the study asks for more frequencies).
FE_MODES = 12

#: Comparison figures and their file names.
FIGURES = {"overlay": "comparison_frequency_energy.png", "convergence": "comparison_convergence.png",
           "spectrum": "comparison_contact_spectrum.png"}


def compare_models(fe: FEReference, entries: list[ModelResult], folder: Path, *, title: str = "",
                   figures: bool = True, fractions=(0.9, 0.95, 0.99)) -> dict:
    """Write ``comparison.csv`` and (``figures``: PNG) the comparison figures of ``entries`` against the FE
    model ``fe`` (:func:`~bladecase.post.compare.fe_reference`) into ``folder``; return the summary section:
    ``{"csv", "figures", "rows", "diagnostics"}`` (diagnostics: sentences, empty when the models agree);
    ``fractions``: the periods (× FE T1) where every model's energy is read."""
    rows = comparison_rows(entries, fe, fractions=fractions)
    write_comparison_csv(rows, folder / "comparison.csv")
    words = diagnose(rows, fe)
    for line in words:
        log.info("comparison: %s", line)
    if not words:
        log.info("comparison: the %d models agree (frequencies, contact measures, energies at common periods)",
                 len(entries))
    if not figures:
        return {"csv": "comparison.csv", "figures": {}, "rows": rows, "diagnostics": words}
    figures = {"overlay": overlay_plot(entries, fe, title=f"{title}: nonsmooth modes of every model"),
               "spectrum": spectral_plot(entries, fe, title=f"{title}: contact spectral measure")}
    sized: dict = {}
    for r in rows[1:]:
        if r.get("size") is not None:
            sized.setdefault(r["method"], set()).add(r["size"])
    if any(len(s) >= 2 for s in sized.values()):
        figures["convergence"] = convergence_plot(rows, title=f"{title}: convergence with the model size")
    files = {}
    for key, fig in figures.items():
        fig.savefig(folder / FIGURES[key], dpi=110)
        files[key] = FIGURES[key]
    return {"csv": "comparison.csv", "figures": files, "rows": rows, "diagnostics": words}
