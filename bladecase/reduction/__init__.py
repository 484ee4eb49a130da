"""Stage 2 — the reduction layer: contact, orthogonal-symmetry basis, Lanczos chain, reduced models.

Data in: an :class:`~bladecase.fe.FEModel` and a :class:`Contact`. Data out: a :class:`ReducedModel`
whose ``.system`` is the :class:`~bladecase.nsm.system.LinearSystem` the solver takes, and which expands
reduced states back to the mesh.

A property of the obstacle (the casing's stiffness, ``Contact.casing``) is a field of :class:`Contact`, turned
into the system's spring by the reduction that takes it (a method registered with ``casing=True``);
:func:`reduce` refuses it for the others (``Contact.rigid``).

Module map, one entry per module (the details are in each module's own docstring):

- :mod:`~bladecase.reduction.contact` — :class:`Contact`: a node or a face, its normal, its clearance; a face on a
  casing of revolution: each node's own normal and clearance;
- :mod:`~bladecase.reduction.tributary` — each node's share of a contact face or line: tributary areas and
  lengths;
- :mod:`~bladecase.reduction.casing` — ``Casing``: a cylinder or cone about the engine axis, each node's clearance
  and normal;
- :mod:`~bladecase.reduction.symmetry` — the orthogonal-symmetry basis: mass factor, symmetry basis, per-dof
  defect;
- :mod:`~bladecase.reduction.lanczos` — the Lanczos chain;
- :mod:`~bladecase.reduction.registry` — :data:`METHODS`, :func:`register`, :func:`reduce`;
- :mod:`~bladecase.reduction.methods` — one module per method (``massless``, ``massless-lanczos``,
  ``massless-modal`` included), each registered there;
- :mod:`~bladecase.reduction.model` — :class:`ReducedModel`: ``.system`` for the solver, ``.free_dofs()`` and
  ``.expand()`` back to the model;
- :mod:`~bladecase.reduction.massless` — the massless contact model of an FE structure (mass moved off the
  contact, condensation, ``MasslessReducedModel``, :func:`massless_model`); such a model extends itself
  (``krylov_extended``), so :mod:`~bladecase.reduction.extension` need not import it;
- :mod:`~bladecase.reduction.nodes` — ``nodal_model``: one massless contact per node of a face, attachment vectors
  or the residual correction, an interior basis reusable at another speed (``NodalReducedModel``);
- :mod:`~bladecase.reduction.nodal_friction` — a nodal model's tangential coupling and compliances, for friction;
- :mod:`~bladecase.reduction.extension` — :func:`krylov_extension`: a reduced model's basis extended by the block
  Krylov sequence of its own factorisation, the reference model of the orbit check (``nodes.nodal_extension``
  does the same for the every-node model; a method whose basis vectors are invariant under ``K⁻¹M`` says so in
  ``FRONTIER``);
- :mod:`~bladecase.reduction.disk` — ``disk_model``: the whole bladed disk as a ``NodalSystem`` from its sector's
  cyclic modes, one massless contact per blade tip or per tip node, the missing flexibility restored per nodal
  diameter; the blade-shift operator of a travelling wave;
- :mod:`~bladecase.reduction.disk_fields` — a reduced disk state as the displacement of every sector (the cyclic
  modes and each nodal diameter's static contact field), for drawing the disk's orbits on the annulus;
- :mod:`~bladecase.reduction.loads` — nodal, pressure and engine-order load vectors, :func:`project_load` onto a
  reduced model;
- :mod:`~bladecase.reduction.mistuning` — a mistuned bladed disk's reduced model from the tuned cyclic modes
  (subset of nominal modes, fundamental mistuning model), its engine-order forced response and amplification;
- :mod:`~bladecase.reduction.mistuning_stats` — random mistuning samples through any executor, their statistics
  against Whitehead's bound, the worst pattern;
- :mod:`~bladecase.reduction.mistuning_fe` — a sector's blade stiffness, the part that mistuning scales;
- :mod:`~bladecase.reduction.mistuning_rub` — which mistuned blade reaches the clearance first as the forcing
  rises, at what force against the tuned disk's, and its lead over the next blade;
- :mod:`~bladecase.reduction.mistuning_disk` — the mistuned disk with one contact per blade, and the engine-order
  load's residual response at the contacts;
- :mod:`~bladecase.reduction.storage` — stage files.
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
