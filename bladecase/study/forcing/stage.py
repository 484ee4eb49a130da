"""The forcing stage of a study: the forced response of the blade, drawn over its nonsmooth modes.

``[forcing]`` (a plain dict, :data:`DEFAULTS` for what it may hold) names the damping, the load — a nodal
force, a pressure on a face group, either one as an engine-order excitation — its amplitude and the forcing
frequencies.  :func:`forced_response` projects the load onto the reduced model
(:func:`bladecase.reduction.loads.project_load`), sweeps the forcing frequency
(:func:`bladecase.nsm.sweep.forced_sweep`: ``periods`` forcing periods per point, each point starting from
the previous one's end state, up and/or down in frequency), re-simulates one cycle of every steady state
from its end state (:class:`ForcedOrbit`: the contact displacement's range, and the re-simulation's return
error and impact count that confirm the class), writes ``forced.csv`` and ``forced_response.png`` and says in
words what was found, including how close the forced peak lies to the nonsmooth modes' arcs.

Engine order ``EO`` (:class:`bladecase.reduction.loads.EngineOrderLoad`): a single blade feels the load at
``f = EO × rpm / 60`` with a phase that only shifts time, so the sweep is a frequency sweep; with
``frequency_unit = "rpm"`` the range is given in rotation speeds, and the CSV and figure show both.

Either contact model: with ``[contact] model = "massless"`` the sweeps run
:func:`bladecase.nsm.massless.forced.simulate_forced_massless` (``k`` then counts contact phases, ``restitution``
must stay 1), and a load on the massless contact dofs enters exactly through its static contact displacement
``g = w_cᵀK_cc⁻¹f_c`` (:func:`contact_load`).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize_scalar

from ... import log
from ...io import save_figure, write_text
from ...nsm import MasslessSystem
from ...nsm.damping import Damping
from ...nsm.massless.forced import MasslessForcedTrajectory, simulate_forced_massless
from ...nsm.newton.forced import ForcedTrajectory, simulate_forced
from ...nsm.sweep import ENERGY_SAMPLES, SweepPoint, forced_sweep, rate_max
from ...post.forcing.plots import forced_response_plot
from ...reduction import ReducedModel
from ...reduction.loads import engine_order_load, nodal_load, pressure_load, project_load
from ..sections import SWEEP_CEILING, longer_periods_weigh, sweep_work_words
from ..values import LIMITS, _amplitude, sweep_periods

__all__ = ["COLUMNS", "DEFAULTS", "ForcedOrbit", "build_load", "check_sweep_work", "contact_load", "contact_reach",
           "forced_response", "forced_scene", "forcing_frequencies", "steady_orbit"]

#: What ``[forcing]`` may hold, with the defaults of the keys that have one (``amplitude`` and one of
#: ``rayleigh`` / ``ratio`` must be given).
DEFAULTS = {"rayleigh": None, "ratio": None, "load": "nodal", "node": None, "group": None, "load_direction": None,
            "amplitude": None, "engine_order": None, "frequencies": [0.8, 1.2], "frequency_unit": "f1",
            "points": 41, "periods": 300, "direction": "up", "restitution": 1.0, "max_p": 4, "animate": 1}

#: Columns of ``forced.csv`` (and of the section's ``points``), with their units. The header is the names alone:
#: a quantity with a unit carries it as the name's suffix (``frequency_hz``, ``period_s``), as ``comparison.csv``
#: and ``summary.json`` do. ``k``: impacts (massless model: contact phases) per ``p`` forcing periods;
#: ``resimulated_contacts``: those the re-simulation of one cycle finds.
COLUMNS = (("sweep", ""), ("frequency_hz", "Hz"), ("period_s", "s"), ("speed_rpm", "rpm"), ("label", ""),
           ("k", ""), ("p", ""), ("periodic", ""), ("energy_j", "J"), ("mean_energy_j", "J"),
           ("contact_max_m", "m"), ("contact_amplitude_m", "m"), ("residual", ""), ("return_error", ""),
           ("resimulated_contacts", ""))


def _settings(forcing: dict) -> dict:
    """``forcing`` with the defaults filled in and checked (``ValueError`` naming the key)."""
    unknown = set(forcing) - set(DEFAULTS)
    if unknown:
        raise ValueError(f"[forcing] {sorted(unknown)[0]}: unknown key (valid: {', '.join(DEFAULTS)})")
    s = {**DEFAULTS, **{k: v for k, v in forcing.items() if v is not None}}
    if (s["rayleigh"] is None) == (s["ratio"] is None):
        raise ValueError("[forcing] rayleigh / ratio: give exactly one damping: rayleigh = [alpha, beta] "
                         "(C = alpha K + beta M) or ratio = zeta (every mode)")
    if s["amplitude"] is None or not math.isfinite(s["amplitude"]):
        raise ValueError(f"[forcing] amplitude: required, a finite number (N for a nodal load, Pa for a pressure), "
                         f"got {s['amplitude']!r}")
    reason = _amplitude(s["amplitude"])
    if reason:
        raise ValueError(f"[forcing] amplitude: {reason}, got {s['amplitude']!r}")
    for key, valid in (("load", ("nodal", "pressure")), ("direction", ("up", "down", "both")),
                       ("frequency_unit", ("Hz", "f1", "rpm"))):
        if s[key] not in valid:
            raise ValueError(f"[forcing] {key}: must be one of {', '.join(map(repr, valid))}, got {s[key]!r}")
    if s["frequency_unit"] == "rpm" and s["engine_order"] is None:
        raise ValueError("[forcing] frequency_unit: 'rpm' (rotation speeds) needs an engine_order")
    lo, hi = s["frequencies"]
    if not 0 < lo < hi:
        raise ValueError(f"[forcing] frequencies: must be [lower, upper] with 0 < lower < upper, "
                         f"got {s['frequencies']}")
    if s["periods"] < 2 * s["max_p"] + 1:
        raise ValueError(f"[forcing] periods: at least 2 × max_p + 1 = {2 * s['max_p'] + 1} forcing periods per "
                         f"point (the periodicity test compares the last two returns), got {s['periods']}")
    if s["load"] == "pressure" and s["group"] is None:
        raise ValueError("[forcing] group: a pressure load needs the mesh group of its face, e.g. group = 'tip'")
    if s["load"] == "pressure" and (s["node"] is not None or s["load_direction"] is not None):
        raise ValueError("[forcing] node / load_direction: only for load = 'nodal' (a pressure acts along the "
                         "face's normal)")
    return s


def build_load(reduced: ReducedModel, forcing: dict) -> tuple[np.ndarray, str]:
    """The free-dof load shape of ``[forcing]`` (per unit amplitude: 1 N, or 1 Pa) and its description.

    ``load = "nodal"``: a force along ``load_direction`` (default: the casing normal) shared by ``node``, or
    the nodes of ``group``, or (neither) the contact's node(s).  ``load = "pressure"``: a pressure on the face
    ``group`` (positive into the body).
    """
    try:
        return _load(reduced, _settings(forcing))
    except ValueError as exc:
        raise ValueError(str(exc) if str(exc).startswith("[forcing]") else f"[forcing] {exc}") from None


def _load(reduced: ReducedModel, s: dict) -> tuple[np.ndarray, str]:
    model, contact = reduced.model, reduced.contact
    if s["load"] == "pressure":
        f = pressure_load(model, s["group"], 1.0)
        words = f"a uniform pressure on face group {s['group']!r}"
    else:
        if s["node"] is not None:
            where, shown = s["node"], f"node {s['node']}"
        elif s["group"] is not None:
            where, shown = s["group"], f"the nodes of group {s['group']!r}"
        elif contact.nodes:
            where, shown = list(contact.nodes), f"the {len(contact.nodes)} contact face nodes"
        else:
            where, shown = contact.node, f"the contact node {contact.node}"
        direction = s["load_direction"] if s["load_direction"] is not None else contact.normal_for(model)
        f = nodal_load(model, where, direction, 1.0)
        words = f"a force on {shown} along {np.round(np.asarray(direction, float), 4).tolist()}"
    if not np.any(f):
        raise ValueError("[forcing] load: it acts on clamped dofs only (reactions): nothing forces the blade")
    if s["engine_order"] is not None:
        words += f", engine order {s['engine_order']}"
    return f, words


def contact_load(reduced: ReducedModel, f_free) -> float:
    """``g = w_cᵀK_cc⁻¹f_c``: the open-phase contact displacement that the load ``f_free`` puts on the massless
    contact dofs by itself (0 for Newton's model, or when the contact dofs are not loaded).

    ``closed_shape = −K_cc⁻¹w_c`` on the contact dofs (:class:`~bladecase.reduction.massless.MasslessReducedModel`),
    so ``g = −closed_shapeᵀf``.
    """
    shape = getattr(reduced, "closed_shape", None)
    if shape is None or not isinstance(reduced.system, MasslessSystem):
        return 0.0
    return -float(np.asarray(shape, dtype=float) @ np.asarray(f_free, dtype=float).reshape(-1))


def contact_reach(reduced: ReducedModel, f_r, g: float = 0.0) -> float:
    """An upper bound of the static contact displacement per unit amplitude of the reduced load ``f_r``:
    ``Σ_j |b_j φ_jᵀf_r| / ω_j²`` over the (open-phase) modes, plus ``|g|`` (:func:`contact_load`) — no
    cancellation between modes, so a load across the casing normal is bounded by what its modes carry."""
    sp_ = reduced.system.spectrum
    omega, phi, b = (np.asarray(a, dtype=float) for a in (sp_.omega, sp_.phi, sp_.b))
    return float(np.sum(np.abs(b * (phi.T @ np.asarray(f_r, dtype=float))) / omega**2) + abs(g))


def check_sweep_work(reduced: ReducedModel, forcing: dict, f_r, g: float = 0.0,
                     max_periods: int | None = None) -> None:
    """Refuse, before the sweep, a forced response out of proportion (``ValueError`` naming the key):

    * an amplitude that pushes the contact statically (:func:`contact_reach`) more than
      ``LIMITS["forcing_reach"]`` clearances: the linear model means nothing there, and the sweep chatters for
      hours (cost per period measured growing like the square root of that ratio);
    * a sweep of more than ``max_periods`` (``[limits] sweep_periods``; ``None``: the largest value that key
      takes, 1e9) forcing periods, each counted in periods ``T1`` of the first linear mode when longer
      (:func:`~bladecase.study.values.sweep_periods`).

    A study runs this check when its reduced model is built (:func:`bladecase.study.stages.build_reduced`),
    before the search, with its own ``[limits] sweep_periods``.
    """
    s = _settings(forcing)
    gap = float(reduced.system.gap)
    reach = abs(float(s["amplitude"])) * contact_reach(reduced, f_r, g)
    top = LIMITS["forcing_reach"]
    if reach > top * gap:
        unit = "Pa" if s["load"] == "pressure" else "N"
        most = top * gap / contact_reach(reduced, f_r, g)
        raise ValueError(f"[forcing] amplitude: {s['amplitude']:g} {unit} moves the contact up to {reach:.3g} m "
                         f"statically, {reach / gap:.3g} × the clearance {gap:g} m (at most {top} ×: beyond, the "
                         f"linear model means nothing and the sweep chatters for hours); valid: |amplitude| <= "
                         f"{most:.3g} {unit}")
    cap = SWEEP_CEILING if max_periods is None else int(max_periods)
    f1 = float(reduced.system.spectrum.contact_modes[0][0] / (2 * np.pi))
    sweeps = 2 if s["direction"] == "both" else 1
    work = sweep_periods(forcing_frequencies(reduced, s) / f1, int(s["periods"]), sweeps)
    if work > cap:
        f = {"points": int(s["points"]), "periods": int(s["periods"]), "direction": s["direction"]}
        longer = f", a higher lower frequency (f1 = {f1:.5g} Hz)" if longer_periods_weigh(f, work) else ""
        raise ValueError(f"[forcing] points × periods: {sweep_work_words(f, work)}, more than [limits] sweep_periods "
                         f"= {cap}: fewer points or periods{longer}, or raise [limits] sweep_periods")


def forcing_frequencies(reduced: ReducedModel, forcing: dict) -> np.ndarray:
    """The forcing frequencies (Hz) of the sweep: ``points`` values evenly spaced over ``frequencies`` in
    ``frequency_unit`` (``"Hz"``; ``"f1"``: × the first linear frequency of the reduced model that sees the
    contact; ``"rpm"``: rotation speeds, ``f = EO × rpm / 60``)."""
    s = _settings(forcing)
    lo, hi = s["frequencies"]
    if s["frequency_unit"] == "f1":
        scale = float(reduced.system.spectrum.contact_modes[0][0] / (2 * np.pi))
    elif s["frequency_unit"] == "rpm":
        scale = s["engine_order"] / 60.0
    else:
        scale = 1.0
    return np.linspace(lo, hi, int(s["points"])) * scale


@dataclass(frozen=True, eq=False)
class ForcedOrbit:
    """One cycle (``p`` forcing periods) of a forced steady state, re-simulated from its end state — the
    orbit-like record the animations take (``T``, ``k``, ``impact_times``, ``impulses``, ``energy``,
    ``system``, ``state(t)``).

    ``T = p × forcing_period``; times start at forcing phase 0 (the forcing is ``F₀ f cos(2πt/forcing_period)``);
    ``return_error`` is the relative mismatch (energy norm) of the state after one cycle, ``k`` the impacts
    the re-simulation finds in it; ``label`` the sweep's class.
    """

    trajectory: ForcedTrajectory | MasslessForcedTrajectory = field(repr=False)
    forcing_period: float
    p: int
    label: str
    energy: float
    return_error: float

    @property
    def T(self) -> float:
        return self.p * self.forcing_period

    @property
    def system(self):
        return self.trajectory.flight.system

    @property
    def k(self) -> int:
        """Impacts (massless model: contact phases begun) in the cycle ``(0, T]``."""
        return int(self.trajectory.impact_times.size)

    @property
    def impact_times(self) -> np.ndarray:
        return self.trajectory.impact_times

    @property
    def impulses(self) -> np.ndarray:
        return self.trajectory.impulses

    def state(self, t) -> tuple[np.ndarray, np.ndarray]:
        """``(x, v)`` at times ``t`` (taken modulo ``T``), shape ``(n, len(t))``."""
        return self.trajectory.state(np.mod(np.atleast_1d(np.asarray(t, dtype=float)), self.T))

    def _contact(self, t) -> np.ndarray:
        """Contact displacement at times ``t``: ``wᵀx``; massless model: ``min(ŵᵀx + gF₀cos Ωt, d)``."""
        tr = self.trajectory
        if isinstance(tr, MasslessForcedTrajectory):
            t = np.atleast_1d(np.asarray(t, dtype=float))
            return np.minimum(tr.flight.contact(tr.modal_state(t)[0], t), tr.flight.gap)
        return self.system.w @ tr.state(t)[0]

    def contact_range(self) -> tuple[float, float]:
        """``(min, max)`` of the contact displacement over the cycle (sampled, then refined)."""
        tr = self.trajectory
        h = 2 * np.pi / (ENERGY_SAMPLES * rate_max(tr))
        t = np.linspace(0.0, self.T, max(3, int(np.ceil(self.T / h)) + 1))
        c = self._contact(t)
        out = []
        for sign, i in ((-1.0, int(np.argmin(c))), (1.0, int(np.argmax(c)))):
            lo, hi = t[max(i - 1, 0)], t[min(i + 1, t.size - 1)]
            hits = tr.impact_times[(tr.impact_times > lo) & (tr.impact_times < hi)]
            best = float(c[i])
            if hits.size == 0 and hi > lo:
                res = minimize_scalar(lambda s, sign=sign: -sign * float(self._contact(s)[0]), bounds=(lo, hi),
                                      method="bounded", options={"xatol": 1e-12 * self.T})
                best = sign * max(sign * best, -float(res.fun))
            out.append(best)
        if self.k:  # at an impact / a closing switch the contact displacement is d
            out[1] = max(out[1], float(np.max(self._contact(tr.impact_times))))
        return out[0], out[1]


def steady_orbit(system, point: SweepPoint, *, damping: Damping, amplitude: float, load,
                 restitution: float = 1.0, contact_load: float = 0.0) -> ForcedOrbit:
    """Re-simulate one cycle (``p`` forcing periods; one period when not periodic) of a sweep point from its
    end state (forcing phase 0: a sweep point's run lasts a whole number of periods); either contact model."""
    p = point.p if point.periodic else 1
    T = point.T
    kw = dict(period=T, amplitude=amplitude, damping=damping, load=load)
    if isinstance(system, MasslessSystem):
        tr = simulate_forced_massless(system, point.x_end, point.v_end, p * T, contact_load=contact_load, **kw)
    else:
        tr = simulate_forced(system, point.x_end, point.v_end, p * T, restitution=restitution, **kw)
    fl = tr.flight
    z0 = np.concatenate(fl.encode(point.x_end, point.v_end))
    z1 = np.concatenate(fl.encode(tr.x_end, tr.v_end))
    weight = np.concatenate([fl.omega, np.ones(fl.omega.size)])
    err = float(np.linalg.norm(weight * (z1 - z0)) / max(np.linalg.norm(weight * z0), np.finfo(float).tiny))
    return ForcedOrbit(tr, T, p, point.label, point.energy, err)


def _damping(s: dict) -> Damping:
    if s["rayleigh"] is not None:
        alpha, beta = s["rayleigh"]
        return Damping(alpha=alpha, beta=beta)
    return Damping(zeta=s["ratio"])


def _row(direction: str, pt: SweepPoint, orbit: ForcedOrbit | None, eo) -> dict:
    lo, hi = orbit.contact_range() if orbit is not None else (np.nan, np.nan)
    f = 1.0 / pt.T
    return {"sweep": direction, "frequency_hz": f, "period_s": pt.T,
            "speed_rpm": float(eo.speed(f)) if eo is not None else None, "label": pt.label, "k": pt.k, "p": pt.p,
            "periodic": bool(pt.periodic), "energy_j": float(pt.energy), "mean_energy_j": float(pt.mean_energy),
            "contact_max_m": hi, "contact_amplitude_m": 0.5 * (hi - lo), "residual": float(pt.residual),
            "return_error": orbit.return_error if orbit is not None else np.nan,
            "resimulated_contacts": orbit.k if orbit is not None else None}


def _sweep(direction: str, system, periods, run: dict) -> tuple[str, list[SweepPoint]]:
    return direction, forced_sweep(system, periods, direction=direction, **run)


def forced_response(reduced: ReducedModel, families: list, forcing: dict, *, folder=None, figures: bool = False,
                    title: str = "", executor=None, progress: bool = False, max_periods: int | None = None) -> dict:
    """The forced response of ``reduced`` under ``[forcing]``, over the nonsmooth modes ``families``.

    Returns the ``summary.json`` section: the settings, ``points`` (columns :data:`COLUMNS`, one entry per
    steady state in the order visited), ``classes`` (count per label), ``peak`` (the highest-energy steady
    state that touches the casing, or the highest overall, and the nearest nonsmooth-mode arc), ``words``, and
    the files written into ``folder`` (``forced.csv``; ``forced_response.png`` when ``figures``).  The two
    sweeps of ``direction = "both"`` are mapped by ``executor``.  The record of each steady state
    (:class:`ForcedOrbit`) is kept under the key ``"orbits"`` (not for JSON: the caller pops it).

    Either contact model (the massless one: ``k`` counts contact phases, ``restitution`` must be 1).  Raises
    ``ValueError`` for bad ``[forcing]`` values, and before the sweep for work out of proportion
    (:func:`check_sweep_work`; ``max_periods``: ``[limits] sweep_periods``, ``None``: at most 1e9 periods ``T1``).

    Examples
    --------
    A steel strip forced at its contact corner, too weakly to reach the casing, around its first frequency:

    >>> from skfem import MeshTri
    >>> from bladecase.fe import Mesh, assemble
    >>> from bladecase.reduction import Contact, reduce
    >>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5))
    >>> p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    >>> model = assemble(Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 0] == 0)}),
    ...                  "steel", order=1, thickness=0.002)
    >>> reduced = reduce(model, Contact.nearest(model, (0.1, 0.02), normal=(0.0, 1.0), gap=1e-4), "modal", 4)
    >>> out = forced_response(reduced, [], {"ratio": 0.05, "amplitude": 0.5, "frequencies": [0.9, 1.1],
    ...                                     "points": 3, "periods": 100})
    >>> out["points"]["label"], [round(a * 1e6, 3) for a in out["points"]["contact_amplitude_m"]]   # µm
    (['0/1', '0/1', '0/1'], [2.441, 5.099, 2.136])
    >>> out["words"].split(". ")[0]
    '3 steady state(s) over 1573–1922 Hz (up sweep): 0 periodic with impacts, 3 without contact'
    """
    s = _settings(forcing)
    massless = isinstance(reduced.system, MasslessSystem)
    if massless and float(s["restitution"]) != 1.0:
        raise ValueError(f"[forcing] restitution: Newton's contact model only (the massless model has no impact "
                         f"law), got {s['restitution']!r}")
    f_free, load_words = build_load(reduced, s)
    f_r = project_load(reduced, f_free)
    g = contact_load(reduced, f_free)
    if not np.any(f_r) and g == 0.0:
        raise ValueError(f"[forcing] load: its projection on the {reduced.method} reduced model is zero (no reduced "
                         "mode feels it): load another place, or reduce with another method or size")
    check_sweep_work(reduced, s, f_r, g, max_periods)
    eo = engine_order_load(f_free, s["engine_order"]) if s["engine_order"] is not None else None
    freqs = forcing_frequencies(reduced, s)
    damping = _damping(s)
    run = dict(damping=damping, amplitude=float(s["amplitude"]), load=f_r, n_periods=int(s["periods"]),
               max_p=int(s["max_p"]), restitution=float(s["restitution"]), progress=progress, contact_load=g)
    directions = ["up", "down"] if s["direction"] == "both" else [s["direction"]]
    task = functools.partial(_sweep, system=reduced.system, periods=1.0 / freqs, run=run)
    swept = executor.map(task, directions, desc="forced sweeps", progress=progress) if executor is not None \
        else [task(d) for d in directions]
    rows, orbits = [], []
    for direction, points in swept:
        for pt in points:
            orbit = None if not pt.complete else steady_orbit(
                reduced.system, pt, damping=damping, amplitude=run["amplitude"], load=f_r,
                restitution=run["restitution"], contact_load=g)
            rows.append(_row(direction, pt, orbit, eo))
            orbits.append(orbit)
    columns = {name: [r[name] for r in rows] for name, _ in COLUMNS}
    unit = "Pa" if s["load"] == "pressure" else "N"
    section = {"contact_model": "massless" if massless else "newton",
               "load": load_words, "amplitude": float(s["amplitude"]), "amplitude_unit": unit,
               "damping": _damping_words(s), "engine_order": s["engine_order"], "direction": s["direction"],
               "periods_per_point": int(s["periods"]), "points": columns,
               "classes": _classes(columns["label"]), "files": {}}
    section["peak"] = _peak(columns, families)
    section["words"] = _words(section, eo, "contact phases" if massless else "impacts")
    if folder is not None:
        section["files"].update(_write(folder, columns, families, figures, title, reduced.system.gap, eo, massless))
    log.info("forced response: %s", section["words"])
    section["orbits"] = orbits
    return section


def _damping_words(s: dict) -> str:
    if s["rayleigh"] is not None:
        return f"Rayleigh C = {s['rayleigh'][0]:g} K + {s['rayleigh'][1]:g} M"
    return f"modal damping ratio {s['ratio']:g}"


def _classes(labels: list[str]) -> dict[str, int]:
    out: dict[str, int] = {}
    for lab in labels:
        out[lab] = out.get(lab, 0) + 1
    return dict(sorted(out.items()))


def _peak(c: dict, families: list) -> dict | None:
    """The highest-energy steady state (the forced peak) and the nonsmooth-mode arc nearest to it."""
    E = np.asarray(c["energy_j"], dtype=float)
    lab = np.asarray(c["label"], dtype=object)
    ok = np.isfinite(E)
    if not ok.any():
        return None
    i = int(np.flatnonzero(ok)[np.argmax(E[ok])])
    f = float(c["frequency_hz"][i])
    peak = {"index": i, "frequency_hz": f, "energy_j": float(E[i]), "label": str(lab[i]), "backbone": None}
    best = None
    for j, bb in enumerate(families):
        fb, Eb = bb.frequencies, bb.energy
        for arc in bb.arcs:
            fa, Ea = fb[arc.start:arc.stop + 1], Eb[arc.start:arc.stop + 1]
            good = np.isfinite(Ea) & (Ea > 0)
            if not good.any():
                continue
            fa, Ea = fa[good], Ea[good]
            order = np.argsort(fa)
            fa, Ea = fa[order], Ea[order]
            on = fa[0] <= f <= fa[-1]
            E_at = float(np.interp(f, fa, Ea)) if on else float(Ea[np.argmin(np.abs(fa - f))])
            df = 0.0 if on else float(np.min(np.abs(fa - f)) / f)
            score = (df, abs(E[i] / E_at - 1))
            if best is None or score < best[0]:
                best = (score, {"family": j, "ipp": bb.ipp, "on_arc": bool(on), "frequency_offset": df,
                                "energy_offset": float(E[i] / E_at - 1), "arc_hz": [float(fa[0]), float(fa[-1])]})
    if best is not None:
        peak["backbone"] = best[1]
    return peak


def _words(section: dict, eo, events: str = "impacts") -> str:
    c, classes = section["points"], section["classes"]
    n = len(c["label"])
    periodic = {k: v for k, v in classes.items() if "/" in k and not k.startswith("0/")}
    free = sum(v for k, v in classes.items() if k.startswith("0/")) + classes.get("linear", 0)
    parts = [f"{n} steady state(s) over {min(c['frequency_hz']):.4g}–{max(c['frequency_hz']):.4g} Hz "
             f"({section['direction']} sweep): {sum(periodic.values())} periodic with {events}"]
    if periodic:
        parts[-1] += " (" + ", ".join(f"{v} × {k}" for k, v in periodic.items()) + f" {events} per forcing periods)"
    if free:
        parts.append(f"{free} without contact")
    for key, text in (("non-periodic", "non-periodic"),
                      ("incomplete", "stopped (chattering)")):
        if classes.get(key):
            parts.append(f"{classes[key]} {text}")
    text = ", ".join(parts) + "."
    pk = section["peak"]
    if pk is None:
        return text
    where = f" ({eo.speed(pk['frequency_hz']):.5g} rpm)" if eo is not None else ""
    text += f" The forced peak at {pk['frequency_hz']:.5g} Hz{where} (E = {pk['energy_j']:.3g} J, {pk['label']})"
    bb = pk["backbone"]
    if bb is None:
        return text + " has no nonsmooth-mode arc to compare with."
    off = f"energy {abs(bb['energy_offset']) * 100:.3g} % {'above' if bb['energy_offset'] > 0 else 'below'}"
    mode = (f"nonsmooth mode ({_phases(bb['ipp'])})" if events == "contact phases"
            else f"{bb['ipp']}-ipp nonsmooth mode")
    if bb["on_arc"]:
        return text + f" lies on an admissible arc of the {mode} ({off})."
    return text + (f" lies outside the nonsmooth-mode arcs: the nearest, the {mode} over "
                   f"{bb['arc_hz'][0]:.5g}–{bb['arc_hz'][1]:.5g} Hz, is {bb['frequency_offset'] * 100:.3g} % away in "
                   f"frequency ({off} at its end).")


def _phases(k: int) -> str:
    return "one contact phase per period" if k == 1 else f"{k} contact phases per period"


def _write(folder, c: dict, families: list, figures: bool, title: str, gap: float, eo,
           massless: bool = False) -> dict:
    from pathlib import Path

    folder = Path(folder)
    header = ",".join(name for name, _ in COLUMNS)  # the unit is the name's suffix (COLUMNS)
    lines = [header]
    for i in range(len(c["label"])):
        lines.append(",".join("" if c[name][i] is None else
                              (f"{c[name][i]:.12g}" if isinstance(c[name][i], float) else str(c[name][i]))
                              for name, _ in COLUMNS))
    write_text(folder / "forced.csv", "\n".join(lines) + "\n")
    files = {"csv": "forced.csv"}
    if figures:
        fig = forced_response_plot(c["frequency_hz"], c["energy_j"], c["label"], sweep=c["sweep"],
                                   backbones=[f for f in families if f.arcs], gap=gap,
                                   engine_order=None if eo is None else eo.engine_order, massless=massless,
                                   title=f"{title}: forced response over the nonsmooth modes" if title else None)
        save_figure(fig, folder / "forced_response.png")
        files["figure"] = "forced_response.png"
    return files


def forced_scene(study, reduced: ReducedModel, orbit: ForcedOrbit, stem: str):
    """The steady state ``orbit`` at ``[output] frames`` instants on every node of the mesh: an
    :class:`~bladecase.post.outputs.OrbitScene` for the orbit-scope writers (``FORMATS.write(formats, "orbit",
    scene, folder)``: GIF/MP4 animations, VTK time series; no manifold: a forced state has no branch)."""
    from ...post import animation
    from ...post.grid import fe_grid, grid_index, nodal_field
    from ...post.outputs import OrbitScene
    from ...post.prestress import centrifugal_fields
    from ..choose import frame_times

    o = study["output"]
    times, impact = frame_times(orbit, o["frames"])
    phases = np.mod(orbit.impact_times / orbit.T, 1.0)
    impact[0] = bool(np.any((phases < 1e-9) | (phases > 1 - 1e-9)))  # frame_times marks t = 0 for an autonomous orbit
    x, v = orbit.state(times)
    model = reduced.model
    x_free, v_free = reduced.free_dofs(x), reduced.free_velocities(x, v)
    if isinstance(orbit.trajectory, MasslessForcedTrajectory):
        x_free, v_free = _massless_contact_dofs(study, reduced, orbit, times, x, v, x_free, v_free)
    u = nodal_field(model, x_free)
    vel = nodal_field(model, v_free)
    mesh = fe_grid(model)
    scale = animation.auto_scale(mesh, u, o["auto_fraction"]) if o["scale"] == "auto" else float(o["scale"])
    title = (f"{study.name}: forced steady state {orbit.label} at {1 / orbit.forcing_period:.5g} Hz")
    return OrbitScene(stem=stem, title=title, mesh=mesh, orbit=orbit, times=times, u=u, v=vel, impact=impact,
                      contact_node=int(grid_index(model, reduced.contact.node)),
                      normal=reduced.contact.normal_for(model), scale=scale, options=o, branch=None,
                      point_data=centrifugal_fields(model))


def _massless_contact_dofs(study, reduced: ReducedModel, orbit: ForcedOrbit, times, x, v, x_free, v_free):
    """The massless contact dofs of a forced steady state: ``reduced.free_dofs`` slaves them to the interior with
    the unforced multiplier; a load ``F(t) f_c`` on them adds ``F K_cc⁻¹f_c`` and moves the multiplier to
    ``λ = k_c max(0, ŵᵀx + gF − d)`` (:func:`contact_load`). Returns the corrected ``(x_free, v_free)``."""
    shape = np.asarray(reduced.closed_shape, dtype=float)  # −K_cc⁻¹w_c on the contact dofs c
    c = np.flatnonzero(shape)
    f_free, _ = build_load(reduced, study["forcing"])
    f_c = np.asarray(f_free, dtype=float)[c]
    if not np.any(f_c):
        return x_free, v_free
    K_cc = reduced.model.K[c][:, c]
    K_cc = K_cc.toarray() if hasattr(K_cc, "toarray") else np.asarray(K_cc)
    load_c = np.linalg.solve(K_cc, f_c)  # K_cc⁻¹f_c
    s, amp = reduced.system, float(study["forcing"]["amplitude"])
    Om = 2 * np.pi / orbit.forcing_period
    F, dF = amp * np.cos(Om * times), -amp * Om * np.sin(Om * times)
    g = contact_load(reduced, f_free)
    y0, dy0 = s.w @ x - s.gap, s.w @ v  # what free_dofs used (no load)
    y, dy = y0 + g * F, dy0 + g * dF
    lam0, lam = s.kc * np.maximum(y0, 0.0), s.kc * np.maximum(y, 0.0)
    dlam0, dlam = s.kc * np.where(y0 > 0, dy0, 0.0), s.kc * np.where(y > 0, dy, 0.0)
    x_free, v_free = np.array(x_free, dtype=float), np.array(v_free, dtype=float)
    x_free[c] += np.outer(load_c, F) + np.outer(shape[c], lam - lam0)
    v_free[c] += np.outer(load_c, dF) + np.outer(shape[c], dlam - dlam0)
    return x_free, v_free
