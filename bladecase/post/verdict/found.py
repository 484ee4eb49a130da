"""The verdict's first line: what was found (:class:`_Found`)."""

from __future__ import annotations

import math

from .base import _Base
from .words import VIOLATION_RTOL, _freq_span, _g, _length, _pct, _plural, _range


class _Found(_Base):
    """What the run found, in one sentence."""

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
        v = self.s.get("validity") or {}
        if v.get("stress_cuts"):  # admissible orbits, but all beyond the elastic limit
            self.code("cut_at_yield_strength")
            return (f"No admissible nonsmooth mode within the elastic limit in the searched periods {where}: "
                    f"{_plural(len(self.fams), 'family', 'families')} of orbits with {what}{at}, whose admissible "
                    f"orbits all stress the blade beyond its yield strength, "
                    f"{v['yield_strength_pa'] / 1e6:.4g} MPa (peak von Mises).")
        if v.get("cuts"):  # admissible orbits, but all beyond the small-displacement limit
            self.code("cut_at_amplitude_limit")
            return (f"No admissible nonsmooth mode within the small-displacement limit in the searched periods "
                    f"{where}: {_plural(len(self.fams), 'family', 'families')} of orbits with {what}{at}, whose "
                    f"admissible orbits all move the tip more than {_length(v['limit_m'])} "
                    f"({100 * v['amplitude_limit']:g} % of the span).")
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
        tongue = next((a["tongue"] for a in sorted(arcs, key=lambda a: a["f_lo"]) if a.get("tongue")), None)
        if tongue is not None:  # the band an engineer can quote ends where the tongue starts
            self.code("band_to_tongue")
            hi = max(a.get("backbone_f_hi", a["f_lo"]) for a in arcs)
        j = self.grown_from(lo, hi)
        kind = "stiffening" if j is None or math.sqrt(lo * hi) >= self.f[j] else "softening"
        head = f"A {kind} nonsmooth mode" + (f" of mode {j + 1}" if j is not None else "")
        words = [f"{head} ({self.phases(fam['ipp'])}): {_freq_span(lo, hi, ' → ')} Hz"
                 + (f" ({self.where(lo, hi, j)}" if j is not None else " (")
                 + (f"; admissible on {len(arcs)} separate arcs)" if len(arcs) > 1 else ")")]
        if tongue is not None:
            top = max(a["f_hi"] for a in arcs)
            words[0] += (f" up to the tongue of the internal resonance {round(tongue['ratio'])}:1 with mode "
                         f"{tongue['mode']} ({tongue['mode_frequency_hz']:.5g} Hz) at {tongue['frequency_hz']:.5g} Hz, "
                         f"whose place moves with the mesh (the arc runs on in it to {top:.5g} Hz; its figures are "
                         "not quoted)")
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
