"""The massless contact model of a finite-element structure (theory §8): :func:`massless_model`.

The contact dofs ``c`` are the free dofs where the constraint vector ``w`` is non-zero (one node's normal dofs,
or those of every node of a face set, :meth:`Contact.face <bladecase.reduction.Contact.face>`); the others are
the interior ``i``.

**Mass.** The contact dofs carry no inertia: :func:`massless_masses` moves their lumped mass, direction by
direction, to the nearest non-contact dofs of the same direction (coupled to them in ``K``; the next ring of
neighbours is added when the first cannot do it), the smallest change ``Σ δ_j²/m_j`` that keeps, for each
direction, the **total mass** and the **first moments** (the centre of mass) exactly, every mass positive. So
the rigid-body translations keep their inertia and their coupling to rotations. The **second moments** (rotary
inertia) are NOT kept: they change by about ``m_c`` times the squared distances the mass moves, a mesh-scale
amount that vanishes under refinement. A lumped (diagonal) mass model is required (``[fem] mass = "lumped"``).

**Phases.** With no inertia, the contact dofs are static in each phase:

- open (``λ = 0``): ``x_c = −K_cc⁻¹K_ci x_i``; interior stiffness ``S = K_ii − K_icK_cc⁻¹K_ci``; the contact
  displacement is ``wᵀx = ŵᵀx_i`` with ``ŵ = −K_icK_cc⁻¹w_c``;
- closed: ``K_cc x_c + K_ci x_i = −λ w_c`` (theory §8), i.e. ``x_c = −K_cc⁻¹(K_ci x_i + λ w_c)`` with
  ``λ = k_c (ŵᵀx_i − d) >= 0`` and ``k_c = 1/(w_cᵀK_cc⁻¹w_c)``, which holds ``wᵀx = d`` exactly.

**Reduction** (the massless-boundary analogue of Craig–Bampton). ``size=None``: the exact condensation of every
interior dof (``V_i = I``; :func:`bladecase.nsm.condense` on the same matrices), for at most
``MASSLESS_DENSE_LIMIT`` interior dofs. ``size=m``: ``V_i`` = the ``m`` lowest modes of the massless structure
(``K φ = ω² M φ`` on all free dofs with ``M`` zero on ``c``, shift-invert Lanczos about 0 with the ONE
factorisation of ``K``; their interior parts are the modes of ``(S, M_ii)``) plus the attachment vector
``(K⁻¹w)_i = S⁻¹ŵ``, M-orthonormalised. ``V_full`` carries the slaved contact rows ``−K_cc⁻¹K_ciV_i``, and the
reduced model is ``MasslessSystem(V_iᵀM_iiV_i, V_fullᵀKV_full, V_fullᵀw, k_c, d)``. The attachment vector makes
the static contact compliance ``1/k_c + ŵ_rᵀS_r⁻¹ŵ_r = wᵀK⁻¹w`` exact at any size. Expansion:
``x = V_full q + λ(q)·[0 on i; −K_cc⁻¹w_c on c]`` (:meth:`MasslessReducedModel.free_dofs`).

**Which contact.** A single node in 3-D is a point load: its static compliance ``wᵀK⁻¹w`` — hence ``k_c`` and
the contact's dynamics — grows without bound as the mesh is refined (like ``1/h``; logarithmically in 2-D). The
mean normal displacement of a face (:meth:`Contact.face`; ``weights="area"`` for the exact mean on any mesh) has
a compliance that converges (``tests/test_massless_fe.py``: order ≈ 1.1–1.3 in 2-D and 3-D).

>>> from skfem import MeshTri
>>> from bladecase.fe import Mesh, assemble
>>> from bladecase.reduction import Contact
>>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5))
>>> p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
>>> strip = Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 0] == 0)})
>>> model = assemble(strip, "steel", order=1, thickness=0.002, mass="lumped")
>>> contact = Contact.nearest(model, (0.1, 0.02), normal=(0.0, 1.0), gap=1e-4)
>>> reduced = massless_model(model, contact, 6)      # 6 modes + the attachment vector
>>> reduced.system
MasslessSystem(n=7, gap=0.0001, kc=2.967e+08)
>>> exact = massless_model(model, contact)           # every interior dof (199): small models only
>>> exact.n, bool(abs(exact.system.kc / reduced.system.kc - 1) < 1e-12)
(199, True)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ..checks import integer
from ..fe import FEModel
from ..linalg import DENSE_LIMIT, SPDFactor, check_factor, lowest_modes, spd_factor
from ..nsm import MASSLESS_DENSE_LIMIT, MasslessSystem, redistribute_mass, series_stiffness
from .contact import Contact
from .model import ReducedModel

__all__ = ["MASS_RINGS", "MasslessReducedModel", "massless_masses", "massless_model"]

#: Rings of neighbours (in the graph of ``K``) searched for dofs to take the contact dofs' mass.
MASS_RINGS = 4

#: ``K``'s name and hint in messages.
_K, _HINT = "K", "is the model clamped?"


@dataclass(frozen=True, eq=False)
class MasslessReducedModel(ReducedModel):
    """A reduced model of the massless contact model: ``system`` is a :class:`~bladecase.nsm.MasslessSystem`.

    ``basis`` is ``V_full`` (open-phase displacements of every free dof; sparse for the exact condensation,
    ``size=None``); ``closed_shape`` the free-dof displacement per unit contact force with the interior held
    (``−K_cc⁻¹w_c`` on the contact dofs, zero elsewhere), added ``λ`` times in a closed phase; ``masses`` the
    redistributed lumped masses of the free dofs (zero on the contact dofs); ``spare`` the interior rows of the
    directions the eigen-solver's Krylov basis holds beyond the modes (Ritz vectors, lowest first; ``None`` when
    ARPACK found the modes), which the reference model reuses (:func:`extend_massless`). :meth:`free_dofs` and
    :meth:`expand_state` take positions (they add the closed-phase correction); velocities go through
    :meth:`free_velocities` (``λ'`` on the contact dofs), which :meth:`expand` uses.
    """

    closed_shape: np.ndarray = field(default=None, repr=False)  # type: ignore[assignment]
    masses: np.ndarray = field(default=None, repr=False)  # type: ignore[assignment]
    spare: np.ndarray | None = field(default=None, repr=False)

    def krylov_extended(self, count: int, fac: SPDFactor) -> MasslessReducedModel:
        """This model extended by the block Krylov sequence of its own factorisation (:func:`extend_massless`; what
        :func:`bladecase.reduction.extension.krylov_extension` does for a massless model)."""
        return extend_massless(self, count, fac)

    @property
    def mass_matrix(self) -> sp.dia_array:
        """The massless model's (lumped, redistributed) mass matrix on the free dofs."""
        return sp.diags_array(self.masses)

    def multiplier(self, x_r) -> np.ndarray | float:
        """Contact force ``λ = k_c max(0, w_rᵀq − d)`` of reduced states ``(n,)`` or ``(n, k)``."""
        s = self.system
        return s.kc * np.maximum(0.0, s.w @ np.asarray(x_r, dtype=float) - s.gap)

    def free_dofs(self, x_r) -> np.ndarray:
        """Free-dof displacements of reduced states, the closed phase's contact correction included.

        ``V_full q + λ(q)·closed_shape``: ``wᵀx = d`` holds where ``λ > 0`` (``d + λ / casing`` against a compliant
        casing); ``V_full q`` where open.
        """
        x = super().free_dofs(x_r)
        lam = self.multiplier(x_r)
        return x + (np.multiply.outer(self.closed_shape, lam) if x.ndim == 2 else self.closed_shape * lam)

    def free_velocities(self, x_r, v_r) -> np.ndarray:
        """Free-dof velocities (``λ' = k_c ŵ_rᵀv`` where closed)."""
        v = super().free_dofs(v_r)
        x_r, v_r = np.asarray(x_r, dtype=float), np.asarray(v_r, dtype=float)
        closed = (self.system.w @ x_r) > self.system.gap
        lam_dot = self.system.kc * (self.system.w @ v_r) * closed
        return v + (np.multiply.outer(self.closed_shape, lam_dot) if v.ndim == 2 else self.closed_shape * lam_dot)

    def __repr__(self) -> str:
        return (f"MasslessReducedModel(size={self.size}, {self.n} reduced dofs of {self.model.n_dofs} free dofs, "
                f"kc={self.system.kc:.4g}, gap={self.system.gap:g})")


# ----------------------------------------------------------------------------- mass


def _neighbours(K: sp.csr_array, dofs: np.ndarray, same: np.ndarray, outside: np.ndarray) -> np.ndarray:
    """Dofs coupled in ``K`` to ``dofs`` where ``same`` (the direction) holds and ``outside`` (not contact)."""
    cols = np.unique(np.concatenate([K.indices[K.indptr[j]:K.indptr[j + 1]] for j in dofs]))
    return cols[same[cols] & outside[cols]]


def _check_lumped(model: FEModel) -> None:
    if model.mass != "lumped":
        raise ValueError(f"the massless contact model moves lumped masses: assemble with mass='lumped' "
                         f"([fem] mass = \"lumped\"), got mass={model.mass!r}")


def massless_masses(model: FEModel, c: np.ndarray) -> np.ndarray:
    """Lumped free-dof masses with those of the contact dofs ``c`` moved to their neighbours (module docstring).

    For each direction, the contact dofs of that direction form one set whose mass goes to the non-contact dofs
    of the same direction coupled to it in ``K`` (a ring; up to :data:`MASS_RINGS` rings when the first cannot
    keep the centre of mass with positive masses, e.g. a face at the end of the body): total mass and first
    moments of each direction kept, second moments (rotary inertia) not.

    Raises
    ------
    ValueError
        A consistent mass model (assemble with ``mass="lumped"``), or no ring of neighbours that can take the mass.
    """
    _check_lumped(model)
    c = np.asarray(c, dtype=int)
    m = np.asarray(model.M.diagonal(), dtype=float).copy()
    K = sp.csr_array(model.K)
    direction, coords = model.dofs.direction, model.dofs.coords[:, :model.dim]
    outside = np.ones(m.size, dtype=bool)
    outside[c] = False
    for d in np.unique(direction[c]):
        cd = c[direction[c] == d]
        total = float(m[cd].sum())
        centre = m[cd] @ coords[cd] / total
        same = direction == d
        ring, error = _neighbours(K, cd, same, outside), "no neighbour"
        for _ in range(MASS_RINGS):
            if ring.size:
                try:  # the set as one virtual node at its centre of mass, moved to the ring
                    moved = redistribute_mass(np.r_[m[ring], total], np.vstack([coords[ring], centre]), ring.size,
                                              np.arange(ring.size))
                    break
                except ValueError as exc:  # its message names the virtual node: say why in words
                    error = ("a mass would become non-positive" if "non-positive" in str(exc)
                             else "too few or aligned neighbours to keep the centre of mass")
            ring = np.union1d(ring, _neighbours(K, ring, same, outside)) if ring.size else ring
        else:
            nodes = sorted(set(model.dofs.node[cd].tolist()))
            raise ValueError(f"the mass of the contact dofs {cd.tolist()} (direction {int(d)}, nodes {nodes}) cannot "
                             f"be moved to {MASS_RINGS} rings of neighbours keeping the total mass and the centre of "
                             f"mass with positive masses ({error})")
        m[ring] = moved[:-1]
        m[cd] = 0.0
    return m


# ----------------------------------------------------------------------------- the model


@dataclass(frozen=True, eq=False)
class _Split:
    """The contact/interior partition of ``K`` and what the phases need from ``K_cc`` (small: the contact)."""

    w: np.ndarray
    c: np.ndarray
    i: np.ndarray
    K: sp.csr_array
    K_ci: sp.csr_array
    cc: SPDFactor

    @property
    def kc(self) -> float:
        return 1.0 / float(self.w[self.c] @ self.cc.solve(self.w[self.c]))

    def closed_shape(self) -> np.ndarray:
        shape = np.zeros(self.w.size)
        shape[self.c] = -self.cc.solve(self.w[self.c])  # the casing pushes back: K_cc x_c + K_ci x_i = −λ w_c
        return shape

    def slave(self, V_i: np.ndarray) -> np.ndarray:
        """Open-phase contact rows ``−K_cc⁻¹K_ci V_i``."""
        return -self.cc.solve(np.asarray(self.K_ci @ V_i)).reshape(self.c.size, -1)

    def schur(self) -> np.ndarray:
        """Dense ``S = K_ii − K_icK_cc⁻¹K_ci`` (small models only)."""
        K_ii = self.K[self.i][:, self.i].toarray()
        S = K_ii + self.K_ci.T @ self.slave(np.eye(self.i.size))
        return 0.5 * (S + S.T)


def _split(model: FEModel, contact: Contact) -> _Split:
    w = np.asarray(contact.w(model), dtype=float).reshape(-1)
    if w.shape != (model.n_dofs,):
        raise ValueError(f"contact.w(model) has {w.size} entries, expected {model.n_dofs} (one per free dof)")
    c = np.flatnonzero(w)
    i = np.flatnonzero(w == 0)
    K = sp.csr_array(model.K)
    K_cc = sp.csc_array(K[c][:, c])
    cc = spd_factor(K_cc.toarray() if c.size <= 500 else K_cc, "K_cc (the contact dofs' stiffness)", hint=_HINT)
    return _Split(w, c, i, K, sp.csr_array(K[c][:, i]), cc)


#: Interior bases of :func:`massless_model`: the registered method of each.
BASES = {"modes": "massless", "krylov": "massless-lanczos", "modal": "massless-modal"}


def massless_model(model: FEModel, contact: Contact, size: int | None = None,
                   factor: SPDFactor | None = None, basis: str = "modes") -> MasslessReducedModel:
    """The massless contact model of ``model`` with ``contact``, exact or reduced (module docstring).

    Parameters
    ----------
    model : FEModel
        A clamped model with lumped mass (``assemble(..., mass="lumped")``).
    contact : Contact
        One node or a face set (:meth:`Contact.face`); its non-zero constraint entries are the contact dofs.
    size : int or None
        ``None``: exact condensation of every interior dof (at most ``MASSLESS_DENSE_LIMIT`` of them).
        ``m``: the ``m`` lowest modes of the massless structure plus the attachment vector, ``m + 1`` reduced
        dofs (``1 <= m <= n_interior - 1``).
    factor : SPDFactor or None
        ``bladecase.fe.stiffness_factor(model)``, reused (the modes and the attachment vector need ``K⁻¹``).
    basis : str
        How a ``size`` reduces the interior (the existing methods applied to the redistributed mass):
        ``"modes"`` (method ``massless``: the massless-boundary Craig–Bampton, modes + attachment vector),
        ``"krylov"`` (``massless-lanczos``: the shift-invert Lanczos vectors ``(K⁻¹M)^j K⁻¹w``, j = 0…size, of the
        massless structure, started from the attachment vector — ``size + 1`` dofs, the static compliance exact)
        or ``"modal"`` (``massless-modal``: the ``size`` modes alone, the compliance truncated).

    Returns
    -------
    MasslessReducedModel
        ``.system`` is a :class:`~bladecase.nsm.MasslessSystem`; ``.free_dofs`` / ``.expand`` go back to the
        model with the closed-phase correction.

    Raises
    ------
    ValueError
        Consistent mass, a contact with no free dof, a bad ``size`` (``None`` on a large model: give a size),
        a ``factor`` of another matrix, a singular ``K``.
    """
    if not isinstance(model, FEModel):
        raise ValueError(f"model must be an FEModel (from bladecase.assemble), got {type(model).__name__}")
    if basis not in BASES:
        raise ValueError(f"basis must be one of {', '.join(map(repr, BASES))}, got {basis!r}")
    if not isinstance(contact, Contact):
        raise ValueError(f"contact must be a bladecase.Contact (node or face, normal, gap), "
                         f"got {type(contact).__name__}")
    factor = check_factor(factor, model.K, "this model's K", "bladecase.fe.stiffness_factor(model)")
    _check_lumped(model)  # before any factorisation
    split = _split(model, contact)
    n_i = split.i.size
    if size is None:
        if n_i > MASSLESS_DENSE_LIMIT:
            raise ValueError(f"size=None condenses all {n_i} interior dofs exactly, limited to MASSLESS_DENSE_LIMIT "
                             f"= {MASSLESS_DENSE_LIMIT}: give a size (e.g. 20 modes of the massless structure)")
    else:
        size = integer("size", size, 1, note=" (modes of the massless structure), or None (exact)")
        if size > n_i - 1:
            raise ValueError(f"size = {size} is too large for method 'massless': the massless structure has {n_i} "
                             f"interior dofs and the attachment vector takes one (valid: 1..{n_i - 1}, or None "
                             "for the exact condensation)")
        if size > n_i // 2 and n_i > DENSE_LIMIT:
            raise ValueError(f"size = {size}: more than half of the {n_i} massless modes needs a dense "
                             f"eigen-solution, limited to DENSE_LIMIT = {DENSE_LIMIT} interior dofs "
                             f"(valid: 1..{n_i // 2})")
    masses = massless_masses(model, split.c)
    if size is None:
        V, M_r = _exact_basis(split), np.diag(masses[split.i])
    else:
        fac = factor if factor is not None else spd_factor(model.K, _K, hint=_HINT)
        attach = fac.solve(split.w)[split.i]
        space: list = []
        if basis == "krylov":
            V_i = _krylov(split, masses, size, fac)
        elif basis == "modal":
            phi = _interior_modes(split, masses, size, fac, space)
            V_i = phi / np.sqrt(np.einsum("ij,i,ij->j", phi, masses[split.i], phi))
        else:
            V_i = _m_orthonormal(_interior_modes(split, masses, size, fac, space), attach, masses[split.i])
        return _reduced(split, masses, V_i, model, contact, BASES[basis], size,
                        spare=space[0][split.i] if space else None)
    S_r = split.schur()
    system = MasslessSystem(np.asarray(M_r), 0.5 * (S_r + S_r.T), np.asarray(V.T @ split.w),
                            series_stiffness(split.kc, contact.casing), contact.gap, casing=contact.casing)
    return MasslessReducedModel("massless", size, system, V, model, contact, closed_shape=split.closed_shape(),
                                masses=masses)


def _reduced(split: _Split, masses: np.ndarray, V_i: np.ndarray, model: FEModel, contact: Contact, method: str,
             size: int, spare: np.ndarray | None = None) -> MasslessReducedModel:
    """The massless model on the interior basis ``V_i`` (the contact rows slaved: ``V_full``)."""
    V = np.zeros((split.w.size, V_i.shape[1]))
    V[split.i], V[split.c] = V_i, split.slave(V_i)
    M_r = V_i.T @ (masses[split.i][:, None] * V_i)
    S_r = V.T @ (split.K @ V)
    system = MasslessSystem(0.5 * (M_r + M_r.T), 0.5 * (S_r + S_r.T), np.asarray(V.T @ split.w),
                            series_stiffness(split.kc, contact.casing), contact.gap, casing=contact.casing)
    return MasslessReducedModel(method, size, system, V, model, contact, closed_shape=split.closed_shape(),
                                masses=masses, spare=spare)


def _interior_operator(split: _Split, masses: np.ndarray, fac: SPDFactor):
    """``X_i -> (K⁻¹ M X)_i`` with ``M`` the redistributed masses (zero on the contact): blocks ``(n_i, k)``."""
    def apply(X: np.ndarray) -> np.ndarray:
        full = np.zeros((split.w.size,) + X.shape[1:])
        full[split.i] = (masses[split.i] * X.T).T
        return fac.solve(full)[split.i]
    return apply


def extend_massless(reduced: MasslessReducedModel, count: int, fac: SPDFactor) -> MasslessReducedModel:
    """:func:`bladecase.reduction.extension.krylov_extension` of a massless model: the interior basis extended
    by the block Krylov sequence of the massless structure (its interior columns and the attachment vector's).

    When the model's modes came from the block Lanczos (``spare``), its Krylov space stands for the random
    directions of :data:`~bladecase.reduction.extension.WIDEN`: the attachment vector's sequence takes the same
    share of the new dofs (one in ``1 + widen``), the eigen-solver's Ritz vectors the rest, lowest first — no solve
    beyond the sequence's."""
    from .extension import FRONTIER, SUFFIX, WIDEN, extend_basis

    split = _split(reduced.model, reduced.contact)
    m_i = reduced.masses[split.i]
    operator, mass = _interior_operator(split, reduced.masses, fac), lambda X: (m_i * X.T).T
    count, frontier, widen = min(count, split.i.size - 1), FRONTIER.get(reduced.method), WIDEN.get(reduced.method, 0)
    V_i = np.asarray(reduced.basis)[split.i]
    if reduced.spare is not None and widen:  # the contact's own sequence, then the eigen-solver's Krylov space
        V_i = extend_basis(V_i, fac.solve(split.w)[split.i], operator, mass,
                           V_i.shape[1] + (count - V_i.shape[1]) // (1 + widen), frontier)
        frontier = ()
    V_i = extend_basis(V_i, fac.solve(split.w)[split.i] if reduced.spare is None else reduced.spare, operator, mass,
                       count, frontier, widen=widen if reduced.spare is None else 0)
    return _reduced(split, reduced.masses, V_i, reduced.model, reduced.contact, reduced.method + SUFFIX,
                    V_i.shape[1])


def _exact_basis(split: _Split) -> sp.csr_array:
    """``V_full = [I on i; −K_cc⁻¹K_ci on c]`` (sparse; the interior dofs are the reduced coordinates)."""
    n, n_i = split.w.size, split.i.size
    X = split.slave(np.eye(n_i))
    r, k = np.nonzero(X)
    rows = np.r_[split.i, split.c[r]]
    cols = np.r_[np.arange(n_i), k]
    return sp.csr_array((np.r_[np.ones(n_i), X[r, k]], (rows, cols)), shape=(n, n_i))


def _interior_modes(split: _Split, masses: np.ndarray, count: int, fac: SPDFactor,
                    space: list | None = None) -> np.ndarray:
    """Interior parts of the ``count`` lowest modes of the massless structure, ``M_ii``-normalised.

    Sparse: ``K φ = ω² M φ`` on all free dofs with ``M`` zero on the contact (shift-invert about 0 with ``fac``;
    its Krylov vectors ``K⁻¹Mv`` have the slaved contact rows, ``S`` is never formed). More than half of the
    modes: dense ``(S, M_ii)`` (a small model).
    """
    n_i = split.i.size
    m_i = masses[split.i]
    if count > n_i // 2:
        _, phi = sla.eigh(split.schur(), np.diag(m_i), subset_by_index=[0, count - 1])
        return phi
    _, phi = lowest_modes(split.K, sp.diags_array(masses, format="csr"), count, factor=fac, dense=False, name=_K,
                          hint=_HINT, space=space)
    return phi[split.i]


def _krylov(split: _Split, masses: np.ndarray, size: int, fac: SPDFactor) -> np.ndarray:
    """Interior parts of ``u_0 = K⁻¹w``, ``u_{j+1} = K⁻¹M u_j`` (``M`` the redistributed masses, zero on the
    contact), ``j < size``, ``M_ii``-orthonormalised with full re-orthogonalisation (twice); the vectors from
    ``u_1`` on carry the slaved contact rows (their load vanishes on the contact). Stops early, with fewer
    vectors, when the space is exhausted (an invariant subspace to round-off)."""
    from .extension import extend_basis

    m_i = masses[split.i]
    return extend_basis(np.zeros((split.i.size, 0)), fac.solve(split.w)[split.i],
                        _interior_operator(split, masses, fac), lambda X: (m_i * X.T).T, size + 1)


def _m_orthonormal(phi: np.ndarray, extra: np.ndarray, m: np.ndarray) -> np.ndarray:
    """``[Φ, e]`` M-orthonormal (``M = diag(m)``): Φ normalised, ``e`` orthogonalised against it twice; ``e`` is
    dropped when it lies in the span of Φ to round-off (the compliance is then exact already)."""
    phi = phi / np.sqrt(np.einsum("ij,i,ij->j", phi, m, phi))
    e = extra.copy()
    size0 = np.sqrt(e @ (m * e))
    for _ in range(2):
        e -= phi @ (phi.T @ (m * e))
    size = np.sqrt(e @ (m * e))
    return phi if size <= 1e-10 * size0 else np.column_stack([phi, e / size])
