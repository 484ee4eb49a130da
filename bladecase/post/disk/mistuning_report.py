"""The report's words on a mistuned disk (``summary["mistuning"]``, :mod:`bladecase.study.disk.mistuning`): the
model and its assumptions in one sentence, the amplification factor's distribution against Whitehead's bound, the worst
blade of the worst sample.

>>> m = {"model": "snm", "family": 0, "modes": 6, "engine_order": 2, "diameter": 2, "damping": 0.005, "sectors": 6,
...      "std": 0.02, "seed": 3, "deviations": None, "samples": 20, "mean": 1.12, "largest": 1.21,
...      "largest_sample": 9, "largest_blade": 4, "whitehead_bound": 1.7247, "above_bound": 0,
...      "percentiles": {"p5": 1.07, "p50": 1.11, "p95": 1.2, "p99": 1.21}, "largest_frequency_hz": 1648.2,
...      "tip": {"node": 9, "direction": "y"}, "blade_cells": 58, "cells": 283}
>>> print(mistuning_sentence(m))
Mistuning (20 random samples, std 2 %): amplification 1.110 (median) to 1.210 (largest: blade 4 of sample 9), \
below Whitehead's bound 1.725 for 6 blades.
>>> lines = mistuning_lines(m)
>>> lines[1]
'## Mistuning'
"""

from __future__ import annotations

__all__ = ["ASSUMPTIONS", "contact_lines", "mistuning_lines", "mistuning_sentence", "rub_lines"]

#: Each model's assumptions in one sentence.
ASSUMPTIONS = {
    "snm": "subset of nominal modes: the mistuned disk's modes are combinations of the tuned modes of the forced "
           "family for every nodal diameter, only each blade's own stiffness is scaled (no mass or disk mistuning), "
           "the deviations are small and the family is isolated in frequency",
    "fmm": "fundamental mistuning model: one isolated mode family whose strain energy is all in the blades, each "
           "deviation scaling a blade's frequency squared as the family sees it, the deviations small",
}


def _samples(m: dict) -> str:
    if m.get("deviations") is not None:
        return "the given pattern"
    return f"{m['samples']} random sample{'s' if m['samples'] != 1 else ''}, std {100 * m['std']:g} %"


def mistuning_sentence(m: dict) -> str:
    """One sentence: the amplification's median and largest, where, against Whitehead's bound."""
    p50 = m["percentiles"]["p50"]
    spread = (f"amplification {m['largest']:.3f}" if m["samples"] == 1
              else f"amplification {p50:.3f} (median) to {m['largest']:.3f}")
    where = f"blade {m['largest_blade']}" + ("" if m["samples"] == 1 else f" of sample {m['largest_sample']}")
    side = (f"{m['above_bound']} sample(s) above" if m["above_bound"] else "below")
    return (f"Mistuning ({_samples(m)}): {spread} (largest: {where}), {side} Whitehead's bound "
            f"{m['whitehead_bound']:.3f} for {m['sectors']} blades.")


def mistuning_lines(m: dict | None) -> list[str]:
    """The report's Markdown section on mistuning (``[]`` without it)."""
    if not m:
        return []
    tip, p = m["tip"], m["percentiles"]
    return ["", "## Mistuning", "",
             f"- {mistuning_sentence(m)}",
             f"- Model ({m['model'].upper()}, {m['modes']} modes: family {m['family']} of every nodal diameter): "
             f"{ASSUMPTIONS[m['model']]}.",
             f"- Forcing: engine order {m['engine_order']} (nodal diameter {m['diameter']}) at each blade's tip "
             f"(node {tip['node']} of the sector, direction {tip['direction']}), response read there; modal damping "
             f"ratio {m['damping']:g}; the blade is {m['blade_cells']} of the sector's {m['cells']} cells.",
             "- Amplification factor (each sample's largest blade amplitude ÷ the tuned disk's): "
             + ("" if m["samples"] == 1 else f"mean {m['mean']:.4f}; 5th/50th/95th/99th percentiles {p['p5']:.4f}, "
                f"{p['p50']:.4f}, {p['p95']:.4f}, {p['p99']:.4f}; largest ")
             + f"{m['largest']:.4f} on blade {m['largest_blade']} at {m['largest_frequency_hz']:.2f} Hz.",
             f"- Whitehead's bound ½(1 + √N) = {m['whitehead_bound']:.4f} for N = {m['sectors']}: "
             f"{m['above_bound']} sample(s) above it" + (" (none expected: check the family is isolated)."
                                                         if m["above_bound"] else ".")] + (
                rub_lines(m.get("rub")) + contact_lines(m.get("contact")))


def contact_lines(c: dict | None) -> list[str]:
    """The report's words on how hard the mistuned blades rub (``summary["mistuning"]["contact"]``; ``[]``
    without it).

    >>> c = {"force_n": 300.0, "samples": 3, "tuned_peak_force_n": 700.0, "tuned_frequency_hz": 1600.0,
    ...      "largest_force_n": {"p50": 830.0, "max": 840.0}, "ratio_to_tuned": {"p50": 1.19, "max": 1.2},
    ...      "worst_sample": 1, "worst_blade": 3, "unsettled": 0, "touching_blades_p50": 4.0}
    >>> contact_lines(c)[0][:58]
    '- Rub at a tip force of 300 N (each blade its own massless'
    """
    if not c:
        return []
    r = c["ratio_to_tuned"]
    ratio = "" if r["p50"] is None else f" ({r['p50']:.3f} and {r['max']:.3f} times the tuned disk's)"
    return [f"- Rub at a tip force of {c['force_n']:.4g} N (each blade its own massless contact at its tip, the "
            f"steady rub at each sample's resonance, {c['samples']} samples): the tuned disk's blades press "
            f"{c['tuned_peak_force_n']:.4g} N at {c['tuned_frequency_hz']:.2f} Hz; mistuned, the hardest-pressing "
            f"blade {c['largest_force_n']['p50']:.4g} N (median) to {c['largest_force_n']['max']:.4g} N{ratio} — "
            f"blade {c['worst_blade']} of sample {c['worst_sample']}; a median {c['touching_blades_p50']:.0f} blades "
            f"touch" + (f"; {c['unsettled']} sample(s) did not settle" if c["unsettled"] else "")
            + ". `mistuning_contact.csv` has every blade's peak force."]


def rub_lines(r: dict | None) -> list[str]:
    """The report's words on which blade rubs first (``summary["mistuning"]["rub"]``; ``[]`` without it).

    >>> r = {"clearance_m": 1e-4, "tuned_level_n": 2.5, "tuned_ratio": {"min": 0.8, "p5": 0.84, "p50": 0.9,
    ...      "max": 0.99}, "lead": {"p5": 0.01, "p50": 0.08}, "soonest_sample": 3, "soonest_blade": 5,
    ...      "soonest_level_n": 2.0, "first_blade_counts": [1, 2]}
    >>> rub_lines(r)[1][:60]
    '- First rub (tip clearance 100 µm): the tuned disk rubs at a'
    """
    if not r:
        return []
    c = r["clearance_m"]
    where = f"{c * 1e6:.4g} µm" if not isinstance(c, list) else f"{min(c) * 1e6:.4g}–{max(c) * 1e6:.4g} µm by blade"
    t, lead = r["tuned_ratio"], r["lead"]
    return ["", f"- First rub (tip clearance {where}): the tuned disk rubs at a tip force of {r['tuned_level_n']:.4g} "
                f"N (each blade's radial tip excursion at its resonance peak against its clearance); mistuned, the "
                f"first blade rubs at {t['p50']:.3f} (median), {t['p5']:.3f} (5th percentile) and {t['min']:.3f} "
                f"(soonest: blade {r['soonest_blade']} of sample {r['soonest_sample']}, {r['soonest_level_n']:.4g} "
                f"N) times that force; the next blade needs {100 * lead['p50']:.1f} % more (median; 5th percentile "
                f"{100 * lead['p5']:.1f} %). `mistuning_rub.csv` has every sample."]
