"""The rotating blade in a study (``[rotation]``): the operating speed every later stage works at, the running
clearance, and the Campbell diagram with the nonsmooth-mode band at each speed.

* **Operating speed** (``[rotation] speed``, default the highest of ``speeds``): the FE model is linearised about
  its centrifugal state there (:func:`~bladecase.fe.rotation.spin`); the reduction, the nonsmooth modes and the
  forced response all use ``K(Ω)``.
* **Running clearance**: the centrifugal growth of the blade along the contact normal closes the clearance;
  ``[contact] clearance`` is the cold one unless ``clearance_at = "speed"``.  A clearance that closes is a
  clear error at the operating speed (with the speed at which the blade first touches), and an entry of the
  Campbell table at the other speeds (no band there).
* **Campbell diagram**: at every speed of ``speeds`` (one task per speed through the study's executor), the
  lowest modes of ``K(Ω)``, followed across speeds by MAC (:mod:`~bladecase.fe.campbell`), the engine orders and
  their crossings, and — unless ``bands = false`` — the reduced model and the nonsmooth-mode search of the study
  at that speed: the band of frequencies the admissible orbits span, from grazing to the end of the arc.  The
  report lists every speed range where an engine order lies inside a band (the contact-induced interaction
  risk).
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np

from ... import log
from ...fe.campbell import EXTRA_MODES, Campbell, from_modes, mac_sample, modes_at_speed
from ...fe.rotation import RotationAxis, SpinState, spin, to_rad_s
from ...post.rotation.report import speed_words, to_unit, unit_name
from ..schema import Study, StudyError

__all__ = ["band_risks", "campbell_stage", "operating_point", "rotation_axis", "running_clearance", "speeds"]


def _section(study: Study) -> dict | None:
    r = study.config.get("rotation")
    return r if r and (r.get("speeds") or r.get("speed") is not None) else None


def rotation_axis(study: Study, model=None) -> RotationAxis:
    """``[rotation] axis`` as a :class:`~bladecase.fe.rotation.RotationAxis`; with ``model``, checked against it:
    a 2-D (plane) model spins only about an axis perpendicular to its plane or in its plane through it
    (:meth:`~bladecase.fe.rotation.RotationAxis.check_plane`: a tilted axis, or one offset out of the plane, is a
    ``StudyError`` naming the axis and the valid ones, never silently flattened)."""
    axis = _section(study)["axis"]
    try:
        out = RotationAxis(axis["origin"], axis["direction"])
        if model is not None:
            out.check_plane(model.dim, float(np.abs(model.mesh.points).max(initial=0.0)))
        return out
    except ValueError as exc:
        raise StudyError(f"[rotation] axis: {exc}") from None


def speeds(study: Study) -> np.ndarray:
    """The Campbell speeds (rad/s, ascending, without repeats)."""
    r = _section(study)
    return np.unique([to_rad_s(v, r["speed_unit"]) for v in r["speeds"]])


def operating_speed(study: Study) -> float | None:
    """The speed (rad/s) of the study's analysis: ``[rotation] speed``, else the highest of ``speeds``; ``None``
    for a study at rest."""
    r = _section(study)
    if r is None:
        return None
    return to_rad_s(r["speed"] if r.get("speed") is not None else max(r["speeds"]), r["speed_unit"])


def running_clearance(study: Study, model, contact, state: SpinState, cold: bool | None = None) -> dict:
    """The contact's centrifugal closure at ``state``'s speed and the running clearance it leaves; ``contact.gap``
    is the cold clearance if ``cold`` (default: ``[contact] clearance_at = "cold"``), else the running one."""
    closure = float(contact.w(model) @ state.displacement)  # towards the casing: +
    cold = study["contact"].get("clearance_at", "cold") == "cold" if cold is None else cold
    given = float(contact.gap)
    running = given - closure if cold else given
    out = {"speed_rad_s": state.speed, "speed_rpm": state.speed * 60 / (2 * math.pi),
           "speed_unit": _section(study)["speed_unit"], "closure_m": closure,
           "clearance_cold_m": given if cold else given + closure, "clearance_running_m": running,
           "static_state": state.static, "static_iterations": state.iterations}
    if running <= 0 and closure > 0:  # the closure grows as Ω²: where the cold clearance is used up
        out["touches_at_rpm"] = out["speed_rpm"] * math.sqrt(out["clearance_cold_m"] / closure)
    return out


def operating_point(study: Study, model, contact, factor=None):
    """``(model, contact, factor, info)`` of the study's analysis: at rest unchanged (``info`` None); at speed the
    model with ``K(Ω)``, the contact at its running clearance, ``K(Ω)``'s factorisation and a summary.  Without a
    contact (``contact=None``: the modes and the Campbell diagram alone) the contact stays ``None`` and ``info``
    has no clearance.

    Raises
    ------
    StudyError
        The running clearance is closed at the operating speed (the message gives the speed at which the blade
        first touches its casing statically).
    """
    omega = operating_speed(study)
    if omega is None:
        return model, contact, factor, None
    axis = rotation_axis(study, model)
    try:
        state = spin(model, omega, axis, static=_section(study).get("static", "auto"))
    except ValueError as exc:
        raise StudyError(f"[rotation] speed: {exc}") from None
    unit = _section(study)["speed_unit"]
    if contact is None:
        info = {"speed_rad_s": state.speed, "speed_rpm": state.speed * 60 / (2 * math.pi), "speed_unit": unit,
                "static_state": state.static, "static_iterations": state.iterations}
        log.info("rotation: %s about %s through %s (no contact)", speed_words(omega, unit),
                 axis.direction.round(6).tolist(), axis.origin.tolist())
        return state.model, None, state.factor, info
    info = running_clearance(study, model, contact, state)
    if info["clearance_running_m"] <= 0:
        touch = to_unit(info.get("touches_at_rpm", float("nan")) * 2 * math.pi / 60, unit)
        raise StudyError(f"[rotation] speed: at {speed_words(omega, unit)} the blade's centrifugal growth along the "
                         f"contact normal ({info['closure_m'] * 1e3:.4g} mm) closes the clearance "
                         f"({info['clearance_cold_m'] * 1e3:.4g} mm cold): it touches its casing statically from "
                         f"about {touch:.6g} {unit_name(unit)}; lower the speed or widen "
                         "[contact] clearance (a clearance measured at speed, not cold: set [contact] clearance_at = "
                         "\"speed\")")
    log.info("rotation: %s about %s through %s; running clearance %.4g mm (cold %.4g mm, "
             "centrifugal closure %.4g mm)", speed_words(omega, unit), axis.direction.round(6).tolist(),
             axis.origin.tolist(), info["clearance_running_m"] * 1e3, info["clearance_cold_m"] * 1e3,
             info["closure_m"] * 1e3)
    hot = contact.closed_by(model, state.displacement) if info["clearance_cold_m"] == contact.gap \
        else dataclasses.replace(contact, gap=info["clearance_running_m"])  # clearance_at = "speed": as given
    return state.model, hot, state.factor, info


def _speed_point(omega: float, *, study: Study, model, contact, axis: RotationAxis, count: int,
                 bands: bool, sample: np.ndarray | None = None) -> dict:
    """One speed of the Campbell diagram (module level: an executor ships it to its workers); its mode shapes on
    the ``sample`` dofs only (:func:`~bladecase.fe.campbell.mac_sample`; ``None``: every dof)."""
    from ..stages import build_reduced, period_unit, search

    n = min(count + EXTRA_MODES, model.n_dofs - 1)
    state, phi, f = modes_at_speed(model, float(omega), axis, n, static=study["rotation"].get("static", "auto"))
    point = {"shapes": phi if sample is None else np.ascontiguousarray(phi[sample]), "frequencies_hz": f,
             "clearance": None if contact is None else running_clearance(study, model, contact, state, cold=True),
             "band_hz": None, "note": None, "cut": None, "stress_cut": None}
    if not bands or contact is None:
        return point
    d = point["clearance"]["clearance_running_m"]
    if d <= 0:
        point["note"] = "clearance closed: the blade rests on its casing"
        return point
    hot = contact.closed_by(model, state.displacement)  # the contact's clearance is the cold one here
    reduced = build_reduced(study, state.model, hot, factor=state.factor)
    families = search(study, reduced.system, label=speed_words(omega, study["rotation"]["speed_unit"]))
    families, point["cut"] = _cut_band(study, model, reduced, families)
    if study["material"].get("yield_strength") is not None:  # the elastic limit (study/stress_limit.py)
        from ..stress_limit import band_cut

        families, point["stress_cut"] = band_cut(reduced, families, float(study["material"]["yield_strength"]))
    arcs = [a for f in families for a in f.arcs]
    if arcs:
        point["band_hz"] = (min(1.0 / a.T_hi for a in arcs), max(1.0 / a.T_lo for a in arcs))
        unit, _ = period_unit(study, reduced.system)
        edge = 1.0 / (study["search"]["periods"][0] * unit)  # the highest frequency the search looks at
        if point["band_hz"][1] >= edge * (1 - 1e-6):
            point["note"] = "the band reaches the edge of [search] periods: it may extend beyond"
    elif point["cut"] is not None:
        point["note"] = (f"every admissible orbit moves the tip more than the small-displacement limit "
                         f"{point['cut']['limit_m'] * 1e3:.4g} mm")
    else:
        point["note"] = "no admissible orbit in [search] periods"
    return point


def _cut_band(study: Study, model, reduced, families: list) -> tuple[list, dict | None]:
    """The families with their arcs cut at the small-displacement limit (``[search] amplitude_limit`` × the span,
    :mod:`~bladecase.study.validity`), and where and why the band was cut (``None``: not cut): the limit, each
    cut's last orbit within it and first beyond, as frequencies and tip amplitudes."""
    from ..render import tip_amplitude
    from ..validity import blade_span, cut_arcs

    span = blade_span(model)
    fraction = study["search"]["amplitude_limit"]
    cut, cuts = cut_arcs(families, [functools.partial(tip_amplitude, reduced)] * len(families), fraction * span)
    if not cuts:
        return families, None
    rows = [{"family": c["family"], "f_beyond_hz": 1.0 / c["T_beyond"],
             "tip_amplitude_beyond_m": c["tip_amplitude_beyond"],
             "f_cut_hz": None if c["T_cut"] is None else 1.0 / c["T_cut"],
             "tip_amplitude_cut_m": c["tip_amplitude_cut"]} for c in cuts]
    return cut, {"limit_m": fraction * span, "span_m": span, "amplitude_limit": fraction, "cuts": rows}


def campbell_stage(study: Study, model, contact, executor, progress: bool = False) -> tuple[Campbell, dict]:
    """The Campbell diagram of the study (see the module): ``(campbell, summary section)``; the bands as
    ``summary["bands"]``, one entry per speed.  ``contact.gap`` is the cold clearance (with ``clearance_at =
    "speed"``, the running clearance at the operating speed plus the closure there: see :func:`operating_point`);
    ``contact=None``: the modes alone (no clearance, no band)."""
    r = _section(study)
    w = speeds(study)
    axis = rotation_axis(study, model)
    count = min(int(r.get("modes", 6)), model.n_dofs - 1)
    sample, M = mac_sample(model)  # a large model's shapes travel back on a sample of its dofs
    points = executor.map(_speed_point, list(w), shared={"study": study, "model": model, "contact": contact,
                                                         "axis": axis, "count": count,
                                                         "bands": bool(r.get("bands", True)) and contact is not None,
                                                         "sample": sample},
                          desc="speeds", progress=progress)
    c = from_modes(w, [p["shapes"] for p in points], [p["frequencies_hz"] for p in points], M, count,
                   r.get("engine_orders", []))
    bands = [p["band_hz"] for p in points]
    unit = r["speed_unit"]
    section = c.to_dict()
    section["axis"] = {"origin": axis.origin.tolist(), "direction": axis.direction.tolist()}
    section["speed_unit"] = unit_name(r["speed_unit"])
    section["speeds"] = [to_unit(x, r["speed_unit"]) for x in w]  # in the study's unit
    clear = [p["clearance"] or {} for p in points]
    section["running_clearance_m"] = [x.get("clearance_running_m") for x in clear] if contact is not None else None
    section["closure_m"] = [x.get("closure_m") for x in clear] if contact is not None else None
    section["bands"] = [None if b is None else {"mode": _rank0(c, s), "low_hz": b[0], "high_hz": b[1],
                                                "truncated": bool(points[s]["note"]),
                                                "cut": points[s]["cut"] is not None
                                                or points[s]["stress_cut"] is not None}
                        for s, b in enumerate(bands)]
    section["band_notes"] = [p["note"] for p in points]
    section["band_cuts"] = [_cut_words(p["cut"], b, unit, x) for p, b, x in zip(points, bands, w)]
    section["band_stress_cuts"] = [_stress_cut_words(p["stress_cut"], b, unit, x) for p, b, x in zip(points, bands, w)]
    for s, (cut, stress) in enumerate(zip(section["band_cuts"], section["band_stress_cuts"])):
        for x in (cut, stress):
            if x is not None:
                x["mode"] = _rank0(c, s)  # the band's mode (0-based), as in "bands"
    section["risks"] = band_risks(w, bands, section["engine_orders"])
    if c.uncertain_links:
        s, j = c.uncertain_links[0]
        log.warning("Campbell: mode %d is followed from %s to %s with a MAC of %.2f only: add speeds between them",
                    j + 1, speed_words(w[s - 1], unit), speed_words(w[s], unit), c.link_mac[s, j])
    for risk in section["risks"]:
        log.warning("engine order %d lies inside the nonsmooth-mode band from %s to %s: contact-induced "
                    "interaction risk", risk["engine_order"], speed_words(risk["from_rad_s"], unit),
                    speed_words(risk["to_rad_s"], unit))
    return c, section


def _cut_words(cut: dict | None, band: tuple | None, unit: str, omega: float) -> dict | None:
    """One speed's entry of ``summary["campbell"]["band_cuts"]``: the band's cut at the small-displacement limit
    (where: the band's new upper edge, the first frequency beyond; why: the tip amplitude there against the limit),
    logged; ``None`` where the band was not cut."""
    if cut is None:
        return None
    beyond = min(cut["cuts"], key=lambda c: c["f_beyond_hz"])  # the lowest frequency beyond the limit
    out = dict(cut, high_hz=None if band is None else band[1], f_beyond_hz=beyond["f_beyond_hz"],
               tip_amplitude_beyond_m=beyond["tip_amplitude_beyond_m"],
               reason=f"the tip amplitude reaches {beyond['tip_amplitude_beyond_m'] * 1e3:.4g} mm at "
                      f"{beyond['f_beyond_hz']:.2f} Hz, beyond the small-displacement limit "
                      f"{cut['limit_m'] * 1e3:.4g} mm ({100 * cut['amplitude_limit']:g} % of the "
                      f"{cut['span_m'] * 1e3:.4g} mm span, [search] amplitude_limit)")
    where = (f"its upper edge stops at {band[1]:.2f} Hz" if band is not None
             else "no admissible orbit is within the limit: no band")
    log.warning("Campbell at %s: the nonsmooth-mode band is cut at the small-displacement limit: %s; %s",
                speed_words(omega, unit), where, out["reason"])
    return out


def _stress_cut_words(cut: dict | None, band: tuple | None, unit: str, omega: float) -> dict | None:
    """One speed's entry of ``summary["campbell"]["band_stress_cuts"]``: the band's cut at ``[material]
    yield_strength`` (:func:`~bladecase.study.stress_limit.band_cut`) with its new upper edge and the reason in
    words, logged; ``None`` where the band was not cut there."""
    if cut is None:
        return None
    point = ", ".join(f"{x:.4g}" for x in cut["at_mm"])
    out = dict(cut, high_hz=None if band is None else band[1],
               reason=f"the peak von Mises stress reaches {cut['von_mises_beyond_pa'] / 1e6:.4g} MPa at "
                      f"{cut['f_beyond_hz']:.2f} Hz (at ({point}) mm), above the yield strength "
                      f"{cut['yield_strength_pa'] / 1e6:.4g} MPa ([material] yield_strength)")
    where = (f"its upper edge stops at {band[1]:.2f} Hz" if band is not None
             else "no admissible orbit is within the limit: no band")
    log.warning("Campbell at %s: the nonsmooth-mode band is cut at the elastic limit: %s; %s",
                speed_words(omega, unit), where, out["reason"])
    return out


def _rank0(c: Campbell, s: int) -> int:
    """The tracked mode that is the lowest at speed ``s`` (the band's mode: [search] periods are in T1)."""
    return int(np.flatnonzero(c.rank[s] == 0)[0]) if (c.rank[s] == 0).any() else 0


def band_risks(speeds_rad_s: np.ndarray, bands: list, engine_orders, samples: int = 2001) -> list[dict]:
    """Speed ranges (rad/s, and rpm rounded to 0.1) where an engine order's frequency ``N Ω / 2π`` lies inside the
    band (``(low, high)`` Hz per speed, ``None`` where there is none), the band's edges interpolated linearly
    between speeds.

    >>> band_risks(np.array([0.0, 100.0]), [(10.0, 11.0), (15.0, 17.0)], [1])
    [{'engine_order': 1, 'from_rad_s': 91.65, 'to_rad_s': 100.0, 'from_rpm': 875.2, 'to_rpm': 954.9}]
    """
    w = np.asarray(speeds_rad_s, dtype=float)
    have = np.array([b is not None for b in bands])
    if w.size < 1 or not have.any():
        return []
    grid = np.linspace(w[0], w[-1], samples) if w.size > 1 else w
    lo = np.array([b[0] if b is not None else np.nan for b in bands])
    hi = np.array([b[1] if b is not None else np.nan for b in bands])
    out = []
    for n in engine_orders:
        f = n * grid / (2 * math.pi)
        low, high = np.interp(grid, w, lo), np.interp(grid, w, hi)
        # no band between two speeds where one of them has none
        gap = np.interp(grid, w, (~have).astype(float)) > 0
        inside = (f >= low) & (f <= high) & ~gap & np.isfinite(low)
        edges = np.flatnonzero(np.diff(np.r_[False, inside, False].astype(int)))
        for a, b in zip(edges[::2], edges[1::2] - 1):
            out.append({"engine_order": int(n), "from_rad_s": round(float(grid[a]), 4),
                        "to_rad_s": round(float(grid[b]), 4),
                        "from_rpm": round(float(grid[a]) * 60 / (2 * math.pi), 1),
                        "to_rpm": round(float(grid[b]) * 60 / (2 * math.pi), 1)})
    return out
