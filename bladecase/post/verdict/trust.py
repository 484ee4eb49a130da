"""The verdict's second line: whether to trust it, and why (:class:`_Trust`)."""

from __future__ import annotations

import math

from .base import _Base
from .words import (
    ARTEFACT_SHARE,
    ENERGY_SCATTER,
    FREQUENCY_RTOL,
    TIP_BEYOND_RTOL,
    _and,
    _length,
    _modes_words,
    _pct,
    rejected_words,
)


class _Trust(_Base):
    """The checks that ran and what they say."""

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
        self._nodal_checks(facts)
        self._reduced_vs_fe(facts, doubts)
        self._comparison(facts, doubts)
        self._mesh(facts, doubts)
        self._tip(limits, doubts)
        self._small_displacements(limits)
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
            self._frequencies(err, f"reduced mode {j + 1} is {err:.1%} off its FE counterpart (FE mode "
                              f"{worst['fe_mode']})", f"the reduced model's linear frequencies match the FE model's "
                              f"to {err:.1e} ({_modes_words([p[0] for p in pairs])}, matched by mode shape)",
                              doubts, facts)
            return
        fe = (self.s.get("model") or {}).get("linear_frequencies_hz") or []
        errs = [e for e, f in zip(r.get("relative_error_vs_fe") or [], fe)
                if e is not None and self.f and f <= max(self.f) * (1 + FREQUENCY_RTOL)]
        if not errs:
            return
        err = max(errs)
        self._frequencies(err, f"the reduced model's frequencies are up to {err:.1%} off the FE model's (nearest "
                          "frequency)", f"the reduced model's linear frequencies match the FE model's to {err:.1e} "
                          f"(nearest frequency, {len(errs)} modes)", doubts, facts)

    def _frequencies(self, err: float, off: str, match: str, doubts: list, facts: list) -> None:
        """The reduced model's frequency check: ``off`` a doubt beyond ``FREQUENCY_RTOL``, else ``match`` a fact."""
        if err > FREQUENCY_RTOL:
            self.code("reduced_model_off_fe")
            doubts.append(off)
        else:
            self.code("reduced_model_matches_fe")
            facts.append(match)

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

    def _nodal_checks(self, facts: list) -> None:
        """The checks of the animated orbit of the mode with every face node a contact."""
        for a in (self.s.get("files") or {}).get("nodal_animations") or []:
            ref = a.get("reference_check") or {}
            facts.append(f"the animated every-node orbit ({a['nodes_touching']} nodes touching) re-simulates back to "
                         f"itself to {a['verification']['return_error']:.1e}"
                         + (f" and survives in {ref['reference']} ({ref['drift']:.1e})" if ref.get("drift") is not None
                            else ""))

    def _mesh(self, facts: list, doubts: list) -> None:
        """The mesh error of the headline figures, measured by ``[convergence]`` (else only a reason code)."""
        c = self.s.get("convergence")
        if not c:
            self.code("mesh_error_unknown")
            return
        meshes = ", ".join(f"×{h:.4g}" for h in c["meshes"])
        figures = c["figures"]
        if c["flagged"]:
            self.code("mesh_error_large")
            said = [f"{figures[k]['words']} {_pct(figures[k]['error'])} %"
                    + ("" if figures[k]["monotone"] else " (not monotone)") for k in c["flagged"]]
            doubts.append(f"on meshes {meshes} the study's mesh is off the mesh-converged value by {_and(said)}")
        else:
            self.code("mesh_converged")
        fine = [f"{f['words']} {_pct(f['error'])} %" for f in figures.values() if not f["flag"]]
        if fine:
            facts.append(f"the mesh error (Richardson over meshes {meshes}) of {_and(fine)}")

    def _small_displacements(self, limits: list) -> None:
        v = self.s.get("validity") or {}
        if v.get("stress_cuts"):
            self.code("cut_at_yield_strength")
            limits.append(f"{'t' if not limits else 'T'}he arcs end where the peak von Mises stress exceeds the "
                          f"yield strength, {v['yield_strength_pa'] / 1e6:.4g} MPa: beyond, the blade yields and a "
                          "linear-elastic model does not hold.")
        if not v.get("cuts"):
            return
        self.code("cut_at_amplitude_limit")
        limits.append(f"{'t' if not limits else 'T'}he arcs end where the tip moves more than {_length(v['limit_m'])} "
                      f"({100 * v['amplitude_limit']:g} % of the span): beyond, a linear-elastic small-displacement "
                      "model does not hold.")

    def _tip(self, limits: list, doubts: list) -> None:
        """The face mean's own limit: nodes of the face beyond the clearance. Past :data:`TIP_BEYOND_RTOL` of the
        clearance it is a doubt too — the contact model the figures come from is not the rub that happens."""
        if self.main is None:
            return
        beyond = [a["tip_excursion"] for a in self.anims if (a.get("tip_excursion") or {}).get("nodes_beyond")]
        if not beyond:
            return
        self.code("tip_not_resolved")
        x = max(beyond, key=lambda t: t["node_max_m"])
        clearance = self.s["contact"].get("clearance_m")
        if clearance and x["node_max_m"] > TIP_BEYOND_RTOL * clearance:
            doubts.append(f"the face mean's contact is not the tip's: a node passes the clearance by "
                          f"{_length(x['node_max_m'])}, {_pct(x['node_max_m'] / clearance)} % of it (limit below)")
        face = f" '{self.s['contact']['face']}'" if self.s["contact"].get("face") else ""
        mean = (f"where the mean goes {_length(x['mean_max_m'])}" if x.get("mean_max_m", 0) > 0
                else "while the mean stays within it")
        limits.append(f"the contact is the mean of the face{face}: {x['nodes_beyond']} of its {x['nodes']} nodes pass "
                      f"the clearance (node {x.get('node_id', x.get('node'))} by {_length(x['node_max_m'])} {mean}), "
                      "so where the tip rubs is not resolved"
                      + (" here — the mode with every node a contact is reported below." if self.s.get("nodal_modes")
                         else ' ([contact] points = "nodes" resolves it).'))

    # --- line 3: what to do next
