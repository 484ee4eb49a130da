"""Stage 2 — the reduction layer: contact, orthogonal-symmetry basis, Lanczos chain, reduced models.

Data in: an :class:`~bladecase.fe.FEModel` and a :class:`Contact`. Data out: a :class:`ReducedModel`
whose ``.system`` is the :class:`~bladecase.nsm.orbits.LinearSystem` the solver takes, and which expands
reduced states back to the mesh.
"""

from .contact import Contact, radial_normal
from .lanczos import (
    LanczosChain,
    MassFactor,
    PerDofDefect,
    SymmetryBasis,
    lanczos_chain,
    mass_factor,
    per_dof_defect,
)
from .methods import FULL_LIMIT, METHODS, ReducedModel, load_reduced, reduce, save_reduced

__all__ = [
    "FULL_LIMIT", "METHODS", "Contact", "LanczosChain", "MassFactor", "PerDofDefect", "ReducedModel",
    "SymmetryBasis", "lanczos_chain", "load_reduced", "mass_factor", "per_dof_defect", "radial_normal",
    "reduce", "save_reduced",
]
