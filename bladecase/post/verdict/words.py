"""The verdict's vocabulary: its thresholds, its reason codes (:data:`REASONS`) and the helpers that put numbers
into words."""

from __future__ import annotations

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

#: A face node past the clearance by more than this fraction of it makes the face mean's figures doubtful (the
#: verdict's "Trust it" becomes "Trust it with care").
TIP_BEYOND_RTOL = 0.1

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
    "tip_not_resolved": "tip nodes pass the clearance the face's mean does not (animations[*].tip_excursion); by more "
                        "than TIP_BEYOND_RTOL of the clearance it is a doubt of the trust line",
    "mesh_converged": "every headline figure's mesh error estimate is within the flag (convergence.figures error)",
    "mesh_error_large": "a headline figure's mesh error estimate exceeds the flag, or it does not converge "
                        "monotonically over the meshes (convergence.flagged)",
    "mesh_error_unknown": "no [convergence] meshes: the figures' mesh error is not measured (summary convergence null)",
    "no_contact": "the study has no [contact]: linear modes and the Campbell diagram only, no nonsmooth mode "
                  "(summary contact null)",
    "band_to_tongue": "the main family's band and figures are read up to its first internal-resonance tongue "
                      "(admissible_arcs[*].tongue, backbone_f_hi)",
    "cut_at_amplitude_limit": "admissible arcs were cut where the tip amplitude exceeds [search] amplitude_limit × "
                              "the span (validity.cuts)",
    "cut_at_yield_strength": "admissible arcs were cut where an orbit's peak von Mises stress exceeds [material] "
                             "yield_strength (validity.stress_cuts)",
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
