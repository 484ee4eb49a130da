"""The full nodal grid of a finite-element model: every FE node, and free-dof vectors placed on it.

A P2 model has degrees of freedom at the vertices AND on the cell edges (faces, centres): at the
midpoints of straight edges when the mesh has only vertices (``tetra``/``triangle``),
at the mesh's own midside nodes when it has them (curved ``tetra10`` from gmsh: the
model's cells are curved through them).  Results (animations, VTK files) must show
the field the model computed on the geometry it computed it on, so they are drawn on
:func:`fe_grid`, with the quadratic cells whole (:data:`VTK_CELL_TYPES`, VTK node order):

* a mesh of quadratic cells (``tetra10``, ``hexahedron20``/``27``, ``wedge15``/``18``, ``triangle6``,
  ``quad8``/``9``) is drawn on all its nodes and cells, as ``mesh.vtu`` holds them — at order 2 the
  midside (face, centre) nodes carry the model's own dofs, at order 1 the field there is interpolated
  from the corners (the linear field of the straight cell: the mean of the two ends of an edge, of the
  corners of a face or cell);
* a P2 model on straight simplices (``tetra``/``triangle``) is drawn on ``tetra10``/``triangle6``
  cells through its edge dofs (the edge midpoints);
* other first-order meshes are drawn on their corners.

:func:`nodal_field` puts free-dof vectors (``x_free``, as from
:meth:`bladecase.reduction.ReducedModel.free_dofs`) on those points.

Numbering: the vertices of the body cells come first, in the order of their mesh node index (point ``s``
is scalar FE dof ``s`` for them); then, for a P2 model on simplices, the edge nodes in the model's dof
order (point ``s`` is scalar dof ``s`` throughout: the free dof with ``fe_index = dim * s + c`` is
component ``c`` at point ``s``), or, for a mesh of quadratic cells otherwise, its other nodes in the
order of their mesh node index.  :func:`grid_index` maps mesh node indices (a contact node, a group) to
grid points.
"""

from __future__ import annotations

import numpy as np

from ..fe import FEModel, Mesh, node_operator
from ..fe.cells import KINDS

#: Edges of the midside nodes of quadratic cells, VTK/meshio node order (``tetra10``, ``triangle6``).
VTK_EDGES = {3: ((0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)), 2: ((0, 1), (1, 2), (2, 0))}

#: VTK cell type (``pyvista.CellType`` name) of each meshio body cell type. The node orders are the same: every
#: node of bladecase's (meshio's) cells sits at the parametric coordinates VTK gives that node of its cell
#: (``vtkCell.GetParametricCoords``, checked by tests/test_quadratic_frames.py). VTK's parametric wedge turns its
#: ``(0, 1, 2)`` face towards ``(3, 4, 5)``, as gmsh, Abaqus and bladecase do; only the faces VTK extracts from
#: a linear wedge assume the other turn (:data:`VTK_NODE_ORDER`).
VTK_CELL_TYPES = {"tetra": "TETRA", "tetra10": "QUADRATIC_TETRA", "triangle": "TRIANGLE",
                  "triangle6": "QUADRATIC_TRIANGLE", "hexahedron": "HEXAHEDRON",
                  "hexahedron20": "QUADRATIC_HEXAHEDRON", "hexahedron27": "TRIQUADRATIC_HEXAHEDRON",
                  "wedge": "WEDGE", "wedge15": "QUADRATIC_WEDGE", "wedge18": "BIQUADRATIC_QUADRATIC_WEDGE",
                  "quad": "QUAD", "quad8": "QUADRATIC_QUAD", "quad9": "BIQUADRATIC_QUAD"}

#: Node order in which a cell type is written to VTK files, where it is not meshio's: the linear wedge as meshio
#: writes it (and so ``mesh.vtu``, :func:`bladecase.save_mesh`), VTK's own face convention — its ``(0, 1, 2)``
#: face turned away from ``(3, 4, 5)``, so that the faces VTK extracts point outwards; VTK's quadratic wedges
#: take bladecase's order as it is (outward faces, positive volume).
VTK_NODE_ORDER = {"wedge": (0, 2, 1, 3, 5, 4)}


def vtk_cells(body_type: str, cells: np.ndarray) -> tuple[str, np.ndarray]:
    """``(pyvista.CellType name, connectivity)`` of meshio ``body_type`` cells as VTK files hold them (the cells of
    ``mesh.vtu``); ``ValueError`` for a type VTK files do not get from bladecase.

    >>> vtk_cells("wedge", np.arange(6)[None])
    ('WEDGE', array([[0, 2, 1, 3, 5, 4]]))
    >>> vtk_cells("hexahedron20", np.arange(20)[None])[0]
    'QUADRATIC_HEXAHEDRON'
    """
    if body_type not in VTK_CELL_TYPES:
        raise ValueError(f"mesh body cells {body_type!r} cannot be written or drawn; valid: "
                         f"{', '.join(VTK_CELL_TYPES)}")
    cells = np.asarray(cells, dtype=np.int64)
    order = VTK_NODE_ORDER.get(body_type)
    return VTK_CELL_TYPES[body_type], cells if order is None else cells[:, list(order)]


#: Simplex families: an order-2 model on their first-order cells is drawn on ``tetra10``/``triangle6`` through its
#: edge dofs; hexahedra, wedges and quadrilaterals of first order are drawn on their corner nodes (the vertex
#: dofs; the higher-order dofs of an order-2 model on them are not drawn).
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


def _layout(model: FEModel) -> str:
    """How :func:`fe_grid` draws ``model``: ``"dofs"`` (point ``s`` is scalar dof ``s``: P2 on simplices),
    ``"nodes"`` (every node of a mesh of quadratic cells: the vertices, then the others) or ``"vertices"`` (the
    corners of a first-order mesh)."""
    if _family(model) in SIMPLICES and model.order == 2:
        return "dofs"
    return "nodes" if KINDS[model.mesh.body_type].order == 2 else "vertices"


def _grid_nodes(model: FEModel) -> np.ndarray:
    """The mesh node of each point of a ``"nodes"`` grid: the body cells' vertices (sorted), then their other
    nodes (sorted)."""
    mesh = model.mesh
    used, _ = _vertices(model)
    cells = np.asarray(mesh.cells[mesh.body_type]).astype(np.int64)
    extra = np.setdiff1d(np.unique(cells[:, KINDS[mesh.body_type].corners:]), used)
    return np.concatenate([used, extra])


def _n_points(model: FEModel) -> int:
    """Grid points of :func:`fe_grid`: every scalar dof (simplices), the vertices only (other families)."""
    if _family(model) in SIMPLICES or model.order == 1:
        return model.dofs.n_total // model.dim
    return _vertices(model)[0].size


def _check_model(model) -> None:
    if not isinstance(model, FEModel):
        raise ValueError(f"model must be an FEModel (from bladecase.assemble), got {type(model).__name__}")


def fe_grid(model: FEModel) -> Mesh:
    """The nodal grid of ``model``: all its FE nodes as points, its elements as cells, quadratic cells whole.

    Parameters
    ----------
    model : FEModel
        An order-1 or order-2 model (:func:`bladecase.assemble`).

    Returns
    -------
    Mesh
        ``points`` ``(n_points, 3)``, ``cells`` one body block in VTK node order (:data:`VTK_CELL_TYPES`), the
        cells keeping the orientation of the mesh's body cells:

        * a mesh of quadratic cells (``tetra10``, ``hexahedron20``/``27``, ``wedge15``/``18``, ``triangle6``,
          ``quad8``/``9``): every node of its body cells and those cells, node for node — the points and cells
          of ``mesh.vtu`` (:func:`bladecase.save_mesh`) when every node of the mesh is a node of a body cell.
          The vertices come first (point ``s`` is vertex dof ``s``), then the other nodes by mesh node index —
          but for a P2 model on ``tetra10``/``triangle6``, numbered as on straight simplices (next);
        * a P2 model on ``tetra``/``triangle``: ``n_points = model.dofs.n_total // dim``, point ``s`` is scalar
          FE dof ``s`` — the vertices, then the edge nodes where the P2 edge dofs are (the mesh's midside nodes,
          or the midpoints of straight edges when it has none) —, ``tetra10``/``triangle6`` cells (the corners,
          then the midside nodes of the edges :data:`VTK_EDGES`);
        * other first-order meshes: their vertices and cells (the higher-order dofs of a P2 model on hexahedra,
          wedges or quadrilaterals are not drawn).

        ``groups`` are the mesh's groups on the grid: their vertices, and the other points whose mesh node is in
        the group or whose edge (face, cell) has all its vertices in it (the rule :func:`~bladecase.fe.assemble`
        clamps by); mesh nodes outside the body cells are dropped.

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

    An 8-node quadrilateral at order 1: all its nodes, the midside ones from the corners.

    >>> quad8 = Mesh(points=np.array([[0., 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0], [1, 0, 0], [2, .5, 0],
    ...                               [1, 1, 0], [0, .5, 0]]), cells={"quad8": np.arange(8)[None]}, dim=2,
    ...              groups={"root": np.array([0, 3, 7])})
    >>> grid = fe_grid(assemble(quad8, "steel", order=1, clamp="root", thickness=0.01))
    >>> grid.body_type, grid.cells["quad8"].tolist(), grid.groups["root"].tolist()
    ('quad8', [[0, 1, 2, 3, 4, 5, 6, 7]], [0, 3, 7])
    """
    _check_model(model)
    mesh, dim = model.mesh, model.dim
    layout = _layout(model)
    used, corners = _vertices(model)
    n_v = used.size
    if layout == "nodes":
        nodes = _grid_nodes(model)
        points = np.zeros((nodes.size, 3))
        points[:, :dim] = np.asarray(mesh.points, dtype=float)[nodes, :dim]
        where = np.full(len(mesh.points), -1, dtype=np.int64)
        where[nodes] = np.arange(nodes.size)
        cells = where[np.asarray(mesh.cells[mesh.body_type], dtype=np.int64)]
        _check_dofs(model, points, n_v)
        groups = {name: _nodes_group(mesh, cells, where, members) for name, members in mesh.groups.items()}
        return Mesh(points=points, cells={mesh.body_type: cells}, dim=dim, groups=groups,
                    source=f"FE nodes of P{model.order} model on {mesh.source or 'mesh'}")
    vertex_points = np.zeros((n_v, 3))
    vertex_points[:, :dim] = np.asarray(mesh.points, dtype=float)[used, :dim]
    if layout == "vertices":
        points, cells, edges = vertex_points, corners, np.zeros((0, 2), dtype=np.int64)
    else:
        edges, cell_edges = _edges(corners, dim)
        points = np.concatenate([vertex_points, 0.5 * (vertex_points[edges[:, 0]] + vertex_points[edges[:, 1]])])
        if KINDS[mesh.body_type].order == 2:  # curved cells: the edge dofs sit at the mesh's own midside nodes
            mid = np.empty(len(edges), dtype=np.int64)
            mid[cell_edges.ravel()] = np.asarray(mesh.cells[mesh.body_type])[:, dim + 1:].ravel()
            points[n_v:, :dim] = np.asarray(mesh.points, dtype=float)[mid, :dim]
        cells = np.concatenate([corners, n_v + cell_edges], axis=1)
    _check_dofs(model, points, n_v)
    groups = {}
    for name, members in mesh.groups.items():
        members = np.asarray(members, dtype=np.int64)
        pos = np.clip(np.searchsorted(used, members), 0, n_v - 1)
        in_group = np.zeros(n_v, dtype=bool)
        in_group[pos[used[pos] == members]] = True
        on_edges = n_v + np.flatnonzero(in_group[edges].all(axis=1))
        groups[name] = np.concatenate([np.flatnonzero(in_group), on_edges]).astype(np.int64)
    source = f"FE nodes of P{model.order} model on {mesh.source or 'mesh'}"
    body = KINDS[mesh.body_type].family if layout == "vertices" else GRID_TYPES[dim, 2]
    return Mesh(points=points, cells={body: cells}, dim=dim, groups=groups, source=source)


def _nodes_group(mesh: Mesh, cells: np.ndarray, where: np.ndarray, members) -> np.ndarray:
    """The grid points (sorted) of a mesh group on a ``"nodes"`` grid: its nodes, and the other nodes of the body
    cells whose parent corners (edge ends, face or cell corners) are all in it."""
    kind = KINDS[mesh.body_type]
    in_group = np.zeros(len(mesh.points), dtype=bool)
    in_group[np.asarray(members, dtype=np.int64)] = True
    body = np.asarray(mesh.cells[mesh.body_type], dtype=np.int64)
    extra = [np.zeros(0, dtype=np.int64)]
    for j in range(kind.corners, kind.n_nodes):
        extra.append(cells[in_group[body[:, list(kind.parents[j])]].all(axis=1), j])
    mine = where[np.flatnonzero(in_group)]
    return np.unique(np.concatenate([mine[mine >= 0], *extra]))


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


def _check_dofs(model: FEModel, points: np.ndarray, n_v: int) -> None:
    """``ValueError`` unless the model's free dofs sit on the grid points their ``fe_index`` names (the vertex
    dofs only, on the ``n_v`` first points, for grids drawn on the vertices or on a mesh's nodes)."""
    dofs, dim = model.dofs, model.dim
    if _layout(model) != "dofs":  # the vertex dofs come first in scikit-fem, the vertices first on the grid
        keep = dofs.fe_index < dim * n_v
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
        The field at every point of ``fe_grid(model)``, zero where clamped: where point ``s`` is scalar dof ``s``
        (vertices; every point of a P2 model on simplices), component ``c`` is the free dof with ``fe_index ==
        dim * s + c``; at the other nodes of a mesh of quadratic cells, the model's field there
        (:func:`bladecase.fe.node_operator`): at order 2 the dof of the edge, face or cell at that node, at
        order 1 the mean of the corners of its edge, face or cell (the straight cell's linear field).

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
    if _layout(model) == "nodes":  # every node of the mesh's quadratic cells: the model's field there
        rows = (dim * _grid_nodes(model)[:, None] + np.arange(dim)).ravel()
        out = np.asarray(node_operator(model)[rows] @ cols).reshape(-1, dim, cols.shape[1])
        return out if x.ndim == 2 else out[:, :, 0]
    out = np.zeros((dofs.n_total, cols.shape[1]))
    out[dofs.fe_index] = cols
    out = out.reshape(dofs.n_total // dim, dim, -1)[: _n_points(model)]
    return out if x.ndim == 2 else out[:, :, 0]


def node_values(model: FEModel, values, points) -> np.ndarray:
    """Values at the model's scalar FE nodes (``(N, ...)``, e.g. :func:`bladecase.fe.stress.nodal_stress`, clamped
    nodes included) at every point of :func:`fe_grid`: a grid point that is an FE node takes its value (found by
    position: ``points`` ``(N, 3)``, :func:`bladecase.fe.stress.fe_node_points`); the other nodes of a mesh of
    quadratic cells drawn at order 1 take the mean of their cell's parent corners (as :func:`nodal_field` does).

    >>> from bladecase.fe import Mesh, assemble
    >>> square = Mesh(points=np.array([[0., 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]),
    ...               cells={"triangle": np.array([[0, 1, 2], [0, 2, 3]])}, dim=2, groups={"root": np.array([0, 1])})
    >>> model = assemble(square, "steel", order=2, clamp="root", thickness=0.01)
    >>> grid = fe_grid(model)
    >>> node_values(model, grid.points[::-1, 0], grid.points[::-1]).tolist() == grid.points[:, 0].tolist()
    True
    """
    from scipy.spatial import cKDTree

    grid = fe_grid(model)
    v = np.asarray(values)
    P = np.asarray(points, dtype=float)
    if P.shape != (v.shape[0], 3):
        raise ValueError(f"points must be ({v.shape[0]}, 3): one per value, got {P.shape}")
    scale = max(float(np.abs(grid.points).max()), 1e-300)
    dist, near = cKDTree(P).query(grid.points)
    found = dist <= COORDS_RTOL * scale * 1e3
    out = np.zeros((len(grid.points),) + v.shape[1:], dtype=float)
    out[found] = v[near[found]]
    if not found.all():  # the other nodes of quadratic cells at order 1: the mean of their corners
        kind = KINDS[model.mesh.body_type]
        cells = grid.cells[grid.body_type]
        for j in range(kind.corners, kind.n_nodes):
            parents = cells[:, list(kind.parents[j])]
            out[cells[:, j]] = out[parents].mean(axis=1)
        if not found[cells[:, : kind.corners]].all():
            raise ValueError("a corner of the grid is no FE node of the model: the points are not the model's")
    return out


def grid_index(model: FEModel, nodes):
    """Grid points of :func:`fe_grid` at mesh nodes (e.g. ``reduced.contact.node``).

    Parameters
    ----------
    model : FEModel
    nodes : int or array_like of int
        Mesh node indices (into ``model.mesh.points``) of vertices of the
        body cells (of any node of them, for a mesh of quadratic cells drawn
        node for node: every model on hexahedra, wedges, quadrilaterals of
        second order, and order 1 on ``tetra10``/``triangle6``).

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
    every = _layout(model) == "nodes"
    known = _grid_nodes(model) if every else _vertices(model)[0]
    n = len(model.mesh.points)
    where = np.full(n, -1, dtype=np.int64)
    where[known] = np.arange(known.size)
    flat = a.astype(np.int64).ravel()
    pos = where[np.clip(flat, 0, n - 1)]
    bad = (flat < 0) | (flat >= n) | (pos < 0)
    if bad.any():
        node = int(flat[bad][0])
        why = (f"out of range (mesh nodes 0..{n - 1})" if not 0 <= node < n else
               f"not a {'node' if every else 'vertex'} of the body cells")
        raise ValueError(f"mesh node {node} has no grid point: it is {why}")
    out = pos.reshape(a.shape)
    return int(out) if out.ndim == 0 else out
