"""The casing's stiffness against the blade's at the contact, in words: a casing far softer than the blade's own
static stiffness at the contact barely changes the modes (:data:`~bladecase.reduction.casing.WEAK_CASING`,
:func:`~bladecase.reduction.casing.frequency_rise_bound`) — said in the log and the report with both figures.

>>> print(weak_casing_words(1.0e5, 4.5e7, casing=1.0e5))   # doctest: +NORMALIZE_WHITESPACE
the casing is far softer than the blade at its contact: the closed contact's stiffness 1e+05 N/m (the casing's 1e+05
N/m in series with the contact's own) is 0.0022 × the blade's static stiffness at the contact 1/(wᵀK⁻¹w) = 4.5e+07 N/m,
below 0.01: the contact barely changes the modes — closed, it raises no mode's frequency by more than 0.11 % (√(1 +
0.0022) − 1: in each mode's own shape the contact's spring adds at most that ratio to ω², as no mode's b²/ω² exceeds
wᵀK⁻¹w), so a nonsmooth-mode band, if any, is at most that wide
>>> weak_casing_words(1.0e7, 4.5e7) is None
True
"""

from __future__ import annotations

from ...reduction.casing import WEAK_CASING, frequency_rise_bound

__all__ = ["weak_casing_words"]


def weak_casing_words(series: float | None, static: float | None, casing: float | None = None) -> str | None:
    """The sentence for a closed contact of stiffness ``series`` (N/m: the casing in series with the contact's own)
    below :data:`~bladecase.reduction.casing.WEAK_CASING` × the blade's static stiffness at the contact ``static``
    (N/m); ``None`` when it is not that soft (or a figure is missing).  ``casing``: the casing's own value, named
    when given."""
    if series is None or static is None or not (static > 0) or not (series < WEAK_CASING * static):
        return None
    ratio = series / static
    rise = frequency_rise_bound(series, static)
    own = f" (the casing's {casing:.4g} N/m in series with the contact's own)" if casing is not None else ""
    return (f"the casing is far softer than the blade at its contact: the closed contact's stiffness {series:.4g} "
            f"N/m{own} is {ratio:.2g} × the blade's static stiffness at the contact 1/(wᵀK⁻¹w) = {static:.4g} N/m, "
            f"below {WEAK_CASING:g}: the contact barely changes the modes — closed, it raises no mode's frequency by "
            f"more than {100 * rise:.2g} % (√(1 + {ratio:.2g}) − 1: in each mode's own shape the contact's spring adds "
            "at most that ratio to ω², as no mode's b²/ω² exceeds wᵀK⁻¹w), so a nonsmooth-mode band, if any, is at "
            "most that wide")
