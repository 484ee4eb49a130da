"""A reduced model: the small system the solver consumes, and the way back to the mesh (:class:`ReducedModel`).

:func:`~bladecase.reduction.reduce` turns an :class:`~bladecase.fe.FEModel` and a
:class:`~bladecase.reduction.contact.Contact` into a :class:`ReducedModel`: a
:class:`~bladecase.nsm.LinearSystem` with dense reduced matrices
``M_r = VᵀMV``, ``K_r = VᵀKV``, constraint vector ``w_r = Vᵀw`` and the same
clearance, plus the basis ``V`` (``x_free ≈ V q``) that maps a reduced orbit
back to the mesh (:meth:`ReducedModel.expand`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from ..fe import FEModel, node_operator
from ..nsm import LinearSystem
from .contact import Contact
from .lanczos import LanczosChain

if TYPE_CHECKING:  # pragma: no cover
    from ..nsm import PeriodicOrbit

__all__ = ["ReducedModel", "node_operator"]


@dataclass(frozen=True, eq=False)
class ReducedModel:
    """A reduced finite-element model with one contact, and the way back to the mesh.

    Attributes
    ----------
    method : str
        One of :data:`~bladecase.reduction.METHODS`.
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

    def free_velocities(self, x_r, v_r) -> np.ndarray:
        """Free-dof velocities of reduced states ``(x_r, v_r)``: ``V v_r`` (a model whose expansion depends on
        the state, e.g. the massless contact model's closed phase, adds its own term)."""
        return self.free_dofs(v_r)

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
        return self._at_nodes(self.free_dofs(x_r))

    def _at_nodes(self, x: np.ndarray) -> np.ndarray:
        """Per-node values of free-dof vectors ``(n_free,)`` or ``(n_free, k)``."""
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
        return self._at_nodes(self.free_dofs(x_r)), self._at_nodes(self.free_velocities(x_r, v_r))

    @cached_property
    def _node_operator(self) -> sp.csr_array:
        return node_operator(self.model)

    def __repr__(self) -> str:
        return (f"ReducedModel({self.method!r}, size={self.size}, {self.n} reduced dofs "
                f"of {self.model.n_dofs} free dofs, gap={self.system.gap:g})")
