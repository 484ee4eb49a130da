"""The JSON documents of a study: the modes file (every branch, every orbit) and the run's summary parts.

Branches are serialised in one place, :meth:`bladecase.nsm.Branch.to_dict` / :meth:`~bladecase.nsm.Branch.from_dict`;
this module only wraps them with the system they belong to.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from ..checks import is_integer
from ..fe import FEModel, Mesh
from ..nsm import Branch, LinearSystem
from ..reduction import Contact, ReducedModel


def families_document(families: list[Branch], system: LinearSystem) -> dict:
    """The modes file's content: the system's size and gap, and every branch."""
    return {"system_dofs": system.n, "gap": system.gap, "families": [f.to_dict() for f in families]}


def load_families(path: str | os.PathLike, system: LinearSystem) -> list[Branch]:
    """Branches from a modes JSON file (``bladecase modes``), attached to ``system`` (orbits as stored).

    ``ValueError`` naming the file for an unreadable or malformed file, a file computed on another system,
    or arcs that do not point at admissible orbits of their family (a hand-edited or truncated file).
    """
    where = f"modes file {str(path)!r}"
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
    try:
        fams = [Branch.from_dict(system, f) for f in data["families"]]
    except KeyError as exc:
        raise ValueError(f"cannot read {where}: field {exc} is missing") from None
    except (ValueError, TypeError, AttributeError, IndexError) as exc:
        raise ValueError(f"cannot read {where}: {exc}") from None
    for i, fam in enumerate(fams):
        _check_arcs(fam, i, where)
    return fams


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


def _range(values: np.ndarray) -> list[float | None]:
    """``[min, max]`` of the finite values; ``[None, None]`` (JSON ``null``: no value) when there is none."""
    values = values[np.isfinite(values)]
    return [float(values.min()), float(values.max())] if values.size else [None, None]


def family_summary(fam: Branch) -> dict:
    """Period, frequency and energy ranges of a branch, and its admissible arcs."""
    T, E = fam.T, fam.energy
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
             "stable_fraction": _stable_fraction(fam.orbits[a.start:a.stop + 1])} for a in fam.arcs
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


#: Most orbits of an arc whose Floquet multipliers are computed for the summary (evenly sampled beyond).
STABILITY_SAMPLES = 50


def _stable_fraction(orbits: list) -> float | None:
    """Share of the arc's admissible orbits that are linearly stable (Floquet), ``None`` when none has a verdict."""
    from ..nsm.floquet import floquet

    pool = [o for o in orbits if o is not None and o.admissible]
    if len(pool) > STABILITY_SAMPLES:
        pool = [pool[i] for i in np.linspace(0, len(pool) - 1, STABILITY_SAMPLES).astype(int)]
    verdicts = []
    for o in pool:
        try:
            verdicts.append(floquet(o).stable)
        except ValueError:  # grazing impact or no verdict: left out
            continue
    return float(np.mean(verdicts)) if verdicts else None


def reduced_summary(reduced: ReducedModel, reference_hz: np.ndarray, fe=None) -> dict:
    """A reduced model's frequencies and contact weights, with the nearest-frequency error vs ``reference_hz``;
    with ``fe`` (:func:`~bladecase.post.compare.fe_reference`) each mode's FE counterpart by mode shape (MAC):
    ``fe_match`` per listed mode, ``None`` when it has none (an artefact) or lies above the FE modes computed."""
    sp = reduced.system.spectrum
    f = sp.frequencies[sp.active]
    nearest = [float(np.min(np.abs(f - fr)) / fr) if f.size else None for fr in reference_hz]
    out = {"method": reduced.method, "size": reduced.size, "reduced_dofs": reduced.n,
           "frequencies_hz": f.tolist(), "contact_weights_b2": (sp.b[sp.active] ** 2).tolist(),
           "relative_error_vs_fe": nearest}
    if fe is not None:
        from ..post.compare import model_matches

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
                 "source": source},
        "dim": model.dim, "dofs": model.n_dofs, "order": model.order, "mass_matrix": model.mass,
        "material": {"name": m.name, "E": m.E, "nu": m.nu, "rho": m.rho},
        "total_mass_kg": model.total_mass, "clamped_nodes": int(model.clamped.size),
        "linear_frequencies_hz": np.asarray(f_fe).tolist(),
    }


def contact_summary(contact: Contact, model: FEModel) -> dict:
    """Contact node, its position, the casing normal, the clearance and the casing's stiffness (None: rigid)."""
    return {"node": contact.node, "face_nodes": list(contact.nodes),
            "casing_stiffness_n_per_m": None if np.isinf(contact.casing) else contact.casing,
            "face_weights": "area" if contact.weights else "equal",
            "position": model.mesh.points[contact.node].tolist(),
            "normal": contact.normal_for(model).tolist(), "clearance_m": contact.gap}
