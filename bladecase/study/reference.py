"""Verification in a richer model: does a reduced model's orbit exist in the structure it stands for?

The event-driven check of :mod:`bladecase.nsm.verify` re-simulates an orbit in the model that produced it, so it
cannot see a reduction artefact (an orbit whose energy sits in a mesh-scale Ritz mode). Here the orbit is
expanded to the FE model's free dofs, projected onto a *reference* model and simulated there for one period from
a state in an open phase. The reference has :data:`REFERENCE_FACTOR` times the model's dofs and is built one of
two ways (:data:`REFERENCE_BASES`):

- ``"krylov"`` (the default): the model's own basis extended by the block Krylov sequence of its factorisation
  (:func:`bladecase.reduction.krylov_extension`): it contains the model, so the orbit is represented exactly and
  what the check measures is what the added dofs — the part of the contact's load the model misses, from the
  lowest frequencies up — change. No second eigen-solve: one solve per added dof with the factorisation the
  model was built with, a fraction of the model's own cost;
- ``"independent"``: a reduced model of another method (:data:`REFERENCE_METHODS`; the same method for the
  massless contact model) from its own eigen-solve — independent of the model's basis, and several times the
  cost of the model it checks. The drift between where it starts and where it is one period
later, in the reference's energy norm, says whether the orbit survives:

    drift = ‖z(T) − z(0)‖_E / ‖z(0)‖_E,   ‖(x, v)‖²_E = xᵀK x + vᵀM v.

It is ``~1e-10`` for an orbit of the reference itself, a few percent where the reduced model is converged, and
of order one when the orbit does not exist in the structure.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .. import log
from ..fe import FEModel
from ..linalg import SPDFactor
from ..reduction import METHODS, Contact, ReducedModel, krylov_extension, reduce

#: The reference model is at least this many times larger than the model it checks.
REFERENCE_FACTOR = 4

#: Largest drift (energy norm, relative) for which an orbit is said to survive in the reference model.
SURVIVAL_RTOL = 0.05

#: Reference methods, in order of preference, for each contact model (the first one unlike the checked model).
REFERENCE_METHODS = {"newton": ("modal", "craig-bampton", "lanczos-si"), "massless": ("massless",)}


#: How a reference model is built (module docstring).
REFERENCE_BASES = ("krylov", "independent")


def study_basis(study) -> str:
    """The study's ``[output] reference_basis``, ``"auto"`` resolved: ``"independent"`` in a study that compares
    reduced models (the yardstick of the comparison is built from none of them), ``"krylov"`` otherwise."""
    basis = study["output"]["reference_basis"]
    if basis == "auto":
        return "independent" if study["reduction"]["compare"] else "krylov"
    return basis


def reference_model(model: FEModel, contact: Contact, reduced: ReducedModel,
                    factor: SPDFactor | None = None, basis: str = "krylov") -> ReducedModel:
    """The reference model of ``reduced``: ``REFERENCE_FACTOR`` × its dofs (module docstring).

    ``basis="krylov"``: ``reduced`` extended by the Krylov sequence of ``factor`` (made when ``None``);
    ``"independent"``: a reduced model of another method (when the contact model offers one), ``REFERENCE_FACTOR``
    × the size, from its own eigen-solve. A model that keeps every dof gets the independent kind (nothing to
    extend).
    """
    if basis not in REFERENCE_BASES:
        raise ValueError(f"basis must be one of {', '.join(map(repr, REFERENCE_BASES))}, got {basis!r}")
    interior = model.n_dofs - int(np.count_nonzero(contact.w(model))) if reduced.method.startswith("massless") \
        else model.n_dofs
    if basis == "krylov" and not sp.issparse(reduced.basis) and reduced.n < interior - 1:
        return krylov_extension(reduced, REFERENCE_FACTOR * reduced.n, factor)
    contact_model = getattr(reduced.system, "contact_model", "newton")
    methods = [m for m in REFERENCE_METHODS[contact_model] if m in METHODS]
    method = next((m for m in methods if m != reduced.method), methods[0])
    size = min(REFERENCE_FACTOR * max(reduced.size or 0, reduced.n), model.n_dofs // 2)
    return reduce(model, contact, method, size, factor=factor)


def _project(reference: ReducedModel, x_free: np.ndarray) -> np.ndarray:
    """Reference coordinates of free-dof vectors: the M-orthogonal projection onto the reference's basis."""
    V = reference.basis
    M = getattr(reference, "mass_matrix", reference.model.M)  # the massless model's redistributed masses
    MV = M @ V
    return np.linalg.solve(np.asarray(V.T @ MV), np.asarray(MV.T @ x_free))


def check_in_reference(orbit, reduced: ReducedModel, reference: ReducedModel) -> dict:
    """Expand ``orbit`` (of ``reduced.system``), project it onto ``reference``, simulate one period there.

    Returns ``{"reference": "<method> (<n> dofs)", "drift": relative drift in the energy norm,
    "contacts": impacts or contact phases in the period (the orbit has ``orbit.k``), "survives": bool}``.
    """
    from ..nsm import simulate
    from ..nsm.massless.model import simulate_massless

    massless = getattr(orbit, "contact_model", "newton") == "massless"
    t0 = orbit.mid_open_time if massless else 0.5 * float(np.diff(np.r_[0.0, orbit.impact_times]).min())
    x_r, v_r = (z[:, 0] for z in orbit.state(np.array([t0])))  # in an open phase: no switch at the start
    q0 = _project(reference, reduced.free_dofs(x_r))
    p0 = _project(reference, reduced.free_velocities(x_r, v_r))
    s = reference.system
    penetration = float(s.w @ q0) - s.gap
    if penetration > 0:  # the reference's contact sees more of the motion: it starts beyond the casing
        return {"reference": f"{reference.method} ({reference.n} dofs)", "drift": float("inf"), "contacts": 0,
                "survives": False, "reason": f"its expanded state lies beyond the casing of the reference model "
                                             f"by {penetration / s.gap:.1%} of the clearance in an open phase"}
    if massless:
        traj = simulate_massless(s, q0, p0, orbit.T)
        contacts = sum(p == "closed" for p in traj.phases)
        K = s.S
    else:
        traj = simulate(s, q0, p0, orbit.T)
        contacts = int(traj.impact_times.size)
        K = s.K
    M = s.M

    def norm2(x, v):
        return float(x @ (K @ x) + v @ (M @ v))

    drift = np.sqrt(norm2(traj.x_end - q0, traj.v_end - p0) / norm2(q0, p0))
    survives = bool(drift <= SURVIVAL_RTOL and contacts == orbit.k)
    return {"reference": f"{reference.method} ({reference.n} dofs)", "drift": float(drift), "contacts": contacts,
            "survives": survives}


def log_check(check: dict, k: int, T: float) -> None:
    """The check in words, in the run's log (a warning when the orbit does not survive)."""
    if check["survives"]:
        log.info("orbit T = %.8g s survives in the reference model %s: back within %.1e (energy norm) after one "
                 "period", T, check["reference"], check["drift"])
    else:
        log.warning("orbit T = %.8g s does NOT survive in the reference model %s: drift %.1e (energy norm), %d "
                    "contact(s) for %d — an artefact of the reduced model", T, check["reference"], check["drift"],
                    check["contacts"], k)


def check_nodal_in_reference(orbit, nodal, reference) -> dict:
    """The check of :func:`check_in_reference` for an orbit with one contact per node (a
    :class:`~bladecase.nsm.massless.nodal_modes.NodalOrbit` of ``nodal.system``): from the middle of its longest
    phase with every node open, projected onto ``reference`` (:func:`bladecase.reduction.nodes.nodal_extension`),
    one period of :func:`~bladecase.nsm.massless.nodes.simulate_nodes` there.

    Returns ``{"reference", "drift", "switches"`` (in the reference) ``, "expected"`` (the orbit's phase changes
    per period) ``, "survives"}``; an orbit with no phase where every node is open is not checked (``"survives":
    None`` and a ``"reason"``). It survives when its drift is at most :data:`SURVIVAL_RTOL`: with many nodes, the
    count of switches is no test of its own (nodes that switch together in the orbit may switch a round-off apart
    in the reference, a grazing node may touch there), so it is given, not judged.
    """
    name = f"{reference.method} ({reference.n} dofs)"
    t0 = open_start(orbit)
    if t0 is None:
        return {"reference": name, "drift": None, "switches": 0, "expected": int(len(orbit.starts)),
                "survives": None, "reason": "no phase of the orbit has every node open"}
    x_r, v_r = (z[:, 0] for z in orbit.state(np.array([t0])))
    q0, p0 = _project(reference, np.column_stack([nodal.basis @ x_r, nodal.basis @ v_r])).T  # open: no λ term
    drift, switches = nodal_drift(reference.system, q0, p0, orbit.T)
    return {"reference": name, "drift": drift, "switches": switches, "expected": phase_changes(orbit),
            "survives": bool(drift <= SURVIVAL_RTOL)}


def open_start(orbit) -> float | None:
    """The middle of the longest phase of a nodal orbit with every node open (``None``: it has none)."""
    open_ = np.flatnonzero(~orbit.active.any(axis=1))
    if not open_.size:
        return None
    j = open_[np.argmax(orbit.durations[open_])]
    return float(orbit.starts[j] + 0.5 * orbit.durations[j])


def nodal_drift(system, x0, v0, T: float) -> tuple[float, int]:
    """One period ``T`` of the exact event-driven simulator of ``system`` (a ``NodalSystem``) from ``(x0, v0)``: the
    relative distance of the end state from the start in the energy norm, and the switches met."""
    from ..nsm.massless.nodes import simulate_nodes

    traj = simulate_nodes(system, x0, v0, T)
    xT, vT = (z[:, 0] for z in traj.state(np.array([T])))

    def norm2(x, v):
        return float(x @ (system.S @ x) + v @ (system.M @ v))

    return float(np.sqrt(norm2(xT - x0, vT - v0) / norm2(x0, v0))), int(traj.starts.size - 1)


def phase_changes(orbit) -> int:
    """The changes of the set of closed nodes per period of a nodal orbit."""
    A = orbit.active
    return int(np.count_nonzero(np.any(A != np.roll(A, 1, axis=0), axis=1))) if len(A) > 1 else 0
