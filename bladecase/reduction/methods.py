"""Reduction layer: from a finite-element model and its contact to the small system the solver consumes.

:func:`reduce` turns an :class:`~bladecase.fe.assembly.FEModel` and a contact (a node,
a casing normal and a clearance, :class:`bladecase.reduction.contact.Contact`) into a
:class:`ReducedModel`: a :class:`~bladecase.nsm.system.LinearSystem` with dense
reduced matrices ``M_r = VᵀMV``, ``K_r = VᵀKV``, constraint vector
``w_r = Vᵀw`` and the same clearance, plus the basis ``V`` (``x_free ≈ V q``)
that maps a reduced orbit back to the mesh (:meth:`ReducedModel.expand`).

Methods (theory §2):

``"full"``
    No reduction (``V = I``): dense ``M``, ``K``; refused above
    :data:`FULL_LIMIT` dofs.
``"modal"``
    The ``size`` lowest M-normalised modes ``Φ`` (sparse shift-invert about
    0): ``M_r = I``, ``K_r = diag(ω²)``, ``w_r = Φᵀw``.  Keeps the lowest
    ``size`` pairs ``(ω_j, b_j)`` exactly.
``"lanczos"``, ``"lanczos-si"``
    ``size`` Lanczos steps started at the contact
    (:func:`bladecase.reduction.lanczos.lanczos_chain`, plain or shift-invert about 0):
    a chain of unit masses, ``LinearSystem(I, J, |ŵ|e₁, d)``, with the
    impacting mass first.  Plain Lanczos matches the moments
    ``Σ b_j² ω_j^{2p}``, ``p < 2·size`` — it resolves the top of the FE
    spectrum first, not the lowest modes; shift-invert matches
    ``Σ b_j² ω_j^{-2p}``, ``p = 1..2·size``, and converges to the lowest
    modes the contact sees.
``"craig-bampton"``
    Boundary dofs = the free dofs of the contact node (all its directions),
    kept as physical coordinates, plus ``size`` fixed-interface modes:
    ``V = [[I, 0], [Ψ, Φ_i]]`` with the constraint modes
    ``Ψ = -K_ii⁻¹K_ib`` (sparse LU) and the lowest modes ``Φ_i`` of
    ``(K_ii, M_ii)``.  Its ``M_r`` is not diagonal, so the Moreau impact law
    (theory §1) is the one that conserves energy.

Every method but ``"full"`` works on sparse matrices only (no dense
``n × n`` array), so the ~100k-dof blades of the FE front end reduce in
seconds; see ``benchmarks/bench_reduction.py``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.spatial import cKDTree

from ..fe import FEModel, natural_frequencies
from ..fe.mesh import _P2_EDGES
from ..nsm import LinearSystem
from .contact import Contact
from .lanczos import LanczosChain, lanczos_chain

if TYPE_CHECKING:  # pragma: no cover
    from ..nsm import PeriodicOrbit

#: Accepted values of ``method`` in :func:`reduce`.
METHODS = ("full", "modal", "lanczos", "lanczos-si", "craig-bampton")

#: Largest model :func:`reduce` keeps whole (``method="full"``) or solves
#: densely (``"modal"``/``"craig-bampton"`` asking for more than half of the
#: available modes): a dense ``n × n`` float matrix is 72 MB at 3000 dofs.
FULL_LIMIT = 3000

_SUGGEST = "use method 'modal', 'lanczos', 'lanczos-si' or 'craig-bampton' with a size such as 50"


@dataclass(frozen=True, eq=False)
class ReducedModel:
    """A reduced finite-element model with one contact, and the way back to the mesh.

    Attributes
    ----------
    method : str
        One of :data:`METHODS`.
    size : int
        The ``size`` asked for: modes (``"modal"``), fixed-interface modes
        (``"craig-bampton"``, which adds the contact node's dofs), Lanczos
        steps, or the number of free dofs (``"full"``).  The number of
        reduced dofs is :attr:`n`.
    system : LinearSystem
        What the solver consumes: dense ``M_r``, ``K_r`` (a sparse chain for
        the Lanczos methods), ``w_r``, the contact's clearance.
    basis : (n_free, n) ndarray, or CSR for ``"full"``
        ``V``: free-dof displacements ``x ≈ V q`` of reduced coordinates
        ``q``; ``M_r = VᵀMV``, ``K_r = VᵀKV``, ``w_r = Vᵀw`` (the sparse
        identity for ``"full"``).
    model : FEModel
        The model that was reduced.
    contact : Contact
        The contact (node, casing normal, clearance).
    chain : LanczosChain or None
        The Lanczos chain (Jacobi matrix, breakdown flag) for the Lanczos
        methods; ``None`` otherwise.
    """

    method: str
    size: int
    system: LinearSystem
    basis: np.ndarray | sp.csr_array = field(repr=False)
    model: FEModel = field(repr=False)
    contact: Contact
    chain: LanczosChain | None = field(default=None, repr=False)

    @property
    def n(self) -> int:
        """Number of reduced degrees of freedom."""
        return self.system.n

    def free_dofs(self, x_r) -> np.ndarray:
        """Free-dof vectors ``V x_r`` of reduced states: ``(n,) -> (n_free,)``, ``(n, k) -> (n_free, k)``."""
        x_r = np.asarray(x_r, dtype=float)
        if x_r.ndim not in (1, 2) or x_r.shape[0] != self.n:
            raise ValueError(
                f"reduced state has shape {x_r.shape}, expected ({self.n},) or ({self.n}, k) "
                f"for this {self.method} model of {self.n} reduced dofs"
            )
        return np.asarray(self.basis @ x_r)

    def expand_state(self, x_r) -> np.ndarray:
        """Per-node displacements of reduced states.

        Parameters
        ----------
        x_r : (n,) or (n, k) array_like
            Reduced coordinates (positions or velocities), one state per column.

        Returns
        -------
        (n_nodes, dim) or (n_nodes, dim, k) ndarray
            Displacement of every mesh node (see :meth:`expand` for which
            nodes carry what).
        """
        x = self.free_dofs(x_r)
        u = self._node_operator @ (x if x.ndim == 2 else x[:, None])
        u = u.reshape(self.model.mesh.points.shape[0], self.model.dim, -1)
        return u if x.ndim == 2 else u[:, :, 0]

    def expand(self, orbit: PeriodicOrbit, t) -> tuple[np.ndarray, np.ndarray]:
        """Displacements and velocities of every mesh node along a periodic orbit of :attr:`system`.

        Parameters
        ----------
        orbit : PeriodicOrbit
            An orbit of this model's reduced system (``orbit.system.n == self.n``).
        t : float or (len(t),) array_like
            Times (the orbit is periodic; at an impact instant the
            post-impact velocity is returned).

        Returns
        -------
        u, v : (n_nodes, dim, len(t)) ndarray
            Per mesh node (``mesh.points`` order) and direction.  Clamped
            nodes and nodes outside the body cells are zero.  The edge dofs
            of P2 models (``dofs.node == -1``) are not mesh nodes and get no
            row of their own; when the mesh has quadratic cells
            (``tetra10``/``triangle6``) their midside nodes carry the FE
            field at the straight edge's midpoint (the edge dof for P2, the
            mean of the two end vertices for P1).
        """
        if not hasattr(orbit, "state") or not hasattr(orbit, "system"):
            raise ValueError(f"orbit must be a PeriodicOrbit of this model's system, got {type(orbit).__name__}")
        if orbit.system.n != self.n:
            raise ValueError(
                f"orbit belongs to a system of {orbit.system.n} dofs, this {self.method} model has {self.n} "
                "reduced dofs: expand an orbit of reduced.system"
            )
        x_r, v_r = orbit.state(np.atleast_1d(np.asarray(t, dtype=float)))
        return self.expand_state(x_r), self.expand_state(v_r)

    @cached_property
    def _node_operator(self) -> sp.csr_array:
        return node_operator(self.model)

    def __repr__(self) -> str:
        return (f"ReducedModel({self.method!r}, size={self.size}, {self.n} reduced dofs "
                f"of {self.model.n_dofs} free dofs, gap={self.system.gap:g})")


def node_operator(model: FEModel) -> sp.csr_array:
    """Sparse map from free-dof vectors to per-node displacements, flattened ``(n_nodes·dim, n_free)``.

    Row ``dim·p + c`` gives component ``c`` at mesh node ``p``: the vertex dof
    of ``p`` when it has one; for the midside nodes of quadratic mesh cells,
    the FE field at the straight edge's midpoint (P2: the edge dof located
    there; P1: the mean of the two end vertices); zero for clamped nodes and
    nodes outside the body cells.
    """
    dofs, dim = model.dofs, model.dim
    n_nodes = model.mesh.points.shape[0]
    vertex = np.flatnonzero(dofs.node >= 0)
    rows = [dim * dofs.node[vertex] + dofs.direction[vertex]]
    cols = [vertex]
    vals = [np.ones(vertex.size)]
    cells = np.asarray(model.mesh.cells[model.mesh.body_type])
    if cells.shape[1] > dim + 1:  # quadratic mesh: fill its midside nodes
        pairs = np.stack([cells[:, [a, b]] for a, b in _P2_EDGES[dim]], axis=1).reshape(-1, 2)
        mids = cells[:, dim + 1:].reshape(-1)
        mids, first = np.unique(mids, return_index=True)
        pairs = pairs[first]
        if model.order == 2:  # the dim dofs of an edge location are consecutive, direction 0 first
            edge = np.flatnonzero((dofs.node < 0) & (dofs.direction == 0))
            if edge.size:
                centre = 0.5 * (model.mesh.points[pairs[:, 0]] + model.mesh.points[pairs[:, 1]])
                dist, k = cKDTree(dofs.coords[edge]).query(centre)
                ok = dist <= 1e-9 * np.abs(model.mesh.points).max()  # else: a clamped edge
                for c in range(dim):
                    rows.append(dim * mids[ok] + c)
                    cols.append(edge[k[ok]] + c)
                    vals.append(np.ones(int(ok.sum())))
        else:
            table = np.full((n_nodes, dim), -1, dtype=np.int64)  # free dof of (node, direction), -1 if none
            table[dofs.node[vertex], dofs.direction[vertex]] = vertex
            for end in (0, 1):
                for c in range(dim):
                    d = table[pairs[:, end], c]
                    ok = d >= 0
                    rows.append(dim * mids[ok] + c)
                    cols.append(d[ok])
                    vals.append(np.full(int(ok.sum()), 0.5))
    return sp.csr_array(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
        shape=(n_nodes * dim, model.n_dofs),
    )


# ----------------------------------------------------------------------------- the front door

def reduce(model: FEModel, contact: Contact, method: str, size: int | None = None) -> ReducedModel:
    """Reduce a finite-element model with one contact to the system the solver consumes.

    Parameters
    ----------
    model : FEModel
        A clamped model (:func:`bladecase.assemble`).
    contact : Contact
        Contact node, casing normal and clearance (:class:`bladecase.reduction.contact.Contact`);
        ``contact.w(model)`` is the constraint vector on the free dofs.
    method : {"full", "modal", "lanczos", "lanczos-si", "craig-bampton"}
        See the module docstring.
    size : int or None
        Modes (``"modal"``, ``1 <= size <= n_free``), fixed-interface modes
        (``"craig-bampton"``, ``1 <= size <= n_free - n_boundary``) or
        Lanczos steps (``1 <= size <= n_free``).  Asking for more than half
        of the available modes switches to a dense eigen-solution, allowed
        up to :data:`FULL_LIMIT` dofs.  ``"full"`` takes ``None`` (or
        ``n_free``).

    Returns
    -------
    ReducedModel

    Raises
    ------
    ValueError
        Unknown method (the message lists the valid ones), a bad size, a
        ``"full"`` model above :data:`FULL_LIMIT` dofs, a contact node with
        no free dof, or a singular (unclamped) model.
    """
    if not isinstance(model, FEModel):
        raise ValueError(f"model must be an FEModel (from bladecase.assemble), got {type(model).__name__}")
    if method not in METHODS:
        valid = ", ".join(repr(m) for m in METHODS)
        raise ValueError(f"unknown reduction method {method!r} (valid: {valid})")
    if not isinstance(contact, Contact):
        raise ValueError(
            f"contact must be a bladecase.Contact (node, normal, gap), got {type(contact).__name__}"
        )
    n = model.n_dofs
    if method == "full":
        if size is not None and size != n:
            raise ValueError(
                f"method 'full' keeps all {n} free dofs: size must be None (or {n}), got {size!r}"
            )
        return _full(model, contact)
    if size is None:
        raise ValueError(f"method {method!r} needs a size (an integer >= 1), got None")
    if isinstance(size, (bool, np.bool_)) or not isinstance(size, (int, np.integer)) or size < 1:
        raise ValueError(
            f"size must be an integer >= 1 (modes or Lanczos steps), got {size!r}"
        )
    size = int(size)
    if method == "modal":
        return _modal(model, contact, size)
    if method == "craig-bampton":
        return _craig_bampton(model, contact, size)
    return _lanczos(model, contact, size, shift_invert=method == "lanczos-si")


def _constraint(model: FEModel, contact) -> np.ndarray:
    w = np.asarray(contact.w(model), dtype=float).reshape(-1)
    if w.shape != (model.n_dofs,):
        raise ValueError(f"contact.w(model) has {w.size} entries, expected {model.n_dofs} (one per free dof)")
    return w


def _full(model: FEModel, contact) -> ReducedModel:
    n = model.n_dofs
    if n > FULL_LIMIT:
        raise ValueError(
            f"method 'full' builds dense {n} x {n} matrices and is limited to FULL_LIMIT = {FULL_LIMIT} "
            f"dofs; this model has {n} free dofs: {_SUGGEST}"
        )
    system = LinearSystem(model.M.toarray(), model.K.toarray(), _constraint(model, contact), contact.gap)
    return ReducedModel("full", n, system, sp.eye_array(n, format="csr"), model, contact)


def _check_count(method: str, size: int, available: int, what: str) -> bool:
    """Validate ``size <= available``; return True when the dense eigen-solution is to be used."""
    if size > available:
        raise ValueError(f"size = {size} is too large for method {method!r}: {what} has {available} modes "
                         f"(valid: 1..{available})")
    dense = size > available // 2
    if dense and available > FULL_LIMIT:
        raise ValueError(
            f"size = {size} is too large for method {method!r}: the sparse eigen-solver computes at most "
            f"{available // 2} of the {available} modes of {what} (more than half needs a dense "
            f"eigen-solution, limited to FULL_LIMIT = {FULL_LIMIT} dofs)"
        )
    return dense


def _sign_convention(phi: np.ndarray) -> np.ndarray:
    """Flip each column so that its largest component is positive (as :class:`~bladecase.nsm.system.Spectrum`)."""
    idx = np.argmax(np.abs(phi), axis=0)
    return phi * np.sign(phi[idx, np.arange(phi.shape[1])])[None, :]


def _lowest_modes(K, M, count: int, dense: bool, lu=None) -> tuple[np.ndarray, np.ndarray]:
    """``(λ, Φ)``: the ``count`` lowest eigenpairs of ``K φ = λ M φ``, ``ΦᵀMΦ = I``, ascending."""
    if dense:
        lam, phi = sla.eigh(K.toarray(), M.toarray(), subset_by_index=[0, count - 1])
    else:
        if lu is None:
            lu = _factor(K, "K")
        op = spla.LinearOperator(K.shape, matvec=lu.solve, matmat=lu.solve, dtype=float)
        lam, phi = spla.eigsh(K, k=count, M=M, sigma=0.0, which="LM", OPinv=op)
        order = np.argsort(lam)
        lam, phi = lam[order], phi[:, order]
        phi = phi / np.sqrt(np.einsum("ij,ij->j", phi, M @ phi))[None, :]
    if not np.all(np.isfinite(lam)) or lam[0] <= 0:
        raise ValueError(f"the stiffness is not positive definite: eigenvalue {lam[0]:.3g} (a mechanism?)")
    return lam, _sign_convention(phi)


def _factor(K, name: str):
    """Sparse LDLᵀ of a symmetric positive definite matrix (SuperLU, symmetric mode), as in :mod:`bladecase.fem`."""
    try:
        return spla.splu(sp.csc_array(K), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                         options={"SymmetricMode": True})
    except RuntimeError as exc:
        raise ValueError(f"{name} is singular ({exc}): is the model clamped?") from None


def _modal(model: FEModel, contact, size: int) -> ReducedModel:
    n = model.n_dofs
    dense = _check_count("modal", size, n, f"the model ({n} free dofs)")
    w = _constraint(model, contact)
    if dense:
        lam, phi = _lowest_modes(model.K, model.M, size, dense=True)
    else:
        f, phi = natural_frequencies(model, size, return_modes=True)
        lam = (2 * np.pi * f) ** 2
        phi = _sign_convention(phi / np.sqrt(np.einsum("ij,ij->j", phi, model.M @ phi))[None, :])
    system = LinearSystem(np.eye(size), np.diag(lam), phi.T @ w, contact.gap)
    return ReducedModel("modal", size, system, phi, model, contact)


def _craig_bampton(model: FEModel, contact, size: int) -> ReducedModel:
    n = model.n_dofs
    b = contact.dofs(model)  # boundary: the contact node's free dofs, in direction order
    w = _constraint(model, contact)
    inner = np.setdiff1d(np.arange(n), b)
    dense = _check_count("craig-bampton", size, inner.size,
                         f"the fixed-interface problem ({inner.size} interior dofs)")
    K, M = sp.csr_array(model.K), sp.csr_array(model.M)
    K_ii = sp.csc_array(K[inner][:, inner])
    M_ii = sp.csr_array(M[inner][:, inner])
    K_ib = K[inner][:, b].toarray()
    lu = _factor(K_ii, "the interior stiffness K_ii")
    psi = -lu.solve(K_ib)  # constraint modes, (n_i, n_b)
    _, phi_i = _lowest_modes(K_ii, M_ii, size, dense=dense, lu=lu)
    nb = b.size
    V = np.zeros((n, nb + size))
    V[b, np.arange(nb)] = 1.0
    V[inner, :nb] = psi
    V[inner, nb:] = phi_i
    M_r = V.T @ (M @ V)
    K_r = V.T @ (K @ V)
    system = LinearSystem(0.5 * (M_r + M_r.T), 0.5 * (K_r + K_r.T), V.T @ w, contact.gap)
    return ReducedModel("craig-bampton", size, system, V, model, contact)


def _lanczos(model: FEModel, contact, size: int, shift_invert: bool) -> ReducedModel:
    n = model.n_dofs
    method = "lanczos-si" if shift_invert else "lanczos"
    if size > n:
        raise ValueError(f"size = {size} is too large for method {method!r}: at most {n} Lanczos steps "
                         f"(the model has {n} free dofs)")
    chain = lanczos_chain(model, size, contact=contact, shift_invert=shift_invert)
    return ReducedModel(method, size, chain.system, chain.basis, model, contact, chain=chain)


# ----------------------------------------------------------------------------- stage files

#: Format tag of the ``.npz`` files written by :func:`save_reduced`.
REDUCED_FORMAT = "bladecase-reduced-1"


def save_reduced(reduced: ReducedModel, path) -> None:
    """Write a :class:`ReducedModel` (reduced system, basis, contact and the FE model) to ``.npz``, atomically.

    The Lanczos chain object is not stored (its Jacobi matrix is the reduced ``K``).
    """
    from ..fe.assembly import model_to_arrays, sparse_to_arrays
    from ..io import atomic_path

    s, c = reduced.system, reduced.contact
    out = {"format": np.array(REDUCED_FORMAT), "method": np.array(reduced.method),
           "size": np.array(-1 if reduced.size is None else reduced.size), "w": s.w, "gap": np.array(s.gap),
           "contact/node": np.array(c.node), "contact/gap": np.array(c.gap),
           "contact/normal": np.array([] if c.normal is None else c.normal, dtype=float)}
    for name, A in (("Mr", s.M), ("Kr", s.K)):
        out.update(sparse_to_arrays(name, A) if sp.issparse(A) else {name: np.asarray(A)})
    if sp.issparse(reduced.basis):
        out.update(sparse_to_arrays("basis", reduced.basis))
    else:
        out["basis"] = np.asarray(reduced.basis)
    out.update(model_to_arrays(reduced.model, prefix="model/"))
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez_compressed(fh, **out)


def load_reduced(path) -> ReducedModel:
    """Read a :class:`ReducedModel` written by :func:`save_reduced`."""
    from ..fe.assembly import model_from_arrays, sparse_from_arrays

    try:
        with np.load(path, allow_pickle=False) as data:
            if "format" not in data or str(data["format"]) != REDUCED_FORMAT:
                raise ValueError(
                    f"{str(path)!r} is not a bladecase reduced-model file (expected format {REDUCED_FORMAT!r}; "
                    "write one with 'bladecase reduce' or bladecase.reduction.save_reduced)")

            def matrix(name):
                return sparse_from_arrays(data, name) if f"{name}/data" in data else np.asarray(data[name])

            model = model_from_arrays(data, prefix="model/", source=str(path))
            normal = np.asarray(data["contact/normal"])
            contact = Contact(int(data["contact/node"]), tuple(normal) if normal.size else None,
                              float(data["contact/gap"]))
            size = int(data["size"])
            system = LinearSystem(matrix("Mr"), matrix("Kr"), np.asarray(data["w"]), float(data["gap"]))
            return ReducedModel(method=str(data["method"]), size=None if size < 0 else size, system=system,
                                basis=matrix("basis"), model=model, contact=contact)
    except (OSError, EOFError, KeyError) as exc:
        raise ValueError(f"cannot read reduced-model file {str(path)!r}: {exc}") from None
