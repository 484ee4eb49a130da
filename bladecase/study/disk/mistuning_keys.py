"""The ``[mistuning]`` section of a study: a mistuned bladed disk's amplification factor under an engine order, from
the tuned disk's cyclic modes (:mod:`bladecase.study.disk.mistuning` runs it).  Its keys (:data:`MISTUNING_KEYS`), the
checks across sections (:func:`mistuning_checks`) and whether a study asks for it (:func:`mistuning_requested`).

Mistuning is of a bladed disk: a ``[geometry] kind = "sector"`` study, or a sector mesh (``[cyclic]`` keys or a
deck's ``*CYCLIC SYMMETRY MODEL``) whose blade is the node group ``[mistuning] blade``.  Either random samples
(``std``, ``samples``, ``seed``) or one given pattern (``deviations``, one number a blade).

>>> from bladecase.study.schema import loads
>>> s = loads('''
... mistuning = {std = 0.02, samples = 50, engine_order = 2}
... [geometry]
... kind = "sector"
... sectors = 6
... hub_radius = 0.1
... rim_radius = 0.2
... disk_thickness = 0.03
... span = 0.1
... root_chord = 0.03
... thickness = 0.005
... ''')
>>> mistuning_requested(s.config), s["mistuning"]["model"], s["mistuning"]["damping"]
(True, 'snm', 0.002)
"""

from __future__ import annotations

import math

from ..keys import _INT, _LIST, _NUM, _STR, Key, StudyError
from ..values import _int_between, _name, _one_of
from .cyclic_keys import cyclic_requested

__all__ = ["MISTUNING_KEYS", "MODELS", "mistuning_checks", "mistuning_requested", "sectors_of"]

#: The reduced-order mistuning models: subset of nominal modes, fundamental mistuning model.
MODELS = ("snm", "fmm")

#: Largest |deviation| (and standard deviation): the model is linear in small deviations.
SMALL = 0.3

#: Most random samples a study accepts.
MAX_SAMPLES = 100_000


def _std(v) -> str | None:
    if math.isfinite(v) and 0 < v < SMALL:
        return None
    return (f"must be a standard deviation > 0 and < {SMALL:g} (each blade's relative stiffness deviation, e.g. "
            "0.02 for 2 %)")


def _damping(v) -> str | None:
    return None if math.isfinite(v) and 0 < v < 1 else "must be a modal damping ratio > 0 and < 1 (e.g. 0.002)"


def _deviations(v) -> str | None:
    ok = all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) and abs(x) < SMALL
             for x in v)
    if not v or not ok:
        return (f"must be a list of one relative stiffness deviation per blade, each a number with |value| < "
                f"{SMALL:g} (blade j's Young's modulus × (1 + value)), e.g. [0.01, -0.02, …]")
    return None


def _clearance(v) -> str | None:
    values = v if isinstance(v, list) else [v]
    ok = all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) and x > 0 for x in values)
    if not values or not ok:
        return ("must be the casing clearance at the blade tips (m, > 0): one number for every blade, or a list of "
                "one per blade (N numbers)")
    return None


#: ``[mistuning]``: key → :class:`~bladecase.study.keys.Key`.
MISTUNING_KEYS: dict[str, Key] = {
    "std": Key(_NUM, None, "Standard deviation of the blades' relative stiffness deviations (normal, e.g. 0.02): "
               "random samples. Give it or 'deviations'.", _std),
    "samples": Key(_INT, 100, "How many random samples (each a mistuned disk), run through [execution]'s executor.",
                   _int_between(1, MAX_SAMPLES)),
    "seed": Key(_INT, 0, "Seed of the random samples (the same seed gives the same samples).",
                _int_between(0, 2**32 - 1)),
    "deviations": Key(_LIST, None, "One given mistuning pattern instead of random samples: blade j's relative "
                      "stiffness deviation, N numbers (blade 0 is the study's sector).", _deviations),
    "engine_order": Key(_INT, 1, "The engine order of the forcing (it excites nodal diameter e mod N, or N − that).",
                        _int_between(1, 1000, " (an engine order)")),
    "damping": Key(_NUM, 0.002, "Modal damping ratio of the tuned modes (viscous).", _damping),
    "family": Key(_INT, 0, "The mode family (0: the lowest mode of every nodal diameter).", _int_between(0, 49)),
    "model": Key(_STR, "snm", "'snm' (subset of nominal modes: the family's tuned modes, the blade's own stiffness "
                 "scaled) or 'fmm' (fundamental mistuning model: the family's strain energy assumed in the blades).",
                 _one_of(*MODELS)),
    "clearance": Key((int, float, list), None, "The casing clearance at the blade tips (m): one number, or one per "
                     "blade (N numbers). Given: which blade rubs first as the forcing rises, how soon against the "
                     "tuned disk, by how much before the next (mistuning_rub.csv). With a [casing] (radius or radii, "
                     "optionally lobes and amplitude, an offset axis) each blade's clearance is the casing's at its "
                     "tip instead; this, if given too, must agree with it.", _clearance),
    "force": Key(_NUM, None, "With 'clearance' (or a [casing]): the engine-order force at each blade's tip (N, "
                 "amplitude) at which "
                 "every blade's rub is computed — each blade its own massless contact at its tip node, the steady "
                 "rub at the mistuned disk's resonance (mistuning_contact.csv). Needs [fem] mass = 'lumped'.",
                 lambda v: None if math.isfinite(v) and v > 0 else "must be a force amplitude > 0 (N)"),
    "contact_samples": Key(_INT, 10, "With 'force': how many samples (the first ones) are run with contact.",
                           _int_between(1, MAX_SAMPLES)),
    "casing_stiffness": Key(_NUM, None, "With 'force': the casing's stiffness at each tip (N/m); default: rigid.",
                            lambda v: None if math.isfinite(v) and v > 0 else "must be a stiffness > 0 (N/m)"),
    "blade": Key(_STR, None, "For a sector mesh file: the node group of the blade (its cells, those with every node "
                 "in the group, are what mistuning scales). The parametric sector's blade is what lies beyond the "
                 "rim radius.", _name),
}


def mistuning_requested(c: dict) -> bool:
    """True when the study (validated sections ``c``) sets a ``[mistuning]`` key."""
    m = c.get("mistuning") or {}
    return any(k in m and m[k] != spec.default for k, spec in MISTUNING_KEYS.items())


def sectors_of(c: dict) -> int | None:
    """N when the study's keys give it (a sector geometry, or ``[cyclic] sectors``), else ``None`` (a deck's)."""
    g = c.get("geometry") or {}
    if g.get("kind") == "sector":
        return g["sectors"]
    return (c.get("cyclic") or {}).get("sectors")


def check_deviations(m: dict, sectors: int) -> None:
    """``deviations`` has one value a blade of a disk of ``sectors``.

    >>> check_deviations({"deviations": [0.0, 0.01]}, 3)
    Traceback (most recent call last):
        ...
    bladecase.study.schema.StudyError: [mistuning] deviations: 2 values, but the disk has 3 blades: give one \
relative stiffness deviation per blade (3 numbers)
    """
    d = m.get("deviations")
    if d is not None and len(d) != sectors:
        raise StudyError(f"[mistuning] deviations: {len(d)} values, but the disk has {sectors} blades: give one "
                         f"relative stiffness deviation per blade ({sectors} numbers)")
    c = m.get("clearance")
    if isinstance(c, list) and len(c) != sectors:
        raise StudyError(f"[mistuning] clearance: {len(c)} values, but the disk has {sectors} blades: give one "
                         f"clearance (m) for every blade, or one per blade ({sectors} numbers)")


def mistuning_checks(c: dict) -> None:
    """The ``[mistuning]`` keys against each other and the other sections (``StudyError`` naming the key): a bladed
    disk only; random samples (``std``) or one pattern (``deviations``), not both; ``deviations`` N long when N is
    known; ``blade`` for a mesh file only, and required there.

    >>> try:
    ...     mistuning_checks({"geometry": {"kind": "blade"}, "mistuning": {"std": 0.01}})
    ... except StudyError as exc:
    ...     print(str(exc)[:60])
    [mistuning]: mistuning is that of a bladed disk, but this st
    """
    if not mistuning_requested(c):
        return
    m, g = c["mistuning"], c.get("geometry")
    if g is not None and g.get("kind") != "sector":
        raise StudyError(f"[mistuning]: mistuning is that of a bladed disk, but this study is a single "
                         f"{g.get('kind')!r} geometry: use [geometry] kind = 'sector' (a disk sector with its blade), "
                         "or a sector mesh file with [cyclic]; or remove [mistuning]")
    if (c.get("contact") or {}).get("clearance") is not None:
        raise StudyError("[mistuning]: the mistuned disk's rub is set in [mistuning] itself (clearance: who rubs "
                         "first; force: how hard each blade rubs), not by [contact]: remove [contact] (or [mistuning])")
    if m["deviations"] is not None:
        both = [k for k in ("std", "samples") if m[k] != MISTUNING_KEYS[k].default]
        if both:
            raise StudyError(f"[mistuning] {both[0]}: give either 'deviations' (one given pattern) or random samples "
                             f"('std', 'samples', 'seed'), not both; got {both[0]} = {m[both[0]]!r} with deviations")
    elif m["std"] is None:
        raise StudyError("[mistuning] std: required for random samples (the standard deviation of the blades' "
                         "relative stiffness deviations, e.g. std = 0.02), or give 'deviations' (N numbers)")
    k = c.get("casing") or {}
    casing = k.get("radius") is not None or k.get("radii") is not None
    if m["force"] is not None and m["clearance"] is None and not casing:
        raise StudyError("[mistuning] force: the rub of each blade needs the casing: give [mistuning] clearance (m), "
                         "or a [casing] (radius) from which each blade's clearance is read")
    if casing and g is None and not cyclic_requested(c):
        raise StudyError("[casing]: the casing of a mistuned disk read from a sector deck: add a [cyclic] key, e.g. "
                         "[cyclic] sectors = N (the deck's N), so that the run is the bladed disk's")
    if m["force"] is not None and (c.get("fem") or {}).get("mass") != "lumped":
        raise StudyError("[mistuning] force: each blade's contact is a massless contact (its tip's mass moved to its "
                         f"neighbours): [fem] mass = 'lumped', got {(c.get('fem') or {}).get('mass')!r}")
    n = sectors_of(c)
    if n is not None:
        check_deviations(m, n)
    if g is not None and m["blade"] is not None:
        raise StudyError(f"[mistuning] blade: only for a sector mesh file; the parametric sector's blade is what "
                         f"lies beyond its rim radius (got blade = {m['blade']!r})")
    if g is None and m["blade"] is None:
        raise StudyError("[mistuning] blade: required for a sector mesh file: the node group of the blade (its "
                         "cells, those with every node in the group, are the stiffness that mistuning scales)")
