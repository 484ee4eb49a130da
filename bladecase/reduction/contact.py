"""The blade–casing contact of a finite-element model: one node (or a face), a normal, a gap.

A :class:`Contact` says which mesh node touches the casing, along which unit
normal ``ν`` and after which clearance ``d``.  On an :class:`~bladecase.fe.FEModel`
it becomes the constraint vector ``w`` of theory §1 (``wᵀx = ν·u_node``, the
normal components on that node's free dofs, zero elsewhere) and the
:class:`~bladecase.nsm.system.LinearSystem` the solver and the reduction layer consume.

Picking the node:

* by id: ``Contact(node, normal, gap)`` or :meth:`Contact.at` (checked against a model);
* the free node nearest a point: :meth:`Contact.nearest`;
* the node of a group (``"tip"`` by default) farthest along a direction, e.g.
  the leading-edge tip corner: :meth:`Contact.farthest`;
* a whole face, ``wᵀx`` = the weighted mean of ``ν·u`` over the free vertices of a group (equal or tributary-area
  weights): :meth:`Contact.face`. One constraint all the same; unlike a single node (a point load in 3-D), its
  static compliance converges under mesh refinement.

Default normal (``normal=None``): the casing's radial direction.  The blades of
:mod:`bladecase.fe.geometry` are radial along the LAST axis — 3-D blades along
``+z``, 2-D plates along ``+y`` — so the default normal is ``(0, 0, 1)`` in 3-D
and ``(0, 1)`` in 2-D (:func:`radial_normal`).  Give the normal explicitly for a
mesh oriented otherwise.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..checks import positive
from ..fe import FEModel
from ..nsm import LinearSystem
from .tributary import area_weights, group_members, tributary_areas, tributary_lengths  # noqa: F401  (public here too)


def radial_normal(dim: int) -> np.ndarray:
    """The default contact normal: the unit vector of the last axis (``+z`` in 3-D, ``+y`` in 2-D).

    >>> radial_normal(3).tolist(), radial_normal(2).tolist()
    ([0.0, 0.0, 1.0], [0.0, 1.0])
    >>> radial_normal(1)
    Traceback (most recent call last):
        ...
    ValueError: dim must be 2 or 3, got 1
    """
    if isinstance(dim, bool) or dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim!r}")
    e = np.zeros(dim)
    e[-1] = 1.0
    return e


def _unit(name: str, value, sizes: Sequence[int] = (2, 3)) -> tuple[float, ...]:
    """``value`` normalised to unit length, as a tuple; ``ValueError`` if not a finite non-zero 2- or 3-vector."""
    try:
        v = np.array(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a vector of {' or '.join(map(str, sizes))} numbers, got {value!r}") from None
    if v.size not in sizes:
        raise ValueError(f"{name} must have {' or '.join(map(str, sizes))} components, got {v.size} ({value!r})")
    if not np.all(np.isfinite(v)):
        raise ValueError(f"{name} must be finite, got {value!r}")
    top = float(np.abs(v).max())  # scale first: the norm of [1e300, 1e300] overflows
    if top == 0.0:
        raise ValueError(f"{name} must be a non-zero vector, got {value!r}")
    v = v / top
    return tuple(float(c) for c in v / np.linalg.norm(v))


def _gap(gap) -> float:
    if gap is None:
        raise ValueError("gap is required: the clearance d > 0 between the contact node at rest and the casing")
    return positive("gap", gap, noun="clearance")


def _in_dim(name: str, vec: Sequence[float], dim: int) -> np.ndarray:
    """A 2- or 3-vector as a ``dim``-vector (a 3-vector with zero ``z`` is accepted in 2-D)."""
    v = np.asarray(vec, dtype=float)
    if v.size == dim:
        return v
    if dim == 2 and v.size == 3 and v[2] == 0.0:
        return v[:2]
    what = "(x, y) or (x, y, 0)" if dim == 2 else "(x, y, z)"
    raise ValueError(f"{name} {tuple(vec)!r} does not fit a {dim}-D model: give {what}")


def _check_model(model) -> FEModel:
    if not isinstance(model, FEModel):
        raise ValueError(f"model must be an FEModel (from bladecase.assemble), got {type(model).__name__}")
    return model


def free_nodes(model: FEModel) -> np.ndarray:
    """Sorted mesh nodes that carry free dofs (vertices of the body cells that are not clamped)."""
    nodes = _check_model(model).dofs.node
    return np.unique(nodes[nodes >= 0])


def _name(model: FEModel, node: int) -> int:
    """A mesh node as messages name it: its number in the mesh file (:attr:`bladecase.fe.Mesh.node_ids`)."""
    ids = getattr(model.mesh, "node_ids", None)
    return int(ids[node]) if ids is not None and 0 <= node < len(ids) else int(node)


def _in_group(model: FEModel, nodes: np.ndarray, group) -> np.ndarray:
    """``nodes`` restricted to mesh group ``group`` (a name or node indices; all of them for ``None``)."""
    if group is None:
        return nodes
    members, what = group_members(model, group)
    nodes = nodes[np.isin(nodes, members)]
    if nodes.size == 0:
        one = what.startswith("group")
        raise ValueError(f"{what} {'has' if one else 'have'} no free node (all {len(members)} of "
                         f"{'its nodes' if one else 'them'} are clamped or off the body)")
    return nodes


@dataclass(frozen=True)
class Contact:
    """A unilateral contact ``ν·u_node <= gap`` on one mesh node.

    Parameters
    ----------
    node : int
        Mesh node index (into ``mesh.points``); it must carry free dofs of the
        model it is used with (a vertex of the body cells, not clamped).
    normal : sequence of 2 or 3 floats, or None
        Casing normal, pointing from the blade towards the casing; stored
        normalised.  ``None``: the radial direction of the model it is used
        with, the last axis (:func:`radial_normal`).  A 3-vector with zero
        ``z`` is accepted for a 2-D model.
    gap : float
        Clearance ``d > 0`` between the node at rest and the casing.

    Raises
    ------
    ValueError
        ``node`` not an integer >= 0, ``normal`` zero, non-finite or of the
        wrong size, ``gap <= 0``.  Whether the node is free is checked when a
        model is given (:meth:`w`, :meth:`at`, :meth:`nearest`, :meth:`farthest`).

    Examples
    --------
    A steel strip 100 mm × 20 mm × 2 mm clamped at ``x = 0``, touching a casing normal to ``+x`` with its
    corner node ``(0.1, 0.02)`` (node 104) after a 0.1 mm clearance:

    >>> from skfem import MeshTri
    >>> from bladecase.fe import Mesh, assemble
    >>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5))
    >>> points = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    >>> strip = Mesh(points, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(points[:, 0] == 0)})
    >>> model = assemble(strip, "steel", order=1, thickness=0.002)
    >>> contact = Contact(104, normal=(2.0, 0.0), gap=1e-4)     # the normal is stored normalised
    >>> contact
    Contact(node=104, normal=(1.0, 0.0), gap=0.0001)
    >>> w = contact.w(model)                                    # wᵀx = ν·u of node 104
    >>> w.size, np.flatnonzero(w).tolist(), contact.dofs(model).tolist()
    (200, [198], [198, 199])
    >>> contact.system(model)
    LinearSystem(n=200, sparse, gap=0.0001)
    >>> Contact(104, normal=None, gap=0.0)
    Traceback (most recent call last):
        ...
    ValueError: gap must be a finite clearance > 0, got 0.0
    """

    node: int
    normal: tuple[float, ...] | None
    gap: float
    #: A weighted node set instead of one node (``Contact.face``): ``wᵀx`` is the mean of ``ν·u`` over these
    #: nodes (equal weights); ``node`` is then the set's node nearest its centroid (drawn, reported).
    nodes: tuple[int, ...] = field(default=(), repr=False)
    #: The weights ``ω_k >= 0`` of ``nodes`` (``Σ ω_k = 1``; less when the face touches the clamp), e.g. the
    #: tributary areas of ``Contact.face(..., weights="area")``; empty: equal weights ``1/len(nodes)``.
    weights: tuple[float, ...] = field(default=(), repr=False)
    #: The casing's stiffness (N/m) against the contact, in series with the blade's (``inf``: a rigid casing, the
    #: seed's model). Only the massless contact model takes a compliant casing (:meth:`with_casing`).
    casing: float = field(default=float("inf"), repr=False)
    #: Per-node unit normals of a face on a casing of revolution (:meth:`on_casing`), in the order of ``nodes``;
    #: empty: every node takes ``normal``.
    normals: tuple[tuple[float, ...], ...] = field(default=(), repr=False)
    #: Per-node clearances along those normals (m); ``gap`` is then their weighted mean (the constraint's).
    clearances: tuple[float, ...] = field(default=(), repr=False)

    def __post_init__(self) -> None:
        node = self.node
        if isinstance(node, (bool, np.bool_)) or not isinstance(node, (int, np.integer)) or node < 0:
            raise ValueError(f"node must be a mesh node index (integer >= 0), got {node!r}")
        object.__setattr__(self, "node", int(node))
        if self.normal is not None:
            object.__setattr__(self, "normal", _unit("normal", self.normal))
        object.__setattr__(self, "gap", _gap(self.gap))
        nodes = tuple(int(k) for k in self.nodes)
        if nodes and (min(nodes) < 0 or self.node not in nodes):
            raise ValueError(f"nodes of a face contact must be mesh node indices including node {self.node}, "
                             f"got {self.nodes!r}")
        object.__setattr__(self, "nodes", nodes)
        weights = tuple(float(x) for x in self.weights)
        if weights:
            total = sum(weights)
            if (len(weights) != len(nodes) or not all(np.isfinite(weights)) or min(weights) < 0
                    or not 0 < total <= 1 + 1e-12):
                raise ValueError(f"weights of a face contact must be one finite value >= 0 per node of nodes "
                                 f"({len(nodes)}), summing to at most 1 and more than 0, got {self.weights!r}")
        object.__setattr__(self, "weights", weights)
        try:
            casing = float(self.casing)
        except (TypeError, ValueError):
            casing = float("nan")
        if not casing > 0:
            raise ValueError(f"casing stiffness must be a number > 0 in N/m (inf: a rigid casing), got {self.casing!r}")
        object.__setattr__(self, "casing", casing)
        normals = tuple(_unit("normals", v) for v in self.normals)
        clearances = tuple(float(x) for x in self.clearances)
        if normals or clearances:
            if len(normals) != len(nodes) or len(clearances) != len(nodes) or not np.all(np.isfinite(clearances)):
                raise ValueError(f"a face on a casing needs one normal and one finite clearance per node of nodes "
                                 f"({len(nodes)}), got {len(normals)} normals and {len(clearances)} clearances")
        object.__setattr__(self, "normals", normals)
        object.__setattr__(self, "clearances", clearances)

    def with_casing(self, stiffness: float) -> Contact:
        """This contact against a compliant casing of ``stiffness`` N/m (``inf``: rigid).

        The casing — its local flexibility, its abradable coating — acts as a spring between the contact and the
        rigid casing at ``gap``: with the massless contact model the closed phase's stiffness is the contact's in
        series with the casing's (:func:`bladecase.nsm.massless.model.series_stiffness`), and the contact moves
        ``λ / stiffness`` beyond the gap. Newton's impact law needs a rigid casing.

        >>> Contact(3, (0.0, 1.0), 1e-4).with_casing(2e6)
        Contact(node=3, normal=(0.0, 1.0), gap=0.0001, casing=2e+06 N/m)
        """
        import dataclasses

        return dataclasses.replace(self, casing=stiffness)

    # ------------------------------------------------------------------ helpers to pick the node

    @classmethod
    def at(
        cls, model: FEModel, node: int, normal: Sequence[float] | None = None, gap: float | None = None
    ) -> Contact:
        """The contact on mesh node ``node`` of ``model`` (checked), normal defaulted to the radial direction.

        >>> import numpy as np
        >>> from bladecase.fe import Mesh, assemble
        >>> square = Mesh(points=np.array([[0., 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]),
        ...               cells={"triangle": np.array([[0, 1, 2], [0, 2, 3]])}, dim=2,
        ...               groups={"root": np.array([0, 1])})
        >>> model = assemble(square, "steel", order=1, thickness=0.01)
        >>> contact = Contact.at(model, 2, gap=1e-4)
        >>> contact
        Contact(node=2, normal=(0.0, 1.0), gap=0.0001)
        >>> contact.w(model).tolist()  # the free dofs: x and y of nodes 2 and 3
        [0.0, 1.0, 0.0, 0.0]
        >>> Contact.at(model, 0, gap=1e-4)
        Traceback (most recent call last):
            ...
        ValueError: contact node 0 is clamped: pick a free node (e.g. a tip node)
        """
        contact = cls(node, normal, gap)
        return contact._resolved(model)

    @classmethod
    def nearest(
        cls, model: FEModel, point: Sequence[float], normal: Sequence[float] | None = None,
        gap: float | None = None, group: str | None = None,
    ) -> Contact:
        """The contact on the free node of ``model`` nearest ``point`` (lowest index on a tie).

        ``point`` has ``model.dim`` coordinates (``(x, y, 0)`` is accepted in 2-D).
        ``group``: search only the free nodes of this mesh group.
        """
        _check_model(model)
        dim = model.dim
        p = _in_dim("point", _finite_vector("point", point), dim)
        nodes = _in_group(model, free_nodes(model), group)
        dist = np.linalg.norm(model.mesh.points[nodes, :dim] - p, axis=1)
        return cls.at(model, int(nodes[np.argmin(dist)]), normal, gap)

    @classmethod
    def farthest(
        cls,
        model: FEModel,
        direction: Sequence[float],
        normal: Sequence[float] | None = None,
        gap: float | None = None,
        group: str | None = "tip",
    ) -> Contact:
        """The contact on the free node of ``group`` farthest along ``direction``.

        E.g. ``Contact.farthest(model, (-1, 0, 0), gap=1e-4)`` picks the tip
        node of smallest ``x`` (the leading-edge tip corner of a blade whose
        leading edge points to ``-x``).  ``group=None`` searches every free
        node.  Ties go to the lowest node index.
        """
        _check_model(model)
        dim = model.dim
        u = _in_dim("direction", _unit("direction", direction), dim)
        nodes = _in_group(model, free_nodes(model), group)
        reach = model.mesh.points[nodes, :dim] @ u
        return cls.at(model, int(nodes[np.argmax(reach)]), normal, gap)

    # ------------------------------------------------------------------ on a model

    def normal_for(self, model: FEModel) -> np.ndarray:
        """The unit normal as a ``model.dim``-vector (the radial default if ``normal`` is ``None``)."""
        dim = _check_model(model).dim
        if self.normal is None:
            return radial_normal(dim)
        return _in_dim("normal", self.normal, dim)

    def dofs(self, model: FEModel) -> np.ndarray:
        """Free dofs of the contact node (one per direction, in direction order); of every node of a face set.

        Raises
        ------
        ValueError
            The node is not a mesh node, is clamped, or is not a vertex of the body cells.
        """
        _check_model(model)
        if self.nodes:
            return np.concatenate([Contact(k, self.normal, self.gap).dofs(model) for k in self.nodes])
        n_nodes = model.mesh.points.shape[0]
        if self.node >= n_nodes:
            raise ValueError(f"contact node {self.node} is not a mesh node (mesh nodes 0..{n_nodes - 1})")
        idx = np.flatnonzero(model.dofs.node == self.node)
        if idx.size == 0:
            name = _name(model, self.node)
            if np.isin(self.node, model.clamped):
                raise ValueError(f"contact node {name} is clamped: pick a free node (e.g. a tip node)")
            raise ValueError(f"contact node {name} is not a vertex of the body cells: it has no dof")
        return idx[np.argsort(model.dofs.direction[idx])]

    def w(self, model: FEModel) -> np.ndarray:
        """Constraint vector ``w`` on the free dofs of ``model``: ``wᵀx = ν·u_node``.

        Returns
        -------
        (model.n_dofs,) ndarray
            The normal's components on the contact node's dofs, zero elsewhere.
        """
        idx = self.dofs(model)
        nu = self.normal_for(model)
        w = np.zeros(model.n_dofs)
        if self.weights:  # the weight of each dof's node (dofs() lists the nodes in order)
            weight = dict(zip(self.nodes, self.weights, strict=True))
            scale = np.array([weight[k] for k in model.dofs.node[idx]])
        else:
            scale = 1.0 / max(len(self.nodes), 1)
        if self.normals:  # each node's own casing normal
            own = {k: _in_dim("normals", v, model.dim) for k, v in zip(self.nodes, self.normals, strict=True)}
            w[idx] = np.array([own[k][c] for k, c in zip(model.dofs.node[idx], model.dofs.direction[idx])]) * scale
        else:
            w[idx] = nu[model.dofs.direction[idx]] * scale
        if not np.any(w):  # a free node always has all its directions free; guard anyway
            raise ValueError(f"the normal {tuple(nu)} has no component on the free dofs of node "
                             f"{_name(model, self.node)}")
        return w

    def system(self, model: FEModel) -> LinearSystem:
        """The FULL model with this contact: ``LinearSystem(model.M, model.K, w, gap)``.

        Sparse matrices are kept (the constructor checks positive definiteness
        with a sparse LDLᵀ).  Its :attr:`~bladecase.nsm.system.LinearSystem.spectrum`
        is dense and limited to :data:`bladecase.nsm.system.DENSE_LIMIT` dofs; reduce
        larger models first (:func:`bladecase.lanczos_chain`).
        """
        self.rigid("Newton's impact law (the full model's LinearSystem)")
        return LinearSystem(model.M, model.K, self.w(model), self.gap)

    def rigid(self, what: str) -> None:
        """``ValueError`` naming ``what`` unless the casing is rigid (a compliant casing needs the massless model)."""
        if np.isfinite(self.casing):
            raise ValueError(f"{what} needs a rigid casing, got casing stiffness {self.casing:g} N/m: a compliant "
                             "casing is taken by the massless contact model only (methods 'massless', "
                             "'massless-lanczos', 'massless-modal'; study key [contact] model = \"massless\")")

    def _resolved(self, model: FEModel) -> Contact:
        """This contact with its normal made explicit for ``model``, after checking the node."""
        self.dofs(model)
        return Contact(self.node, tuple(self.normal_for(model)), self.gap, self.nodes, self.weights, self.casing,
                       self.normals, self.clearances)

    @classmethod
    def face(cls, model: FEModel, group: str | Sequence[int] = "tip", normal: Sequence[float] | None = None,
             gap: float | None = None, weights: str = "equal") -> Contact:
        """The contact of a whole face: ``wᵀx`` = the mean normal displacement of the free vertices of ``group`` (a
        mesh group, or the face's mesh node indices, 0-based: ``model.mesh.index_of(ids)`` turns the node numbers
        of a file into them).

        One constraint vector all the same. Unlike a single node in 3-D — a point load, whose static compliance
        ``wᵀK⁻¹w`` grows without bound as the mesh is refined (like ``1/h``; like ``log(1/h)`` in 2-D) — a face's
        mean displacement has a compliance that converges.

        ``weights="equal"`` (default): ``ω_k = 1/len(nodes)``, the mean over the nodes; it is the face's mean
        displacement only on a uniform mesh, and even there the face's edge nodes are over-weighted (point loads
        of weight ``~h^(dim-1)``), so the compliance converges erratically at first. ``weights="area"``: the
        tributary areas (lengths in 2-D) of the boundary facets of the body cells whose vertices are all in
        ``group``, ``ω_k = Σ_f |f|/dim / Σ_f |f|`` — the exact mean of the (P1-interpolated) normal displacement
        over the face, on any mesh; a clamped vertex's share is dropped (``Σ ω_k < 1``), and the mid-edge dofs of
        P2 models get no weight.

        >>> from skfem import MeshTri
        >>> from bladecase.fe import Mesh, assemble
        >>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5))
        >>> p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
        >>> tip = np.flatnonzero(p[:, 0] == 0.1)
        >>> strip = Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 0] == 0), "tip": tip})
        >>> model = assemble(strip, "steel", order=1, thickness=0.002)
        >>> c = Contact.face(model, "tip", (1.0, 0.0), 1e-4)
        >>> c, len(c.nodes), float(c.w(model).sum())
        (Contact(face of 5 nodes around node=102, normal=(1.0, 0.0), gap=0.0001), 5, 1.0)
        >>> np.round(Contact.face(model, "tip", (1.0, 0.0), 1e-4, weights="area").weights, 12)  # ends: half
        array([0.125, 0.25 , 0.25 , 0.25 , 0.125])
        >>> Contact.face(model, tip.tolist(), (1.0, 0.0), 1e-4).w(model).tolist() == c.w(model).tolist()  # by nodes
        True
        """
        if weights not in ("equal", "area"):
            raise ValueError(f"weights must be 'equal' or 'area', got {weights!r}")
        _check_model(model)
        nodes = _in_group(model, free_nodes(model), group)
        centre = model.mesh.points[nodes].mean(axis=0)
        middle = int(nodes[np.argmin(np.linalg.norm(model.mesh.points[nodes] - centre, axis=1))])
        omega = tuple(float(x) for x in area_weights(model, group, nodes)) if weights == "area" else ()
        return cls(middle, normal, gap, tuple(int(k) for k in nodes), omega)._resolved(model)

    @classmethod
    def on_casing(cls, model: FEModel, casing, group: str | Sequence[int] = "tip", weights: str = "area") -> Contact:
        """The face contact of ``group`` under a casing of revolution (:class:`~bladecase.reduction.casing.Casing`):
        each node with its own normal (the casing's, there) and its own clearance along it; the constraint is the
        weighted mean of the nodes' normal displacements against the weighted mean clearance.

        ``ValueError`` naming the node when a node of the face touches or crosses the casing at rest.

        >>> from skfem import MeshTri
        >>> from bladecase.fe import Mesh, assemble
        >>> from bladecase.fe.rotation import RotationAxis
        >>> from bladecase.reduction.casing import Casing
        >>> t = MeshTri.init_tensor(np.linspace(-0.01, 0.01, 5), np.linspace(0.2, 0.3, 21))
        >>> p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
        >>> strip = Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 1] == 0.2),
        ...                                                     "tip": np.flatnonzero(p[:, 1] == 0.3)})
        >>> model = assemble(strip, "steel", order=1, thickness=0.002)
        >>> c = Contact.on_casing(model, Casing(RotationAxis((0, 0, 0), (0, 0, 1)), radius=0.3002))
        >>> np.round(np.array(c.clearances) * 1e6, 2).tolist()    # µm: the corners are farther from the axis
        [33.38, 158.34, 200.0, 158.34, 33.38]
        >>> round(c.gap * 1e6, 2), np.round(c.normals[0], 4).tolist()   # area-weighted mean; a radial normal
        (137.51, [-0.0333, 0.9994, 0.0])
        """
        face = cls.face(model, group, None, 1.0, weights)
        points = np.zeros((len(face.nodes), 3))
        points[:, : model.dim] = np.asarray(model.mesh.points, dtype=float)[list(face.nodes), : model.dim]
        d, n = casing.clearances(points)
        if (d <= 0).any():
            k = int(np.argmin(d))
            raise ValueError(f"contact node {model.mesh.node_id(face.nodes[k])} at {points[k].round(6).tolist()} "
                             f"touches or crosses the casing at rest (clearance {d[k]:.4g} m): check the casing's "
                             "radius, its axis, and the mesh's unit")
        omega = np.array(face.weights) if face.weights else np.full(len(face.nodes), 1.0 / len(face.nodes))
        gap = float(omega @ d)
        mean = omega @ n
        return cls(face.node, tuple((mean / np.linalg.norm(mean))[: model.dim].tolist()), gap, face.nodes,
                   face.weights, face.casing, tuple(tuple(v) for v in n.tolist()), tuple(d.tolist()))

    def node_clearances(self, model: FEModel) -> tuple[np.ndarray, np.ndarray]:
        """``(d, ν)`` of every node of the contact (its ``nodes``, or the one ``node``): its clearance and unit
        normal, ``(k,)`` and ``(k, dim)``."""
        nodes = self.nodes or (self.node,)
        if self.normals:
            nu = np.array([_in_dim("normals", v, model.dim) for v in self.normals])
            return np.array(self.clearances), nu
        return np.full(len(nodes), self.gap), np.tile(self.normal_for(model), (len(nodes), 1))

    def node_normal_map(self, model: FEModel):
        """The sparse ``(k, n_dofs)`` map from free-dof vectors to the normal displacement ``ν_k·u_k`` of each node
        of the contact (its ``nodes``, or the one ``node``), each with its own normal."""
        import scipy.sparse as sp

        nodes = self.nodes or (self.node,)
        _, nu = self.node_clearances(model)
        rows, cols, vals = [], [], []
        for r, k in enumerate(nodes):
            idx = np.flatnonzero(model.dofs.node == k)
            rows += [r] * idx.size
            cols += idx.tolist()
            vals += nu[r][model.dofs.direction[idx]].tolist()
        return sp.csr_array((vals, (rows, cols)), shape=(len(nodes), model.n_dofs))

    def closed_by(self, model: FEModel, u: np.ndarray) -> Contact:
        """This contact after its nodes moved by the free-dof displacement ``u`` (a static state, e.g. the
        centrifugal one): the clearance ``gap − wᵀu`` and each node's ``d_k − ν_k·u_k`` (a node's may close;
        ``ValueError`` when the constraint's own clearance does: the caller checks ``gap − wᵀu`` first)."""
        import dataclasses

        clearances = tuple((np.array(self.clearances) - self.node_normal_map(model) @ u).tolist()) \
            if self.clearances else ()
        return dataclasses.replace(self, gap=self.gap - float(self.w(model) @ u), clearances=clearances)

    def __repr__(self) -> str:
        where = f"face of {len(self.nodes)} nodes around node={self.node}" if self.nodes else f"node={self.node}"
        if self.weights:
            where = "area-weighted " + where
        casing = "" if np.isinf(self.casing) else f", casing={self.casing:.4g} N/m"
        return f"Contact({where}, normal={self.normal}, gap={self.gap}{casing})"


def _finite_vector(name: str, value) -> np.ndarray:
    try:
        v = np.array(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a vector of 2 or 3 numbers, got {value!r}") from None
    if v.size not in (2, 3) or not np.all(np.isfinite(v)):
        raise ValueError(f"{name} must be 2 or 3 finite numbers, got {value!r}")
    return v
