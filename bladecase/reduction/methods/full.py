"""Method ``"full"``: no reduction (``V = I``), dense ``M``, ``K``; refused above :data:`~.common.FULL_LIMIT` dofs
(or the caller's ``limit``, at most :data:`bladecase.nsm.system.DENSE_LIMIT`: the dense spectrum's bound)."""

from __future__ import annotations

import scipy.sparse as sp

from ...checks import integer
from ...fe import FEModel
from ...nsm import LinearSystem
from ...nsm.system import DENSE_LIMIT
from ..contact import Contact
from ..model import ReducedModel
from .common import FULL_LIMIT, SUGGEST, constraint


def build(model: FEModel, contact: Contact, size: int | None = None, factor=None,
          limit: int | None = None) -> ReducedModel:
    """The whole model as a dense system; ``size`` must be ``None`` or ``model.n_dofs``; refused (before any
    matrix is made dense) above ``limit`` free dofs (default :data:`~.common.FULL_LIMIT`)."""
    n = model.n_dofs
    if size is not None and size != n:
        raise ValueError(f"method 'full' keeps all {n} free dofs: size must be None (or {n}), got {size!r}")
    name = "FULL_LIMIT" if limit is None else "limit"
    limit = FULL_LIMIT if limit is None else integer("limit", limit, 1, DENSE_LIMIT, note=" (free dofs)")
    if n > limit:
        raise ValueError(
            f"method 'full' builds dense {n} x {n} matrices and is limited to {name} = {limit} "
            f"dofs; this model has {n} free dofs: {SUGGEST}"
        )
    system = LinearSystem(model.M.toarray(), model.K.toarray(), constraint(model, contact), contact.gap)
    return ReducedModel("full", n, system, sp.eye_array(n, format="csr"), model, contact)
