"""The report's words on a rotating blade: the operating speed and running clearance, and the Campbell diagram
(tracked frequencies, engine-order crossings, nonsmooth-mode bands and the speed ranges where an engine order
lies inside one) — written from the summary alone.

>>> lines = rotation_report({"speed_rad_s": 100.0, "speed_rpm": 954.9, "closure_m": 1e-5, "clearance_cold_m": 1e-4,
...                          "clearance_running_m": 9e-5, "axis": {"origin": [0, 0, 0], "direction": [1, 0, 0]}}, None)
>>> lines[3].split(":")[0]
'- Operating speed 954.9 rpm (100 rad/s) about the axis (1, 0, 0) through (0, 0, 0) m'
>>> lines[4]
'- Running clearance 0.09 mm: cold clearance 0.1 mm, closed by 0.01 mm of centrifugal growth along the casing normal.'
"""

from __future__ import annotations


def _vec(v) -> str:
    return "(" + ", ".join(f"{x:.4g}" for x in v) + ")"


def rotation_report(rotation: dict | None, campbell: dict | None) -> list[str]:
    """Markdown lines for ``summary["rotation"]`` (the operating point) and ``summary["campbell"]``."""
    lines: list[str] = []
    if rotation:
        lines += ["", "## Rotation", "",
                  f"- Operating speed {rotation['speed_rpm']:.6g} rpm ({rotation['speed_rad_s']:.6g} rad/s) about the "
                  f"axis {_vec(rotation['axis']['direction'])} through {_vec(rotation['axis']['origin'])} m: every "
                  "result below is about the centrifugal state there (stress stiffening, spin softening; "
                  + _static_words(rotation) + ").",
                  f"- Running clearance {rotation['clearance_running_m'] * 1e3:.4g} mm: cold clearance "
                  f"{rotation['clearance_cold_m'] * 1e3:.4g} mm, closed by {rotation['closure_m'] * 1e3:.4g} mm of "
                  "centrifugal growth along the casing normal."]
    if campbell:
        lines += _campbell_lines(campbell)
    return lines


def _campbell_lines(c: dict) -> list[str]:
    rpm = c["speeds_rpm"]
    tracked = c["tracked_frequencies_hz"]
    bands = c.get("bands") or [None] * len(rpm)
    notes = c.get("band_notes") or [None] * len(rpm)
    lines = ["", "## Campbell diagram", "",
             f"{len(tracked)} modes followed by mode shape (MAC) over {len(rpm)} speeds"
             + (f", engine orders {', '.join(map(str, c['engine_orders']))}" if c["engine_orders"] else "")
             + "; the nonsmooth-mode band is the range of frequencies of the admissible orbits at that speed "
             "(from grazing to the end of the arc), in `campbell.png` as a shaded band.", "",
             "| speed (rpm) | running clearance (mm) | " + " | ".join(f"mode {j + 1} (Hz)" for j in range(len(tracked)))
             + " | nonsmooth-mode band (Hz) |",
             "|---:|---:|" + "---:|" * len(tracked) + "---|"]
    for s, w in enumerate(rpm):
        band = bands[s]
        words = (f"mode {band['mode'] + 1}: {band['low_hz']:.2f} – {band['high_hz']:.2f}"
                 + (" (or more: the band reaches the edge of [search] periods)" if band.get("truncated") else "")
                 if band else notes[s] or "—")
        lines.append(f"| {w:.6g} | {c['running_clearance_m'][s] * 1e3:.4g} | "
                     + " | ".join(f"{f[s]:.2f}" for f in tracked) + f" | {words} |")
    if c["crossings"]:
        lines += ["", "Engine-order crossings: " + "; ".join(
            f"EO {x['engine_order']} × mode {x['mode'] + 1} at {x['speed_rad_s'] * 30 / 3.141592653589793:.5g} rpm "
            f"({x['frequency_hz']:.2f} Hz)" for x in c["crossings"]) + "."]
    low = [(s, j) for j, m in enumerate(c.get("link_mac", [])) for s, v in enumerate(m) if v < 0.8]
    if low:
        s, j = low[0]
        lines += ["", f"**Doubtful tracking:** mode {j + 1} changes shape between {rpm[s - 1]:.6g} and {rpm[s]:.6g} "
                  f"rpm (MAC {c['link_mac'][j][s]:.2f} < 0.8): the modes may have swapped there; add speeds in "
                  "between."]
    risks = c.get("risks") or []
    if risks:
        lines += ["", "**Contact-induced interaction risk:** " + "; ".join(
            f"engine order {r['engine_order']} lies inside the nonsmooth-mode band from {r['from_rpm']:.6g} to "
            f"{r['to_rpm']:.6g} rpm" for r in risks) + " — there, the engine order can drive the blade onto its "
            "casing on a nonsmooth mode."]
    elif any(bands) and c["engine_orders"]:
        lines += ["", "No engine order enters a nonsmooth-mode band at the speeds computed (bands between speeds "
                  "interpolated linearly)."]
    return lines


def _static_words(rotation: dict) -> str:
    """Which centrifugal static state the results are about."""
    state, n = rotation.get("static_state"), rotation.get("static_iterations")
    if state == "nonlinear":
        return f"the geometrically nonlinear static state, {n} Newton iterations"
    if state == "second-order":
        return f"a second-order static state, {n} iterations"
    return "the linear static state"
