"""The study keys of friction at the tip and of an abradable coating on the casing: ``[contact] friction`` and
``[casing] abradable`` (tables), their checks, and the cross-checks with the ``[rub]`` stage that uses them
(:func:`friction_checks`).

>>> _friction({"mu": 0.15}) is None, _friction({"mu": 0.15, "model": "coulomb"}) is None
(True, True)
>>> _friction({"mu": 0.15, "mode_amplitudes": [1.5, 0.8]})[:61]
'mode_amplitudes must be a list of 1 to 20 numbers in (1, 100]'
>>> _friction({"mu": 0.15, "model": "stick"})
"model must be 'rotation' or 'coulomb', got 'stick'"
"""

from __future__ import annotations

import math

from ..keys import Key, StudyError

__all__ = ["ABRADABLE_KEY", "FRICTION_KEY", "FRICTION_MODELS", "friction_checks"]

#: The friction models a study may ask for.
FRICTION_MODELS = ("rotation", "coulomb")

#: At most this many amplitudes of the mode with friction (each an orbit and its free decay at every speed).
MAX_MODE_AMPLITUDES = 20


def _number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _friction(v: dict) -> str | None:
    """``None`` or what is wrong with ``[contact] friction``."""
    extra = sorted(set(v) - {"mu", "model", "mode_amplitudes"})
    if extra:
        return f"unknown key {extra[0]!r} (valid: mu, model, mode_amplitudes)"
    if "mu" not in v:
        return "needs mu, the friction coefficient, e.g. {mu = 0.15, model = \"rotation\"}"
    if not _number(v["mu"]) or not 0 <= v["mu"] <= 2:
        return f"mu must be a finite number in [0, 2] (the Coulomb friction coefficient), got {v['mu']!r}"
    model = v.get("model", "rotation")
    if model not in FRICTION_MODELS:
        return f"model must be 'rotation' or 'coulomb', got {model!r}"
    amps = v.get("mode_amplitudes")
    if amps is not None and not (isinstance(amps, list) and 1 <= len(amps) <= MAX_MODE_AMPLITUDES
                                 and all(_number(a) and 1 < a <= 100 for a in amps)):
        return (f"mode_amplitudes must be a list of 1 to {MAX_MODE_AMPLITUDES} numbers in (1, 100] (the first mode's "
                f"amplitude over its grazing amplitude; at 1 or below it does not touch the casing), got {amps!r}")
    return None


def _abradable(v: dict) -> str | None:
    """``None`` or what is wrong with ``[casing] abradable``."""
    extra = sorted(set(v) - {"thickness", "yield", "stiffness", "cells"})
    if extra:
        return f"unknown key {extra[0]!r} (valid: thickness, yield, stiffness, cells)"
    units = {"thickness": "m", "yield": "Pa: the contact pressure at which the coating is removed",
             "stiffness": "Pa/m: the pressure per unit penetration"}
    for key, unit in units.items():
        if key not in v:
            return f"needs {key} ({unit}), e.g. {{thickness = 1e-3, yield = 5e6, stiffness = 2e13, cells = 360}}"
        if not _number(v[key]) or not v[key] > 0:
            return f"{key} must be a finite number > 0 ({unit}), got {v[key]!r}"
    cells = v.get("cells", 360)
    if isinstance(cells, bool) or not isinstance(cells, int) or not 3 <= cells <= 100_000:
        return f"cells must be an integer in [3, 100000] (equal angular cells round the casing), got {cells!r}"
    return None


FRICTION_KEY = Key((dict,), None, "Coulomb friction at each contact node of the [rub] response: {mu = 0.15, model = "
                   "'rotation'} ('rotation': the sliding dominated by the rotation, ΩR ≫ the vibration velocity, "
                   "checked per node and speed; 'coulomb': stick–slip, each touching node sliding either way or "
                   "sticking to the casing, for a slow speed); mode_amplitudes = [1.5, 2, 3]: the first mode with "
                   "friction at these multiples of its grazing amplitude at each speed, its frequency and damping "
                   "ratio checked by its free decay (friction_modes.csv, friction_modes.png); default: none.",
                   _friction)

ABRADABLE_KEY = Key((dict,), None, "An abradable coating on the casing, worn by the [rub] response: {thickness (m), "
                    "yield (Pa: the contact pressure at which it is removed), stiffness (Pa/m), cells (round the "
                    "casing, default 360)}; each revolution's worn profile is the clearance of the next.", _abradable)


def friction_checks(c: dict) -> None:
    """``[contact] friction`` and ``[casing] abradable`` need the ``[rub]`` response that uses them; the coating is the
    casing's compliance (no ``casing_stiffness`` beside it). Fills in their defaults (``model``, ``cells``)."""
    from ..disk.cyclic_keys import cyclic_requested

    ct, k = c["contact"], c.get("casing") or {}
    rub = (c.get("rub") or {}).get("speeds")
    fr, ab = ct.get("friction"), k.get("abradable")
    if rub and cyclic_requested(c):
        for given, what in ((fr, "[contact] friction"), (ab, "[casing] abradable")):
            if given is not None:
                raise StudyError(f"{what}: the rub of a bladed disk (a [cyclic] study) is computed without friction "
                                 "and wear; remove it, or study one blade's rub (without [cyclic])")
    if fr is not None:
        if not rub:
            raise StudyError("[contact] friction: it acts in the rub response: give [rub] speeds (with an out-of-round "
                             "[casing]), or remove friction")
        ct["friction"] = {"mu": float(fr["mu"]), "model": fr.get("model", "rotation")}
        if fr.get("mode_amplitudes") is not None:
            ct["friction"]["mode_amplitudes"] = sorted({float(a) for a in fr["mode_amplitudes"]})
        if ct["friction"]["model"] == "coulomb" and ab is not None:
            raise StudyError('[contact] friction: model = "coulomb" (stick–slip) is not run with a [casing] abradable '
                             'coating; use model = "rotation" with the coating, or remove abradable')
    if ab is not None:
        if not rub:
            raise StudyError("[casing] abradable: the coating is worn by the rub response: give [rub] speeds, or "
                             "remove abradable")
        for key in ("casing_stiffness", "casing_stiffness_per_area"):
            if ct.get(key) is not None:
                raise StudyError(f"[contact] {key}: with a [casing] abradable coating the casing's compliance is the "
                                 f"coating's (its stiffness per area × each node's area); remove {key}")
        k["abradable"] = {"thickness": float(ab["thickness"]), "yield": float(ab["yield"]),
                          "stiffness": float(ab["stiffness"]), "cells": int(ab.get("cells", 360))}
