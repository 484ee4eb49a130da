"""Stage 2 — the reduction layer: contact, orthogonal-symmetry basis, Lanczos chain, reduced models.

Data in: an :class:`~bladecase.fe.FEModel` and a :class:`Contact`. Data out: a :class:`ReducedModel`
whose ``.system`` is the :class:`~bladecase.nsm.system.LinearSystem` the solver takes, and which expands
reduced states back to the mesh.

Modules: :mod:`~bladecase.reduction.contact` (:class:`Contact`), :mod:`~bladecase.reduction.symmetry`
(mass factor, symmetry basis, per-dof defect), :mod:`~bladecase.reduction.lanczos` (the Lanczos chain),
:mod:`~bladecase.reduction.model` (:class:`ReducedModel`), :mod:`~bladecase.reduction.extension` (a
richer model from the same Krylov space, :func:`krylov_extension`), :mod:`~bladecase.reduction.massless` (the massless
contact model of an FE structure, :func:`massless_model`), :mod:`~bladecase.reduction.registry`
(:data:`METHODS`, :func:`register`, :func:`reduce`), :mod:`~bladecase.reduction.methods` (one module per
method), :mod:`~bladecase.reduction.storage` (stage files).
"""

from .contact import Contact, radial_normal
from .disk import DiskModel, disk_model, massless_sector, sector_system
from .extension import krylov_extension
from .lanczos import LanczosChain, chain_grounding, chain_jacobi, lanczos_chain
from .loads import EngineOrderLoad, engine_order_load, nodal_load, pressure_load, project_load
from .massless import MasslessReducedModel, massless_masses, massless_model
from .methods import FULL_LIMIT
from .mistuning import MistuningModel, amplification, forced_response, mistuning_model
from .model import ReducedModel, node_operator
from .registry import METHODS, Registry, reduce, register
from .storage import load_reduced, save_reduced
from .symmetry import MassFactor, PerDofDefect, SymmetryBasis, mass_factor, per_dof_defect, per_dof_law

__all__ = [
    "FULL_LIMIT", "METHODS", "Contact", "DiskModel", "disk_model", "massless_sector", "sector_system",
    "EngineOrderLoad", "LanczosChain", "MassFactor", "MasslessReducedModel",
    "PerDofDefect",
    "ReducedModel", "Registry", "SymmetryBasis", "chain_grounding", "chain_jacobi", "krylov_extension",
    "lanczos_chain", "load_reduced",
    "mass_factor", "massless_masses", "massless_model", "node_operator", "per_dof_defect", "per_dof_law",
    "radial_normal", "reduce", "register", "save_reduced", "engine_order_load", "nodal_load", "pressure_load",
    "project_load", "MistuningModel", "amplification", "forced_response", "mistuning_model",
]
