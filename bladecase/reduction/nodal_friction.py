"""What friction at the contact nodes becomes in a :class:`~bladecase.reduction.nodes.NodalReducedModel`:
:func:`nodal_friction`.

Each contact node ``j`` slides along the casing in the circumferential direction about the engine axis; the casing's
motion relative to the tip is ``−s·(a × r̂_j)`` for a blade turning ``s = ±1`` times positively about the axis
``a`` (``r̂_j``: the node's radial direction). A unit force along it on node ``j`` is the free-dof vector
``t_j`` (``T_full``, ``n_free × m``); in the reduced model it becomes

- ``T = VᵀT_full``: the generalised force on the reduced dofs (the open phase's condensed load);
- the nodes' own compliances, the interior held, as the normal one ``H_s`` is built
  (:func:`~bladecase.reduction.nodes.nodal_model`): ``C_nt = W_cᵀK_cc⁻¹T_c`` and ``C_tt = T_cᵀK_cc⁻¹T_c`` on the
  contact dofs ``c``, or with the residual correction ``C_nt = W_fullᵀK⁻¹T_full − W_rᵀS_r⁻¹T_r`` (and ``C_tt``
  alike) — the static compliance the kept modes miss.

The result is the :class:`~bladecase.nsm.massless.friction.Friction` the solver flies, with each node's radius
for the sliding check.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..linalg import SPDFactor, check_factor, spd_factor
from ..nsm.massless.friction import Friction
from .nodes import NodalReducedModel

__all__ = ["nodal_friction", "tangential_map"]


def tangential_map(reduced: NodalReducedModel, origin, direction, turning: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """``(T_full, radius)``: the free-dof vector of a unit force along the casing's motion relative to each contact
    node (``n_free × m``) and each node's radius about the axis (m)."""
    if turning not in (1, -1):
        raise ValueError(f"turning must be +1 (the blade turns positively about the axis) or -1, got {turning!r}")
    model = reduced.model
    a = np.zeros(3)
    a[: len(direction)] = direction
    a /= np.linalg.norm(a)
    o = np.zeros(3)
    o[: len(origin)] = origin
    nodes = reduced.contact.nodes or (reduced.contact.node,)
    T = np.zeros((model.n_dofs, len(nodes)))
    radius = np.zeros(len(nodes))
    for j, k in enumerate(nodes):
        p = np.zeros(3)
        p[: model.dim] = model.mesh.points[k][: model.dim]
        x = p - o
        r = x - (x @ a) * a
        radius[j] = np.linalg.norm(r)
        if radius[j] == 0:
            raise ValueError(f"contact node {model.mesh.node_id(k)} lies on the engine axis: it has no sliding "
                             "direction")
        t = -turning * np.cross(a, r / radius[j])
        idx = np.flatnonzero(model.dofs.node == k)
        T[idx, j] = t[model.dofs.direction[idx]]
    return T, radius


def nodal_friction(reduced: NodalReducedModel, mu: float, origin, direction, turning: int = 1,
                   factor: SPDFactor | None = None) -> Friction:
    """The :class:`~bladecase.nsm.massless.friction.Friction` of ``reduced`` with coefficient ``mu``, the blade
    turning ``turning = ±1`` times positively about the axis through ``origin`` along ``direction`` (module
    docstring). ``factor``: the model's stiffness factorisation, reused (residual models only).

    >>> from skfem import MeshTri
    >>> from bladecase.fe import Mesh, assemble
    >>> from bladecase.reduction import Contact
    >>> from bladecase.reduction.nodes import nodal_model
    >>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5))
    >>> p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    >>> strip = Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 0] == 0),
    ...                                                     "tip": np.flatnonzero(p[:, 0] == 0.1)})
    >>> model = assemble(strip, "steel", order=1, thickness=0.002, mass="lumped")
    >>> reduced = nodal_model(model, Contact.face(model, "tip", (1.0, 0.0), 1e-4, weights="area"), 6)
    >>> f = nodal_friction(reduced, 0.15, origin=(-0.3, 0.0), direction=(0.0, 0.0, 1.0))
    >>> f.T.shape, float(f.radius.min().round(4)), float(f.radius.max().round(4))   # the tip 0.4 m out
    ((11, 5), 0.4, 0.4005)
    """
    model = reduced.model
    s = reduced.system
    T_full, radius = tangential_map(reduced, origin, direction, turning)
    V = np.asarray(reduced.basis.toarray() if sp.issparse(reduced.basis) else reduced.basis)
    T_r = V.T @ T_full
    W_full = sp.csr_array(reduced.normal_map).T.toarray()
    if reduced.residual:
        factor = check_factor(factor, model.K, "this model's K", "bladecase.fe.stiffness_factor(model)")
        fac = factor if factor is not None else spd_factor(model.K, "K (the model's stiffness)")
        X = fac.solve(T_full)
        W_r = V.T @ W_full
        Z = np.linalg.solve(s.S, T_r)
        C_nt = W_full.T @ X - W_r.T @ Z
        C_tt = T_full.T @ X - T_r.T @ Z
    else:
        N = sp.csr_array(reduced.normal_map)
        c = np.flatnonzero(np.asarray(abs(N).sum(axis=0)).ravel())
        K = sp.csr_array(model.K)
        cc = spd_factor(sp.csc_array(K[c][:, c]).toarray(), "K_cc (the contact nodes' stiffness)")
        X = cc.solve(T_full[c])
        C_nt = W_full[c].T @ X
        C_tt = T_full[c].T @ X
    return Friction(mu, T=T_r, C_nt=C_nt, C_tt=C_tt, radius=radius)
