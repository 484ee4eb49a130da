"""Method ``"craig-bampton"``: the contact node's dofs kept physical, plus ``size`` fixed-interface modes.

Boundary dofs = the free dofs of the contact node (all its directions);
``V = [[I, 0], [Ψ, Φ_i]]`` with the constraint modes ``Ψ = -K_ii⁻¹K_ib`` and
the lowest modes ``Φ_i`` of ``(K_ii, M_ii)``, both from one factorisation of
``K_ii`` (:mod:`bladecase.linalg`).  Its ``M_r`` is not diagonal, so the
Moreau impact law (theory §1) is the one that conserves energy.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ...fe import FEModel
from ...linalg import lowest_modes, spd_factor
from ..contact import Contact
from ..model import ReducedModel
from .common import check_count, projected_system

#: The interior stiffness's name in messages.
K_II = "the interior stiffness K_ii"


def build(model: FEModel, contact: Contact, size: int, factor=None) -> ReducedModel:
    """Craig–Bampton with ``size`` fixed-interface modes (``factor`` of ``K`` is not used: ``K_ii`` is factorised)."""
    n = model.n_dofs
    b = contact.dofs(model)  # boundary: the contact node's free dofs, in direction order
    inner = np.setdiff1d(np.arange(n), b)
    dense = check_count("craig-bampton", size, inner.size,
                        f"the fixed-interface problem ({inner.size} interior dofs)")
    K, M = sp.csr_array(model.K), sp.csr_array(model.M)
    K_ii = sp.csc_array(K[inner][:, inner])
    M_ii = sp.csr_array(M[inner][:, inner])
    lu = spd_factor(K_ii, K_II, hint="is the model clamped?")
    psi = -lu.solve(K[inner][:, b])  # constraint modes, (n_i, n_b)
    _, phi_i = lowest_modes(K_ii, M_ii, size, factor=lu, dense=dense, name=K_II)
    nb = b.size
    V = np.zeros((n, nb + size))
    V[b, np.arange(nb)] = 1.0
    V[inner, :nb] = psi
    V[inner, nb:] = phi_i
    return ReducedModel("craig-bampton", size, projected_system(model, contact, V), V, model, contact)
