"""Helpers shared by the reduction methods: the constraint vector, size checks, Galerkin projection."""

from __future__ import annotations

import numpy as np

from ...fe import FEModel
from ...linalg import DENSE_LIMIT
from ...nsm import LinearSystem
from ..contact import Contact

#: Largest model :func:`~bladecase.reduction.reduce` keeps whole (``method="full"``) or solves
#: densely (``"modal"``/``"craig-bampton"`` asking for more than half of the
#: available modes): a dense ``n × n`` float matrix is 72 MB at 3000 dofs
#: (the same bound as :data:`bladecase.linalg.DENSE_LIMIT`).
FULL_LIMIT = DENSE_LIMIT

#: What to use instead of a method that is refused for a large model.
SUGGEST = "use method 'modal', 'lanczos', 'lanczos-si' or 'craig-bampton' with a size such as 50"


def constraint(model: FEModel, contact: Contact) -> np.ndarray:
    """The contact's constraint vector ``w`` on the free dofs of ``model`` (checked)."""
    w = np.asarray(contact.w(model), dtype=float).reshape(-1)
    if w.shape != (model.n_dofs,):
        raise ValueError(f"contact.w(model) has {w.size} entries, expected {model.n_dofs} (one per free dof)")
    return w


def check_count(method: str, size: int, available: int, what: str) -> bool:
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


def projected_system(model: FEModel, contact: Contact, V: np.ndarray) -> LinearSystem:
    """``LinearSystem(VᵀMV, VᵀKV, Vᵀw, gap)``, the reduced matrices symmetrised (Galerkin projection on ``V``)."""
    M_r = V.T @ (model.M @ V)
    K_r = V.T @ (model.K @ V)
    return LinearSystem(0.5 * (M_r + M_r.T), 0.5 * (K_r + K_r.T), V.T @ constraint(model, contact), contact.gap)
