"""The sections of a study beyond the pipeline's own: ``[forcing]`` (the forced–damped response of the blade:
damping, load, forcing frequencies, the sweep; run by :func:`bladecase.study.forcing.stage.forced_response`),
``[execution]`` (where independent tasks run: :func:`bladecase.study.executor.make_executor`) and ``[limits]``
(the caps on the work a study may ask for, which a big machine may raise), ``[rotation]`` (the blade's rotation:
the speed every stage works at and the Campbell diagram, :mod:`bladecase.study.rotation.stage`), with their
cross-checks."""

from __future__ import annotations

import os

import numpy as np

from ..fe.geometry import MAX_CELLS
from ..nsm.system import DENSE_LIMIT
from .executor import make_executor
from .keys import _BOOL, _INT, _LIST, _NUM, _STR, Key, StudyError
from .rub.keys import ABRADABLE_KEY, FRICTION_KEY, friction_checks  # noqa: F401 (FRICTION_KEY: schema's)
from .values import (
    LIMITS,
    _amplitude,
    _count_capped,
    _direction,
    _int_at_least,
    _int_between,
    _name,
    _one_of,
    _periods,
    _rayleigh,
    sweep_periods,
)

#: ``[forcing]``: key → :class:`~bladecase.study.keys.Key` (the section runs when ``amplitude`` is given).
FORCING_KEYS: dict[str, Key] = {
    "rayleigh": Key(_LIST, None, "Rayleigh damping [alpha, beta]: C = alpha K + beta M (alpha in s, beta in 1/s); "
                    "give this or 'ratio'.", _rayleigh),
    "ratio": Key(_NUM, None, "Modal damping ratio of every mode (e.g. 0.01); give this or 'rayleigh'.",
                 lambda v: None if 0 < v < 1 else "must be in (0, 1) (a damping ratio)"),
    "load": Key(_STR, "nodal", "'nodal' (a force shared by nodes) or 'pressure' (a uniform pressure on the "
                "face 'group').", _one_of("nodal", "pressure")),
    "node": Key(_INT, None, "Nodal load: the mesh node loaded; default (no node, no group): the contact "
                "node(s).", _int_between(0, LIMITS["node"])),
    "group": Key(_STR, None, "Nodal load: the mesh group whose nodes share the force; pressure load: the face "
                 "group (required).", _name),
    "load_direction": Key(_LIST, None, "Nodal load: the force's direction; default: the casing normal.",
                          _direction),
    "amplitude": Key(_NUM, None, "Load amplitude F0: the total force (N) of a nodal load, the pressure (Pa) "
                     "of a pressure load (> 0 pushes into the body); the load is F0 f cos(2π f t).  The forced "
                     "response runs when it is given.", _amplitude),
    "engine_order": Key(_INT, None, "Engine order EO of a travelling excitation: the blade is forced at "
                        "EO × rotation speed (its phase on a single blade only shifts time).",
                        _int_between(1, LIMITS["engine_order"])),
    "frequencies": Key(_LIST, [0.8, 1.2], "Forcing range [lower, upper] in 'frequency_unit'.", _periods),
    "frequency_unit": Key(_STR, "f1", "'Hz', 'f1' (× the first linear frequency of the reduced model that sees "
                          "the contact) or 'rpm' (rotation speeds; needs engine_order).",
                          _one_of("Hz", "f1", "rpm")),
    "points": Key(_INT, 41, "Forcing frequencies of the sweep, evenly spaced.",
                  _int_between(1, LIMITS["forcing_points"])),
    "periods": Key(_INT, 300, "Forcing periods integrated at each frequency (>= 2 max_p + 1).",
                   _int_between(3, LIMITS["forcing_periods"])),
    "direction": Key(_STR, "up", "Sweep in forcing frequency: 'up', 'down' or 'both' (each point starts from the "
                     "previous one's end state).", _one_of("up", "down", "both")),
    "restitution": Key(_NUM, 1.0, "Newton's coefficient of restitution e in (0, 1] (1: as the nonsmooth modes).",
                       lambda v: None if 0 < v <= 1 else "must be in (0, 1]"),
    "max_p": Key(_INT, 4, "Longest steady-state period looked for, in forcing periods.", _int_between(1, 16)),
    "animate": Key(_INT, 1, "Periodic steady states with impacts to animate (the highest-energy ones); above "
                   f"{LIMITS['animate']}: all of them, at most {LIMITS['animate']} (logged).",
                   _count_capped(LIMITS["animate"])),
}


def forcing_checks(c: dict) -> None:
    """``[forcing]`` (when its amplitude is given): one damping, the keys of its load kind, enough periods,
    no restitution with the massless contact model."""
    f = c["forcing"]
    if f["amplitude"] is None:
        given = sorted(k for k, spec in FORCING_KEYS.items() if f[k] != spec.default)
        if given:
            raise StudyError(f"[forcing] amplitude: required to run the forced response (the section sets "
                             f"{', '.join(given)})")
        return
    if (f["rayleigh"] is None) == (f["ratio"] is None):
        raise StudyError("[forcing] rayleigh / ratio: give exactly one damping: rayleigh = [alpha, beta] "
                         "(C = alpha K + beta M) or ratio = zeta (every mode)")
    if f["frequency_unit"] == "rpm" and f["engine_order"] is None:
        raise StudyError("[forcing] frequency_unit: 'rpm' (rotation speeds) needs an engine_order")
    if f["load"] == "pressure" and f["group"] is None:
        raise StudyError("[forcing] group: a pressure load needs the mesh group of its face, e.g. group = 'tip'")
    if f["load"] == "pressure" and (f["node"] is not None or f["load_direction"] is not None):
        raise StudyError("[forcing] node / load_direction: only for load = 'nodal' (a pressure acts along the "
                         "face's normal)")
    if f["periods"] < 2 * f["max_p"] + 1:
        raise StudyError(f"[forcing] periods: at least 2 × max_p + 1 = {2 * f['max_p'] + 1}, got {f['periods']}")
    if c["contact"]["model"] == "massless" and f["restitution"] != 1.0:
        raise StudyError(f"[forcing] restitution: Newton's contact model only (the massless contact model has no "
                         f"impact law), got {f['restitution']!r}")
    unit, hi = f["frequency_unit"], f["frequencies"][1]
    top = LIMITS["forcing_frequency"][unit]
    if hi > top:
        raise StudyError(f"[forcing] frequencies: the upper frequency must be <= {top:g} {unit}, got "
                         f"{f['frequencies']}")
    _sweep_work(c)


def _sweep_work(c: dict) -> None:
    """The forced sweep's work (:func:`~bladecase.study.values.sweep_periods`) within ``[limits] sweep_periods``;
    with ``frequency_unit = 'f1'`` the forcing periods longer than ``T1`` count in ``T1`` (other units: at the
    forcing stage, which knows ``f1``)."""
    f, cap = c["forcing"], c["limits"]["sweep_periods"]
    sweeps = 2 if f["direction"] == "both" else 1
    lo, hi = f["frequencies"]
    ratios = np.linspace(lo, hi, f["points"]) if f["frequency_unit"] == "f1" else np.ones(f["points"])
    work = sweep_periods(ratios, f["periods"], sweeps)
    if work > cap:
        longer = ", a higher lower frequency" if longer_periods_weigh(f, work) else ""
        raise StudyError(f"[forcing] points × periods: {sweep_work_words(f, work)}, more than [limits] sweep_periods "
                         f"= {cap}: fewer points or periods{longer}, or raise [limits] sweep_periods")


def sweep_work_words(f: dict, work: float) -> str:
    """``41 points × 300 periods × 2 sweeps = 24600 forcing periods``, with the count in periods ``T1`` when the
    forcing periods longer than ``T1`` weigh (more than 10 %)."""
    sweeps = 2 if f["direction"] == "both" else 1
    plain = f["points"] * f["periods"] * sweeps
    text = (f"{f['points']} points × {f['periods']} periods{f' × {sweeps} sweeps' if sweeps > 1 else ''} = {plain} "
            "forcing periods")
    if work > 1.1 * plain:
        text += f" ({work:.3g} periods T1: a forcing period longer than T1 counts in periods T1)"
    return text


def longer_periods_weigh(f: dict, work: float) -> bool:
    """True when the forcing periods longer than ``T1`` make most of the sweep's work."""
    return work > 2 * f["points"] * f["periods"] * (2 if f["direction"] == "both" else 1)


#: ``[execution]``: key → :class:`~bladecase.study.keys.Key`.
EXECUTION_KEYS: dict[str, Key] = {
    "executor": Key(_STR, None, "Where the independent tasks (each model's search, the forcing sweeps) run: "
                    "'serial', 'processes' (local processes) or 'dask' (a Dask LocalCluster of 'workers' processes, "
                    "or the cluster at 'scheduler'); default: 'dask' with a scheduler or workers > 1, else 'serial'.",
                    _one_of("serial", "processes", "dask")),
    "workers": Key(_INT, None, "Local worker processes ('processes', or 'dask' without 'scheduler'); default: "
                   "one per core.", _int_at_least(1)),
    "scheduler": Key(_STR, None, "Address of an existing Dask scheduler, e.g. 'tcp://host:8786' (the workers "
                     "need bladecase at the same version); implies executor = 'dask'.",
                     lambda v: None if v.strip() else "must be an address such as 'tcp://host:8786'"),
}


def execution_checks(c: dict) -> None:
    """``[execution]``: at most ``[limits] workers`` local processes, and the executor's own checks (nothing is
    started here)."""
    x = c["execution"]
    cap = worker_limit(c["limits"])
    if x["workers"] is not None and x["workers"] > cap and x["scheduler"] is None:
        cores = os.cpu_count() or 1
        why = (f"{WORKERS_PER_CORE} per core of this machine's {cores}" if c["limits"]["workers"] is None
               else "[limits] workers")
        raise StudyError(f"[execution] workers: {x['workers']} local worker processes, at most {cap} ({why}): fewer "
                         "workers, or raise [limits] workers")
    try:
        make_executor(x["executor"], x["workers"], x["scheduler"])
    except ValueError as exc:
        raise StudyError(f"[execution] {exc}") from None


#: Local worker processes per core allowed when ``[limits] workers`` is not set.
WORKERS_PER_CORE = 8


def worker_limit(limits: dict) -> int:
    """Most local worker processes: ``[limits] workers``, else :data:`WORKERS_PER_CORE` per core."""
    return limits["workers"] if limits["workers"] is not None else WORKERS_PER_CORE * (os.cpu_count() or 1)


#: Default of ``[limits] dofs_full``: measured on a 2-D plate of 2940 free dofs, ``method = "full"`` builds
#: its dense model in 5 s and a 1-ipp search takes 40 s; the dense eigen-solution grows as ``n³``.
DOFS_FULL = 3000

#: Default of ``[limits] sweep_periods``: 8 × the default sweep (41 points × 300 periods); measured on the plate
#: (modal 10): about 1 ms per forcing period without contact, 0.1 s with impacts.
SWEEP_PERIODS = 100_000

#: Most forcing periods ``[limits] sweep_periods`` may allow, and the cap of a forced response run without a
#: study (:func:`bladecase.study.forcing.stage.forced_response` without ``max_periods``).
SWEEP_CEILING = 10**9

#: ``[limits]``: key → :class:`~bladecase.study.keys.Key`.  Each caps work that would otherwise run for hours or
#: not fit in memory; the study is refused before any work, with the estimate and the key that raises the cap.
LIMIT_KEYS: dict[str, Key] = {
    "cells": Key(_INT, MAX_CELLS, "Most mesh cells gmsh may make from [geometry] (estimated from the size "
                 "before meshing).", _int_between(1, 10**9)),
    "dofs_full": Key(_INT, DOFS_FULL, "Most free dofs of a model kept whole by [reduction] method = 'full' "
                     "(dense matrices, a dense search).", _int_between(1, DENSE_LIMIT)),
    "sweep_periods": Key(_INT, SWEEP_PERIODS, "Most forcing periods the forced sweep integrates (points × "
                         "periods × sweeps; a forcing period longer than T1 counts in periods T1).",
                         _int_between(1, SWEEP_CEILING)),
    "workers": Key(_INT, None, f"Most local worker processes of [execution] workers; default: {WORKERS_PER_CORE} "
                   "per core of the machine.", _int_between(1, LIMITS["workers"])),
}



#: Most speeds of a Campbell diagram (each is an eigen-solution, and with bands a reduction and a search).
MAX_SPEEDS = 200


def _speeds(v) -> str | None:
    if not v:
        return None
    if len(v) > MAX_SPEEDS:
        return f"must list at most {MAX_SPEEDS} speeds, got {len(v)}"
    if not all(isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x) and x >= 0 for x in v):
        return "must be a list of finite numbers >= 0"
    return None


def _axis(v) -> str | None:
    from .values import _direction, _point

    keys = set(v)
    if keys - {"origin", "direction"} or "direction" not in keys:
        return "must be {origin = [x, y, z], direction = [dx, dy, dz]} (origin optional, default [0, 0, 0])"
    if not isinstance(v["direction"], list) or _direction(v["direction"]):
        return "direction must be a list of 2 or 3 finite numbers, not all zero"
    if "origin" in v and (not isinstance(v["origin"], list) or _point(v["origin"])):
        return "origin must be a list of 2 or 3 finite numbers (m)"
    return None


def _orders(v) -> str | None:
    top = LIMITS["engine_order"]
    if not all(isinstance(x, int) and not isinstance(x, bool) and 1 <= x <= top for x in v):
        return f"must be a list of integers between 1 and {top}"
    return None


#: ``[rotation]``: key → :class:`~bladecase.study.keys.Key` (a study rotates when ``speeds`` or ``speed`` is given).
ROTATION_KEYS: dict[str, Key] = {
    "speeds": Key(_LIST, [], "Rotation speeds of the Campbell diagram (in 'speed_unit'), e.g. [0, 5000, 10000, "
                  "17189]: at each, the lowest modes about the centrifugal state, and the nonsmooth-mode band.",
                  _speeds),
    "speed": Key(_NUM, None, "The speed every stage works at (reduction, nonsmooth modes, forcing), in "
                 "'speed_unit'; default: the highest of 'speeds'.",
                 lambda v: None if np.isfinite(v) and v >= 0 else "must be a finite number >= 0"),
    "speed_unit": Key(_STR, "rpm", "'rpm', 'rad/s' or 'Hz' (revolutions per second).",
                      _one_of("rpm", "rad/s", "Hz")),
    "axis": Key((dict,), None, "The rotation axis: {origin = [x, y, z], direction = [dx, dy, dz]} (m; the engine "
                "axis, e.g. through the hub centre); required with 'speeds' or 'speed'.", _axis),
    "engine_orders": Key(_LIST, [], "Engine orders drawn on the Campbell diagram, e.g. [1, 2, 36]; their "
                         "crossings with the modes and with the nonsmooth-mode bands are reported.", _orders),
    "static": Key(_STR, "auto", "The static centrifugal state: 'linear' (the linear prestress), 'second-order' (its "
                  "own stress stiffness in the static solve: the tension resists the bending the load causes on a "
                  "leaned or swept blade), 'nonlinear' (geometrically nonlinear: large rotations, the load following "
                  "the deformation, the vibration about it with its full tangent, as CalculiX's NLGEOM) or 'auto' "
                  "(linear unless one second-order step moves it by more than 1 %, then nonlinear).",
                  _one_of("linear", "second-order", "nonlinear", "auto")),
    "modes": Key(_INT, 6, "Modes followed (by shape) on the Campbell diagram.", _int_between(1, 50)),
    "bands": Key(_BOOL, True, "At each speed of 'speeds', also reduce and search the nonsmooth modes: the band "
                 "of frequencies of the admissible orbits (costs a reduction and a search per speed)."),
}


def rotation_checks(c: dict) -> None:
    """``[rotation]``: an axis whenever the blade rotates; the unit's name normalised."""
    r = c.get("rotation")
    if not r:
        return
    rotates = bool(r["speeds"]) or r["speed"] is not None
    if rotates and r["axis"] is None:
        raise StudyError("[rotation] axis: required with speeds or speed (the engine axis: {origin = [x, y, z], "
                         "direction = [dx, dy, dz]})")
    if r["axis"] is not None:
        axis = r["axis"]
        r["axis"] = {"origin": list(axis.get("origin", [0.0, 0.0, 0.0])), "direction": list(axis["direction"])}
    if r["engine_orders"] and not r["speeds"]:
        raise StudyError(f"[rotation] engine_orders: drawn on the Campbell diagram, which needs speeds; got "
                         f"{r['engine_orders']} without speeds")


def _radii(v) -> str | None:
    ok = (len(v) == 2 and all(isinstance(p, list) and len(p) == 2 and all(
        isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x) for x in p) for p in v))
    if not ok or v[0][0] == v[1][0] or min(v[0][1], v[1][1]) <= 0:
        return "must be [[s1, R1], [s2, R2]]: two distinct axial stations (m along the axis) with radii > 0 (m)"
    return None


#: ``[casing]``: key → :class:`~bladecase.study.keys.Key` (a casing of revolution under a face contact).
CASING_KEYS: dict[str, Key] = {
    "radius": Key(_NUM, None, "A cylindrical casing's radius (m) about the axis.",
                  lambda v: None if np.isfinite(v) and v > 0 else "must be a finite number > 0 (m)"),
    "radii": Key(_LIST, None, "A conical casing: [[s1, R1], [s2, R2]], radii (m) at two axial stations (m along the "
                 "axis from its origin), linear in between and beyond.", _radii),
    "axis": Key((dict,), None, "The casing's axis, {origin = [x, y, z], direction = [dx, dy, dz]}; default: "
                "[rotation] axis.", _axis),
    "lobes": Key(_INT, None, "An out-of-round casing: the number n of lobes of its shape. A contact node at the "
                 "angle φ about the axis, turning at Ω, sees the clearance d − amplitude·cos(n(Ωt + φ)) ([rub]).",
                 _int_between(1, 1000)),
    "amplitude": Key(_NUM, None, "The out-of-round casing's amplitude (m): how far each lobe reaches inwards from the "
                     "round casing; with 'lobes'.",
                     lambda v: None if np.isfinite(v) and 0 < v <= 0.1 else "must be a finite number in (0, 0.1] (m)"),
    "abradable": ABRADABLE_KEY,
}


def casing_checks(c: dict, model: bool = True) -> None:
    """``[casing]``: one of radius/radii, an axis (its own or [rotation]'s), a face contact, no [contact] clearance
    (each node's comes from the casing); without ``[casing]``, ``[contact] clearance`` is required. In a mistuning
    study without a contact face, the casing gives the blade tips' clearances: no face, and the disk's axis by
    default."""
    from .disk.mistuning_keys import mistuning_requested

    k = c.get("casing") or {}
    tips = mistuning_requested(c) and c["contact"]["face"] is None and c["contact"].get("nodes") is None
    given = k and (k.get("radius") is not None or k.get("radii") is not None)
    ct = c["contact"]
    if not given:
        for key in ("axis", "lobes", "amplitude"):
            if k.get(key) is not None:
                raise StudyError(f"[casing] {key}: a casing needs radius (a cylinder) or radii (a cone)")
        if ct["clearance"] is None and model:
            raise StudyError("[contact] clearance: required (m), or a [casing] with radius or radii from which each "
                             "contact node's clearance is computed")
        return
    if k["radius"] is not None and k["radii"] is not None:
        raise StudyError("[casing] radii: give radius (a cylinder) or radii (a cone), not both")
    if k["axis"] is None:
        r = c.get("rotation") or {}
        if r.get("axis") is not None:
            k["axis"] = dict(r["axis"])
        elif not tips:  # (a mistuned disk's tips: the disk's own axis, known once the sector is read)
            raise StudyError("[casing] axis: required (or [rotation] axis): the casing is a surface of revolution "
                             "about the engine axis")
    else:
        axis = k["axis"]
        k["axis"] = {"origin": list(axis.get("origin", [0.0, 0.0, 0.0])), "direction": list(axis["direction"])}
    if (k["lobes"] is None) != (k["amplitude"] is None):
        given, missing = ("lobes", "amplitude") if k["amplitude"] is None else ("amplitude", "lobes")
        raise StudyError(f"[casing] {missing}: an out-of-round casing needs lobes and amplitude together (got "
                         f"{given} = {k[given]!r} alone)")
    if ct["face"] is None and ct.get("nodes") is None and not tips:
        raise StudyError("[casing]: each node of a contact face gets its clearance from the casing: set [contact] "
                         "face (e.g. 'tip') or nodes")
    if ct["clearance"] is not None:
        raise StudyError(f"[contact] clearance: with a [casing], each node's clearance comes from the casing; remove "
                         f"clearance = {ct['clearance']!r}")


#: ``[rub]``: key → :class:`~bladecase.study.keys.Key` (the rub response of a turning blade in an out-of-round casing;
#: runs when ``speeds`` is given).
RUB_KEYS: dict[str, Key] = {
    "speeds": Key(_LIST, [], "Rotation speeds of the rub response (in 'speed_unit'), e.g. [8000, 8100, …]: at each, "
                  "the blade turns from rest inside the out-of-round [casing] (lobes, amplitude) with one contact per "
                  "node of the contact face; the figures are read on the last 'window' revolutions.", _speeds),
    "speed_unit": Key(_STR, "rpm", "'rpm', 'rad/s' or 'Hz' (revolutions per second).", _one_of("rpm", "rad/s", "Hz")),
    "revolutions": Key(_INT, 40, "Revolutions simulated at each speed (from rest).", _int_between(2, 100_000)),
    "window": Key(_INT, 10, "The last revolutions read for the figures; the window before them tells whether the "
                  "response has settled (at most revolutions / 2).", _int_between(1, 50_000)),
    "max_revolutions": Key(_INT, None, "A speed that has not settled after 'revolutions' runs on, a window at a time, "
                           "up to this many revolutions in all (default: 10 × revolutions); one that never settles is "
                           "characterised (periodic over another period, transient, quasi-periodic or irregular).",
                           _int_between(2, 1_000_000)),
    "rayleigh": Key(_LIST, None, "Rayleigh damping [alpha, beta]: C = alpha K + beta M (alpha in s, beta in 1/s); "
                    "give this or 'ratio'.", _rayleigh),
    "ratio": Key(_NUM, None, "Modal damping ratio of every mode of the blade with its contacts open (e.g. 0.005); "
                 "give this or 'rayleigh'.", lambda v: None if 0 < v < 1 else "must be in (0, 1) (a damping ratio)"),
    "size": Key(_INT, 8, "Modes of the massless structure in the rub's reduced model (plus one static attachment "
                "vector per contact node).", _int_between(1, 500)),
}


def rub_checks(c: dict) -> None:
    """``[rub]`` (when its speeds are given): an out-of-round [casing], a face contact, the massless model, one
    damping, a window of at most half the revolutions, a cap of at least the revolutions."""
    friction_checks(c)
    r = c.get("rub")
    if not r:
        return
    if not r["speeds"]:
        given = sorted(k for k, spec in RUB_KEYS.items() if r[k] != spec.default)
        if given:
            raise StudyError(f"[rub] speeds: required to run the rub response (the section sets {', '.join(given)})")
        return
    if min(r["speeds"]) <= 0:
        raise StudyError(f"[rub] speeds: must all be > 0 (the blade turns), got {r['speeds']}")
    k = c.get("casing") or {}
    if k.get("lobes") is None:
        raise StudyError("[rub] speeds: the rub response needs an out-of-round casing: [casing] radius (or radii), "
                         "lobes and amplitude")
    if c["contact"]["model"] != "massless" or c["fem"]["mass"] != "lumped":
        raise StudyError("[rub] speeds: the rub response uses the massless contact model at every contact node: set "
                         "[contact] model = \"massless\" and [fem] mass = \"lumped\"")
    if (r["rayleigh"] is None) == (r["ratio"] is None):
        raise StudyError("[rub] rayleigh / ratio: give exactly one damping: rayleigh = [alpha, beta] "
                         "(C = alpha K + beta M) or ratio = zeta (every mode)")
    if r["window"] > r["revolutions"] // 2:
        raise StudyError(f"[rub] window: at most revolutions / 2 = {r['revolutions'] // 2} (the window before it "
                         f"tells whether the response settled), got {r['window']}")
    if r["max_revolutions"] is not None and r["max_revolutions"] < r["revolutions"]:
        raise StudyError(f"[rub] max_revolutions: at least revolutions = {r['revolutions']} (the cap of a speed that "
                         f"runs on to settle), got {r['max_revolutions']}")
    r["speed_unit"] = {"hz": "Hz"}.get(r["speed_unit"].lower(), r["speed_unit"])


#: ``[convergence]``: key → :class:`~bladecase.study.keys.Key` (the mesh error of the headline figures; runs when
#: ``meshes`` is given).
MAX_MESHES = 6


def _meshes(v) -> str | None:
    if not v:
        return None
    if not all(isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x) for x in v):
        return "must be a list of numbers (element-size factors), e.g. [1, 0.7, 0.5]"
    if not all(0.1 <= x <= 1 for x in v):
        return (f"factors must be in [0.1, 1] (1: the study's own mesh; 0.5: elements half as large), got "
                f"{[x for x in v if not 0.1 <= x <= 1]}")
    factors = {float(x) for x in v}
    if 1.0 not in factors:
        return f"must include 1 (the study's own mesh, whose figures the report gives), got {v}"
    if not 3 <= len(factors) <= MAX_MESHES:
        return (f"needs 3 to {MAX_MESHES} different factors (three meshes give an observed order and a Richardson "
                f"estimate), got {len(factors)}: {v}")
    return None


CONVERGENCE_KEYS: dict[str, Key] = {
    "meshes": Key(_LIST, [], "Element-size factors of the meshes the study is run on, 1 (the study's own) included, "
                  "e.g. [1, 0.7, 0.5]: each headline figure is given with its observed order and the Richardson "
                  "estimate of its mesh error. With a [mesh] file each finer mesh splits every cell edge in "
                  "n = round(1/factor) parts.", _meshes),
    "ratio": Key(_NUM, None, "T/T1 at which the orbit's figures (energy, tip amplitude, contact force) are compared "
                 "across the meshes (each mesh's own T1). Not set: the animated orbit's, else the middle of the "
                 "widest admissible arc.", lambda v: None if 0 < v < 100 else "must be in (0, 100) (× T1)"),
}


def convergence_checks(c: dict) -> None:
    """``[convergence] meshes`` (when given): with a ``[mesh]`` file, the factors must give three different numbers
    of parts per edge (:func:`bladecase.fe.refine.splits_for`)."""
    v = c.get("convergence")
    if not v or not v["meshes"] or "geometry" in c:
        return
    from ..fe import splits_for

    factors = sorted({float(x) for x in v["meshes"]}, reverse=True)
    splits = [splits_for(x) for x in factors]
    if len(set(splits)) < 3:
        raise StudyError("[convergence] meshes: with a [mesh] file the finer meshes split every cell edge in n parts "
                         "(element size × 1/n, n the nearest to 1/factor): "
                         + ", ".join(f"{x:g} → n = {n}" for x, n in zip(factors, splits))
                         + f"; give factors that make 3 different n, e.g. [1, 0.5, 0.33], got {v['meshes']}")
