"""The massless contact model of a finite-element structure touched at every node of its contact group:
:func:`nodal_model`.

Each node ``j`` of the contact (its face group: :meth:`Contact.face <bladecase.reduction.Contact.face>`, or on a
casing of revolution: :meth:`Contact.on_casing <bladecase.reduction.Contact.on_casing>`) is its own unilateral
constraint ``ν_j·u_j <= d_j``, with its own normal ``ν_j`` and clearance ``d_j``. The contact dofs ``c`` are the
dofs of those nodes that their normals move (every one for a normal off the axes); they carry no inertia (their
lumped mass moved to the neighbours as for one constraint, :func:`~bladecase.reduction.massless.massless_masses`),
the others are the interior ``i``. With one node, this is :func:`~bladecase.reduction.massless.massless_model`.

- open phase: ``x_c = −K_cc⁻¹K_ci x_i``; the nodes' normal displacements ``W_cᵀx_c = Wᵀx_i`` with
  ``W = −K_icK_cc⁻¹W_c`` (``W_c``: the ``m`` normal vectors on the contact dofs);
- forces ``λ`` on the nodes: ``x_c = −K_cc⁻¹(K_ci x_i + W_cλ)``; the nodes' own flexibility is
  ``H_s = W_cᵀK_cc⁻¹W_c`` (``m × m``, the interior held).

**Reduction** (massless-boundary Craig–Bampton with ``m`` constraints): ``V_i`` = the ``size`` lowest modes of the
massless structure plus the ``m`` attachment vectors ``(K⁻¹W_full)_i = S⁻¹W``, M-orthonormalised (an attachment
vector already in the span is dropped). The static compliance of the nodes, ``H_s + WᵀS⁻¹W = W_fullᵀK⁻¹W_full``,
is then exact at any size. The reduced model is
``NodalSystem(V_iᵀM_iiV_i, V_fullᵀKV_full, V_fullᵀW_full, H_s, d, k)``.

**Which nodes.** A node in 3-D is a point: its own flexibility grows like ``1/h`` as the mesh is refined; a
casing compliance per unit area (``k_j = k_A·A_j``, ``A_j`` the node's tributary area) grows faster (``1/h²``)
and keeps the contact forces and the penetrations converging. A rigid casing (``k_j = inf``) at every node of a
fine mesh has no converged limit: the results then depend on the mesh (as for any node-to-surface contact).

**Pressure, not per-node forces.** A node's force falls like its tributary area as the tip mesh is refined: it is
a mesh quantity. The model keeps each node's tributary area ``A_j`` (:attr:`NodalReducedModel.areas`, the shares
the area weights of :meth:`Contact.face <bladecase.reduction.Contact.face>` are made of) and its position along the
tip's chord (:attr:`NodalReducedModel.chord`, :func:`chord_positions`), and turns the nodes' forces at an instant
into what converges (:func:`contact_load`): the **contact pressure** ``p_j = λ_j / A_j``, the **total force**
``Σ λ_j``, the **loaded area** ``Σ_{λ_j > 0} A_j`` and **where the load sits** along the chord.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ..checks import integer
from ..fe import FEModel
from ..linalg import DENSE_LIMIT, SPDFactor, check_factor, spd_factor
from ..nsm.massless.nodes import NodalSystem
from .contact import Contact, tributary_areas
from .massless import _HINT, _K, _check_lumped, _interior_modes, _Split, massless_masses
from .model import ReducedModel

__all__ = ["NodalReducedModel", "chord_positions", "chord_region", "contact_load", "contact_pressure",
           "nodal_extension", "nodal_model"]


@dataclass(frozen=True, eq=False)
class NodalReducedModel(ReducedModel):
    """A reduced model of the massless contact model with one constraint per contact node: ``system`` is a
    :class:`~bladecase.nsm.massless.nodes.NodalSystem`.

    ``normal_map`` (``m × n_free``, sparse) gives each node's normal displacement ``ν_j·u_j``; ``closed_shapes``
    (``n_free × m``) the free-dof displacement per unit force on each node with the interior held, added
    ``λ_j`` times where a node is pressed; ``masses`` the redistributed lumped masses; ``interior`` the interior
    basis ``V_i`` (reusable at another speed: :func:`nodal_model`'s ``interior``); ``areas`` each node's tributary
    area (m²; in 2-D a length times the thickness; 0 for a node on no face facet, e.g. a mid-side node) and
    ``chord`` its position along the tip's chord (0 at the leading edge, 1 at the trailing edge:
    :func:`chord_positions`).
    """

    closed_shapes: np.ndarray = field(default=None, repr=False)  # type: ignore[assignment]
    masses: np.ndarray = field(default=None, repr=False)  # type: ignore[assignment]
    normal_map: sp.csr_array = field(default=None, repr=False)  # type: ignore[assignment]
    interior: np.ndarray = field(default=None, repr=False)  # type: ignore[assignment]
    residual: bool = False
    areas: np.ndarray = field(default=None, repr=False)  # type: ignore[assignment]
    chord: np.ndarray = field(default=None, repr=False)  # type: ignore[assignment]

    def contact_load(self, forces) -> dict:
        """The contact pressure, total force, loaded area and where the load sits for the nodes' ``forces`` at one
        instant (N, ``(m,)``): :func:`contact_load` with this model's areas and chord positions."""
        return contact_load(forces, self.areas, self.chord)

    @property
    def mass_matrix(self) -> sp.dia_array:
        """The model's (lumped, redistributed) mass matrix on the free dofs."""
        return sp.diags_array(self.masses)

    def free_dofs(self, x_r, gap=None) -> np.ndarray:
        """Free-dof displacements of reduced states, each pressed node's correction included."""
        x = super().free_dofs(x_r)
        lam = self.system.forces(np.asarray(x_r, dtype=float), gap)
        return x + self.closed_shapes @ lam

    def __repr__(self) -> str:
        return (f"NodalReducedModel(size={self.size}, {self.n} reduced dofs of {self.model.n_dofs} free dofs, "
                f"{self.system.m} contact nodes)")


def _m_orthonormal(V: np.ndarray, m: np.ndarray, keep: int) -> np.ndarray:
    """The columns of ``V`` M-orthonormalised (``M = diag(m)``) in order, twice; a column after the first ``keep``
    that lies in the span of the previous ones to 1e-10 is dropped."""
    out = []
    for k in range(V.shape[1]):
        e = V[:, k].copy()
        size0 = np.sqrt(e @ (m * e))
        if out:
            Q = np.column_stack(out)
            for _ in range(2):
                e -= Q @ (Q.T @ (m * e))
        size = np.sqrt(e @ (m * e))
        if k >= keep and size <= 1e-10 * size0:
            continue
        out.append(e / size)
    return np.column_stack(out)


def nodal_model(model: FEModel, contact: Contact, size: int, factor: SPDFactor | None = None,
                casing=None, interior: np.ndarray | None = None, residual: bool = False) -> NodalReducedModel:
    """The massless contact model of ``model`` with one unilateral constraint per node of ``contact``, reduced to
    the ``size`` lowest modes of the massless structure plus one attachment vector per node (module docstring).

    Parameters
    ----------
    model : FEModel
        A clamped model with lumped mass.
    contact : Contact
        A face contact (:meth:`Contact.face`, :meth:`Contact.on_casing`): its nodes, with their normals and
        clearances (``Contact.node_clearances``).
    size : int
        Modes of the massless structure (``>= 1``).
    factor : SPDFactor or None
        ``bladecase.fe.stiffness_factor(model)``, reused.
    casing : None, float or (m,) array_like
        The casing's stiffness at each node (N/m); a float: a total shared by the nodes' weights (their
        tributary areas); ``None``: the contact's own (``contact.casing``, shared the same way; ``inf``: rigid).
    interior : (n_interior, k) ndarray or None
        An interior basis to reuse (``model_at_another_speed``'s ``interior_basis``, M-orthonormal for the same
        masses): the model is then the Ritz projection of this ``model`` on it, the contact rows condensed with
        this model's ``K`` — no eigen-solution (``size`` is recorded only).
    residual : bool
        ``False`` (default): the ``m`` attachment vectors are dofs of the reduced model (their local, mesh-scale
        modes — MHz on a blade tip — are in its dynamics). ``True``: the interior basis is the ``size`` modes alone
        and the static flexibility they miss, ``W_fullᵀK⁻¹W_full − W_rᵀS_r⁻¹W_r``, is added to the nodes' own
        flexibility — the residual (mode-acceleration) correction: those local modes respond statically, the
        static compliance stays exact, and the fastest phase is a few times the highest kept mode instead of MHz.

    >>> from skfem import MeshTri
    >>> from bladecase.fe import Mesh, assemble
    >>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5))
    >>> p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    >>> strip = Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 0] == 0),
    ...                                                     "tip": np.flatnonzero(p[:, 0] == 0.1)})
    >>> model = assemble(strip, "steel", order=1, thickness=0.002, mass="lumped")
    >>> reduced = nodal_model(model, Contact.face(model, "tip", (1.0, 0.0), 1e-4, weights="area"), 6)
    >>> reduced.system        # 6 modes + one attachment vector per tip node
    NodalSystem(n=11, m=5 contacts, gap 0.0001–0.0001 m, rigid)
    """
    if not isinstance(model, FEModel):
        raise ValueError(f"model must be an FEModel (from bladecase.assemble), got {type(model).__name__}")
    if not isinstance(contact, Contact):
        raise ValueError(f"contact must be a bladecase.Contact, got {type(contact).__name__}")
    factor = check_factor(factor, model.K, "this model's K", "bladecase.fe.stiffness_factor(model)")
    _check_lumped(model)
    nodes = np.array(contact.nodes or (contact.node,))
    m = nodes.size
    d, _ = contact.node_clearances(model)
    N = sp.csr_array(contact.node_normal_map(model))  # (m, n_dofs)
    c = np.flatnonzero(np.asarray(abs(N).sum(axis=0)).ravel())  # the dofs some node's normal moves (w ≠ 0)
    i = np.setdiff1d(np.arange(model.n_dofs), c)
    size = integer("size", size, 1, note=" (modes of the massless structure)")
    if size > i.size - m:
        raise ValueError(f"size = {size} is too large: the massless structure has {i.size} interior dofs and the "
                         f"{m} attachment vectors take {m} (valid: 1..{i.size - m})")
    if size > i.size // 2 and i.size > DENSE_LIMIT:
        raise ValueError(f"size = {size}: more than half of the {i.size} massless modes needs a dense eigen-solution "
                         f"(valid: 1..{i.size // 2})")
    K = sp.csr_array(model.K)
    K_cc = sp.csc_array(K[c][:, c])
    cc = spd_factor(K_cc.toarray() if c.size <= 1500 else K_cc, "K_cc (the contact nodes' stiffness)", hint=_HINT)
    Wfull = N.T.toarray()  # (n_dofs, m)
    Wc = Wfull[c]
    split = _Split(Wfull[:, 0], c, i, K, sp.csr_array(K[c][:, i]), cc)
    masses = massless_masses(model, c)
    fac = None
    if interior is None or residual:
        fac = factor if factor is not None else spd_factor(model.K, _K, hint=_HINT)
        attach_full = fac.solve(Wfull)
    if interior is None:
        phi = _interior_modes(split, masses, size, fac)
        V_i = _m_orthonormal(phi if residual else np.column_stack([phi, attach_full[i]]), masses[i], phi.shape[1])
    else:
        V_i = np.asarray(interior, dtype=float)
        if V_i.ndim != 2 or V_i.shape[0] != i.size:
            raise ValueError(f"interior basis of shape {V_i.shape}: expected ({i.size}, k), one row per interior dof")
    V = np.zeros((model.n_dofs, V_i.shape[1]))
    V[i], V[c] = V_i, split.slave(V_i)
    M_r = V_i.T @ (masses[i][:, None] * V_i)
    S_r = V.T @ (K @ V)
    X = cc.solve(Wc)
    Hs = Wc.T @ X
    if residual:  # what the modes miss of the static compliance, on the nodes' own flexibility
        W_r = V.T @ Wfull
        Z = np.linalg.solve(S_r, W_r)
        Hs = Wfull.T @ attach_full - W_r.T @ Z
    closed = np.zeros((model.n_dofs, m))
    if residual:  # the static response to the forces that the modes do not carry
        closed = -(attach_full - V @ Z)
    else:
        closed[c] = -X
    k = _node_casing(contact, m, casing)
    system = NodalSystem(M_r, S_r, V.T @ Wfull, Hs, d, k, nodes=tuple(model.mesh.node_id(k) for k in nodes))
    areas = _areas(model, nodes)
    return NodalReducedModel("massless-nodes", size, system, V, model, contact, closed_shapes=closed,
                             masses=masses, normal_map=N, interior=V_i, residual=residual, areas=areas,
                             chord=chord_positions(model.mesh.points[nodes], areas))


def nodal_extension(nodal: NodalReducedModel, count: int, factor: SPDFactor | None = None) -> NodalReducedModel:
    """``nodal`` extended to ``count`` interior dofs by the block Krylov sequence of the massless structure started
    from the nodes' attachment vectors (:func:`bladecase.reduction.extension.extend_basis`; the interior modes are
    not applied again, they are invariant), rebuilt by :func:`nodal_model` on that interior with the same casing
    and residual choice — a richer model containing ``nodal``, for checking its orbits, from the same
    factorisation and no eigen-solve.

    >>> from skfem import MeshTri
    >>> from bladecase.fe import Mesh, assemble
    >>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5))
    >>> p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    >>> strip = Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 0] == 0),
    ...                                                     "tip": np.flatnonzero(p[:, 0] == 0.1)})
    >>> model = assemble(strip, "steel", order=1, thickness=0.002, mass="lumped")
    >>> nodal = nodal_model(model, Contact.face(model, "tip", (1.0, 0.0), 1e-4, weights="area"), 6, residual=True)
    >>> nodal_extension(nodal, 24).system
    NodalSystem(n=24, m=5 contacts, gap 0.0001–0.0001 m, rigid)
    """
    from .extension import SUFFIX, extend_basis
    from .massless import _interior_operator

    model, contact = nodal.model, nodal.contact
    count = integer("count", count, nodal.n, note=f" (at least the model's {nodal.n} dofs)")
    factor = check_factor(factor, model.K, "this model's K", "bladecase.fe.stiffness_factor(model)")
    fac = factor if factor is not None else spd_factor(model.K, _K, hint=_HINT)
    N = nodal.normal_map
    c = np.flatnonzero(np.asarray(abs(N).sum(axis=0)).ravel())
    i = np.setdiff1d(np.arange(model.n_dofs), c)
    split = _Split(np.zeros(model.n_dofs), c, i, sp.csr_array(model.K), None, None)  # what the operator needs
    m_i = nodal.masses[i]
    V_i = extend_basis(nodal.interior, fac.solve(N.T.toarray())[i], _interior_operator(split, nodal.masses, fac),
                       lambda X: (m_i * X.T).T, min(count, i.size - 1),
                       frontier=() if nodal.residual else range(nodal.size, nodal.interior.shape[1]))
    out = nodal_model(model, contact, nodal.size, fac, casing=nodal.system.casing, interior=V_i,
                      residual=nodal.residual)
    return dataclasses.replace(out, method=nodal.method + SUFFIX, size=V_i.shape[1])


def _node_casing(contact: Contact, m: int, casing) -> np.ndarray:
    """Per-node casing stiffness (N/m): an array as given, a total shared by the nodes' weights."""
    if casing is None:
        casing = contact.casing
    k = np.asarray(casing, dtype=float)
    if k.ndim == 0:
        if np.isinf(k):
            return np.full(m, np.inf)
        w = np.array(contact.weights) if contact.weights else np.full(m, 1.0 / m)
        w = w / w.sum()
        if np.any(w <= 0):
            raise ValueError("a contact node has no tributary area (a mid-side node or one beside the clamp): a "
                             "casing stiffness shared by area cannot reach it; give one stiffness per node")
        return float(k) * w
    if k.shape != (m,) or np.any(np.isnan(k)) or np.any(k <= 0):
        raise ValueError(f"casing stiffness per node must be {m} values > 0 (N/m; inf: rigid), got shape {k.shape}")
    return k


# ----------------------------------------------------------------------------- contact pressure


def _areas(model: FEModel, nodes: np.ndarray) -> np.ndarray:
    """Each contact node's tributary area (m²), from the facets whose corners are all contact nodes — the shares
    ``Contact.face(..., weights="area")`` divides by the face's total; zeros for a set of nodes that holds no facet
    (a line of nodes, a single node): no pressure there."""
    try:
        return tributary_areas(model, nodes)
    except ValueError:  # no boundary facet among the nodes
        return np.zeros(len(nodes))


def chord_positions(points, areas) -> np.ndarray:
    """Each point's position along the face's chord, 0 at the leading edge and 1 at the trailing edge.

    The chord is the face's longest in-plane extent: the first principal direction of the points. Its leading
    edge is the end on the side of the face's area centroid (the weights ``areas``): an aerofoil's rounded nose is
    its thick end, its centroid lies at about 40 % of the chord from the nose (on the demo blade's tip, 44 %), and
    the blunt trailing edge is thin. A face with no thick end (its centroid within 1 % of the chord of the middle,
    e.g. a rectangular plate's edge) has no leading edge to find: its ``0`` end is the one of lowest coordinate
    along the principal direction, taken with its largest component positive.

    >>> chord_positions([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [4.0, 0.0, 0.0]], [3.0, 2.0, 1.0]).tolist()  # thick at x=0
    [0.0, 0.25, 1.0]
    >>> chord_positions([[4.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]], [3.0, 2.0, 1.0]).tolist()  # thick at x=4
    [0.0, 0.75, 1.0]
    """
    P = np.asarray(points, dtype=float)
    a = np.asarray(areas, dtype=float)
    C = P - P.mean(axis=0)
    if P.shape[0] < 2 or not np.any(C):
        return np.zeros(P.shape[0])
    direction = np.linalg.svd(C, full_matrices=False)[2][0]
    direction = direction * np.sign(direction[np.argmax(np.abs(direction))])
    s = C @ direction
    s = (s - s.min()) / float(np.ptp(s))
    if a.sum() > 0 and float(a @ s) / float(a.sum()) > 0.51:  # the thick end is at s = 1: the leading edge
        s = 1.0 - s
    return s


def chord_region(centre) -> str | None:
    """A position along the chord (0 leading edge – 1 trailing edge) in words, by thirds: ``"leading edge"``
    (below 1/3), ``"mid-chord"``, ``"trailing edge"`` (above 2/3); ``None`` for ``None`` (no load).

    >>> [chord_region(x) for x in (0.1, 0.5, 0.9, None)]
    ['leading edge', 'mid-chord', 'trailing edge', None]
    """
    if centre is None or not np.isfinite(centre):
        return None
    return "leading edge" if centre < 1 / 3 else "mid-chord" if centre <= 2 / 3 else "trailing edge"


def contact_pressure(forces, areas) -> np.ndarray:
    """The contact pressure of each node (Pa): its force over its tributary area, ``forces`` ``(m,)`` or ``(m, k)``
    (``k`` instants); NaN on a node without area (a mid-side node of a quadratic face: it carries no share of the
    face). Summed over the nodes, pressure × area is the total force.

    >>> contact_pressure([2.0, 4.0, 2.0], [1e-6, 2e-6, 1e-6]).tolist()   # a uniform 2 MPa, forces ∝ areas
    [2000000.0, 2000000.0, 2000000.0]
    """
    f = np.asarray(forces, dtype=float)
    a = np.asarray(areas, dtype=float).reshape((-1,) + (1,) * (f.ndim - 1))
    return np.divide(f, a, out=np.full(np.broadcast_shapes(f.shape, a.shape), np.nan), where=a > 0)


def contact_load(forces, areas, chord) -> dict:
    """What the casing's load on the face is at one instant, from the nodes' ``forces`` (N, ``(m,)``), their
    tributary ``areas`` (m²) and positions along the ``chord`` (0 leading edge – 1 trailing edge):

    ``{"max_pressure_pa", "total_force_n", "loaded_area_m2", "centre", "location"}``: the largest contact pressure
    over the nodes (:func:`contact_pressure`), the total force ``Σ λ_j``, the area of the nodes in contact
    (``λ_j > 0``), the force-weighted centroid along the chord ``Σ λ_j s_j / Σ λ_j`` and its third of the chord in
    words (:func:`chord_region`); ``centre`` and ``location`` are ``None`` without load.

    >>> load = contact_load([0.0, 3.0, 1.0], [1e-6, 1e-6, 2e-6], [1.0, 0.1, 0.0])
    >>> load["total_force_n"], round(load["loaded_area_m2"] * 1e6, 12), round(load["centre"], 12), load["location"]
    (4.0, 3.0, 0.075, 'leading edge')
    """
    f = np.asarray(forces, dtype=float)
    a = np.asarray(areas, dtype=float)
    total = float(f.sum())
    p = contact_pressure(f, a)
    centre = float(f @ np.asarray(chord, dtype=float)) / total if total > 0 else None
    return {"max_pressure_pa": float(np.nanmax(p)) if np.isfinite(p).any() else 0.0, "total_force_n": total,
            "loaded_area_m2": float(a[f > 0].sum()), "centre": centre, "location": chord_region(centre)}
