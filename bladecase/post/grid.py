"""The full nodal grid of a finite-element model: every FE node, and free-dof vectors placed on it.

A P2 model has degrees of freedom at the vertices AND on the cell edges: at the
midpoints of straight edges when the mesh has only vertices (``tetra``/``triangle``),
at the mesh's own midside nodes when it has them (curved ``tetra10`` from gmsh: the
model's cells are curved through them).  Results (animations, VTK files) must show
the field the model computed, so they are drawn on :func:`fe_grid`: one point
per scalar FE node, quadratic cells (``tetra10``/``triangle6``, VTK node order)
for order-2 models.  :func:`nodal_field` puts free-dof vectors (``x_free``, as
from :meth:`bladecase.reduction.ReducedModel.free_dofs`) on those points.

Numbering: grid point ``s`` is scalar FE dof ``s`` (the free dof with
``fe_index = dim * s + c`` is component ``c`` at point ``s``), i.e. the
vertices first (in the order of their mesh node index), then the edge nodes of
an order-2 model.  :func:`grid_index` maps mesh node indices (a contact node,
a group) to grid points.
"""

from __future__ import annotations

import numpy as np

from ..fe import FEModel, Mesh
from ..fe.cells import KINDS

#: Edges of the midside nodes of quadratic cells, VTK/meshio node order (``tetra10``, ``triangle6``).
VTK_EDGES = {3: ((0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)), 2: ((0, 1), (1, 2), (2, 0))}

#: VTK cell type (``pyvista.CellType`` name) of each meshio body cell type; the node orders are the same.
VTK_CELL_TYPES = {"tetra": "TETRA", "tetra10": "QUADRATIC_TETRA", "triangle": "TRIANGLE",
                  "triangle6": "QUADRATIC_TRIANGLE", "hexahedron": "HEXAHEDRON", "wedge": "WEDGE", "quad": "QUAD"}

#: Simplex families: their order-2 grid carries the edge nodes; hexahedra, wedges and quadrilaterals are drawn
#: on their corner nodes (the vertex dofs; the higher-order dofs of an order-2 model are not drawn).
SIMPLICES = ("tetra", "triangle")

#: meshio cell type of the grid's body cells, by dimension and model order.
GRID_TYPES = {(3, 1): "tetra", (3, 2): "tetra10", (2, 1): "triangle", (2, 2): "triangle6"}

#: Largest distance between a grid point and the location of its free dofs, relative to the model's size.
COORDS_RTOL = 1e-9


def _vertices(model: FEModel) -> tuple[np.ndarray, np.ndarray]:
    """``(used, corners)``: the sorted mesh nodes that are vertices of the body cells (the FE vertices, in
    scalar-dof order, as :func:`bladecase.fe.assemble` numbers them) and the cells' corners as indices into
    ``used`` (the mesh's own orientation)."""
    mesh = model.mesh
    cells = np.asarray(mesh.cells[mesh.body_type])[:, : KINDS[mesh.body_type].corners].astype(np.int64)
    used, local = np.unique(cells, return_inverse=True)
    return used, local.reshape(cells.shape)


def _family(model: FEModel) -> str:
    return KINDS[model.mesh.body_type].family


def _n_points(model: FEModel) -> int:
    """Grid points of :func:`fe_grid`: every scalar dof (simplices), the vertices only (other families)."""
    if _family(model) in SIMPLICES or model.order == 1:
        return model.dofs.n_total // model.dim
    return _vertices(model)[0].size


def _check_model(model) -> None:
    if not isinstance(model, FEModel):
        raise ValueError(f"model must be an FEModel (from bladecase.assemble), got {type(model).__name__}")


def fe_grid(model: FEModel) -> Mesh:
    """The nodal grid of ``model``: all its FE nodes as points, its elements as cells.

    Parameters
    ----------
    model : FEModel
        An order-1 or order-2 model (:func:`bladecase.assemble`).

    Returns
    -------
    Mesh
        ``points`` ``(n_points, 3)`` with ``n_points = model.dofs.n_total // dim``:
        point ``s`` is scalar FE dof ``s`` — the vertices of the body cells,
        then (order 2) the edge nodes, where the P2 edge dofs are: the mesh's
        midside nodes, or the midpoints of straight edges when it has none.  ``cells`` has one body block: ``tetra10`` /
        ``triangle6`` (VTK node order: the corners, then the midside nodes of
        the edges :data:`VTK_EDGES`) for an order-2 model, ``tetra`` /
        ``triangle`` for order 1; cells keep the orientation of the mesh's
        body cells.  ``groups`` are the mesh's groups on the grid: their
        vertices, and (order 2) the edge nodes whose two end vertices are in
        the group (the rule :func:`~bladecase.fe.assemble` clamps by);
        mesh nodes outside the body cells are dropped.

    Raises
    ------
    ValueError
        ``model`` is not an :class:`FEModel`, or its dof map does not match its
        mesh (a model built by other means than :func:`bladecase.assemble`).

    Examples
    --------
    Two P2 triangles: 4 vertices and 5 edge nodes.

    >>> import numpy as np
    >>> from bladecase.fe import Mesh, assemble
    >>> from bladecase.post.grid import fe_grid
    >>> square = Mesh(points=np.array([[0., 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]),
    ...               cells={"triangle": np.array([[0, 1, 2], [0, 2, 3]])}, dim=2,
    ...               groups={"root": np.array([0, 1])})
    >>> model = assemble(square, "steel", order=2, clamp="root", thickness=0.01)
    >>> grid = fe_grid(model)
    >>> grid.body_type, grid.points.shape, grid.cells["triangle6"][0].tolist()
    ('triangle6', (9, 3), [0, 1, 2, 4, 7, 5])
    >>> grid.points[4].tolist(), grid.groups["root"].tolist()
    ([0.5, 0.0, 0.0], [0, 1, 4])
    """
    _check_model(model)
    mesh, dim, order = model.mesh, model.dim, model.order
    used, corners = _vertices(model)
    n_v = used.size
    vertex_points = np.zeros((n_v, 3))
    vertex_points[:, :dim] = np.asarray(mesh.points, dtype=float)[used, :dim]
    family = _family(model)
    if order == 1 or family not in SIMPLICES:
        points, cells, edges = vertex_points, corners, np.zeros((0, 2), dtype=np.int64)
    else:
        edges, cell_edges = _edges(corners, dim)
        points = np.concatenate([vertex_points, 0.5 * (vertex_points[edges[:, 0]] + vertex_points[edges[:, 1]])])
        if KINDS[mesh.body_type].order == 2:  # curved cells: the edge dofs sit at the mesh's own midside nodes
            mid = np.empty(len(edges), dtype=np.int64)
            mid[cell_edges.ravel()] = np.asarray(mesh.cells[mesh.body_type])[:, dim + 1:].ravel()
            points[n_v:, :dim] = np.asarray(mesh.points, dtype=float)[mid, :dim]
        cells = np.concatenate([corners, n_v + cell_edges], axis=1)
    _check_dofs(model, points)
    groups = {}
    for name, nodes in mesh.groups.items():
        nodes = np.asarray(nodes, dtype=np.int64)
        pos = np.clip(np.searchsorted(used, nodes), 0, n_v - 1)
        in_group = np.zeros(n_v, dtype=bool)
        in_group[pos[used[pos] == nodes]] = True
        on_edges = n_v + np.flatnonzero(in_group[edges].all(axis=1))
        groups[name] = np.concatenate([np.flatnonzero(in_group), on_edges]).astype(np.int64)
    source = f"FE nodes of P{order} model on {mesh.source or 'mesh'}"
    body = GRID_TYPES[dim, order] if family in SIMPLICES else family
    return Mesh(points=points, cells={body: cells}, dim=dim, groups=groups, source=source)


def _edges(corners: np.ndarray, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """The unique edges ``(n_edges, 2)`` (vertex pairs, low first) and each cell's edges ``(n_cells, n_local)``
    in :data:`VTK_EDGES` order.

    The edges are numbered as scikit-fem numbers its P2 edge dofs: by their
    sorted vertex pair (``MeshTet.edges`` / ``MeshTri.facets``); :func:`_check_dofs`
    verifies it against the model's dof map.
    """
    n_v = int(corners.max()) + 1
    pairs = np.stack([corners[:, [a, b]] for a, b in VTK_EDGES[dim]], axis=1)  # (cells, local, 2)
    lo, hi = pairs.min(axis=2), pairs.max(axis=2)
    keys, cell_edges = np.unique(lo * n_v + hi, return_inverse=True)
    edges = np.column_stack([keys // n_v, keys % n_v])
    return edges, cell_edges.reshape(lo.shape)


def _check_dofs(model: FEModel, points: np.ndarray) -> None:
    """``ValueError`` unless the model's free dofs sit on the grid points their ``fe_index`` names."""
    dofs, dim = model.dofs, model.dim
    if len(points) < dofs.n_total // dim:  # drawn on the vertices: their dofs come first in scikit-fem
        keep = dofs.fe_index < dim * len(points)
        err = np.abs(points[dofs.fe_index[keep] // dim] - dofs.coords[keep]).max(initial=0.0)
        if err > COORDS_RTOL * max(float(np.abs(points).max()), 1e-300):
            raise ValueError(f"the model's vertex dofs differ from the mesh's vertices by up to {err:.3g}: its dof "
                             "numbering is not scikit-fem's vertices first")
        return
    if dofs.n_total != dim * len(points):
        raise ValueError(
            f"model has {dofs.n_total} dofs before clamping, its mesh gives {len(points)} P{model.order} nodes "
            f"x {dim} directions = {dim * len(points)}: the model does not match its mesh"
        )
    if len(dofs):
        scale = max(float(np.abs(points).max()), 1e-300)
        err = np.abs(points[dofs.fe_index // dim] - dofs.coords).max()
        if err > COORDS_RTOL * scale:
            raise ValueError(
                f"the model's dof locations differ from its nodes by up to {err:.3g} (size {scale:.3g}): "
                "its dof numbering is not scikit-fem's vertices-then-sorted-edges"
            )


def nodal_field(model: FEModel, x_free) -> np.ndarray:
    """Free-dof vectors as per-point vectors on :func:`fe_grid` (clamped dofs zero).

    Parameters
    ----------
    model : FEModel
    x_free : (model.n_dofs,) or (model.n_dofs, F) array_like
        Displacements (or velocities, mode shapes) of the free dofs, one
        state per column (e.g. ``reduced.free_dofs(x_r)``).

    Returns
    -------
    (n_points, dim) or (n_points, dim, F) ndarray
        Component ``c`` of point ``s`` of ``fe_grid(model)`` is the free dof
        with ``fe_index == dim * s + c``, zero if that dof is clamped.

    Raises
    ------
    ValueError
        ``x_free`` of the wrong shape, or not real numbers.

    Examples
    --------
    >>> import numpy as np
    >>> from bladecase.fe import Mesh, assemble
    >>> from bladecase.post.grid import nodal_field
    >>> square = Mesh(points=np.array([[0., 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]),
    ...               cells={"triangle": np.array([[0, 1, 2], [0, 2, 3]])}, dim=2,
    ...               groups={"root": np.array([0, 1])})
    >>> model = assemble(square, "steel", order=2, clamp="root", thickness=0.01)
    >>> y = model.dofs.coords[:, 1]  # u = (y, 0): zero on the clamped root y = 0
    >>> u = nodal_field(model, np.where(model.dofs.direction == 0, y, 0.0))
    >>> u.shape, u[:, 0].tolist()
    ((9, 2), [0.0, 0.0, 1.0, 1.0, 0.0, 0.5, 0.5, 0.5, 1.0])
    """
    _check_model(model)
    x = np.asarray(x_free)
    if x.dtype.kind not in "biuf":
        raise ValueError(f"x_free must be real numbers, got dtype {x.dtype}")
    if x.ndim not in (1, 2) or x.shape[0] != model.n_dofs:
        raise ValueError(
            f"x_free must have shape (n_dofs,) or (n_dofs, F) with n_dofs = {model.n_dofs} (the model's free dofs); "
            f"got {x.shape}"
        )
    dofs, dim = model.dofs, model.dim
    cols = x.reshape(model.n_dofs, -1)
    out = np.zeros((dofs.n_total, cols.shape[1]))
    out[dofs.fe_index] = cols
    out = out.reshape(dofs.n_total // dim, dim, -1)[: _n_points(model)]
    return out if x.ndim == 2 else out[:, :, 0]


def grid_index(model: FEModel, nodes):
    """Grid points of :func:`fe_grid` at mesh nodes (e.g. ``reduced.contact.node``).

    Parameters
    ----------
    model : FEModel
    nodes : int or array_like of int
        Mesh node indices (into ``model.mesh.points``) of vertices of the
        body cells.

    Returns
    -------
    int or ndarray
        The grid point of each node (same shape as ``nodes``).

    Raises
    ------
    ValueError
        A node out of range, or not a vertex of the body cells (e.g. a
        midside node of a ``tetra10`` mesh: no FE node of its own).

    Examples
    --------
    >>> import numpy as np
    >>> from bladecase.fe import Mesh, assemble
    >>> from bladecase.post.grid import grid_index
    >>> mesh = Mesh(points=np.array([[9., 9, 0], [0, 0, 0], [1, 0, 0], [0, 1, 0]]),
    ...             cells={"triangle": np.array([[1, 2, 3]])}, dim=2, groups={"root": np.array([1, 2])})
    >>> grid_index(assemble(mesh, "steel", order=1, thickness=0.01), [1, 3])  # node 0 is no vertex
    array([0, 2])
    """
    _check_model(model)
    a = np.asarray(nodes)
    if a.dtype.kind not in "iu":
        raise ValueError(f"nodes must be integer mesh node indices, got {nodes!r}")
    used, _ = _vertices(model)
    flat = a.astype(np.int64).ravel()
    pos = np.clip(np.searchsorted(used, flat), 0, used.size - 1)
    bad = used[pos] != flat
    if bad.any():
        node = int(flat[bad][0])
        n = len(model.mesh.points)
        why = f"out of range (mesh nodes 0..{n - 1})" if not 0 <= node < n else "not a vertex of the body cells"
        raise ValueError(f"mesh node {node} has no grid point: it is {why}")
    out = pos.reshape(a.shape)
    return int(out) if out.ndim == 0 else out
