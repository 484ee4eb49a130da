"""``"massless"``: the massless contact model of an FE blade, reduced so that the contact stays right (theory §8).

The contact dofs ``c`` (the free dofs where ``w ≠ 0``) lose their lumped mass, moved to the neighbouring dofs of
the same direction (those coupled to them in ``K``) so that the total mass and the centre of mass are kept in
each direction (:func:`bladecase.nsm.massless.redistribute_mass`; the rotary inertia about the contact node is
not kept: it changes by ``m_c`` times the squared distances moved, a mesh-scale amount). With no inertia, the
contact dofs are static in each phase:

- open (``λ = 0``): ``x_c = −K_cc⁻¹K_ci x_i``; interior stiffness ``S = K_ii − K_icK_cc⁻¹K_ci``; the contact
  displacement is ``ŵᵀx_i`` with ``ŵ = −K_icK_cc⁻¹w_c``;
- closed: ``x_c = −K_cc⁻¹(K_ci x_i + λ w_c)``, ``λ = k_c (ŵᵀx_i − d) >= 0``, ``k_c = 1/(w_cᵀK_cc⁻¹w_c)``, which
  holds ``wᵀx = d`` exactly.

Reduction (the massless-boundary analogue of Craig–Bampton): the interior basis is the ``size`` lowest modes of
the massless structure (``S φ = ω² M_ii φ``, shift-invert Lanczos with the ONE factorisation of ``K``:
``S⁻¹ = (K⁻¹)_ii``) plus the static attachment vector ``S⁻¹ŵ`` (the interior part of ``K⁻¹w``), M-orthonormalised.
The reduced model is a :class:`~bladecase.nsm.MasslessSystem` ``(V_iᵀM_iiV_i, V_fullᵀKV_full, V_fullᵀw, k_c, d)``
where ``V_full`` carries the slaved contact rows; the attachment vector makes the static contact compliance
``1/k_c + ŵ_rᵀS_r⁻¹ŵ_r = wᵀK⁻¹w`` exact at any size.

A single node in 3-D is a point load: its static compliance ``wᵀK⁻¹w`` grows without bound as the mesh is refined
(logarithmically in 2-D), so point-contact results depend on the mesh through ``k_c``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ...fe import FEModel
from ...linalg import spd_factor
from ...nsm import MasslessSystem
from ...nsm.massless import redistribute_mass
from ..contact import Contact
from ..model import ReducedModel
from .common import constraint


@dataclass(frozen=True, eq=False)
class MasslessReducedModel(ReducedModel):
    """A reduced model of the massless contact model: ``system`` is a :class:`~bladecase.nsm.MasslessSystem`.

    ``basis`` is ``V_full`` (open-phase displacements of every free dof); ``closed_shape`` is the free-dof
    displacement per unit contact force with the interior held (``−K_cc⁻¹w_c`` on the contact dofs), added
    ``λ`` times in a closed phase; ``masses`` the redistributed lumped masses of the free dofs.
    """

    closed_shape: np.ndarray = field(default=None, repr=False)  # type: ignore[assignment]
    masses: np.ndarray = field(default=None, repr=False)  # type: ignore[assignment]

    @property
    def mass_matrix(self) -> sp.dia_array:
        """The massless model's (lumped, redistributed) mass matrix on the free dofs."""
        return sp.diags_array(self.masses)

    def _multiplier(self, x_r: np.ndarray) -> np.ndarray:
        s = self.system
        return s.kc * np.maximum(0.0, s.w @ x_r - s.gap)

    def free_dofs(self, x_r) -> np.ndarray:
        """Free-dof displacements of reduced states, the closed phase's contact correction included."""
        x = super().free_dofs(x_r)
        lam = self._multiplier(np.asarray(x_r, dtype=float))
        return x + (np.multiply.outer(self.closed_shape, lam) if x.ndim == 2 else self.closed_shape * lam)

    def free_velocities(self, x_r, v_r) -> np.ndarray:
        """Free-dof velocities (``λ' = k_c ŵᵀv`` where closed)."""
        v = super().free_dofs(v_r)
        x_r, v_r = np.asarray(x_r, dtype=float), np.asarray(v_r, dtype=float)
        closed = (self.system.w @ x_r) > self.system.gap
        lam_dot = self.system.kc * (self.system.w @ v_r) * closed
        return v + (np.multiply.outer(self.closed_shape, lam_dot) if v.ndim == 2 else self.closed_shape * lam_dot)

    def __repr__(self) -> str:
        return (f"MasslessReducedModel(size={self.size}, {self.n} reduced dofs of {self.model.n_dofs} free dofs, "
                f"kc={self.system.kc:.4g}, gap={self.system.gap:g})")


def massless_masses(model: FEModel, c: np.ndarray) -> np.ndarray:
    """Lumped free-dof masses with those of the dofs ``c`` moved to their neighbours (same direction, coupled in
    ``K``), keeping the total mass and the centre of mass of each direction."""
    if model.mass != "lumped":
        raise ValueError("the massless contact model moves lumped masses: assemble with mass='lumped' "
                         "([fem] mass = \"lumped\"), got a consistent mass matrix")
    m = np.asarray(model.M.diagonal(), dtype=float).copy()
    K = sp.csr_array(model.K)
    direction, coords = model.dofs.direction, model.dofs.coords
    contact = set(c.tolist())
    for j in c:
        row = K.indices[K.indptr[j]:K.indptr[j + 1]]
        nb = np.array([i for i in row if i not in contact and direction[i] == direction[j]], dtype=int)
        if nb.size == 0:
            raise ValueError(f"contact dof {j} has no neighbour to take its mass")
        m = redistribute_mass(m, coords, int(j), nb)
    return m


def build(model: FEModel, contact: Contact, size: int, factor=None) -> MasslessReducedModel:
    """``size`` modes of the massless structure plus the contact's attachment vector (``size + 1`` dofs)."""
    w = constraint(model, contact)
    n = model.n_dofs
    c = np.flatnonzero(w)
    i = np.setdiff1d(np.arange(n), c)
    if size > i.size - 1:
        raise ValueError(f"size = {size} is too large for method 'massless': the massless structure has "
                         f"{i.size} interior dofs (valid: 1..{i.size - 1})")
    masses = massless_masses(model, c)
    K = sp.csr_array(model.K)
    K_cc = K[c][:, c].toarray()
    K_ci = sp.csr_array(K[c][:, i])
    K_ii = sp.csr_array(K[i][:, i])
    slave = np.linalg.solve(K_cc, np.eye(c.size))  # K_cc⁻¹ (small: the contact dofs)
    kc = 1.0 / float(w[c] @ slave @ w[c])
    fac = factor if factor is not None else spd_factor(model.K, "K", hint="is the model clamped?")

    def s_inv(x):
        full = np.zeros(n)
        full[i] = np.ravel(x)
        return fac.solve(full)[i]

    attach = fac.solve(w)[i]  # S⁻¹ŵ
    phi = _modes(K_ii, K_ci, slave, masses[i], size, s_inv)
    Vi = _m_orthonormal(phi, attach, masses[i])
    V = np.zeros((n, Vi.shape[1]))
    V[i] = Vi
    V[c] = -slave @ (K_ci @ Vi)
    closed = np.zeros(n)
    closed[c] = -slave @ w[c]  # the casing pushes back: x_c = −K_cc⁻¹(K_ci x_i + λ w_c)
    M_r = Vi.T @ (masses[i][:, None] * Vi)
    S_r = V.T @ (K @ V)
    system = MasslessSystem(0.5 * (M_r + M_r.T), 0.5 * (S_r + S_r.T), V.T @ w, kc, contact.gap)
    return MasslessReducedModel("massless", size, system, V, model, contact, closed_shape=closed, masses=masses)


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


def _modes(K_ii, K_ci, slave, m_i, count: int, s_inv) -> np.ndarray:
    """The ``count`` lowest modes of ``(S, diag(m_i))``, ``S = K_ii − K_icK_cc⁻¹K_ci`` (never formed when sparse)."""
    n_i = K_ii.shape[0]
    if count > n_i // 2:  # ARPACK cannot; a small model: dense
        import scipy.linalg as sla

        from ...linalg import DENSE_LIMIT

        if n_i > DENSE_LIMIT:
            raise ValueError(f"size = {count} needs a dense eigen-solution of {n_i} interior dofs "
                             f"(at most {n_i // 2} modes on the sparse path)")
        A = K_ci.toarray()
        S = K_ii.toarray() - A.T @ slave @ A
        _, phi = sla.eigh(0.5 * (S + S.T), np.diag(m_i), subset_by_index=[0, count - 1])
        return phi
    S = spla.LinearOperator((n_i, n_i), matvec=lambda x: K_ii @ np.ravel(x) - K_ci.T @ (slave @ (K_ci @ np.ravel(x))),
                            dtype=float)
    OPinv = spla.LinearOperator((n_i, n_i), matvec=s_inv, dtype=float)
    _, phi = spla.eigsh(S, k=count, M=sp.diags_array(m_i), sigma=0.0, OPinv=OPinv, which="LM")
    return phi
