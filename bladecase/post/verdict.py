"""The run's verdict in three lines: what was found, whether to trust it and why, what to do next.

:func:`verdict` reads a run's summary (``summary.json``) — and, when given, its modes file (``modes.json``: why
orbits are not admissible) — and returns ``{"found", "trust", "next", "reasons"}``: three sentences in words and
the machine-readable codes of :data:`REASONS` behind them. Every number it says is one of the summary's (or
computed from them); a cause the run's data do not show is never named, and a question they cannot answer is said
to be open (``no_reason_in_data``).
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

#: Admissible arcs narrower than this (relative, in frequency) are called narrow in words.
NARROW_RTOL = 1e-3

#: An arc whose lowest frequency is within this (relative) of a linear frequency starts at grazing.
GRAZING_RTOL = 1e-6

#: A mode whose contact weight ``b²`` is below this fraction of the largest (over the modes with an FE counterpart)
#: barely moves the contact: the contact group sits on its node line (or the normal is orthogonal to its motion).
WEAK_B2 = 1e-3

#: Modes with ``|b| <= this × max|b|`` are not seen by the contact at all (as ``[search] period_unit = "T<j>"``).
UNSEEN_B = 1e-11

#: The reduced model's frequencies are said to match the FE model's within this relative error.
FREQUENCY_RTOL = 0.01

#: A massless study's casing is "as stiff as the contact" when rigid or at least this fraction of ``k_c``.
STIFF_CASING = 0.1

#: Energies at one period that spread by more than this (relative to the largest) scatter across models.
ENERGY_SCATTER = 0.1

#: An internal resonance is read with the main family when its frequency lies within its arcs' span, or this far
#: (relative) above it.
RESONANCE_NEAR = 0.01

#: A mode with no FE counterpart is harmless to an animated orbit holding less than this share of its energy in it.
ARTEFACT_SHARE = 0.01

#: An orbit of ``modes.json`` crosses the casing when its ``max_violation`` exceeds this fraction of the clearance.
VIOLATION_RTOL = 1e-6

#: The reason codes of :func:`verdict` and what each says.
REASONS = {
    "mode_found": "a family has an admissible arc (summary families[*].admissible_arcs)",
    "no_family_in_range": "the search found no family in the searched periods (families == [])",
    "no_admissible_orbit": "families exist but none has an admissible arc",
    "grazing_outside_range": "no linear period the contact sees lies in [search] periods (reduction.frequencies_hz, "
                             "contact_weights_b2, search.periods, search.period_unit_s)",
    "contact_on_node_line": "the lowest modes move the contact with b² below WEAK_B2 of the largest "
                            "(reduction.contact_weights_b2, fe_match)",
    "orbits_cross_casing": "orbits of the families cross the casing (modes.json max_violation)",
    "casing_would_pull": "orbits of the families need a pulling casing: a negative impulse or contact momentum "
                         "(modes.json impulses)",
    "stiff_casing": "massless model, casing rigid or as stiff as the contact (contact.casing_stiffness_n_per_m vs "
                    "contact_stiffness_n_per_m), and no mode leaves grazing",
    "narrow_arc": "the widest admissible arc spans less than NARROW_RTOL of its frequency",
    "arc_at_range_end": "the main family's arcs reach an end of [search] periods (T_lo, T_hi vs search.periods)",
    "internal_resonance": "the main family ends in an internal resonance (families[*].resonance)",
    "partly_unstable": "some orbits of the main family's arcs are linearly unstable (stable_fraction < 1)",
    "no_reason_in_data": "nothing in the summary explains why nothing was found",
    "verified": "every animated orbit re-simulates to itself (files.animations[*].verification.ok)",
    "verification_failed": "an animated orbit does not re-simulate to itself (verification.ok false)",
    "reference_survived": "every animated orbit survives in the reference model (reference_check.survives)",
    "reference_failed": "an animated orbit does not survive in the reference model (reference_check.survives false), "
                        "or no orbit was animated because every orbit tried failed the check (reference.rejected)",
    "not_animated": "admissible arcs, but no orbit animated: nothing was re-simulated or checked",
    "no_reference_check": "no reference model ([output] reference = false: summary reference is null)",
    "reduced_model_matches_fe": "the reduced model's frequencies match the FE model's within FREQUENCY_RTOL "
                                "(reduction.fe_match or relative_error_vs_fe)",
    "reduced_model_off_fe": "a reduced mode is more than FREQUENCY_RTOL off its FE counterpart",
    "reduced_model_artefacts": "reduced modes with no FE counterpart (fe_match fe_mode null, not beyond_fe)",
    "comparison_converged": "every method of the comparison grid converged (comparison.rows convergence)",
    "comparison_not_converged": "a method of the comparison grid did not converge between its two largest sizes",
    "models_disagree": "compared models find admissible arcs where the study's model finds none, or none where it "
                       "finds some (comparison.rows admissible_arcs)",
    "energies_scatter": "the energies at a common period spread by more than ENERGY_SCATTER across the compared "
                        "models (comparison.rows energy_*)",
    "tip_not_resolved": "tip nodes pass the clearance the face's mean does not (animations[*].tip_excursion)",
    "switch_contact_model": "Newton's impact law, an orbit that failed the reference check (or none animated) and "
                            "energies that scatter across models: the massless contact model is advised",
}


def massless_summary(summary: dict) -> bool:
    """Whether a run's summary is of the massless contact model (contact phases, not impacts)."""
    model = summary["contact"].get("model")
    if model is not None:
        return model == "massless"
    return str(summary["reduction"].get("method", "")).startswith("massless")  # a summary without the key


def orbit_words(k: int, massless: bool) -> str:
    """An orbit named by its contacts per period, in the contact model's words.

    >>> orbit_words(1, True), orbit_words(2, True), orbit_words(2, False)
    ('orbit with one contact phase per period', 'orbit with 2 contact phases per period', '2-ipp orbit')
    """
    if not massless:
        return f"{k}-ipp orbit"
    return f"orbit with {'one contact phase' if k == 1 else f'{k} contact phases'} per period"


def verdict(summary: dict, modes: dict | str | os.PathLike | None = None) -> dict:
    """The run's verdict from its ``summary`` (``summary.json``) and, optionally, its ``modes`` (the
    ``modes.json`` document or its path: why orbits are not admissible, exact stable shares).

    Returns ``{"found": str, "trust": str, "next": str, "reasons": [codes of REASONS]}``.

    >>> s = {"contact": {"model": "massless", "clearance_m": 1e-4, "casing_stiffness_n_per_m": None},
    ...      "reduction": {"method": "massless", "frequencies_hz": [100.0, 400.0], "contact_weights_b2": [1.0, 1.0]},
    ...      "reference": None, "search": {"ipp": [1], "periods": [0.5, 0.6], "period_unit": "T1",
    ...      "period_unit_s": 0.01}, "families": [], "files": {"animations": []}}
    >>> v = verdict(s)
    >>> v["reasons"]
    ['no_family_in_range', 'grazing_outside_range']
    >>> print(v["found"].replace(": ", ":\\n"))
    No nonsmooth mode in the searched periods [0.5, 0.6] × T1 (= [0.005, 0.006] s):
    the search found no family of orbits with one contact phase per period there.
    """
    return _Verdict(summary, _modes(modes)).result()


def rejected_words(summary: dict) -> str | None:
    """Why no orbit was animated although a reference check ran, from ``summary["reference"]["rejected"]``: the
    orbits tried and their figures, or that none was tried; ``None`` when the summary does not say (no
    reference model, or a summary written before it recorded them)."""
    ref = summary.get("reference") or {}
    if "rejected" not in ref:
        return None
    tried = ref["rejected"]
    where = f"the reference model {ref['method']} ({ref['reduced_dofs']} dofs)"
    if not tried:
        return ("no orbit was tried (`[output] animate = 0`, or no orbit named in `[output] orbits` was found), so "
                f"{where} checked none")

    def one(c: dict) -> str:
        why = (f"drifts by {c['drift']:.1e} in one period" if c.get("drift") is not None
               else c.get("reason", "cannot start in an open phase"))
        contacts = ("" if c.get("contacts") in (None, c.get("ipp")) or c.get("drift") is None
                    else f", {c['contacts']} contact(s) for {c['ipp']}")
        return f"T = {c['T']:.8g} s ({c['frequency_hz']:.5g} Hz) {why}{contacts}"
    shown = "; ".join(one(c) for c in tried[:4]) + (f"; and {len(tried) - 4} more" if len(tried) > 4 else "")
    return f"{_plural(len(tried), 'orbit')} tried, none survives in {where}: {shown}"


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


# ----------------------------------------------------------------------------- formatting


def _pct(x: float) -> str:
    """``x`` (a fraction) in percent, two significant digits below 10 %."""
    p = 100 * x
    return f"{p:.0f}" if abs(p) >= 10 else f"{p:.2g}"


def _pcts(lo: float, hi: float) -> str:
    """``4–4.05``: two fractions in percent, with the digits it takes for them to differ."""
    a, b = _pct(lo), _pct(hi)
    for d in range(3, 7):
        if a != b:
            break
        a, b = f"{100 * lo:.{d}g}", f"{100 * hi:.{d}g}"
    return f"{a}–{b}"


def _g(x: float, digits: int = 3) -> str:
    return f"{x:.{digits}g}"


def _freq_span(lo: float, hi: float, arrow: str = "–") -> str:
    """``210.5 → 215.4`` with as many decimals as it takes for the ends to differ (at most 6)."""
    for d in range(1, 7):
        a, b = f"{lo:.{d}f}", f"{hi:.{d}f}"
        if a != b:
            break
    return f"{a}{arrow}{b}"


def _range(lo: float, hi: float, unit: str) -> str:
    """``0.738–1.36 mm``, or one value when both ends print alike."""
    a, b = _g(lo), _g(hi)
    return f"{a} {unit}" if a == b else f"{a}–{b} {unit}"


def _length(m: float) -> str:
    """A length in µm below a millimetre, in mm above."""
    return f"{m * 1e6:.3g} µm" if abs(m) < 1e-3 else f"{m * 1e3:.3g} mm"


def _and(items: list[str]) -> str:
    """``a``, ``a and b``, ``a, b and c``."""
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + f" and {items[-1]}"


def _plural(n: int, word: str, many: str | None = None) -> str:
    return f"{n} {word if n == 1 else (many or word + 's')}"


def _modes_words(idx: list[int]) -> str:
    """1-based mode numbers: ``modes 1–3``, ``modes 1 and 4``, ``mode 2``."""
    nums = [j + 1 for j in idx]
    if len(nums) == 1:
        return f"mode {nums[0]}"
    if nums == list(range(nums[0], nums[-1] + 1)):
        return f"modes {nums[0]}–{nums[-1]}"
    return "modes " + ", ".join(map(str, nums[:-1])) + f" and {nums[-1]}"


# ----------------------------------------------------------------------------- the verdict


class _Verdict:
    """The three sentences and their codes, from one summary."""

    def __init__(self, summary: dict, modes: dict | None):
        self.s, self.modes = summary, modes
        self.codes: list[str] = []
        self.massless = massless_summary(summary)
        r = summary["reduction"]
        self.f = [float(x) for x in r.get("frequencies_hz") or []]
        self.b2 = [float(x) for x in r.get("contact_weights_b2") or []][: len(self.f)]
        top = max((math.sqrt(max(b, 0.0)) for b in self.b2), default=0.0)
        #: modes the contact sees at all (as the T<j> period unit counts them)
        self.seen = [j for j, b in enumerate(self.b2) if math.sqrt(max(b, 0.0)) > UNSEEN_B * top]
        self.weak = self._weak_modes()
        s = summary["search"]
        self.unit, self.unit_s = s.get("period_unit", "s"), float(s.get("period_unit_s") or 1.0)
        self.periods = [float(x) for x in s["periods"]]
        self.T_lo, self.T_hi = self.periods[0] * self.unit_s, self.periods[1] * self.unit_s
        self.T1 = (1 / self.f[self.seen[0]]) if self.seen and self.f[self.seen[0]] > 0 else None
        self.fams = summary.get("families") or []
        self.with_arcs = [(i, f) for i, f in enumerate(self.fams) if f.get("admissible_arcs")]
        self.anims = (summary.get("files") or {}).get("animations") or []
        self.main = self._main_family()

    # --- helpers on the data

    def code(self, *codes: str) -> None:
        for c in codes:
            if c not in self.codes:
                self.codes.append(c)

    def _weak_modes(self) -> list[int]:
        """The modes whose ``b²`` is below :data:`WEAK_B2` of the largest (over the modes with an FE counterpart
        when the summary matches them: the massless attachment mode or mesh-scale modes do not set the scale)."""
        if not self.b2:
            return []
        largest = max(self.b2[j] for j in self._b2_pool())
        return [j for j, b in enumerate(self.b2) if largest > 0 and b < WEAK_B2 * largest]

    def _b2_pool(self) -> list[int]:
        """The modes whose ``b²`` sets the scale: those with an FE counterpart (all, without the matching)."""
        matches = self.s["reduction"].get("fe_match")
        pool = [j for j in range(len(self.b2))
                if matches is None or (j < len(matches) and matches[j] and matches[j].get("fe_mode") is not None)]
        return pool or list(range(len(self.b2)))

    def leading_weak(self) -> list[int]:
        """Modes 1..k, all weak (the contact group on their node line)."""
        out = []
        for j in range(len(self.b2)):
            if j not in self.weak:
                break
            out.append(j)
        return out

    def _main_family(self) -> tuple[int, dict] | None:
        """The family with the widest admissible arc (relative, in frequency), as the animations choose."""
        def width(item):
            i, fam = item
            return (max((a["f_hi"] - a["f_lo"]) / a["f_hi"] for a in fam["admissible_arcs"]),
                    fam.get("admissible_orbits", 0), -i)
        return max(self.with_arcs, key=width) if self.with_arcs else None

    def grown_from(self, f_lo: float, f_hi: float) -> int | None:
        """The mode (0-based) whose linear frequency is nearest (in ratio) to the middle of ``[f_lo, f_hi]``,
        among the modes the contact sees."""
        mid = math.sqrt(f_lo * f_hi)
        pool = [j for j in self.seen if self.f[j] > 0] or [j for j in range(len(self.f)) if self.f[j] > 0]
        return min(pool, key=lambda j: abs(math.log(mid / self.f[j]))) if pool else None

    def where(self, f_lo: float, f_hi: float, j: int, named: bool = True) -> str:
        """Where ``[f_lo, f_hi]`` lies relative to the linear frequency of mode ``j`` (``named``: say which, else
        ``it``)."""
        fj = self.f[j]
        lo, hi = f_lo / fj - 1, f_hi / fj - 1
        lin = f"the linear frequency of mode {j + 1}, {fj:.1f} Hz" if named else "it"
        if abs(lo) <= GRAZING_RTOL:
            return f"from grazing to {_pct(hi)} % above {lin}"
        if lo > 0:
            return f"{_pcts(lo, hi)} % above {lin}"
        if hi < 0:
            return f"{_pcts(-hi, -lo)} % below {lin}"
        return f"from {_pct(-lo)} % below to {_pct(hi)} % above {lin}"

    def range_words(self) -> str:
        a, b = self.periods
        unit = "s" if self.unit == "s" else f"× {self.unit}"
        secs = "" if self.unit == "s" else f" (= [{self.T_lo:.6g}, {self.T_hi:.6g}] s)"
        return f"[{a:g}, {b:g}] {unit}{secs}"

    def in_units(self, T: float) -> str:
        """A period in the study's period unit: ``1.0 T1``, ``0.00475 s``."""
        if self.unit == "s":
            return f"{T:.6g} s"
        v = f"{T / self.unit_s:.4g}"
        return f"{v}{'' if '.' in v or 'e' in v else '.0'} {self.unit}"

    def grazing_in_range(self) -> list[int]:
        """The modes the contact sees whose linear period lies in the searched range."""
        return [j for j in self.seen if self.f[j] > 0 and self.T_lo <= 1 / self.f[j] <= self.T_hi]

    def arcs(self, fam: dict) -> list[dict]:
        return fam.get("admissible_arcs") or []

    def phases(self, k: int) -> str:
        if self.massless:
            return "one contact phase per period" if k == 1 else f"{k} contact phases per period"
        return "one impact per period" if k == 1 else f"{k} impacts per period"

    # --- line 1: what was found

    def found(self) -> str:
        if self.main is not None:
            self.code("mode_found")
            i, fam = self.main
            text = self._family_words(fam)
            others = [(k, f) for k, f in self.with_arcs if k != i]
            if others:
                shown = "; ".join(f"family {k}, {self.phases(f['ipp'])}, {self._span_of(f)} Hz"
                                  for k, f in others[:3])
                text += (f"; and {_plural(len(others), 'more family', 'more families')} with admissible arcs ({shown}"
                         + (", …" if len(others) > 3 else "") + ")")
            return text + "."
        where = self.range_words()
        what = " or ".join(self.phases(k) for k in self.s["search"].get("ipp", [1]))
        if not self.fams:
            self.code("no_family_in_range")
            return (f"No nonsmooth mode in the searched periods {where}: the search found no family of orbits with "
                    f"{what} there.")
        self.code("no_admissible_orbit")
        ends = [x for f in self.fams for x in f.get("frequency_range_hz") or [] if x is not None]
        n_orbits = sum(f.get("orbits", 0) for f in self.fams)
        at = ""
        if ends:
            lo, hi = min(ends), max(ends)
            j = self.grown_from(lo, hi)
            at = f" at {_freq_span(lo, hi)} Hz" + (f", {self.where(lo, hi, j)}" if j is not None else "")
        text = (f"No admissible nonsmooth mode in the searched periods {where}: "
                f"{_plural(len(self.fams), 'family', 'families')} of orbits with {what}{at}, none of "
                f"{'its' if len(self.fams) == 1 else 'their'} {n_orbits} orbits admissible")
        why = self._inadmissible_words()
        return text + (f": {why}" if why else "") + "."

    def _span_of(self, fam: dict) -> str:
        arcs = self.arcs(fam)
        return _freq_span(min(a["f_lo"] for a in arcs), max(a["f_hi"] for a in arcs))

    def _family_words(self, fam: dict) -> str:
        """The main family in words: stiffening or softening, of which mode, its arcs' frequencies against that
        mode's linear frequency, tip amplitude, contact force (Newton: impulses), stable share."""
        arcs = self.arcs(fam)
        lo, hi = min(a["f_lo"] for a in arcs), max(a["f_hi"] for a in arcs)
        j = self.grown_from(lo, hi)
        kind = "stiffening" if j is None or math.sqrt(lo * hi) >= self.f[j] else "softening"
        head = f"A {kind} nonsmooth mode" + (f" of mode {j + 1}" if j is not None else "")
        words = [f"{head} ({self.phases(fam['ipp'])}): {_freq_span(lo, hi, ' → ')} Hz"
                 + (f" ({self.where(lo, hi, j)}" if j is not None else " (")
                 + (f"; admissible on {len(arcs)} separate arcs)" if len(arcs) > 1 else ")")]
        tips = [x for a in arcs for x in (a.get("tip_amplitude_range_mm") or []) if x is not None]
        if tips:
            words.append(f"tip amplitude {_range(min(tips), max(tips), 'mm')}")
        if self.massless:
            forces = [x for a in arcs for x in (a.get("contact_force_range_n") or []) if x is not None]
            if forces:
                words.append(f"contact force up to {_g(max(forces))} N")
        else:
            imp = [x for a in arcs for x in (a.get("contact_impulse_range_ns") or []) if x is not None]
            if imp:
                words.append(f"impulses up to {_g(max(imp))} N·s per impact")
        stable = self._stable_words(self.main[0], arcs)
        if stable:
            words.append(stable)
        return ", ".join(words)

    def _stable_words(self, index: int, arcs: list[dict]) -> str | None:
        """``stable over 47 % of its admissible orbits`` (exact from modes.json; from the arcs' shares when they
        agree or there is one arc; the range of the shares otherwise)."""
        fractions = [a.get("stable_fraction") for a in arcs if a.get("stable_fraction") is not None]
        exact = self._modes_stable(index)
        if exact is not None:
            share, n = exact
        elif fractions and max(fractions) == min(fractions):
            share, n = fractions[0], None
        elif fractions:
            if min(fractions) < 1:
                self.code("partly_unstable")
            return (f"linearly stable over {_pct(min(fractions))}–{_pct(max(fractions))} % of the orbits of each "
                    "admissible arc")
        else:
            return None
        if share < 1:
            self.code("partly_unstable")
        of = f" (of {n} with a Floquet verdict)" if n is not None and share < 1 else ""
        return f"linearly stable over {_pct(share)} % of its admissible orbits{of}"

    def _modes_stable(self, index: int) -> tuple[float, int] | None:
        fams = (self.modes or {}).get("families") or []
        if index >= len(fams):
            return None
        fam = fams[index]
        orbits = fam.get("orbits") or []
        on_arc = {j for a in fam.get("arcs") or [] for j in range(a["start"], a["stop"] + 1)}
        verdicts = [orbits[j].get("stable") for j in sorted(on_arc) if j < len(orbits) and isinstance(orbits[j], dict)]
        verdicts = [v for v in verdicts if v is not None]
        if not verdicts:
            return None
        return sum(bool(v) for v in verdicts) / len(verdicts), len(verdicts)

    def _inadmissible_words(self) -> str | None:
        """Why the families' orbits are not admissible, from modes.json: the casing would pull, the orbit crosses
        the casing (how far)."""
        fams = (self.modes or {}).get("families")
        if not fams:
            return None
        gap = float(self.s["contact"].get("clearance_m") or (self.modes or {}).get("gap") or 0)
        orbits = [o for f in fams for o in f.get("orbits") or [] if isinstance(o, dict) and "admissible" in o]
        bad = [o for o in orbits if not o["admissible"]]
        if not bad:
            return None
        pull = [o for o in bad if any(x < 0 for x in o.get("impulses") or [])]
        cross = [o for o in bad if o.get("max_violation") is not None and gap > 0
                 and o["max_violation"] > VIOLATION_RTOL * gap]

        def how_many(part: list) -> str:
            return f"all {len(bad)}" if len(part) == len(bad) else f"{len(part)} of the {len(bad)}"

        words = []
        if pull:
            self.code("casing_would_pull")
            what = "contact momentum ∫λ dt" if self.massless else "impulse"
            words.append(f"{how_many(pull)} need a pulling casing (a negative {what})")
        if cross:
            self.code("orbits_cross_casing")
            far = max(o["max_violation"] for o in cross)
            words.append(f"{how_many(cross)} cross the casing, by up to {_length(far)} ({far / gap:.3g} × the "
                         "clearance)")
        return "; ".join(words) or None

    # --- line 2: whether to trust it

    def trust(self) -> str:
        facts, doubts, limits = [], [], []
        bad = False
        if self.main is not None:
            if self.anims:
                bad |= self._checks_of_animations(facts, doubts)
            else:
                self.code("not_animated")
                ref = self.s.get("reference")
                words = rejected_words(self.s)
                if ref and words and ref["rejected"]:
                    self.code("reference_failed")
                    bad = True
                    facts_or_doubts = f"no orbit was animated: {words}"
                elif ref and words:
                    facts_or_doubts = f"no orbit was animated, so none was re-simulated; {words}"
                elif ref:
                    facts_or_doubts = (f"no orbit was animated, so none was re-simulated or checked in the reference "
                                       f"model {ref['method']} ({ref['reduced_dofs']} dofs) — this summary keeps no "
                                       "record of orbits the reference check rejected (run.log names them)")
                else:
                    facts_or_doubts = "no orbit was animated, so none was re-simulated"
                doubts.append(facts_or_doubts)
        self._reduced_vs_fe(facts, doubts)
        self._comparison(facts, doubts)
        self._tip(limits)
        body = "; ".join(facts + doubts)
        if self.main is None:
            head = "Nothing to verify (no admissible orbit)"
            text = head + (f"; {body}" if body else "")
        else:
            if bad:
                head = "Do not trust it yet"
            elif not self.anims:
                head = "Unchecked"
            elif doubts:
                head = "Trust it with care"
            else:
                head = "Trust it"
            text = f"{head}: {body}" if body else head
        text += "."
        if limits:
            text += " Limit: " + " ".join(limits)
        return text

    def _checks_of_animations(self, facts: list, doubts: list) -> bool:
        """The re-simulation and the reference-model check of the animated orbits; ``True`` when one failed."""
        bad = False
        n = len(self.anims)
        checks = [a.get("verification") or {} for a in self.anims]
        failed = [(a, c) for a, c in zip(self.anims, checks) if c and not c.get("ok", True)]
        errors = [c["return_error"] for c in checks if c.get("return_error") is not None]
        if failed:
            bad = True
            self.code("verification_failed")
            doubts += [f"the event-driven re-simulation of the orbit at T = {a['T']:.8g} s does not return to it "
                       f"(error {c.get('return_error', float('nan')):.2g})" for a, c in failed]
        elif errors:
            self.code("verified")
            facts.append(f"{'the animated orbit re-simulates' if n == 1 else f'the {n} animated orbits re-simulate'} "
                         f"event-driven back to {'itself' if n == 1 else 'themselves'} to {max(errors):.1e}")
        refs = [(a, a["reference_check"]) for a in self.anims if a.get("reference_check")]
        lost = [(a, c) for a, c in refs if not c.get("survives")]
        if lost:
            bad = True
            self.code("reference_failed")
            for a, c in lost:
                drift = c.get("drift")
                how = (c["reason"] if c.get("reason") else f"it drifts by {drift:.0%} in one period (energy norm)"
                       if drift is not None and math.isfinite(drift) else "it does not come back")
                contacts = "" if c.get("contacts") in (None, a.get("ipp")) else \
                    f", with {c['contacts']} contact(s) for {a.get('ipp')}"
                doubts.append(f"the orbit at T = {a['T']:.8g} s did not survive in the reference model "
                              f"{c.get('reference')}: {how}{contacts}")
        elif refs:
            self.code("reference_survived")
            worst = max(c.get("drift", 0.0) for _, c in refs)
            facts.append(f"{'it survives' if n == 1 else 'they survive'} in the reference model "
                         f"{refs[0][1]['reference']}, back within {worst:.2g} after one period (energy norm)")
        if not refs:
            if self.s.get("reference") is None:
                self.code("no_reference_check")
                doubts.append("no reference-model check ran ([output] reference = false)")
        return bad

    def artefact_modes(self) -> set[int]:
        """1-based reduced modes with no FE counterpart (not above the FE modes computed)."""
        return {j + 1 for j, m in enumerate(self.s["reduction"].get("fe_match") or [])
                if m and m.get("fe_mode") is None and not m.get("beyond_fe")}

    def _artefact_share(self, modes: set[int]) -> float | None:
        """The largest energy share the animated orbits hold in ``modes`` (their ``modal_energy.top_modes``;
        ``None`` without animated orbits)."""
        shares = [sum(t["share"] for t in (a.get("modal_energy") or {}).get("top_modes") or [] if t["mode"] in modes)
                  for a in self.anims if a.get("modal_energy")]
        return max(shares) if shares else None

    def _reduced_vs_fe(self, facts: list, doubts: list) -> None:
        r = self.s["reduction"]
        matches = r.get("fe_match")
        if matches is not None:
            pairs = [(j, m) for j, m in enumerate(matches) if m and m.get("fe_mode") is not None
                     and m.get("relative_error") is not None]
            artefacts = [(j, m) for j, m in enumerate(matches) if m and m.get("fe_mode") is None
                         and not m.get("beyond_fe")]
            if artefacts:
                self.code("reduced_model_artefacts")
                words = (f"reduced {_modes_words([j for j, _ in artefacts])} "
                         f"{'has' if len(artefacts) == 1 else 'have'} no FE counterpart (best MAC "
                         + ", ".join(f"{m['mac']:.2f}" for _, m in artefacts) + ")")
                share = self._artefact_share({j + 1 for j, _ in artefacts})
                if share is not None and share < ARTEFACT_SHARE:
                    facts.append(f"{words}, but {'it holds' if len(artefacts) == 1 else 'they hold'} under "
                                 f"{ARTEFACT_SHARE:.0%} of the animated orbits' energy")
                elif share is not None:
                    doubts.append(f"{words} and {'holds' if len(artefacts) == 1 else 'hold'} {share:.0%} of an "
                                  "animated orbit's energy: an artefact of the reduction")
                else:
                    (doubts if self.main is not None else facts).append(words)
            if not pairs:
                return
            j, worst = max(pairs, key=lambda p: abs(p[1]["relative_error"]))
            err = abs(worst["relative_error"])
            if err > FREQUENCY_RTOL:
                self.code("reduced_model_off_fe")
                doubts.append(f"reduced mode {j + 1} is {err:.1%} off its FE counterpart (FE mode {worst['fe_mode']})")
            else:
                self.code("reduced_model_matches_fe")
                facts.append(f"the reduced model's linear frequencies match the FE model's to {err:.1e} "
                             f"({_modes_words([p[0] for p in pairs])}, matched by mode shape)")
            return
        fe = (self.s.get("model") or {}).get("linear_frequencies_hz") or []
        errs = [e for e, f in zip(r.get("relative_error_vs_fe") or [], fe)
                if e is not None and self.f and f <= max(self.f) * (1 + FREQUENCY_RTOL)]
        if not errs:
            return
        err = max(errs)
        if err > FREQUENCY_RTOL:
            self.code("reduced_model_off_fe")
            doubts.append(f"the reduced model's frequencies are up to {err:.1%} off the FE model's (nearest frequency)")
        else:
            self.code("reduced_model_matches_fe")
            facts.append(f"the reduced model's linear frequencies match the FE model's to {err:.1e} (nearest "
                         f"frequency, {len(errs)} modes)")

    def comparison_rows(self) -> list[dict]:
        return [r for r in (self.s.get("comparison") or {}).get("rows") or [] if r.get("method") != "fe"]

    def scatter(self) -> tuple[str, float, float] | None:
        """The energy column where the compared models' energies spread most, if more than
        :data:`ENERGY_SCATTER`: ``(period, lowest, highest)``."""
        rows = self.comparison_rows()
        worst = None
        for col in [k for k in (rows[0] if rows else {}) if k.startswith("energy_")]:
            vals = [float(r[col]) for r in rows if r.get(col) not in (None, "")]
            if len(vals) >= 2 and max(vals) > 0 and (max(vals) - min(vals)) / max(vals) > ENERGY_SCATTER:
                spread = (max(vals) - min(vals)) / max(vals)
                if worst is None or spread > worst[0]:
                    label = col.removeprefix("energy_").removesuffix("_j").replace("T1", " T1")
                    worst = (spread, label, min(vals), max(vals))
        return None if worst is None else worst[1:]

    def _comparison(self, facts: list, doubts: list) -> None:
        rows = self.comparison_rows()
        if not rows:
            return
        verdicts = {}
        for r in rows:
            if r.get("convergence") and r["convergence"] != "n/a":
                verdicts.setdefault(r["method"], (r["convergence"], r))
        sizes = {}
        for r in rows:
            if r.get("size") is not None:
                sizes.setdefault(r["method"], []).append(r["size"])
        off = {m: v for m, (v, _) in verdicts.items() if str(v).startswith("not converged")}
        if off:
            self.code("comparison_not_converged")
            doubts += [f"the comparison's {m} models are {v}" + (
                f" between sizes {sorted(sizes[m])[-2]} and {sorted(sizes[m])[-1]}" if len(sizes.get(m, [])) >= 2
                else "") for m, v in off.items()]
        elif verdicts:
            self.code("comparison_converged")
            facts.append("the comparison grid converged (" + ", ".join(f"{m}: {v}" for m, (v, _) in verdicts.items())
                         + ")")
        others = rows[1:]  # the first row is the study's own model
        differ = [r["model"] for r in others if r.get("admissible_arcs") is not None
                  and (r["admissible_arcs"] > 0) != (self.main is not None)]
        if differ:
            self.code("models_disagree")
            found = "found no admissible arc" if self.main is not None else "found admissible arcs"
            doubts.append(f"of the {len(others)} compared models, {_and(differ)} {found} in the same periods")
        spread = self.scatter()
        if spread:
            self.code("energies_scatter")
            at, lo, hi = spread
            doubts.append(f"the compared models' energies at {at} range from {lo:.3g} to {hi:.3g} J")

    def _tip(self, limits: list) -> None:
        if self.main is None:
            return
        beyond = [a["tip_excursion"] for a in self.anims if (a.get("tip_excursion") or {}).get("nodes_beyond")]
        if not beyond:
            return
        self.code("tip_not_resolved")
        x = max(beyond, key=lambda t: t["node_max_m"])
        face = f" '{self.s['contact']['face']}'" if self.s["contact"].get("face") else ""
        mean = (f"where the mean goes {_length(x['mean_max_m'])}" if x.get("mean_max_m", 0) > 0
                else "while the mean stays within it")
        limits.append(f"the contact is the mean of the face{face}: {x['nodes_beyond']} of its {x['nodes']} nodes pass "
                      f"the clearance (node {x.get('node_id', x.get('node'))} by {_length(x['node_max_m'])} {mean}), "
                      "so where the tip rubs is not resolved"
                      + (" here — the mode with every node a contact is reported below." if self.s.get("nodal_modes")
                         else ' ([contact] points = "nodes" resolves it).'))

    # --- line 3: what to do next

    def next(self) -> str:
        steps = self._next_found() if self.main is not None else self._next_nothing()
        lead = self.leading_weak()
        if self.main is not None and lead:
            self.code("contact_on_node_line")
            steps.append(f"{_modes_words(lead)[0].upper()}{_modes_words(lead)[1:]} barely "
                         f"move{'s' if len(lead) == 1 else ''} the contact ({self._b2_words(lead)}): the contact "
                         "group is on their node line.")
        if not steps:
            steps.append("No check of this run calls for another run: the arc's tip amplitude and contact "
                         f"{'force' if self.massless else 'impulses'} above are its figures.")
        return " ".join(steps)

    def _grazing_words(self, idx: list[int]) -> str:
        """``the grazing energies ½ω²(d/b)² = 3.1e+04, 2.2e+05 J``: the energy at which each mode first touches."""
        d = float(self.s["contact"].get("clearance_m") or 0)
        vals = [0.5 * (2 * math.pi * self.f[j]) ** 2 * d * d / self.b2[j] for j in idx if self.b2[j] > 0]
        if not vals or d <= 0:
            return "far larger amplitudes"
        return ("grazing energ" + ("y" if len(vals) == 1 else "ies") + " ½ω²(d/b)² = "
                + ", ".join(f"{e:.2g}" for e in vals) + " J")

    def _b2_words(self, idx: list[int]) -> str:
        pool = self._b2_pool()
        big = max(pool, key=lambda j: self.b2[j]) if pool else None
        ref = f": {self.b2[big]:.2g}, mode {big + 1}" if big is not None else ""
        over = " over the modes matched to the FE model" if self.s["reduction"].get("fe_match") is not None else ""
        return (f"b² = {', '.join(f'{self.b2[j]:.2g}' for j in idx)}, below {WEAK_B2:g} × the largest{over}{ref}; "
                f"{self._grazing_words(idx)}")

    def _next_found(self) -> list[str]:
        steps = []
        s = self.s
        failed = [a for a in self.anims if (a.get("verification") or {}).get("ok") is False]
        if failed:
            steps.append("Find out why the orbit at T = " + ", ".join(f"{a['T']:.8g}" for a in failed)
                         + " s does not re-simulate before using the arc.")
        lost = [a for a in self.anims if a.get("reference_check") and not a["reference_check"].get("survives")]
        size = s["reduction"].get("size")
        grid = (f" (`[reduction] sizes = [{size}, {4 * size}]` compares them)" if isinstance(size, int) else "")
        if lost or (not self.anims and s.get("reference")):
            model = f"{s['reduction']['method']} {size}"
            if self._switch_advised(bool(lost)):
                at, lo, hi = self.scatter()
                tried = ("the orbits tried do not survive in the reference model" if lost else
                         rejected_words(s) or "no orbit was animated (none survived the reference check, unless "
                         "`[output] animate = 0`)")
                steps.append(f"With Newton's impact law the orbits depend on the reduced model here: {tried}, and "
                             f"the energies at {at} range from {lo:.3g} to {hi:.3g} J across the compared models; the "
                             "massless contact model ([contact] model = \"massless\", docs/massless.md) has no "
                             "impact law.")
            elif lost:
                what = ("the orbit" + ("s" if len(lost) > 1 else "") + " at T = "
                        + ", ".join(f"{a['T']:.8g}" for a in lost) + " s")
                steps.append(f"Treat {what} as {'an artefact' if len(lost) == 1 else 'artefacts'} of the {model} "
                             f"model until a larger model shows {'it' if len(lost) == 1 else 'them'}{grid}.")
            elif (words := rejected_words(s)) is not None and not s["reference"]["rejected"]:
                steps.append(f"No orbit was animated, so nothing confirms the arcs: {words}; set `[output] animate` "
                             "to check the arcs' orbits in the reference model.")
            else:
                tried = (f"{words}; " if words else "unless `[output] animate = 0`, every orbit tried failed the "
                         "reference check (run.log names them) and ")
                steps.append(f"No orbit was animated, so nothing confirms the arcs: {tried}the arcs are artefacts of "
                             f"the {model} model until a larger model shows them{grid}.")
        elif self.anims and s.get("reference") is None and not self.comparison_rows():
            steps.append("Check it in a larger model: `[output] reference = true` re-simulates the animated orbits in "
                         "a model four times larger" + (f", and `[reduction] sizes = [{size}, {4 * size}]` compares "
                                                        "two sizes" if isinstance(size, int) else "") + ".")
        steps += self._casing_or_narrow()
        steps += self._range_end()
        res = self.main[1].get("resonance")
        arcs = self.arcs(self.main[1])
        if res and min(a["f_lo"] for a in arcs) <= res["frequency_hz"] <= max(a["f_hi"] for a in arcs) * (
                1 + RESONANCE_NEAR):
            self.code("internal_resonance")
            fake = " (a mode with no FE counterpart)" if res["mode"] in self.artefact_modes() else ""
            steps.append(f"Read the backbone below {res['frequency_hz']:.1f} Hz: there the family's energy flows into "
                         f"mode {res['mode']}{fake} ({res['mode_frequency_hz']:.1f} Hz, {res['ratio']:.2f} × the "
                         "orbit's frequency, an internal resonance).")
        for d in [c for c in self.codes if c in ("reduced_model_off_fe", "comparison_not_converged")]:
            if d == "reduced_model_off_fe":
                steps.append("Enlarge `[reduction] size`: the reduced model misses the FE frequencies (above).")
            else:
                steps.append("Add a larger size to `[reduction] sizes` until the energies converge.")
        return steps

    def _switch_advised(self, lost: bool) -> bool:
        """Newton's law, a reference failure (or none animated) and energies that scatter across models."""
        ok = not self.massless and self.scatter() is not None and (lost or not self.anims)
        if ok:
            self.code("switch_contact_model")
        return ok

    def _casing_words(self) -> str | None:
        """The massless contact's stiffnesses, when the casing is as stiff as the contact (:data:`STIFF_CASING`)."""
        c = self.s["contact"]
        kc, k = c.get("contact_stiffness_n_per_m"), c.get("casing_stiffness_n_per_m")
        if not self.massless or not kc or (k is not None and k < STIFF_CASING * kc):
            return None
        blade = c.get("static_stiffness_n_per_m")
        blade_words = (f" ({kc / blade:.3g} × the blade's static stiffness at the contact, {blade:.3g} N/m)"
                       if blade else "")
        if k is None:
            head = (f"Against a rigid casing the closed contact is as stiff as the blade's own contact stiffness "
                    f"k_c = {kc:.3g} N/m{blade_words}")
        else:
            head = (f"The casing (k = {k:.3g} N/m) is {k / kc:.3g} × the blade's own contact stiffness "
                    f"k_c = {kc:.3g} N/m{blade_words}: the closed contact's stiffness, k_s = "
                    f"{c.get('series_stiffness_n_per_m') or kc:.3g} N/m, is set by k_c")
        return (head + ", a mesh-scale stiffness whose closed phase lies above the retained modes "
                "(docs/massless.md, \"A compliant casing\"). If the real casing or its abradable coating is softer, "
                "give its stiffness in `[contact] casing_stiffness`.")

    def widest(self) -> tuple[float, dict, dict] | None:
        arcs = [((a["f_hi"] - a["f_lo"]) / a["f_hi"], a, f) for _, f in self.with_arcs for a in self.arcs(f)
                if a["f_hi"] > 0]
        return max(arcs, key=lambda x: x[0]) if arcs else None

    def narrow_words(self) -> str | None:
        """The sentence on a narrow widest arc: where it and its family's other arcs lie relative to the linear
        frequency they grow from (both contact models)."""
        w = self.widest()
        if w is None or w[0] >= NARROW_RTOL:
            return None
        width, arc, fam = w
        arcs = self.arcs(fam)
        lo, hi = min(a["f_lo"] for a in arcs), max(a["f_hi"] for a in arcs)
        j = self.grown_from(lo, hi)
        n_adm, n = fam.get("admissible_orbits"), fam.get("orbits")
        counts = (f"; {n_adm} of the family's {n} orbits in the searched periods are admissible"
                  if n_adm is not None and n else "")
        if j is None:
            return f"the widest admissible arc spans {width:.1e} of its frequency{counts}"
        if len(arcs) == 1:
            text = f"the widest admissible arc spans {width:.1e} of its frequency, {self.where(lo, hi, j)}"
        else:
            text = (f"the widest admissible arc spans {width:.1e} of its frequency, "
                    f"{self.where(arc['f_lo'], arc['f_hi'], j)}; its family's {len(arcs)} arcs together lie "
                    f"{self.where(lo, hi, j, named=False)}")
        if abs(lo / self.f[j] - 1) <= GRAZING_RTOL and hi / self.f[j] - 1 < NARROW_RTOL:
            return (f"{text}: the mode is admissible only next to where it grows from the linear mode (grazing)"
                    f"{counts}; read its energies as those of a barely touching linear mode")
        return (f"{text}: the family is admissible only on "
                f"{'this narrow stretch' if len(arcs) == 1 else 'these narrow stretches'}{counts}")

    def _casing_or_narrow(self) -> list[str]:
        narrow = self.narrow_words()
        if narrow is None:
            return []
        self.code("narrow_arc")
        steps = [f"{narrow[0].upper()}{narrow[1:]}."]
        casing = self._casing_words()
        if casing:
            self.code("stiff_casing")
            steps.append(casing)
        return steps

    def _range_end(self) -> list[str]:
        i, fam = self.main
        arcs = self.arcs(fam)
        out = []
        if min(a["T_lo"] for a in arcs) <= self.T_lo * (1 + 1e-9):
            out.append(f"The arcs reach the lower end of the searched periods ({self.in_units(self.T_lo)}, the "
                       f"highest frequency {1 / self.T_lo:.1f} Hz): widen `[search] periods` below it to follow the "
                       "mode further.")
        top = max(arcs, key=lambda a: a["T_hi"])
        j = self.grown_from(top["f_lo"], top["f_hi"])
        near = j is not None and abs(top["f_lo"] / self.f[j] - 1) <= NARROW_RTOL
        if top["T_hi"] >= self.T_hi * (1 - 1e-9) and not near:
            out.append(f"The arcs reach the upper end of the searched periods ({self.in_units(self.T_hi)}) short of "
                       "grazing: widen `[search] periods` above it.")
        if out:
            self.code("arc_at_range_end")
        return out

    def _next_nothing(self) -> list[str]:
        steps = []
        inside = self.grazing_in_range()
        strong = [j for j in inside if j not in self.weak]
        if not inside:
            self.code("grazing_outside_range")
            steps.append(self._outside_words())
        elif not strong:
            self.code("contact_on_node_line")
            lead = self.leading_weak()
            seen_strong = [j for j in self.seen if j not in self.weak]
            target = (f"; the first mode it sees well is mode {seen_strong[0] + 1} ({self.f[seen_strong[0]]:.1f} Hz, "
                      f"b² = {self.b2[seen_strong[0]]:.2g}, linear period {self.in_units(1 / self.f[seen_strong[0]])})"
                      if seen_strong else "")
            node_line = (f"the contact group is on a node line of {_modes_words(lead)}" if lead else
                         "the contact barely moves in these modes")
            steps.append(f"The searched periods hold the linear period of {_modes_words(inside)} only, which the "
                         f"contact barely sees ({self._b2_words(inside)}): {node_line}{target}. Move the contact "
                         "off that node line, or search around the period of a mode it sees.")
        if self.fams and strong:
            casing = self._casing_words()
            if casing:
                self.code("stiff_casing")
                steps.append(casing)
        if not steps:
            self.code("no_reason_in_data")
            j = strong[0]
            what = "no family" if not self.fams else "no admissible orbit"
            known = ("the run's data give no further reason" if self.fams and self.modes else
                     "nothing in summary.json says why (run.log has the search's messages)")
            steps.append(f"The searched periods hold the linear period of mode {j + 1} "
                         f"({self.in_units(1 / self.f[j])}, {self.f[j]:.1f} Hz), which the contact sees "
                         f"(b² = {self.b2[j]:.2g}), yet the search found {what} there; {known}.")
        return steps

    def _outside_words(self) -> str:
        """Where the first linear period the contact sees lies relative to the searched range, and what to widen."""
        if self.T1 is None:
            return "The contact sees no mode of the reduced model (every contact weight b² is zero)."
        j = self.seen[0]
        T1 = self.T1
        at = self.in_units(T1)
        lin = f"The first linear period the contact sees, mode {j + 1}'s ({T1:.6g} s, {self.f[j]:.1f} Hz, {at})"
        a, b = self.periods
        one = T1 / (1.0 if self.unit == "s" else self.unit_s)
        if T1 > self.T_hi:
            where = f"lies above the searched periods (their upper end is {self.in_units(self.T_hi)})"
            wider = f"[{a:g}, {one * 1.001:.4g}]"
        else:
            where = f"lies below the searched periods (their lower end is {self.in_units(self.T_lo)})"
            wider = f"[{one * 0.9:.4g}, {b:g}]"
        others = "" if len(self.seen) == 1 else ", and no other mode's linear period lies in them"
        unit = "s" if self.unit == "s" else f"× {self.unit}"
        return (f"{lin} {where}{others}: a nonsmooth mode grows from a linear mode at grazing, its linear period. "
                f"Widen `[search] periods` to include {at} (e.g. {wider} {unit}).")

    def result(self) -> dict:
        found = self.found()
        trust = self.trust()
        nxt = self.next()
        return {"found": found, "trust": trust, "next": nxt, "reasons": list(self.codes)}
