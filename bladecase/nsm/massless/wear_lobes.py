"""The held-out check of a worn profile's lobes against the tip's vibration: :func:`lobe_check`,
:func:`dominant_ratio`.

A tip vibrating at ``f_vib`` while the blade turns at ``f_rot`` meets the casing ``f_vib / f_rot`` times a
revolution: near an engine order ``N`` it wears ``N`` lobes. The check reads each side from its own data only, over
the SAME ``window`` revolutions — the last ones that wore the coating (a revolution wears when it deepens some cell
by more than :data:`WEAR_FLOOR` of the final profile's deepest wear): a coating worn to the tip's reach wears no more,
and the vibration that made its lobes is the one of the revolutions that removed it:

- **the lobes** from the profile alone: the coating removed over the window (the profile at the end less the
  profile before the window), its strongest circumferential harmonic
  (:func:`~bladecase.nsm.massless.wear.harmonic_lobes`).
  The wear since rest also holds the transient revolutions, worn at other frequencies, which a later vibration
  need not wear over again;
- **f_vib / f_rot** from the response alone: the strongest line of the Hann-windowed spectrum of the tip's normal
  displacement over the window (:func:`dominant_ratio`), above half an engine order, its trend taken out (slower
  is the drift of the tip's mean position as the coating opens, not a vibration).

The verdict is ``"agree"`` or ``"differ"`` where both are defined, else ``"undefined"`` with the reason:

- no coating removed in any revolution;
- the profile has no one lobe count: another harmonic, not a multiple of the strongest, within
  :data:`~bladecase.nsm.massless.wear.LOBE_SHARE` of it;
- the response has no one frequency: another spectral line (beyond the strongest's main lobe, above half an
  engine order) within the same share of the strongest — the tip vibrates at several frequencies, and which one the
  coating keeps is not a property of the response;
- ``f_vib / f_rot`` is ``ε`` from the nearest engine order with ``|ε|·window > ½``: over the window the vibration
  drifts by more than half a lobe round the casing, the wear is smeared and has no lobe count to compare.

>>> tip = np.cos(2 * np.pi * 7.02 * np.arange(1200) / 100).reshape(12, 100)
>>> theta = (np.arange(90) + 0.5) * 2 * np.pi / 90
>>> depths = np.array([k * 1e-6 * (1 + np.cos(7 * theta)) for k in range(1, 13)])
>>> c = lobe_check(depths, tip, 100)
>>> c.verdict, c.lobes, c.expected, round(c.ratio, 2)
('agree', 7, 7, 7.02)
>>> c = lobe_check(depths, np.cos(2 * np.pi * 7.4 * np.arange(1200) / 100).reshape(12, 100), 100)
>>> c.verdict, c.reason[:50]
('undefined', 'f_vib / f_rot = 7.4 is 0.4 from the engine order 7')
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from .wear import LOBE_SHARE, harmonic_lobes

__all__ = ["LobeCheck", "dominant_ratio", "lobe_check", "lobe_words"]

#: A revolution wears the coating when it deepens some cell by more than this share of the final deepest wear.
WEAR_FLOOR = 1e-6

#: The lowest frequency over the rotation's that counts as a vibration (slower: the drift of the tip's mean
#: position): half an engine order, which would wear no lobe.
LOWEST_RATIO = 0.5


@dataclass(frozen=True)
class LobeCheck:
    """:func:`lobe_check`'s answer: ``verdict`` (``"agree"``, ``"differ"``, ``"undefined"``), the ``window``
    (revolutions read), the ``lobes`` of the wear over the window and their ``rival`` harmonic (``0``: none),
    ``ratio`` = f_vib / f_rot and the runner-up spectral line's ratio and share of the strongest (``second``,
    ``second_share``), ``expected`` = round(ratio), ``reason`` (empty unless undefined), and the strongest line of
    each revolution of the window alone (``per_revolution``: a vibration that stays one shows one value), and the
    window's ``last`` revolution (counted from 1; ``0``: no revolution wore the coating)."""

    verdict: str
    window: int
    lobes: int
    rival: int
    ratio: float
    second: float
    second_share: float
    expected: int
    reason: str
    per_revolution: tuple = ()
    last: int = 0

    def as_dict(self) -> dict:
        """The check as plain numbers and words."""
        return {**asdict(self), "per_revolution": list(self.per_revolution)}


def dominant_ratio(signal, samples_per_turn: int) -> tuple[float, float, float]:
    """``(ratio, second, share)``: the strongest line of the Hann-windowed spectrum of ``signal`` (sampled
    ``samples_per_turn`` times a revolution over whole revolutions, its mean and linear trend taken out) above
    :data:`LOWEST_RATIO` of the rotation frequency, refined by the parabola through its bin and its neighbours (log
    amplitudes); the strongest other local maximum outside its main lobe (two bins each side), and its amplitude
    over the strongest's (``second = share = 0``: none).

    >>> t = np.arange(400) / 100                                       # four revolutions, 100 samples each
    >>> r, second, share = dominant_ratio(np.cos(2 * np.pi * 8 * t) + 0.6 * np.cos(2 * np.pi * 10.5 * t), 100)
    >>> round(r, 3), second, round(share, 2)
    (8.0, 10.5, 0.6)
    """
    y = np.asarray(signal, dtype=float)
    s = np.arange(y.size) - 0.5 * (y.size - 1)
    y = (y - y.mean() - s * (s @ y) / max(s @ s, 1e-300)) * np.hanning(y.size)  # the trend is no vibration
    a = np.abs(np.fft.rfft(y))
    turns = y.size / samples_per_turn
    lo = int(np.floor(LOWEST_RATIO * turns)) + 1
    if a.size <= lo or not a[lo:].max() > 0:
        return 0.0, 0.0, 0.0
    k = lo + int(np.argmax(a[lo:]))
    shift = 0.0
    if 1 <= k < a.size - 1:
        left, mid, right = np.log(a[k - 1:k + 2] + 1e-300)
        den = left - 2 * mid + right
        shift = 0.5 * (left - right) / den if den != 0 else 0.0
    peaks = [j for j in range(lo, a.size - 1) if abs(j - k) > 2 and a[j] >= a[j - 1] and a[j] >= a[j + 1]]
    j = max(peaks, key=lambda i: a[i]) if peaks else None
    second, share = (0.0, 0.0) if j is None else (j / turns, float(a[j] / a[k]))
    return float((k + shift) / turns), float(second), share


def lobe_check(depths, tip, samples_per_turn: int, window: int = 4, share: float = LOBE_SHARE) -> LobeCheck:
    """The held-out check over the last ``window`` revolutions (module docstring): ``depths`` the profile after each
    revolution (``(revolutions, cells)``, m), ``tip`` the tip's normal displacement over each revolution
    (``(revolutions, samples_per_turn)``); ``share`` the share of the strongest within which a rival counts.

    >>> theta = (np.arange(90) + 0.5) * 2 * np.pi / 90
    >>> depths = np.array([np.zeros(90), 1e-6 * (1 + np.cos(8 * theta))])
    >>> lobe_check(depths, np.cos(2 * np.pi * 9 * np.arange(200) / 100).reshape(2, 100), 100, window=1).verdict
    'differ'
    """
    depths, tip = np.atleast_2d(np.asarray(depths, dtype=float)), np.atleast_2d(np.asarray(tip, dtype=float))
    if isinstance(window, bool) or int(window) != window or window < 1:
        raise ValueError(f"window must be an integer >= 1 (revolutions), got {window!r}")
    if depths.shape[0] != tip.shape[0] or tip.shape[1] != samples_per_turn:
        raise ValueError(f"depths and tip must hold one row per revolution and tip {samples_per_turn} samples a row, "
                         f"got {depths.shape} and {tip.shape}")
    gained = np.diff(depths, axis=0, prepend=0.0).max(axis=1)  # each revolution's deepest new wear
    wearing = np.flatnonzero(gained > WEAR_FLOOR * max(float(depths[-1].max()), 0.0))
    last = int(wearing[-1]) + 1 if wearing.size else depths.shape[0]  # the window ends with the last wearing turn
    n = min(int(window), last)
    worn = depths[last - 1] - (depths[last - 1 - n] if n < last else 0.0)
    lobes, rival = harmonic_lobes(worn, share)
    ratio, second, second_share = dominant_ratio(tip[last - n:last].ravel(), samples_per_turn)
    expected = int(round(ratio))
    eps = ratio - expected
    reasons = []
    if not wearing.size:
        reasons.append("no coating removed in any revolution")
    elif rival:
        reasons.append(f"the wear over the {n} revolutions read has no one lobe count: harmonic {rival} is within "
                       f"{share:g} of harmonic {lobes}")
    if second_share >= 1 - share:
        reasons.append(f"the tip vibrates at several frequencies: {second:.3g} × f_rot at {second_share:.2f} of the "
                       f"strongest, {ratio:.3g} × f_rot")
    elif abs(eps) * n > 0.5:
        reasons.append(f"f_vib / f_rot = {ratio:.3g} is {abs(eps):.2g} from the engine order {expected}: over the {n} "
                       f"revolutions read the lobes drift by {abs(eps) * n:.2g} lobe lengths, the wear is smeared")
    verdict = "undefined" if reasons else ("agree" if lobes == expected else "differ")
    each = tuple(dominant_ratio(row, samples_per_turn)[0] for row in tip[last - n:last])
    return LobeCheck(verdict, n, lobes, rival, ratio, second, second_share, expected, "; ".join(reasons), each,
                     last if wearing.size else 0)


def lobe_words(c: dict) -> str:
    """A :class:`LobeCheck` as a dict (:meth:`LobeCheck.as_dict`) in words.

    >>> lobe_words({"verdict": "agree", "lobes": 8, "ratio": 8.04, "expected": 8, "reason": ""})
    'the wear has 8 lobes, round(f_vib / f_rot) = round(8.04) = 8: they agree'
    >>> lobe_words({"verdict": "undefined", "lobes": 9, "ratio": 7.94, "expected": 8, "reason": "no coating removed"})
    'no lobe count to compare with round(f_vib / f_rot): no coating removed'
    """
    if c["verdict"] == "undefined":
        return f"no lobe count to compare with round(f_vib / f_rot): {c['reason']}"
    return (f"the wear has {c['lobes']} lobes, round(f_vib / f_rot) = round({c['ratio']:.3g}) = {c['expected']}: "
            + ("they agree" if c["verdict"] == "agree" else "they differ"))
