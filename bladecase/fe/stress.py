"""Stresses of a displacement field at the nodes of a finite-element model, and their von Mises equivalent.

:func:`nodal_stress` evaluates the stress of a displacement in every element at that element's own nodes (its
scikit-fem basis taken at the reference coordinates of its degrees of freedom: the element's exact field there,
through curved cells as the model has them), then averages, at each node, the values of the elements that share
it — the usual nodal recovery (CalculiX's ``*NODE FILE`` ``S``: extrapolated from the integration points, then
averaged; for a straight ``C3D10`` its 4-point extrapolation of the linear strain field is this evaluation
exactly). All elements at once (batched products over the cells), never a matrix over the nodes.

Two stresses:

* ``"linear"`` — the small-strain stress ``σ = λ tr(ε) I + 2μ ε``, ``ε = ½(∇u + ∇uᵀ)``: the prestress of a
  linear (or second-order) centrifugal state (:func:`bladecase.fe.rotation.spin`);
* ``"cauchy"`` — the true stress of a large-rotation state (:mod:`~bladecase.fe.nonlinear_static`, St-Venant–
  Kirchhoff): ``σ = J⁻¹ F S Fᵀ`` from the second Piola–Kirchhoff stress ``S = λ tr(E) I + 2μ E`` of the Green strain
  ``E = ½(FᵀF − I)``, ``F = I + ∇u``, ``J = det F`` — what CalculiX prints after an ``NLGEOM`` step; its
  components are in the global axes, its values listed at the nodes of the undeformed mesh.

A plane model's out-of-plane stress is ``σ_zz = λ tr(ε)`` in plane strain (``ε_zz = 0``) and ``0`` in plane stress;
:func:`von_mises` takes all six components.

The small-strain stress is linear in the displacement: :func:`stress_modes` gives it for many displacements at once
(the columns of a reduced model's basis, one pass over the cells, their gradients computed once), in Voigt order
``xx, yy, zz, xy, yz, zx`` (:data:`VOIGT`); a combination ``Σ_j q_j σ_j`` of them is the stress of ``Σ_j q_j u_j``,
whose von Mises equivalent :func:`von_mises_voigt` reads.
"""

from __future__ import annotations

import numpy as np

from .model import FEModel

__all__ = ["STRESS_KINDS", "VOIGT", "fe_node_points", "nodal_stress", "stress_modes", "von_mises", "von_mises_voigt"]

#: The stresses :func:`nodal_stress` computes.
STRESS_KINDS = ("linear", "cauchy")

#: The components of :func:`stress_modes`: Voigt order ``xx, yy, zz, xy, yz, zx`` as ``(row, column)`` pairs.
VOIGT = ((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0))

#: Values held at once by :func:`stress_modes` (vectors × nodal points × 9 per batch of cells), to bound memory.
BATCH_VALUES = 2_000_000

#: Where the evaluation points of an element's nodes may sit from the nodes themselves (× the model's size).
NODE_RTOL = 1e-8


def _nodal_basis(model: FEModel):
    """``(basis, nodal)``: the model's scikit-fem basis and the same basis with its quadrature at the reference
    coordinates of each element's degrees of freedom (point ``j`` is local dof ``j``)."""
    from skfem import CellBasis

    from .assembly import _basis

    basis = _basis(model.mesh, np.asarray(model.mesh.points, dtype=float), model.dim, model.order)[0]
    X = getattr(basis.elem, "doflocs", None)
    if X is None:
        raise ValueError(f"the {type(basis.elem).__name__} element has no nodal points (doflocs): no nodal stress")
    X = np.ascontiguousarray(np.asarray(X, dtype=float).T)
    nodal = CellBasis(basis.mesh, basis.elem, mapping=basis.mapping, quadrature=(X, np.ones(X.shape[1])),
                      dofs=basis.dofs, disable_doflocs=True)
    at = nodal.mapping.F(X)  # (dim, cells, points): where each element puts its nodal points
    where = np.asarray(basis.doflocs)[:, basis.element_dofs]  # (dim, points, cells): the nodes themselves
    err = float(np.abs(at - where.transpose(0, 2, 1)).max(initial=0.0))
    size = float(np.ptp(model.mesh.points[:, : model.dim], axis=0).max())
    if err > NODE_RTOL * size:
        raise ValueError(f"the elements' nodal points miss their nodes by up to {err:.3g} (size {size:.3g}): the "
                         "element's local dofs are not its doflocs' order")
    return basis, nodal


def _cell_stress(model: FEModel, H: np.ndarray, kind: str) -> np.ndarray:
    """The stress ``(cells, points, 3, 3)`` of the displacement gradients ``H`` ``(cells, points, dim, dim)``."""
    dim = model.dim
    lam, mu = model.material.lame(model.plane if dim == 2 else None)
    eye = np.eye(dim)
    if kind == "linear":
        E = 0.5 * (H + np.swapaxes(H, -1, -2))
    else:
        E = 0.5 * (H + np.swapaxes(H, -1, -2) + np.swapaxes(H, -1, -2) @ H)
    trace = np.trace(E, axis1=-2, axis2=-1)
    S = lam * trace[..., None, None] * eye + 2.0 * mu * E
    out = np.zeros(H.shape[:2] + (3, 3))
    if kind == "linear":
        out[..., :dim, :dim] = S
        J = 1.0
    else:
        F = eye + H
        J = np.linalg.det(F)
        out[..., :dim, :dim] = F @ S @ np.swapaxes(F, -1, -2) / J[..., None, None]
    if dim == 2 and model.plane == "strain":  # ε_zz = 0 (E_zz = 0, F_zz = 1): σ_zz = λ tr
        out[..., 2, 2] = lam * trace / J
    return out


def nodal_stress(model: FEModel, u_free, kind: str = "linear") -> np.ndarray:
    """The stress of the displacement ``u_free`` (m, on the model's free dofs) at every node of the model,
    averaged over the elements that share it (module docstring).

    Parameters
    ----------
    model : FEModel
        The model the displacement is of (its mesh, material, order: P1 or P2, straight or curved cells).
    u_free : (model.n_dofs,) array_like
        The displacement (clamped dofs zero).
    kind : {"linear", "cauchy"}
        The small-strain stress, or the Cauchy stress of a large-rotation state (module docstring).

    Returns
    -------
    (N, 3, 3) ndarray
        The stress tensor (Pa) at each of the model's ``N`` scalar FE nodes (point ``s`` carries the free dofs
        with ``fe_index == dim * s + c``: the mesh's vertices first; at order 2 the edge, face and cell nodes),
        clamped nodes included; a plane model's ``σ_zz`` as the module says.

    Raises
    ------
    ValueError
        A ``u_free`` of the wrong shape or not finite, an unknown ``kind``.

    Examples
    --------
    A steel bar stretched along x with its sides held (``u = (εx, 0, 0)``, zero at the clamped root ``x = 0``):
    ``σ_xx = (λ + 2μ) ε``, ``σ_yy = σ_zz = λ ε``, no shear, at every node.

    >>> from skfem import MeshTet
    >>> from bladecase.fe import Mesh, assemble
    >>> t = MeshTet.init_tensor(np.linspace(0, 0.1, 5), *2 * [np.linspace(0, 0.01, 2)])
    >>> bar = assemble(Mesh(t.p.T, {"tetra": t.t.T}, dim=3, groups={"root": np.flatnonzero(t.p[0] == 0)}),
    ...                "steel", order=2)
    >>> u = np.where(bar.dofs.direction == 0, 1e-3 * bar.dofs.coords[:, 0], 0.0)
    >>> s = nodal_stress(bar, u)
    >>> lam, mu = bar.material.lame()
    >>> s.shape, bool(np.allclose(s, np.diag([lam + 2 * mu, lam, lam]) * 1e-3, rtol=0, atol=1e-6 * mu * 1e-3))
    ((81, 3, 3), True)
    """
    if kind not in STRESS_KINDS:
        raise ValueError(f"kind must be one of {', '.join(map(repr, STRESS_KINDS))}, got {kind!r}")
    u = np.asarray(u_free, dtype=float)
    if u.shape != (model.n_dofs,) or not np.all(np.isfinite(u)):
        raise ValueError(f"u_free must be {model.n_dofs} finite numbers (the model's free dofs), got shape {u.shape}")
    from .assembly import CHUNK_CELLS, _gradients

    basis, nodal = _nodal_basis(model)
    dim = model.dim
    full = np.zeros(dim * basis.N)
    full[model.dofs.fe_index] = u
    U = full.reshape(-1, dim)[basis.element_dofs.T]  # (cells, local dofs, dim)
    total = np.zeros((basis.N, 9))
    for start in range(0, basis.nelems, CHUNK_CELLS):
        cells = slice(start, min(start + CHUNK_CELLS, basis.nelems))
        G = _gradients(nodal, cells)  # (cells, local dofs a, dim k, points q)
        H = np.einsum("eai,eakq->eqik", U[cells], G)  # ∇u at each nodal point
        sigma = _cell_stress(model, H, kind).reshape(H.shape[0], H.shape[1], 9)
        owners = basis.element_dofs[:, cells].T  # (cells, points): the node of each nodal point
        np.add.at(total, owners.ravel(), sigma.reshape(-1, 9))
    count = np.bincount(basis.element_dofs.ravel(), minlength=basis.N)
    return (total / np.maximum(count, 1)[:, None]).reshape(-1, 3, 3)


def fe_node_points(model: FEModel) -> np.ndarray:
    """Where the model's scalar FE nodes are ``(N, 3)`` (m): the points :func:`nodal_stress` gives values at.

    >>> from skfem import MeshTri
    >>> from bladecase.fe import Mesh, assemble
    >>> t = MeshTri.init_tensor(np.linspace(0, 1, 2), np.linspace(0, 1, 2))
    >>> square = assemble(Mesh(np.c_[t.p.T, np.zeros(4)], {"triangle": t.t.T}, dim=2, groups={"root": [0, 2]}),
    ...                   "steel", order=2, thickness=0.01)
    >>> fe_node_points(square).shape                  # 4 vertices, 5 edge midpoints
    (9, 3)
    """
    from .assembly import _basis

    basis = _basis(model.mesh, np.asarray(model.mesh.points, dtype=float), model.dim, model.order)[0]
    out = np.zeros((basis.N, 3))
    out[:, : model.dim] = np.asarray(basis.doflocs).T
    return out


def von_mises(sigma) -> np.ndarray:
    """The von Mises equivalent stress of stress tensors ``(..., 3, 3)``:
    ``√(½[(σ₁₁−σ₂₂)² + (σ₂₂−σ₃₃)² + (σ₃₃−σ₁₁)²] + 3(σ₁₂² + σ₂₃² + σ₃₁²))``.

    >>> von_mises(np.diag([100.0, 0.0, 0.0])), von_mises(np.diag([5.0, 5.0, 5.0]))   # uniaxial; hydrostatic
    (np.float64(100.0), np.float64(0.0))
    >>> round(float(von_mises(np.array([[0, 1.0, 0], [1.0, 0, 0], [0, 0, 0]]))), 12)  # pure shear τ: √3 τ
    1.732050807569
    """
    s = np.asarray(sigma, dtype=float)
    a, b, c = s[..., 0, 0], s[..., 1, 1], s[..., 2, 2]
    shear = s[..., 0, 1] ** 2 + s[..., 1, 2] ** 2 + s[..., 2, 0] ** 2
    return np.sqrt(0.5 * ((a - b) ** 2 + (b - c) ** 2 + (c - a) ** 2) + 3.0 * shear)


def stress_modes(model: FEModel, vectors) -> np.ndarray:
    """The small-strain nodal stress (:func:`nodal_stress`, ``kind="linear"``) of each column of ``vectors``, in
    one pass over the cells: ``(k, N, 6)`` in :data:`VOIGT` order (Pa per unit of the column).

    Parameters
    ----------
    model : FEModel
        The model the displacements are of.
    vectors : (model.n_dofs, k) array_like
        Displacements on the free dofs, one per column (e.g. a reduced model's basis; a dense array).

    Returns
    -------
    (k, N, 6) ndarray
        ``out[j]`` is :func:`nodal_stress` of ``vectors[:, j]`` at the model's ``N`` scalar FE nodes, its components
        ``σ_xx, σ_yy, σ_zz, σ_xy, σ_yz, σ_zx``.

    Raises
    ------
    ValueError
        ``vectors`` not ``(n_dofs, k)`` or not finite.

    Examples
    --------
    Two stretches of a steel bar along x with its sides held: their stresses, and that of their sum, are linear.

    >>> from skfem import MeshTet
    >>> from bladecase.fe import Mesh, assemble
    >>> t = MeshTet.init_tensor(np.linspace(0, 0.1, 5), *2 * [np.linspace(0, 0.01, 2)])
    >>> bar = assemble(Mesh(t.p.T, {"tetra": t.t.T}, dim=3, groups={"root": np.flatnonzero(t.p[0] == 0)}),
    ...                "steel", order=1)
    >>> u = np.where(bar.dofs.direction == 0, bar.dofs.coords[:, 0], 0.0)
    >>> S = stress_modes(bar, np.c_[1e-3 * u, 2e-3 * u])
    >>> lam, mu = bar.material.lame()
    >>> S.shape, bool(np.allclose(S[1], 2 * S[0])), bool(np.allclose(S[0, :, 0], (lam + 2 * mu) * 1e-3))
    ((2, 20, 6), True, True)
    """
    import scipy.sparse as sp

    V = np.asarray(vectors, dtype=float)
    if V.ndim != 2 or V.shape[0] != model.n_dofs or not np.all(np.isfinite(V)):
        raise ValueError(f"vectors must be a finite ({model.n_dofs}, k) array (the model's free dofs, one "
                         f"displacement a column), got shape {V.shape}")
    from .assembly import CHUNK_CELLS, _gradients

    basis, nodal = _nodal_basis(model)
    dim, k = model.dim, V.shape[1]
    full = np.zeros((dim * basis.N, k))
    full[model.dofs.fe_index] = V
    U = full.reshape(basis.N, dim, k)
    points = basis.element_dofs.shape[0]
    step = int(max(1, min(CHUNK_CELLS, BATCH_VALUES // max(1, 9 * k * points))))
    rows, cols = zip(*VOIGT)
    total = np.zeros((basis.N, k * 6))
    for start in range(0, basis.nelems, step):
        cells = slice(start, min(start + step, basis.nelems))
        G = _gradients(nodal, cells)  # (cells, local dofs a, dim, points q)
        owners = basis.element_dofs[:, cells].T  # (cells, points)
        H = np.einsum("eaik,eajq->keqij", U[owners], G)  # ∇u of every vector at each nodal point
        n_cells = H.shape[1]
        sigma = _cell_stress(model, H.reshape(k * n_cells, points, dim, dim), "linear")[..., rows, cols]
        sigma = sigma.reshape(k, n_cells * points, 6).transpose(1, 0, 2).reshape(n_cells * points, k * 6)
        P = sp.csr_array((np.ones(owners.size), (owners.ravel(), np.arange(owners.size))),
                         shape=(basis.N, owners.size))  # nodal point → its node
        total += P @ sigma
    count = np.bincount(basis.element_dofs.ravel(), minlength=basis.N)
    return (total / np.maximum(count, 1)[:, None]).reshape(basis.N, k, 6).transpose(1, 0, 2)


def von_mises_voigt(s) -> np.ndarray:
    """The von Mises equivalent of stresses ``(..., 6)`` in :data:`VOIGT` order (as :func:`von_mises`).

    >>> float(von_mises_voigt(np.array([100.0, 0, 0, 0, 0, 0]))), round(float(von_mises_voigt(np.eye(6)[3])), 12)
    (100.0, 1.732050807569)
    """
    s = np.asarray(s, dtype=float)
    a, b, c = s[..., 0], s[..., 1], s[..., 2]
    shear = s[..., 3] ** 2 + s[..., 4] ** 2 + s[..., 5] ** 2
    return np.sqrt(0.5 * ((a - b) ** 2 + (b - c) ** 2 + (c - a) ** 2) + 3.0 * shear)
