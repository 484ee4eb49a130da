"""The JSON documents of a study: the modes file (every branch, every orbit) and the run's summary parts.

Branches are serialised in one place, :meth:`bladecase.nsm.Branch.to_dict` / :meth:`~bladecase.nsm.Branch.from_dict`;
this module only wraps them with the system they belong to — and its fingerprint (:func:`system_fingerprint`), so
that a modes file is never read back against another reduced model or clearance, and re-checks every orbit a
modes file says is admissible (:func:`load_families`).
"""

from __future__ import annotations

import hashlib
import json
import os
import weakref
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ..checks import is_integer
from ..fe import FEModel, Mesh
from ..fe.select import held_nodes
from ..nsm import Branch, LinearSystem, MasslessSystem, PeriodicOrbit
from ..reduction import Contact, ReducedModel
from .arc_figures import (  # noqa: F401 (ENGINEERING_*, TONGUE_SHARE: documented here before)
    ENGINEERING_RANGES,
    ENGINEERING_SAMPLES,
    TONGUE_SHARE,
    _arc_picks,
    _backbone,
    _range,
)

#: Largest scale-free residual of an orbit's equations (impact conditions ``ΠΛ = 0``, ``ΣΛ = d``; the massless
#: closing conditions) accepted when a modes file is read back: solved orbits are at round-off (~1e-13).
ORBIT_RTOL = 1e-8

#: The modes file's key holding :func:`system_fingerprint` of the system its families were computed on.
FINGERPRINT_KEY = "system_fingerprint"


def _check_system(system, what: str) -> None:
    if not isinstance(system, (LinearSystem, MasslessSystem)):
        raise ValueError(f"{what}: system must be a LinearSystem or a MasslessSystem (e.g. a reduced model's "
                         f".system), got {type(system).__name__}")


def system_fingerprint(system: LinearSystem | MasslessSystem) -> str:
    """``"sha256:…"`` of what defines ``system``: its contact model, matrices, contact vector, clearance (and, for
    the massless model, the contact and casing stiffnesses) — exactly, as float64 values.

    The same for a dense and a sparse copy of one matrix (its non-zero entries are hashed in row-major order with
    their indices and its shape), different for another reduced model or another clearance.

    >>> from bladecase.nsm import chain
    >>> a, b = system_fingerprint(chain(2, gap=1.0)), system_fingerprint(chain(2, gap=0.5))
    >>> a.startswith("sha256:"), a == system_fingerprint(chain(2, gap=1.0)), a == b
    (True, True, False)
    """
    _check_system(system, "system_fingerprint")
    h = hashlib.sha256()
    if isinstance(system, MasslessSystem):
        h.update(b"bladecase-system-1:massless")
        parts = (("M", system.M), ("S", system.S), ("w", system.w), ("kc", system.kc), ("gap", system.gap),
                 ("casing", system.casing))
    else:
        h.update(b"bladecase-system-1:newton")
        parts = (("M", system.M), ("K", system.K), ("w", system.w), ("gap", system.gap))
    for name, value in parts:
        h.update(name.encode())
        _hash_values(h, value)
    return "sha256:" + h.hexdigest()


def _hash_values(h, value) -> None:
    """A matrix (dense or sparse) as its shape and its non-zero ``(row, column, value)`` in row-major order; a
    vector or a number as its shape and its values (float64, ``-0.0`` as ``0.0``)."""
    if sp.issparse(value) or np.ndim(value) == 2:
        if sp.issparse(value):
            A = sp.csr_array(value, dtype=float, copy=True)
            A.sum_duplicates()
            A.eliminate_zeros()
            A.sort_indices()
            rows = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))
            cols, vals = A.indices, A.data
        else:
            A = np.asarray(value, dtype=float)
            rows, cols = np.nonzero(A)
            vals = A[rows, cols]
        h.update(np.asarray(A.shape, dtype=np.int64).tobytes())
        for arr, dtype in ((rows, np.int64), (cols, np.int64), (vals + 0.0, np.float64)):
            h.update(np.ascontiguousarray(arr, dtype=dtype).tobytes())
        return
    arr = np.asarray(value, dtype=float)
    h.update(np.asarray(arr.shape, dtype=np.int64).tobytes())
    h.update(np.ascontiguousarray(arr + 0.0, dtype=np.float64).tobytes())


def families_document(families: list[Branch], system: LinearSystem | MasslessSystem) -> dict:
    """The modes file's content: the system's size, gap and fingerprint (:func:`system_fingerprint`), and every
    branch (each computed on ``system``: ``ValueError`` otherwise)."""
    _check_system(system, "families_document")
    if isinstance(families, (str, bytes, dict)) or not hasattr(families, "__iter__"):
        raise ValueError(f"families_document: families must be a list of Branch, got {type(families).__name__}")
    families = list(families)
    fingerprint = system_fingerprint(system)
    for i, fam in enumerate(families):
        if not isinstance(fam, Branch):
            raise ValueError(f"families_document: family {i} must be a Branch, got {type(fam).__name__}")
        if fam.system is not None and fam.system is not system and (
                not isinstance(fam.system, (LinearSystem, MasslessSystem))
                or system_fingerprint(fam.system) != fingerprint):
            raise ValueError(f"families_document: family {i} ({fam.k}-ipp) was computed on another system "
                             f"({fam.system!r}) than the one given ({system!r})")
    return {"system_dofs": system.n, "gap": system.gap, FINGERPRINT_KEY: fingerprint,
            "families": [_with_stability(f if f.system is not None else f.bind(system)) for f in families]}


def _with_stability(fam: Branch) -> dict:
    """``fam.to_dict()`` with every orbit's ``stable``, ``stability`` (the verdict, or why there is none) and
    ``multipliers`` (:func:`stability_records`)."""
    out = fam.to_dict()
    for rec, st in zip(out["orbits"], stability_records(fam)):
        if st is None:  # a resonant scan period: no orbit
            rec["stability"] = "no orbit (resonant period)"
        else:
            rec.update(st)
    return out


def load_families(path: str | os.PathLike, system: LinearSystem | MasslessSystem,
                  reduced: str | os.PathLike | None = None) -> list[Branch]:
    """Branches from a modes JSON file (``bladecase modes``), attached to ``system``.

    ``ValueError`` naming the file for an unreadable or malformed file, a file computed on another system (its
    size, or its fingerprint, :func:`system_fingerprint`: another reduced model or another clearance), a file
    without a fingerprint (written by an older version), arcs that do not point at admissible orbits of their
    family, or an orbit marked admissible that is not an admissible orbit of ``system`` — each such orbit is
    re-checked (its equations solved to :data:`ORBIT_RTOL`, its admissibility proved again): a hand-edited or
    truncated file is refused, naming the family and the period.  ``reduced``: the reduced-model file
    ``system`` comes from, named in the messages.
    """
    where = f"modes file {str(path)!r}"
    again = f"run `bladecase modes` again on {str(reduced) if reduced is not None else 'the reduced model'}"
    _check_system(system, f"load_families({str(path)!r})")
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise ValueError(f"cannot read {where}: {exc}") from None
    if not isinstance(data, dict) or not isinstance(data.get("families"), list):
        raise ValueError(f"{where} is not a bladecase modes file: expected an object with a list 'families' "
                         "(write one with 'bladecase modes')")
    n = data.get("system_dofs")
    if n is not None and not is_integer(n):
        raise ValueError(f"{where}: 'system_dofs' must be an integer number of dofs, got {n!r}")
    if n is not None and n != system.n:
        raise ValueError(f"{where} was computed on a system of {n} dofs, this one has {system.n}")
    _check_fingerprint(data, system, where, again)
    try:
        fams = [Branch.from_dict(system, f) for f in data["families"]]
    except KeyError as exc:
        raise ValueError(f"cannot read {where}: field {exc} is missing") from None
    except (ValueError, TypeError, AttributeError, IndexError) as exc:
        raise ValueError(f"cannot read {where}: {exc}") from None
    for i, (fam, raw) in enumerate(zip(fams, data["families"])):
        _recertify(fam, raw, system, f"{where}: family {i} ({fam.k}-ipp)", again)
        _check_arcs(fam, i, where)
    return fams


def _check_fingerprint(data: dict, system, where: str, again: str) -> None:
    """The file's fingerprint is the system's (``ValueError`` naming both otherwise, or when it has none)."""
    stored = data.get(FINGERPRINT_KEY)
    if stored is None:
        raise ValueError(f"{where} has no fingerprint of the system it was computed on: it was written by an older "
                         f"bladecase version, and cannot be checked against this reduced model and clearance; "
                         f"{again}")
    own = system_fingerprint(system)
    if stored != own:
        gap = data.get("gap")
        note = (f"; its clearance is {gap!r}, this model's {system.gap!r}"
                if isinstance(gap, (int, float)) and not isinstance(gap, bool) and gap != system.gap else "")
        raise ValueError(f"{where} was computed for another reduced model or clearance (fingerprint "
                         f"{str(stored)[:19]}…, this model's {own[:19]}…{note}): {again}")


def _recertify(fam: Branch, raw: dict, system, where: str, again: str) -> None:
    """Every orbit of ``fam`` the file marks admissible is an admissible orbit of ``system``: its equations hold
    (:data:`ORBIT_RTOL`) and its admissibility is proved again (``ValueError`` naming it otherwise)."""
    records = raw.get("orbits") if isinstance(raw, dict) else None
    marked = [j for j, o in enumerate(fam.orbits) if o is not None and (
        o.admissible if isinstance(o, PeriodicOrbit) else bool((records[j] or {}).get("admissible")))]
    if not marked:
        return
    if isinstance(system, MasslessSystem):
        problems = {j: _massless_problem(system, fam.orbits[j]) for j in marked}
    else:
        problems = _newton_problems(system, [fam.orbits[j] for j in marked])
        problems = dict(zip(marked, problems))
    bad = [(j, why) for j, why in problems.items() if why]
    if bad:
        j, why = bad[0]
        more = f" (and {len(bad) - 1} more orbit(s) of this family)" if len(bad) > 1 else ""
        raise ValueError(f"{where}, orbit {j} at T = {fam.orbits[j].T:.10g} is marked admissible but is not an "
                         f"admissible orbit of this system: {why}{more} — a hand-edited file, or one computed on "
                         f"another model; {again}")


def _newton_problems(system: LinearSystem, orbits: list) -> list[str | None]:
    """Why each of ``orbits`` (Newton contact, one family) is not an admissible orbit of ``system`` (``None``:
    it is)."""
    from ..nsm import ModalKernel, check_period
    from ..nsm.newton.modal import check_times
    from ..nsm.newton.orbits import make_orbits

    out: list[str | None] = [None] * len(orbits)
    ok = []
    for j, o in enumerate(orbits):
        try:
            T = check_period(system, o.T)
            times = check_times(o.impact_times)
            lam = np.asarray(o.impulses, dtype=float).reshape(-1)
            if lam.shape != times.shape or not np.all(np.isfinite(lam)):
                raise ValueError(f"{lam.size} impulse(s) for {times.size} impact time(s)")
            if abs(times[-1] - T) > 1e-12 * T:
                raise ValueError(f"the last impact time {times[-1]!r} is not the period {T!r}")
            md = ModalKernel.of(system, T)
            Pi, Sigma = md.matrices(times)
            scale = max(np.abs(Sigma).max(), np.abs(Pi).max()) * max(np.abs(lam).max(), np.finfo(float).tiny)
            r_pi = np.abs(Pi @ lam).max() / scale
            r_sigma = np.abs(Sigma @ lam - system.gap).max() / system.gap
        except (ValueError, np.linalg.LinAlgError) as exc:
            out[j] = f"its impact data do not define an orbit here ({exc})"
            continue
        if max(r_pi, r_sigma) > ORBIT_RTOL:
            out[j] = (f"its impact times and impulses do not solve the orbit equations of this system (relative "
                      f"residual {max(r_pi, r_sigma):.3g} > {ORBIT_RTOL:g})")
            continue
        ok.append(j)
    if ok:
        again = make_orbits(system, [orbits[j].T for j in ok], [orbits[j].impact_times for j in ok],
                            [orbits[j].impulses for j in ok])
        for j, o in zip(ok, again):
            stored = float(orbits[j].energy)
            if not abs(stored - o.energy) <= ORBIT_RTOL * abs(o.energy):  # NaN too
                out[j] = f"its energy {stored:.10g} is not the orbit's ({o.energy:.10g})"
                continue
            if o.admissible:
                continue
            if np.any(o.impulses < 0):
                out[j] = f"an impulse is negative ({float(o.impulses.min()):.6g}): the casing would pull"
            else:
                out[j] = (f"it crosses the casing (wᵀx - d = {o.max_violation:.6g} at t = {o.max_violation_time:.6g}, "
                          "beyond the tolerance of the proof) or its admissibility cannot be proved")
    return out


def _massless_problem(system: MasslessSystem, orbit) -> str | None:
    """Why ``orbit`` (massless contact) is not an admissible orbit of ``system`` (``None``: it is)."""
    from ..nsm.massless.orbits import SymmetricOrbit, closing_residual
    from ..nsm.massless.phases import PhasedOrbit, solve_half

    try:
        if isinstance(orbit, SymmetricOrbit):
            a, r = closing_residual(system, orbit.alpha, orbit.beta)
        elif isinstance(orbit, PhasedOrbit):
            a, r = solve_half(system, orbit.first, orbit.durations)
        else:
            return f"it is a {type(orbit).__name__}, not an orbit of the massless contact model"
        r = np.atleast_1d(np.asarray(r, dtype=float))
        stored = np.asarray(orbit.a, dtype=float)
        if stored.shape != np.shape(a) or not np.all(np.isfinite(r)):
            raise ValueError(f"{stored.size} amplitude(s) for a system of {system.n} interior dofs")
    except (ValueError, np.linalg.LinAlgError, IndexError, KeyError) as exc:
        return f"its data do not define an orbit here ({exc})"
    off = max(np.abs(r).max() / system.gap,
              np.abs(stored - a).max() / max(np.abs(a).max(), np.finfo(float).tiny))
    if off > ORBIT_RTOL:
        return (f"its phases and amplitudes do not solve the orbit equations of this system (relative residual "
                f"{off:.3g} > {ORBIT_RTOL:g})")
    if not orbit.admissible:
        return "its admissibility is not proved (the contact force turns negative, or it crosses the casing)"
    return None


def _check_arcs(fam: Branch, i: int, where: str) -> None:
    """Every arc of family ``i`` spans existing, admissible orbits."""
    for j, arc in enumerate(fam.arcs):
        if not 0 <= arc.start <= arc.stop < len(fam.orbits):
            raise ValueError(f"{where}: family {i}, arc {j} spans orbits {arc.start}..{arc.stop}, but the family has "
                             f"{len(fam.orbits)} orbit(s) (valid: 0 <= start <= stop <= {len(fam.orbits) - 1})")
        bad = [k for k in range(arc.start, arc.stop + 1) if fam.orbits[k] is None or not fam.orbits[k].admissible]
        if bad:
            raise ValueError(f"{where}: family {i}, arc {j} (orbits {arc.start}..{arc.stop}) includes orbit {bad[0]}, "
                             "which is not admissible: an arc spans admissible orbits only")


def family_summary(fam: Branch, engineering=None) -> dict:
    """Period, frequency and energy ranges of a branch, and its admissible arcs (each with the share of its orbits
    that are linearly stable, :func:`stability_records`).

    ``engineering``: a function of an orbit giving its engineering quantities
    (:func:`bladecase.study.render.orbit_engineering` bound to the reduced model); each arc then gets their ranges
    over its admissible orbits (:func:`_arc_engineering`).
    """
    T, E = fam.T, fam.energy
    records = stability_records(fam)
    out = {
        "ipp": fam.k,
        "orbits": len(fam.orbits),
        "period_range_s": _range(T),
        "frequency_range_hz": _range(1 / T),
        "energy_range_j": _range(E),
        "admissible_orbits": int(fam.admissible.sum()),
        "admissible_arcs": [
            {"T_lo": a.T_lo, "T_hi": a.T_hi, "f_lo": 1 / a.T_hi, "f_hi": 1 / a.T_lo,
             "energy_range_j": _range(E[a.start:a.stop + 1][fam.admissible[a.start:a.stop + 1]]),
             "refined_lo": bool(a.refined_lo), "refined_hi": bool(a.refined_hi),
             "stable_fraction": _stable_fraction(records[a.start:a.stop + 1]),
             **_backbone(fam, a, engineering)} for a in fam.arcs
        ],
    }
    out["resonance"] = _resonance(fam, E)
    return out


#: A family whose energy grows by more than this factor is checked for an internal resonance at its top.
RESONANCE_GROWTH = 30.0


def _resonance(fam: Branch, E: np.ndarray) -> dict | None:
    """Where the energy of a family that grows without bound goes: the mode holding the largest share of its
    most energetic orbit (time-averaged over the free flights), when that is not the family's own mode."""
    from ..nsm.energy import modal_energy_split

    if not np.isfinite(E).any() or not np.nanmax(E) > RESONANCE_GROWTH * np.nanmin(E):
        return None
    top = fam.orbits[int(np.nanargmax(E))]
    split = modal_energy_split(top)
    j = int(np.argmax(split.shares))
    f = 1 / top.T
    if split.frequencies[j] < 1.5 * f:
        return None  # the family's own (lowest) mode holds it: a stiffening, not a resonance
    return {"frequency_hz": float(f), "growth": float(np.nanmax(E) / np.nanmin(E)), "mode": j + 1,
            "mode_frequency_hz": float(split.frequencies[j]), "share": float(split.shares[j]),
            "ratio": float(split.frequencies[j] / f)}


#: Systems of at most this many dofs get the Floquet verdict of every admissible orbit (modes file, summary).
#: Larger ones — a ``2n × 2n`` monodromy per orbit, its eigenvalues costing ``~(2n)³`` — get it for
#: :data:`STABILITY_SAMPLES` orbits per admissible arc, evenly spread, both ends included.
STABILITY_DOFS = 100

#: Orbits per admissible arc whose Floquet multipliers are computed on a system above :data:`STABILITY_DOFS` dofs.
STABILITY_SAMPLES = 50

#: Why an orbit has no Floquet verdict in the modes file: it is not a motion of the blade against the casing.
NOT_ADMISSIBLE = "not computed: the orbit is not admissible (it crosses the casing, or the casing would pull)"

#: Floquet records already computed, per orbit object (the modes file and the summary ask for the same orbits).
_STABILITY: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def orbit_stability(orbit) -> dict:
    """The Floquet verdict of one orbit (:func:`bladecase.nsm.floquet.floquet`, either contact model):
    ``{"stable": bool, "stability": verdict in words, "multipliers": [[re, im], …]}``; with no verdict (e.g. a
    grazing impact) ``stable`` is ``None`` and ``stability`` says why. Computed once per orbit object."""
    from ..nsm.floquet import floquet

    try:
        return _STABILITY[orbit]
    except (KeyError, TypeError):
        pass
    try:
        fl = floquet(orbit)
        out = {"stable": bool(fl.stable), "stability": fl.verdict,
               "multipliers": [[float(z.real), float(z.imag)] for z in fl.multipliers]}
    except ValueError as exc:
        out = {"stable": None, "stability": f"no verdict ({exc})", "multipliers": None}
    try:
        _STABILITY[orbit] = out
    except TypeError:  # an orbit record that takes no weak reference: not cached
        pass
    return out


def _sampled(fam: Branch) -> bool:
    """Whether the Floquet verdicts of ``fam`` are sampled (a system above :data:`STABILITY_DOFS` dofs)."""
    return fam.system is not None and fam.system.n > STABILITY_DOFS


def stability_records(fam: Branch) -> list[dict | None]:
    """One Floquet record per point of ``fam`` (:func:`orbit_stability`; ``None`` at a resonant scan period).

    Every admissible orbit on an admissible arc is analysed (on a system above :data:`STABILITY_DOFS` dofs,
    :data:`STABILITY_SAMPLES` per arc); the others say why they have no verdict (``stable`` is ``None``, never
    without a reason in ``stability``): not admissible (:data:`NOT_ADMISSIBLE`), or not sampled.
    """
    picked = {j for a in fam.arcs for j in _arc_picks(fam, a, STABILITY_SAMPLES if _sampled(fam) else None)}
    out: list[dict | None] = []
    for j, o in enumerate(fam.orbits):
        if o is None:
            out.append(None)
        elif j in picked:
            out.append(orbit_stability(o))
        elif not o.admissible:
            out.append({"stable": None, "stability": NOT_ADMISSIBLE, "multipliers": None})
        elif _sampled(fam) and any(a.start <= j <= a.stop for a in fam.arcs):
            out.append({"stable": None, "multipliers": None,
                        "stability": f"not computed: on a system of {fam.system.n} dofs the multipliers are "
                                     f"computed for {STABILITY_SAMPLES} orbits per admissible arc, evenly spread"})
        else:
            out.append({"stable": None, "stability": "not computed: admissible, but on no admissible arc",
                        "multipliers": None})
    return out


def _stable_fraction(records: list[dict | None]) -> float | None:
    """Share of the analysed orbits (records of :func:`stability_records`) that are linearly stable (Floquet),
    ``None`` when none has a verdict."""
    verdicts = [r["stable"] for r in records if r is not None and r["stable"] is not None]
    return float(np.mean(verdicts)) if verdicts else None


def reduced_summary(reduced: ReducedModel, reference_hz: np.ndarray, fe=None) -> dict:
    """A reduced model's frequencies and contact weights, with the nearest-frequency error vs ``reference_hz``;
    with ``fe`` (:func:`~bladecase.post.comparison.compare.fe_reference`) each mode's FE counterpart by mode shape
    (MAC): ``fe_match`` per listed mode, ``None`` when it has none (an artefact) or lies above the FE modes computed."""
    sp = reduced.system.spectrum
    f = sp.frequencies[sp.active]
    nearest = [float(np.min(np.abs(f - fr)) / fr) if f.size else None for fr in reference_hz]
    out = {"method": reduced.method, "size": reduced.size, "reduced_dofs": reduced.n,
           "frequencies_hz": f.tolist(), "contact_weights_b2": (sp.b[sp.active] ** 2).tolist(),
           "relative_error_vs_fe": nearest}
    if fe is not None:
        from ..post.comparison.compare import model_matches

        found = {m.index: m for m in model_matches(reduced, fe, modes=12)}
        out["fe_match"] = [_match(found.get(int(j))) for j in np.flatnonzero(sp.active)]
    return out


def _match(m) -> dict | None:
    if m is None:
        return None
    return {"fe_mode": None if m.fe_index is None else m.fe_index + 1, "mac": m.mac, "best_fe": m.best_fe + 1,
            "relative_error": m.relative_error, "beyond_fe": m.beyond_fe}


def model_summary(mesh: Mesh, model: FEModel, f_fe: np.ndarray, source: str) -> dict:
    """The mesh and FE model of a run: sizes, material, mass and linear frequencies."""
    m = model.material
    return {
        "mesh": {"nodes": len(mesh.points), "cells": len(mesh.cells[mesh.body_type]), "type": mesh.body_type,
                 "source": source, "unit": mesh.unit, "node_numbering": mesh.numbering,
                 "extent_m": float(np.ptp(mesh.points, axis=0).max())},
        "dim": model.dim, "dofs": model.n_dofs, "order": model.order, "mass_matrix": model.mass,
        "thickness_m": model.thickness, "plane": model.plane,
        "material": {"name": m.name, "E": m.E, "nu": m.nu, "rho": m.rho},
        "total_mass_kg": model.total_mass, "clamped_nodes": int(held_nodes(mesh, model.clamped).size),
        "clamped_corner_nodes": int(model.clamped.size),
        "linear_frequencies_hz": np.asarray(f_fe).tolist(),
    }


def contact_summary(contact: Contact, model: FEModel, reduced: ReducedModel | None = None, fe=None,
                    face: str | None = None) -> dict:
    """Contact node, its position, the casing normal, the clearance and the casing's stiffness (None: rigid).

    With ``reduced``: the contact model (``"newton"`` or ``"massless"``) and, for the massless one, the contact's
    own stiffness ``k_c = 1/(w_cᵀK_cc⁻¹w_c)`` (the contact dofs with the interior held) and its value in series with
    the casing (:func:`~bladecase.nsm.series_stiffness`); with ``fe``
    (:func:`~bladecase.post.comparison.compare.fe_reference`) the blade's static stiffness at the contact
    ``1/(wᵀK⁻¹w)`` (the whole blade); ``face``: the name of a face contact's node group.
    """
    ids = model.mesh.node_ids
    out = {"node": contact.node, "node_id": int(ids[contact.node]), "face_nodes": list(contact.nodes),
           "face_node_ids": [int(ids[k]) for k in contact.nodes],
           "casing_stiffness_n_per_m": None if np.isinf(contact.casing) else contact.casing,
           "face_weights": "area" if contact.weights else "equal",
           "position": model.mesh.points[contact.node].tolist(),
           "normal": contact.normal_for(model).tolist(), "clearance_m": contact.gap}
    if face is not None and contact.nodes:
        out["face"] = face
    if reduced is not None:
        system = reduced.system
        out["model"] = getattr(system, "contact_model", "newton")
        if isinstance(system, MasslessSystem):
            out["contact_stiffness_n_per_m"] = float(system.kc_structure)
            out["series_stiffness_n_per_m"] = float(system.kc)
    if fe is not None and fe.static_compliance > 0:
        out["static_stiffness_n_per_m"] = 1.0 / float(fe.static_compliance)
    return out


def write_mesh(mesh: Mesh, staging: Path, files: dict, source: str, what: str = "mesh", note: str = "") -> None:
    """A run's ``mesh.vtu`` in ``staging``, named in ``files``, and its one log line ("mesh: 412 nodes, 180 tetra10
    cells (gmsh)"; ``source``: where the mesh came from, ``note`` what the line adds)."""
    from .. import log
    from ..fe import save_mesh

    save_mesh(mesh, staging / "mesh.vtu")
    files["mesh"] = "mesh.vtu"
    log.info("%s: %d nodes, %d %s cells (%s)%s", what, len(mesh.points), len(mesh.cells[mesh.body_type]),
             mesh.body_type, source, note)
