"""Load vectors on a finite-element model and their projection onto a reduced model.

A load is a vector ``f`` on the FREE dofs of an :class:`~bladecase.fe.FEModel` (the order of ``model.K``):
the external force is ``F₀ f cos(Ωt)`` in the forced simulation (:func:`bladecase.nsm.newton.forced.simulate_forced`).

* :func:`nodal_load` — a force of given total ``amplitude`` (N) along a direction, shared equally by one node
  or a set of nodes (a list, or a mesh group);
* :func:`pressure_load` — the consistent nodal forces of a uniform pressure ``p`` (Pa) on a boundary face
  group: ``f_i = −p ∫_Γ N_i n dS`` over the boundary facets whose vertices are all in the group, ``n`` the
  outward normal (a positive pressure pushes on the surface, into the body); in 2-D times the thickness.
  The forces of the clamped dofs (reactions) are dropped;
* :func:`engine_order_load` — a travelling excitation of engine order ``EO`` (see :class:`EngineOrderLoad`);
* :func:`project_load` — the Galerkin projection ``f_r = Vᵀ f`` onto a reduced model (any method, the
  massless contact model included: ``V`` is its open-phase basis, which carries the static condensation of the
  contact dofs, so ``f_r`` is the condensed load ``f_i − K_icK_cc⁻¹f_c``).

>>> from skfem import MeshTri
>>> from bladecase.fe import Mesh, assemble
>>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 11), np.linspace(0, 0.02, 3))
>>> p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
>>> strip = Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 0] == 0),
...                                                      "tip": np.flatnonzero(p[:, 0] == 0.1)})
>>> model = assemble(strip, "steel", order=2, thickness=0.002)
>>> f = pressure_load(model, "tip", 1e5)                   # 1 bar on the 20 mm × 2 mm tip face
>>> round(float(f[model.dofs.direction == 0].sum()), 12)   # −p × area, along x (the outward normal is +x)
-4.0
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..fe import FEModel
from .model import ReducedModel

__all__ = ["EngineOrderLoad", "engine_order_load", "nodal_load", "pressure_load", "project_load"]


def _model(model) -> FEModel:
    if not isinstance(model, FEModel):
        raise ValueError(f"model must be a bladecase FEModel, got {type(model).__name__}")
    return model


def _finite(name: str, value) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a finite number, got {value!r}") from None
    if not np.isfinite(v):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return v


def _unit_direction(direction, dim: int) -> np.ndarray:
    d = np.asarray(direction, dtype=float).reshape(-1) if direction is not None else np.zeros(0)
    if dim == 2 and d.size == 3 and d[2] == 0:
        d = d[:2]
    if d.size != dim or not np.all(np.isfinite(d)) or not np.any(d):
        raise ValueError(f"direction must be a finite non-zero vector of {dim} components in {dim}-D, "
                         f"got {direction!r}")
    return d / np.linalg.norm(d)


def _nodes(model: FEModel, node_or_nodes) -> np.ndarray:
    if isinstance(node_or_nodes, str):
        nodes = np.asarray(model.mesh.group(node_or_nodes))
    else:
        nodes = np.atleast_1d(np.asarray(node_or_nodes))
        if nodes.dtype.kind not in "iu" or nodes.ndim != 1:
            raise ValueError(f"node_or_nodes must be a mesh node index, a list of them or a group name, "
                             f"got {node_or_nodes!r}")
    if nodes.size == 0:
        raise ValueError(f"node_or_nodes selects no node: {node_or_nodes!r}")
    return np.unique(nodes)


def nodal_load(model: FEModel, node_or_nodes: int | Sequence[int] | str, direction: Sequence[float],
               amplitude: float = 1.0) -> np.ndarray:
    """A force of total ``amplitude`` (N) along ``direction``, shared equally by the given free nodes.

    ``node_or_nodes``: a mesh node index, a list of them, or a mesh group name.  ``direction``: ``model.dim``
    components (``(x, y, 0)`` accepted in 2-D), normalised here.  Every node must carry free dofs (a clamped
    node raises ``ValueError``).

    >>> from skfem import MeshTri
    >>> from bladecase.fe import Mesh, assemble
    >>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 3), np.linspace(0, 0.02, 2))
    >>> p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    >>> model = assemble(Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 0] == 0)}),
    ...                  "steel", order=1, thickness=0.002)
    >>> f = nodal_load(model, [2, 5], (0.0, 2.0), 10.0)          # 5 N up on each of nodes 2 and 5
    >>> f[model.dof_of(np.array([2, 5]), 1)].tolist(), float(f.sum())
    ([5.0, 5.0], 10.0)
    """
    model = _model(model)
    amplitude = _finite("amplitude", amplitude)
    u = _unit_direction(direction, model.dim)
    nodes = _nodes(model, node_or_nodes)
    f = np.zeros(model.n_dofs)
    for c in range(model.dim):
        if u[c] != 0:
            f[model.dof_of(nodes, c)] += amplitude * u[c] / nodes.size
    return f


def _fe_mesh(model: FEModel):
    """The scikit-fem mesh and scalar element :func:`bladecase.fe.assemble` built ``model`` on (same numbering)."""
    from skfem import ElementTetP1, ElementTetP2, ElementTriP1, ElementTriP2, MeshTet, MeshTri

    mesh, dim = model.mesh, model.dim
    if mesh.body_type not in ("tetra", "tetra10", "triangle", "triangle6"):
        raise ValueError(f"pressure loads are implemented on simplex meshes (tetra, triangle), this mesh has "
                         f"{mesh.body_type!r} cells")
    cells = np.asarray(mesh.cells[mesh.body_type])[:, : dim + 1].astype(np.int64)
    used, local = np.unique(cells, return_inverse=True)
    p = np.ascontiguousarray(np.asarray(mesh.points, dtype=float)[used, :dim].T)
    fe_mesh = (MeshTet if dim == 3 else MeshTri)(p, np.ascontiguousarray(local.reshape(cells.shape).T))
    element = {(3, 1): ElementTetP1, (3, 2): ElementTetP2, (2, 1): ElementTriP1, (2, 2): ElementTriP2}[dim, model.order]
    return fe_mesh, element(), used


def pressure_load(model: FEModel, group: str, pressure: float = 1.0) -> np.ndarray:
    """Consistent nodal forces of a uniform ``pressure`` (Pa) on the boundary facets of mesh ``group``.

    ``f_i = −p ∫_Γ N_i n dS`` (``n`` outward; a positive pressure pushes into the body) over the boundary
    facets (triangles in 3-D, edges in 2-D) whose vertices are all in ``group``, with the model's own
    elements (P1/P2; at order 2 the facets are curved through the mesh's midside nodes, as the model's
    cells); in 2-D times the thickness.  Forces on clamped dofs are dropped.
    On a flat face the forces add up to ``−p × area × n`` exactly.

    Raises ``ValueError`` when the group has no boundary facet.
    """
    from skfem import FacetBasis, LinearForm, asm

    from ..fe import MappingCurved, curved_geometry

    model = _model(model)
    pressure = _finite("pressure", pressure)
    nodes = np.asarray(model.mesh.group(group))
    fe_mesh, element, used = _fe_mesh(model)
    inside = np.isin(used, nodes)
    boundary = fe_mesh.boundary_facets()
    facets = boundary[inside[fe_mesh.facets[:, boundary]].all(axis=0)]
    if facets.size == 0:
        raise ValueError(f"group {group!r} holds no boundary facet of the body (no "
                         f"{'triangle' if model.dim == 3 else 'edge'} of the surface has all its vertices in it)")
    geometry = curved_geometry(model.mesh, used, fe_mesh) if model.order == 2 else None
    basis = FacetBasis(fe_mesh, element, facets=facets, mapping=MappingCurved(geometry) if geometry else None)
    dim = model.dim
    scalar = model.dofs.fe_index // dim
    if not np.allclose(basis.doflocs[:, scalar].T, model.dofs.coords[:, :dim], rtol=0,
                       atol=1e-9 * np.abs(model.mesh.points).max()):
        raise ValueError("the model's dof numbering does not match its mesh: was it assembled by "
                         "bladecase.fe.assemble?")
    full = np.zeros(dim * basis.N)
    for c in range(dim):
        form = LinearForm(lambda v, w, c=c: w.n[c] * v)
        full[c::dim] = asm(form, basis)
    depth = model.thickness if dim == 2 else 1.0
    return -pressure * depth * full[model.dofs.fe_index]


@dataclass(frozen=True)
class EngineOrderLoad:
    """A travelling excitation of engine order ``EO`` as a single blade feels it.

    On blade ``j`` of a bladed disk of ``N`` blades turning at ``Ω_rot`` (rad/s), a stationary flow
    disturbance with ``EO`` lobes around the annulus is the load ``F₀ f cos(EO·Ω_rot·t − EO·2πj/N)``: all
    blades feel the same spatial shape ``f`` at the frequency ``Ω = EO·Ω_rot``, blade ``j`` with the phase lag
    ``φ_j = EO·2πj/N`` (a wave travelling with the rotation).  On a SINGLE blade (no disk coupling, no
    mistuning) the phase only shifts the time origin: the steady states are those of the standing load ``f``
    at ``Ω``, so an engine-order sweep is a forcing-frequency sweep with ``f = EO × rpm / 60``.  What the
    single-blade model does not hold: the inter-blade coupling through the disk (the travelling wave matters
    only there), the centrifugal stiffening and softening (the stiffness is that at rest), and a load
    amplitude that changes with the speed (here ``F₀`` is constant over the sweep).

    Attributes
    ----------
    vector : (n_free,) ndarray
        Spatial shape ``f`` (a nodal or pressure load on the free dofs).
    engine_order : int
    blades, blade : int
        ``N`` and ``j`` of the blade modelled (``blades=1``: the phase is 0).
    """

    vector: np.ndarray
    engine_order: int
    blades: int = 1
    blade: int = 0

    @property
    def phase(self) -> float:
        """``φ_j = EO·2πj/N`` (rad, in ``[0, 2π)``): a time shift ``φ_j/Ω`` of the blade's response."""
        return float(np.mod(2 * np.pi * self.engine_order * self.blade / self.blades, 2 * np.pi))

    def frequency(self, speed_rpm) -> np.ndarray | float:
        """Forcing frequency (Hz) at rotation speed ``speed_rpm``: ``EO × rpm / 60``."""
        return self.engine_order * np.asarray(speed_rpm, dtype=float) / 60.0

    def speed(self, frequency_hz) -> np.ndarray | float:
        """Rotation speed (rpm) at which the engine order excites ``frequency_hz``: ``60 f / EO``."""
        return 60.0 * np.asarray(frequency_hz, dtype=float) / self.engine_order


def engine_order_load(load, engine_order: int, *, blades: int = 1, blade: int = 0) -> EngineOrderLoad:
    """The engine-order ``engine_order`` excitation of spatial shape ``load`` (:class:`EngineOrderLoad`).

    ``load``: a free-dof load vector (:func:`nodal_load`, :func:`pressure_load`).  ``blades``, ``blade``:
    the disk's blade count ``N`` and the blade modelled ``j`` (they set the phase ``EO·2πj/N`` only).

    >>> eo = engine_order_load(np.array([0.0, 1.0]), 3, blades=24, blade=2)
    >>> round(eo.phase, 6), float(eo.frequency(6000.0)), float(eo.speed(300.0))   # 3 × 6000/60 = 300 Hz
    (1.570796, 300.0, 6000.0)
    """
    f = np.asarray(load, dtype=float).reshape(-1)
    if f.size == 0 or not np.all(np.isfinite(f)):
        raise ValueError(f"load must be a finite non-empty vector on the free dofs, got shape {np.shape(load)}")
    for name, v, lo in (("engine_order", engine_order, 1), ("blades", blades, 1), ("blade", blade, 0)):
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)) or v < lo:
            raise ValueError(f"{name} must be an integer >= {lo}, got {v!r}")
    if blade >= blades:
        raise ValueError(f"blade must be in 0..blades-1 = 0..{blades - 1}, got {blade!r}")
    return EngineOrderLoad(f, int(engine_order), int(blades), int(blade))


def project_load(reduced: ReducedModel, f_free) -> np.ndarray:
    """Galerkin projection ``f_r = Vᵀ f`` of a free-dof load onto ``reduced`` (``V = reduced.basis``).

    Work-consistent for every method: ``f_rᵀ q = fᵀ (V q)``.  For the massless contact model ``V`` is the
    open-phase basis (slaved contact rows), so ``f_r`` is the statically condensed load.

    >>> from bladecase.nsm import LinearSystem
    >>> from bladecase.reduction import ReducedModel
    >>> V = np.array([[1.0, 0.0], [0.5, 1.0], [0.0, 2.0]])
    >>> r = ReducedModel("modal", 2, LinearSystem(np.eye(2), np.eye(2), np.array([0.0, 1.0]), 1.0), V, None, None)
    >>> project_load(r, [1.0, 2.0, 3.0]).tolist()
    [2.0, 8.0]
    """
    basis = getattr(reduced, "basis", None)
    if basis is None:
        raise ValueError(f"reduced must be a ReducedModel with a basis, got {type(reduced).__name__}")
    f = np.asarray(f_free, dtype=float).reshape(-1)
    if f.size != basis.shape[0] or not np.all(np.isfinite(f)):
        raise ValueError(f"f_free must be a finite vector of the model's {basis.shape[0]} free dofs, got shape "
                         f"{np.shape(f_free)}")
    out = basis.T @ f
    return np.asarray(out.toarray() if sp.issparse(out) else out, dtype=float).reshape(-1)
