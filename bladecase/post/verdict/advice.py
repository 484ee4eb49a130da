"""The verdict's third line: what to do next, with the reason computed from the run (:class:`_Next`)."""

from __future__ import annotations

import math

from .base import _Base
from .words import (
    GRAZING_RTOL,
    NARROW_RTOL,
    RESONANCE_NEAR,
    STIFF_CASING,
    WEAK_B2,
    _length,
    _modes_words,
    rejected_words,
)


class _Next(_Base):
    """What to do next."""

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
        v = self.s.get("validity") or {}
        if self.fams and v.get("cuts") and not steps:
            steps.append(f"Every admissible orbit found moves the tip more than {_length(v['limit_m'])} "
                         f"({100 * v['amplitude_limit']:g} % of the span), where the linear-elastic, small-"
                         "displacement model no longer holds: this mode exists here only at amplitudes the model "
                         "cannot follow. A larger limit (`[search] amplitude_limit`) is for a blade that really "
                         "moves that far elastically.")
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
