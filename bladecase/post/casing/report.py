"""The casing-stiffness sensitivity: one figure — the nonsmooth mode's admissible backbone (energy against
frequency) for each casing stiffness of a ``[contact] casing_stiffness = [...]`` list, one colour per stiffness —
and the report's words on how much the answer moves (:func:`casing_report`).

>>> import numpy as np
>>> from bladecase.nsm import backbone, chain
>>> soft = backbone(chain(2, k=1.0, m=0.5, gap=1.0), np.linspace(2.0, 8.0, 25))
>>> fig = casing_figure([1e5, 1e6], [[soft], []])
>>> [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
['casing 1e+05 N/m', 'casing 1e+06 N/m: no admissible arc']
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure

from ..plots import new_figure

__all__ = ["casing_figure", "casing_report"]


def casing_figure(stiffnesses: Sequence[float], branches: Sequence[Sequence], title: str | None = None) -> Figure:
    """Energy (J, log) against frequency (Hz) of the admissible orbits of every family found with each casing
    stiffness (N/m), one colour per stiffness; a stiffness with no admissible arc is named in the legend."""
    fig = new_figure(figsize=(7.0, 4.8), layout="constrained")
    ax = fig.add_subplot()
    for i, (k, fams) in enumerate(zip(stiffnesses, branches)):
        color = f"C{i % 10}"
        drawn = False
        for f in fams:
            fr, en = np.asarray(f.frequencies, dtype=float), np.asarray(f.energy, dtype=float)
            for a in f.arcs:
                sel = slice(a.start, a.stop + 1)
                ok = np.asarray(f.admissible)[sel]
                x, y = fr[sel][ok], en[sel][ok]
                if x.size:
                    ax.plot(x, y, "-" if x.size > 1 else "o", color=color,
                            label=None if drawn else f"casing {k:.3g} N/m")
                    drawn = True
        if not drawn:
            ax.plot([], [], "-", color=color, label=f"casing {k:.3g} N/m: no admissible arc")
    ax.set_yscale("log")
    ax.set_xlabel("frequency 1/T (Hz)")
    ax.set_ylabel("energy (J)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title or "the nonsmooth mode's admissible backbone for each casing stiffness")
    return fig


def casing_report(section: dict | None) -> list[str]:
    """Markdown lines for ``summary["casing_sweep"]`` (:func:`bladecase.study.casing.stage.casing_sweep`).

    >>> rows = [{"casing_n_per_m": k, "series_n_per_m": k, "f_lo_hz": 210.5, "f_hi_hz": f, "energy_top_j": e,
    ...          "stable_fraction": s} for k, f, e, s in [(1e6, 215.42, 0.07, 1.0), (1e5, 213.55, 23.0, 1.0)]]
    >>> from bladecase.study.casing.stage import spread
    >>> lines = casing_report({"rows": rows, "spread": spread(rows)})
    >>> lines[-1][:61]
    '- Across these stiffnesses the admissible arc ends between 21'
    """
    if not section:
        return []
    lines = ["", "## Casing stiffness: how much the answer moves", "",
             "The nonsmooth modes searched again with each casing stiffness of `[contact] casing_stiffness` (the "
             "first is the one of the results above; only the contact's spring changes); `casing.png` draws each "
             "admissible backbone.", "",
             "| casing (N/m) | in series with the blade (N/m) | admissible arc (Hz) | top energy (J) | stable orbits |",
             "|---:|---:|---|---:|---:|"]
    for r in section["rows"]:
        if r["f_hi_hz"] is None:
            lines.append(f"| {r['casing_n_per_m']:.3g} | {r['series_n_per_m']:.4g} | none | — | — |")
            continue
        stable = "—" if r["stable_fraction"] is None else f"{r['stable_fraction']:.0%}"
        lines.append(f"| {r['casing_n_per_m']:.3g} | {r['series_n_per_m']:.4g} | {r['f_lo_hz']:.5g} – "
                     f"{r['f_hi_hz']:.5g} | {r['energy_top_j']:.3g} | {stable} |")
    sp = section["spread"]
    if sp.get("with_arcs", 0) >= 2:
        ratio = sp.get("energy_top_ratio")
        lines += ["", f"- Across these stiffnesses the admissible arc ends between {sp['f_hi_hz'][0]:.5g} and "
                  f"{sp['f_hi_hz'][1]:.5g} Hz ({sp['f_hi_relative']:.1%} apart); the energy it reaches there spans "
                  f"{sp['energy_top_j'][0]:.3g}–{sp['energy_top_j'][1]:.3g} J"
                  + (f" (a factor {ratio:.3g})" if ratio else "")
                  + (": quote the frequency band; quote an amplitude or an energy only as this range, unless the "
                     "casing's stiffness is known better" if ratio and ratio > 2 else ": the answer hardly depends on "
                     "the casing's stiffness in this range") + "."]
    elif sp.get("with_arcs", 0) < len(section["rows"]):
        lines += ["", f"- Only {sp.get('with_arcs', 0)} of the {len(section['rows'])} stiffnesses give an admissible "
                  "arc: whether the mode exists at all depends on the casing here."]
    return lines
