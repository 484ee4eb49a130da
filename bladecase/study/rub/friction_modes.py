"""The first mode with friction at each ``[rub]`` speed (``[contact] friction`` ``mode_amplitudes``): its frequency and
damping ratio against the amplitude by the extended periodic motion concept (a term ``−ξMx′`` balances what friction
and damping take over a period; ``ζ = ξ/2ω``), each checked by the free decay from its orbit's start without the
term; their part of the summary (``rub.friction.modes``), the log, ``friction_modes.csv`` and
``friction_modes.png``.

The amplitudes are multiples of the first mode's grazing amplitude at that speed (the open mode's amplitude at which
its nearest tip node reaches the casing), given at the turning point. The casing slides past each node at ``ΩR``: the
rotation model flies the mode with the friction force along it (:func:`~bladecase.nsm.massless.friction_modes.
friction_mode`), the stick–slip model with each node's sliding speed ``ΩR`` (:func:`~bladecase.nsm.massless.
friction_modes_coulomb.coulomb_mode`).

>>> import numpy as np
>>> from bladecase.nsm import Damping
>>> from bladecase.nsm.massless import Friction, NodalSystem
>>> s = NodalSystem(np.eye(2), np.array([[1.0, 0.2], [0.2, 2.5]]), np.array([[1.0], [0.3]]), [[0.02]], gap=[1.0])
>>> f = Friction(0.15, T=np.array([[0.2], [1.0]]), radius=[1.0])
>>> out = mode_points(s, f, 50.0, [1.3], Damping(zeta=0.01))
>>> p = out["points"][0]
>>> round(p["frequency_hz"] / out["open_hz"], 4), round(p["zeta"], 5)       # stiffened, and friction takes less
(1.1709, 0.00866)
>>> round(p["decay_error"], 3)            # the free decay: friction works on a decaying orbit, not on a balanced one
-0.023
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from ... import log
from ...io import csv_cell, save_figure, write_text
from ...nsm.massless.friction import Friction
from ...nsm.massless.friction_modes import decay_ratio, friction_mode, harmonic_amplification
from ...nsm.massless.friction_modes_coulomb import coulomb_decay_ratio, coulomb_mode
from ...nsm.massless.nodes import NodalSystem

__all__ = ["DECAY_RTOL", "INTERNAL_GAIN", "INTERNAL_SHARE", "MODE_COLUMNS", "log_friction_modes", "mode_points",
           "modes_section", "write_friction_modes"]

#: The concept's ratio and the free decay's agree to this (relative) or the report says the mode is doubtful there
#: (friction works on a decaying orbit and not on the balanced one: a few per cent apart on small examples; on the
#: demo blade's tip within 0.2 %).
DECAY_RTOL = 0.05

#: A higher mode answering one of the orbit's harmonics this many times over (dynamic amplification) and holding at
#: least :data:`INTERNAL_SHARE` of the orbit's modal energy makes the mode an internal resonance: the report says the
#: figures are not a single nonlinear mode's.
INTERNAL_GAIN = 10.0
INTERNAL_SHARE = 1e-3

#: The columns of ``friction_modes.csv``: name → what it holds.
MODE_COLUMNS = {
    "speed": "the speed, in the study's unit",
    "speed_rad_s": "the speed (rad/s)",
    "amplitude_ratio": "the first mode's amplitude at its turning point over its grazing amplitude at this speed",
    "tip_amplitude_mm": "the open mode's largest normal tip displacement at that amplitude (mm)",
    "frequency_hz": "the mode's frequency with contact and friction (Hz)",
    "frequency_shift": "its change from the open first mode's frequency (relative)",
    "zeta": "the mode's damping ratio with contact and friction (extended periodic motion concept)",
    "structural_zeta": "the open first mode's damping ratio ([rub] ratio or rayleigh)",
    "decay_zeta": "the damping ratio of the free decay from the orbit's start, without the balancing term (the check)",
    "decay_error": "decay_zeta / zeta − 1",
    "residual": "the orbit's closing residual relative to its amplitude",
    "converged": "whether the orbit closed",
    "internal_mode": "the higher mode (1 = the first) that answers one of the orbit's harmonics most, if at least "
                     "INTERNAL_GAIN-fold (an internal resonance), else empty",
    "internal_harmonic": "that harmonic of the orbit",
    "internal_gain": "its dynamic amplification",
    "seconds": "CPU seconds of the mode and its check",
}


def mode_points(system: NodalSystem, friction: Friction, speed: float, ratios, damping) -> dict:
    """The first mode of ``system`` with ``friction`` at ``speed`` (rad/s) at the amplitudes ``ratios`` × its grazing
    amplitude (each from the one before), with the free decay's ratio: ``{"open_hz", "structural_zeta",
    "grazing_tip_m", "points": [...]}``, a point ``{"amplitude_ratio", "tip_amplitude_m", "frequency_hz", "zeta",
    "decay_zeta", "decay_error", "residual", "converged", "seconds"}`` or ``{"amplitude_ratio", "error"}`` where the
    orbit could not be computed."""
    omega, phi = system.modes
    reach = np.abs(system.W.T @ phi[:, 0])
    with np.errstate(divide="ignore"):
        grazing = float(np.min(np.where(reach > 0, system.gap / np.where(reach > 0, reach, 1.0), np.inf)))
    out = {"open_hz": float(omega[0] / (2 * np.pi)), "structural_zeta": float(np.atleast_1d(damping.ratios(omega))[0]),
           "grazing_tip_m": float(grazing * reach.max()) if np.isfinite(grazing) else None, "points": []}
    if not np.isfinite(grazing):
        return out
    coulomb = friction.model == "coulomb"
    sliding = 0.0 if friction.radius is None else speed * np.asarray(friction.radius, dtype=float)
    guess = None
    for ratio in sorted(float(r) for r in ratios):
        clock = time.process_time()
        a = ratio * grazing
        try:
            if coulomb:
                m = coulomb_mode(system, friction, a, damping=damping, sliding=sliding, guess=guess)
                zd = coulomb_decay_ratio(system, friction, m, damping, sliding=sliding)
            else:
                m = friction_mode(system, friction, a, damping=damping, guess=guess)
                zd = decay_ratio(system, friction, m, damping)
        except ValueError as exc:
            out["points"].append({"amplitude_ratio": ratio, "error": str(exc)})
            guess = None
            continue
        guess = m if m.converged else None
        share = _shares(system, m)
        near = [(k, h, g) for k, h, g in harmonic_amplification(omega, damping.ratios(omega), m.frequency)
                if g >= INTERNAL_GAIN and share[k] >= INTERNAL_SHARE]
        k, h, gain = max(near, key=lambda r: r[2], default=(None, None, 0.0))
        internal = None if k is None else {"mode": k + 1, "frequency_hz": float(omega[k] / (2 * np.pi)),
                                           "harmonic": h, "gain": gain, "share": float(share[k])}
        out["points"].append({"internal": internal, "mode_share": float(share[0]),
            "amplitude_ratio": ratio, "tip_amplitude_m": float(a * reach.max()),
            "frequency_hz": float(m.frequency / (2 * np.pi)), "zeta": float(m.zeta), "decay_zeta": float(zd),
            "decay_error": float(zd / m.zeta - 1) if m.zeta != 0 else None, "residual": float(m.residual),
            "converged": bool(m.converged), "seconds": time.process_time() - clock})
    return out


def _shares(system: NodalSystem, m) -> np.ndarray:
    """Each open-phase mode's share of the modal energy ``Σ ½(ω_j²q_j² + p_j²)`` at the orbit's start."""
    omega, phi = system.modes
    q, p = phi.T @ (system.M @ m.x0), phi.T @ (system.M @ m.v0)
    e = (omega * q) ** 2 + p**2
    return e / e.sum()


def modes_section(rows: list[dict], points: list[dict], unit: str) -> dict | None:
    """The summary's ``rub.friction.modes``: per speed (the rows' ``speed``, in ``unit``) its :func:`mode_points`,
    and what is doubtful — orbits that did not close or could not be computed, a free decay off the concept by more than
    :data:`DECAY_RTOL` — in words; ``None`` when no speed has modes."""
    per = [{"speed": row["speed"], "speed_rad_s": row["speed_rad_s"], **p["friction_modes"]}
           for row, p in zip(rows, points) if p.get("friction_modes") is not None]
    if not per:
        return None
    doubts, worst, internal, flagged = [], None, [], set()
    for s in per:
        for q in s["points"]:
            where = f"{q['amplitude_ratio']:g} × grazing at {s['speed']:.6g} {unit}"
            if "error" in q:
                doubts.append(f"at {where} the orbit could not be computed ({q['error'][:120]})")
            elif not q["converged"]:
                doubts.append(f"at {where} the orbit did not close (residual {q['residual']:.1e}): its figures are "
                              "not a mode's")
            elif q["decay_error"] is not None:
                if q.get("internal") and s["speed"] not in flagged:  # once a speed, from its least amplitude
                    flagged.add(s["speed"])
                    i = q["internal"]
                    ratio = i["frequency_hz"] / q["frequency_hz"]
                    internal.append(f"at {s['speed']:.6g} {unit} from {q['amplitude_ratio']:g} × grazing: mode "
                                    f"{i['mode']} ({i['frequency_hz']:.6g} Hz, {ratio:.4g} × the mode's frequency) "
                                    f"answers the orbit's harmonic {i['harmonic']} {i['gain']:.0f}-fold and holds "
                                    f"{i['share']:.2%} of its modal energy: an internal resonance, so the orbit is not "
                                    "one nonlinear mode's alone and a forced response's resonance width need not give "
                                    "its damping ratio, least of all friction's part of it")
                worst = q if worst is None or abs(q["decay_error"]) > abs(worst["decay_error"]) else worst
                if abs(q["decay_error"]) > DECAY_RTOL:
                    doubts.append(f"at {where} the free decay's damping ratio is {q['decay_error']:+.1%} off the "
                                  f"concept's ({q['decay_zeta']:.4%} against {q['zeta']:.4%}): the ratio is doubtful "
                                  "there")
    return {"speed_unit": unit, "speeds": per, "worst_decay_error": None if worst is None else worst["decay_error"],
            "doubts": doubts + internal}


def _rows(section: dict):
    for s in section["speeds"]:
        for q in s["points"]:
            if "error" not in q:
                yield s, q


def log_friction_modes(section: dict | None, unit: str) -> None:
    """One line per speed: the mode's frequency and damping ratio over the amplitudes, and the check."""
    if not section:
        return
    for s in section["speeds"]:
        good = [q for q in s["points"] if "error" not in q]
        if not good:
            log.warning("rub: at %.6g %s no mode with friction could be computed", s["speed"], unit)
            continue
        lo, hi = good[0], good[-1]
        log.info("rub: at %.6g %s the first mode with friction from %g to %g × its grazing amplitude: %.6g → %.6g Hz "
                 "(open %.6g Hz), damping ratio %.4f → %.4f %% (structural %.4f %%); the free decay within %.2g %%",
                 s["speed"], unit, lo["amplitude_ratio"], hi["amplitude_ratio"], lo["frequency_hz"],
                 hi["frequency_hz"], s["open_hz"], 100 * lo["zeta"], 100 * hi["zeta"], 100 * s["structural_zeta"],
                 100 * max(abs(q["decay_error"] or 0.0) for q in good))
    for words in section["doubts"]:
        log.warning("rub: the mode with friction: %s", words)


def write_friction_modes(folder: Path, section: dict, figures: bool, title: str | None) -> dict:
    """``friction_modes.csv`` (:data:`MODE_COLUMNS`) and, with ``figures``, ``friction_modes.png``."""
    lines = [",".join(MODE_COLUMNS)]
    for s, q in _rows(section):
        cells = {"speed": s["speed"], "speed_rad_s": s["speed_rad_s"], "amplitude_ratio": q["amplitude_ratio"],
                 "tip_amplitude_mm": q["tip_amplitude_m"] * 1e3, "frequency_hz": q["frequency_hz"],
                 "frequency_shift": q["frequency_hz"] / s["open_hz"] - 1, "zeta": q["zeta"],
                 "structural_zeta": s["structural_zeta"], "decay_zeta": q["decay_zeta"],
                 "decay_error": q["decay_error"], "residual": q["residual"], "converged": q["converged"],
                 "mode_share": q["mode_share"],
                 **{f"internal_{k}": (q.get("internal") or {}).get(k) for k in ("mode", "harmonic", "gain", "share")},
                 "seconds": q["seconds"]}
        lines.append(",".join(csv_cell(cells[c]) for c in MODE_COLUMNS))
    write_text(folder / "friction_modes.csv", "\n".join(lines) + "\n")
    files = {"friction_modes_csv": "friction_modes.csv"}
    if figures:
        from ...post.rub.friction_modes_plot import friction_modes_plot

        save_figure(friction_modes_plot(section, title=f"{title}: the first mode with friction" if title else None),
                    folder / "friction_modes.png")
        files["friction_modes_figure"] = "friction_modes.png"
    return files
