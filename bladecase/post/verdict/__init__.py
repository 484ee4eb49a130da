"""The run's verdict in three lines: what was found, whether to trust it and why, what to do next.

:func:`verdict` reads a run's summary (``summary.json``) — and, when given, its modes file (``modes.json``: why
orbits are not admissible) — and returns ``{"found", "trust", "next", "reasons"}``: three sentences in words and
the machine-readable codes of :data:`REASONS` behind them. Every number it says is one of the summary's (or
computed from them); a cause the run's data do not show is never named, and a question they cannot answer is said
to be open (``no_reason_in_data``).

Modules: :mod:`~bladecase.post.verdict.words` (thresholds, :data:`REASONS`, wording helpers),
:mod:`~bladecase.post.verdict.base` (the data read from the summary), :mod:`~bladecase.post.verdict.found`,
:mod:`~bladecase.post.verdict.trust`, :mod:`~bladecase.post.verdict.advice` (the three lines).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from .advice import _Next
from .found import _Found
from .trust import _Trust
from .words import (  # noqa: F401 (the verdict's public names)
    ARTEFACT_SHARE,
    ENERGY_SCATTER,
    FREQUENCY_RTOL,
    GRAZING_RTOL,
    NARROW_RTOL,
    REASONS,
    RESONANCE_NEAR,
    STIFF_CASING,
    UNSEEN_B,
    VIOLATION_RTOL,
    WEAK_B2,
    massless_summary,
    orbit_words,
    rejected_words,
)


class _Verdict(_Found, _Trust, _Next):
    """The three sentences and their codes, from one summary."""

    def result(self) -> dict:
        found = self.found()
        trust = self.trust()
        nxt = self.next()
        return {"found": found, "trust": trust, "next": nxt, "reasons": list(self.codes)}


def verdict(summary: dict, modes: dict | str | os.PathLike | None = None) -> dict:
    """The run's verdict from its ``summary`` (``summary.json``) and, optionally, its ``modes`` (the
    ``modes.json`` document or its path: why orbits are not admissible, exact stable shares).

    Returns ``{"found": str, "trust": str, "next": str, "reasons": [codes of REASONS]}``.

    >>> s = {"contact": {"model": "massless", "clearance_m": 1e-4, "casing_stiffness_n_per_m": None},
    ...      "reduction": {"method": "massless", "frequencies_hz": [100.0, 400.0], "contact_weights_b2": [1.0, 1.0]},
    ...      "reference": None, "search": {"ipp": [1], "periods": [0.5, 0.6], "period_unit": "T1",
    ...      "period_unit_s": 0.01}, "families": [], "files": {"animations": []}}
    >>> v = verdict(s)
    >>> v["reasons"]   # and no [convergence] in the summary: the mesh error is not measured
    ['no_family_in_range', 'mesh_error_unknown', 'grazing_outside_range']
    >>> print(v["found"].replace(": ", ":\\n"))
    No nonsmooth mode in the searched periods [0.5, 0.6] × T1 (= [0.005, 0.006] s):
    the search found no family of orbits with one contact phase per period there.
    """
    return _Verdict(summary, _modes(modes)).result()



def narrow_words(summary: dict) -> str | None:
    """Where the widest admissible arc lies, when it is narrower than :data:`NARROW_RTOL` (``None`` otherwise): in
    words that hold for both contact models — next to grazing, or a narrow stretch some way above the linear
    frequency."""
    return _Verdict(summary, None).narrow_words()



def _modes(modes) -> dict | None:
    if modes is None or isinstance(modes, dict):
        return modes
    path = Path(modes)
    if not path.is_file():
        return None
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None

