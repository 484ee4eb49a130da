"""The report's words on a rotating blade: the operating speed and running clearance, and the Campbell diagram
(tracked frequencies, engine-order crossings, nonsmooth-mode bands and the speed ranges where an engine order
lies inside one) — written from the summary alone.

>>> lines = rotation_report({"speed_rad_s": 100.0, "speed_rpm": 954.9, "closure_m": 1e-5, "clearance_cold_m": 1e-4,
...                          "clearance_running_m": 9e-5, "axis": {"origin": [0, 0, 0], "direction": [1, 0, 0]}}, None)
>>> lines[3].split(":")[0]                       # no speed_unit in the summary: rpm
'- Operating speed 954.93 rpm (100 rad/s) about the axis (1, 0, 0) through (0, 0, 0) m'
>>> lines[4]
'- Running clearance 0.09 mm: cold clearance 0.1 mm, closed by 0.01 mm of centrifugal growth along the casing normal.'
"""

from __future__ import annotations

import math

#: rad/s per unit of each study speed unit (as :data:`bladecase.fe.rotation.SPEED_UNITS`, keyed by the study's
#: spelling).
_PER = {"rad/s": 1.0, "rpm": 2.0 * math.pi / 60.0, "hz": 2.0 * math.pi}


def unit_name(unit: str | None) -> str:
    """The study's speed unit as the words write it: ``"rpm"``, ``"rad/s"`` or ``"Hz"`` (default rpm)."""
    u = (unit or "rpm").lower()
    return {"hz": "Hz"}.get(u, u)


def to_unit(rad_s: float, unit: str | None) -> float:
    """A speed in rad/s in the study's unit.

    >>> round(to_unit(1800.0, "rpm"), 1), to_unit(1800.0, "rad/s")
    (17188.7, 1800.0)
    """
    return float(rad_s) / _PER[(unit or "rpm").lower()]


def speed_words(rad_s: float, unit: str | None) -> str:
    """A speed in the study's unit first and the other common one in brackets: rad/s → ``"1800 rad/s (17188.7
    rpm)"``, rpm → ``"17188.7 rpm (1800 rad/s)"``, Hz → ``"30 Hz (1800 rpm)"``.

    >>> speed_words(1800.0, "rad/s"), speed_words(1800.0, "rpm"), speed_words(20 * math.pi, "Hz")
    ('1800 rad/s (17188.7 rpm)', '17188.7 rpm (1800 rad/s)', '10 Hz (600 rpm)')
    """
    name = unit_name(unit)
    other = "rad/s" if name == "rpm" else "rpm"
    return f"{to_unit(rad_s, name):.6g} {name} ({to_unit(rad_s, other):.6g} {other})"


def _vec(v) -> str:
    return "(" + ", ".join(f"{x:.4g}" for x in v) + ")"


def rotation_report(rotation: dict | None, campbell: dict | None) -> list[str]:
    """Markdown lines for ``summary["rotation"]`` (the operating point) and ``summary["campbell"]``, speeds in the
    study's unit (``speed_unit``; rpm for a summary without one) with the other common unit in brackets."""
    lines: list[str] = []
    if rotation:
        unit = rotation.get("speed_unit", "rpm")
        lines += ["", "## Rotation", "",
                  f"- Operating speed {speed_words(rotation['speed_rad_s'], unit)} about the "
                  f"axis {_vec(rotation['axis']['direction'])} through {_vec(rotation['axis']['origin'])} m: every "
                  "result below is about the centrifugal state there (stress stiffening, spin softening; "
                  + _static_words(rotation) + ")."]
        if rotation.get("clearance_running_m") is not None:
            lines.append(f"- Running clearance {rotation['clearance_running_m'] * 1e3:.4g} mm: cold clearance "
                         f"{rotation['clearance_cold_m'] * 1e3:.4g} mm, closed by {rotation['closure_m'] * 1e3:.4g} "
                         "mm of centrifugal growth along the casing normal.")
    if campbell:
        lines += _campbell_lines(campbell)
    return lines


def _campbell_lines(c: dict) -> list[str]:
    unit = unit_name(c.get("speed_unit"))
    other = "rad/s" if unit == "rpm" else "rpm"
    w = c["speeds_rad_s"]
    tracked = c["tracked_frequencies_hz"]
    bands = c.get("bands") or [None] * len(w)
    notes = c.get("band_notes") or [None] * len(w)
    clear = c.get("running_clearance_m")
    lines = ["", "## Campbell diagram", "",
             f"{len(tracked)} modes followed by mode shape (MAC) over {len(w)} speeds"
             + (f", engine orders {', '.join(map(str, c['engine_orders']))}" if c["engine_orders"] else "")
             + ("; the nonsmooth-mode band is the range of frequencies of the admissible orbits at that speed "
                "(from grazing to the end of the arc), in `campbell.png` as a shaded band." if clear is not None
                else "; linear modes only (no contact, no nonsmooth-mode band)."), "",
             f"| speed ({unit}) | ({other}) | " + ("running clearance (mm) | " if clear is not None else "")
             + " | ".join(f"mode {j + 1} (Hz)" for j in range(len(tracked)))
             + (" | nonsmooth-mode band (Hz) |" if clear is not None else " |"),
             "|---:|---:|" + ("---:|" if clear is not None else "") + "---:|" * len(tracked)
             + ("---|" if clear is not None else "")]
    for s, x in enumerate(w):
        band = bands[s]
        words = (f"mode {band['mode'] + 1}: {band['low_hz']:.2f} – {band['high_hz']:.2f}"
                 + (" (cut at the small-displacement limit)" if band.get("cut") else
                    " (or more: the band reaches the edge of [search] periods)" if band.get("truncated") else "")
                 if band else notes[s] or "—")
        lines.append(f"| {to_unit(x, unit):.6g} | {to_unit(x, other):.6g} | "
                     + (f"{clear[s] * 1e3:.4g} | " if clear is not None else "")
                     + " | ".join(f"{f[s]:.2f}" for f in tracked) + (f" | {words} |" if clear is not None else " |"))
    if c["crossings"]:
        lines += ["", "Engine-order crossings: " + "; ".join(
            f"EO {x['engine_order']} × mode {x['mode'] + 1} at {speed_words(x['speed_rad_s'], unit)}, "
            f"{x['frequency_hz']:.2f} Hz" for x in c["crossings"]) + "."]
    low = [(s, j) for j, m in enumerate(c.get("link_mac", [])) for s, v in enumerate(m) if v < 0.8]
    if low:
        s, j = low[0]
        lines += ["", f"**Doubtful tracking:** mode {j + 1} changes shape between {speed_words(w[s - 1], unit)} and "
                  f"{speed_words(w[s], unit)} (MAC {c['link_mac'][j][s]:.2f} < 0.8): the modes may have swapped "
                  "there; add speeds in between."]
    lines += _cut_lines(c, unit)
    risks = c.get("risks") or []
    if risks:
        lines += ["", "**Contact-induced interaction risk:** " + "; ".join(
            f"engine order {r['engine_order']} lies inside the nonsmooth-mode band from "
            f"{_risk_speed(r, 'from', unit)} to {_risk_speed(r, 'to', unit)}" for r in risks)
            + " — there, the engine order can drive the blade onto its casing on a nonsmooth mode."]
    elif any(bands) and c["engine_orders"]:
        lines += ["", "No engine order enters a nonsmooth-mode band at the speeds computed (bands between speeds "
                  "interpolated linearly)."]
    return lines


def _cut_lines(c: dict, unit: str) -> list[str]:
    """Where and why the bands were cut at the small-displacement limit and at the elastic limit, speed by speed."""
    return _amplitude_cut_lines(c, unit) + _stress_cut_lines(c, unit)


def _stress_cut_lines(c: dict, unit: str) -> list[str]:
    """Where and why the bands were cut at ``[material] yield_strength``, speed by speed."""
    cuts = [(x, cut) for x, cut in zip(c["speeds_rad_s"], c.get("band_stress_cuts") or []) if cut]
    if not cuts:
        return []
    words = [f"at {speed_words(x, unit)}, "
             + (f"the band stops at {cut['high_hz']:.2f} Hz" if cut.get("high_hz") is not None else "no band is left")
             + f": {cut['reason']}" for x, cut in cuts]
    return ["", "**Bands cut at the elastic limit:** " + "; ".join(words) + ". Beyond, the blade yields: a "
            "linear-elastic model no longer holds, and the band's edge there is not a figure to quote."]


def _amplitude_cut_lines(c: dict, unit: str) -> list[str]:
    """Where and why the bands were cut at the small-displacement limit, speed by speed."""
    cuts = [(x, cut) for x, cut in zip(c["speeds_rad_s"], c.get("band_cuts") or []) if cut]
    if not cuts:
        return []
    words = [f"at {speed_words(x, unit)}, "
             + (f"the band stops at {cut['high_hz']:.2f} Hz" if cut.get("high_hz") is not None else "no band is left")
             + f": {cut['reason']}" for x, cut in cuts]
    return ["", "**Bands cut at the small-displacement limit:** " + "; ".join(words) + ". Beyond, the orbits move the "
            "tip further than a linear-elastic, small-displacement model of the blade can follow: the band's edge "
            "there is not a figure to quote."]


def _risk_speed(r: dict, end: str, unit: str) -> str:
    """A risk's end in words (a summary written before the risks carried rad/s: its rpm)."""
    rad_s = r.get(f"{end}_rad_s")
    return speed_words(rad_s, unit) if rad_s is not None else f"{r[f'{end}_rpm']:.6g} rpm"


def _static_words(rotation: dict) -> str:
    """Which centrifugal static state the results are about."""
    state, n = rotation.get("static_state"), rotation.get("static_iterations")
    if state == "nonlinear":
        return f"the geometrically nonlinear static state, {n} Newton iterations"
    if state == "second-order":
        return f"a second-order static state, {n} iterations"
    return "the linear static state"
