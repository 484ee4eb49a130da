"""The mesh that travels from geometry (or a user's file) to the FE assembly.

A :class:`Mesh` is plain data: node coordinates, cells by meshio cell type,
and named node groups.  :func:`load_mesh` reads any format meshio reads
(:func:`from_meshio` converts an in-memory ``meshio.Mesh``) and checks the
elements; :func:`save_mesh` writes ``.vtu``/``.vtk``/``.inp`` files with the
groups in a form :func:`load_mesh` reads back.
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .. import log
from ..io import atomic_path, check_output_file
from .cells import BODY_TYPES, BOUNDARY_TYPES, KINDS
from .groups import GROUP_PREFIX, NODE_ID_KEY, file_groups, file_node_ids
from .mesh_checks import (  # noqa: F401  (public names of this module before they moved)
    _LINE_FORMATS,
    _OFFSET_FACTOR,
    COINCIDENT_RTOL,
    EXTENT_RANGE,
    FORMAT_ALIASES,
    LENGTH_UNITS,
    _body_type,
    _check_blocks,
    _check_coincident,
    _check_complete,
    _check_one_body,
    _read_quietly,
    _wedge18_in_vtk_order,
    check_extent,
    check_input_file,
    reader_formats,
)
from .quality import (  # noqa: F401  (the former home of these names)
    _P2_EDGES,
    DEGENERATE_RTOL,
    _check_orientation,
    jacobian_dets,
    signed_measures,
)

#: meshio simplex cell types accepted as the body of a model, by dimension and order (all accepted types:
#: :data:`bladecase.fe.cells.BODY_TYPES`).
VOLUME_TYPES = {3: {1: "tetra", 2: "tetra10"}, 2: {1: "triangle", 2: "triangle6"}}


@dataclass(frozen=True, eq=False)
class Mesh:
    """A mesh of one body cell type with named groups.

    Attributes
    ----------
    points : (n_nodes, 3) float ndarray
        Node coordinates (``z = 0`` for planar meshes).
    cells : dict[str, ndarray]
        Connectivity by meshio cell type: one body type (``"tetra"``, ``"tetra10"``,
        ``"hexahedron"``, ``"hexahedron20"``, ``"hexahedron27"``, ``"wedge"``, ``"wedge15"``,
        ``"wedge18"``; ``"triangle"``, ``"triangle6"``, ``"quad"``, ``"quad8"``, ``"quad9"`` in 2-D)
        and boundary cells (``"triangle"``, ``"quad"``, …, ``"line"``, ``"vertex"``), node
        indices into ``points`` (0-based), meshio (VTK) node ordering.
    dim : int
        2 (planar, plane stress) or 3 (solid).
    groups : dict[str, ndarray]
        Named node sets (sorted unique node indices): physical groups, cell
        sets and node sets of the source file, e.g. ``"root"``, ``"tip"``,
        ``"blade"``.
    source : str
        Where the mesh came from (file path or generator), for messages.
    node_ids : (n_nodes,) int ndarray
        The node numbers of the file (Abaqus, CalculiX, ANSYS: as written there), used in every message that names
        a node; for files without node numbers (gmsh, VTK) and generated meshes, the 0-based index
        (``arange(n_nodes)``, the default). :attr:`numbering` says which.
    unit : str
        The length unit of the source's coordinates (:data:`~bladecase.fe.mesh_checks.LENGTH_UNITS`); ``points``
        are always in metres.
    material : dict or None
        The material the file gives the body's elements, in the file's own units (:attr:`unit` implies them):
        ``{"name", "E", "nu", "rho", "source": "deck", "where"}`` — an Abaqus/CalculiX ``*MATERIAL`` (through the
        ``*SOLID SECTION`` of the body's elements), an ANSYS archive's ``MP`` records (through the elements'
        material number) —, or ``{"name", "problem", "source", "where"}`` when it cannot be used (several materials
        for the body, no density, …); ``None`` when the file carries none.
        :func:`bladecase.fe.material.mesh_material` converts it to SI.

    Examples
    --------
    A 100 mm × 20 mm strip of triangles made by scikit-fem, clamped along ``x = 0``:

    >>> from skfem import MeshTri
    >>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5)).oriented()
    >>> points = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    >>> strip = Mesh(points, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(points[:, 0] == 0)},
    ...              source="strip")
    >>> len(strip.points), strip.body_type, strip.order, strip.group("root").tolist()
    (105, 'triangle', 1, [0, 1, 2, 3, 4])
    >>> strip.group("tip")
    Traceback (most recent call last):
        ...
    ValueError: mesh strip has no group 'tip' (groups: root)
    """

    points: np.ndarray
    cells: dict
    dim: int
    groups: dict = field(default_factory=dict)
    source: str = ""
    node_ids: np.ndarray | None = None
    unit: str = "m"
    material: dict | None = None

    def __post_init__(self) -> None:
        n = len(self.points)
        ids = np.arange(n, dtype=np.int64) if self.node_ids is None else np.asarray(self.node_ids, dtype=np.int64)
        if ids.shape != (n,) or (n and (ids.min() < 0 or np.unique(ids).size != n)):
            raise ValueError(f"mesh {self.source or ''}: node_ids must be {n} distinct integers >= 0, one per node, "
                             f"got an array of shape {ids.shape}")
        object.__setattr__(self, "node_ids", ids)
        if self.unit not in LENGTH_UNITS:
            raise ValueError(f"mesh unit must be one of {', '.join(LENGTH_UNITS)}, got {self.unit!r}")
        if self.material is not None and not isinstance(self.material, dict):
            raise ValueError(f"mesh {self.source or ''}: material must be a dict or None, got "
                             f"{type(self.material).__name__}")

    @property
    def numbering(self) -> str:
        """``"file"`` when nodes carry the file's own numbers (:attr:`node_ids`), ``"index"`` for the 0-based index."""
        return "index" if np.array_equal(self.node_ids, np.arange(len(self.points))) else "file"

    def node_id(self, index) -> int:
        """The node number (as in the file) of the node at 0-based ``index``."""
        return int(self.node_ids[int(index)])

    def index_of(self, ids, what: str = "node") -> np.ndarray:
        """0-based indices of the nodes numbered ``ids`` (as in the file); ``ValueError`` naming the first number
        that is not a node of the mesh.

        >>> m = Mesh(np.eye(3), {"triangle": np.array([[0, 1, 2]])}, 2, node_ids=np.array([1001, 1003, 1005]),
        ...          source="m")
        >>> m.numbering, m.index_of([1005, 1001]).tolist(), m.node_id(1)
        ('file', [2, 0], 1003)
        >>> m.index_of([1002])
        Traceback (most recent call last):
            ...
        ValueError: node 1002 is not a node of mesh m (3 nodes numbered 1001 to 1005)
        """
        ids = np.asarray(ids).ravel()
        if ids.dtype.kind not in "iu":
            raise ValueError(f"{what} numbers must be integers, got {ids.tolist()[:5]!r}")
        order = np.argsort(self.node_ids, kind="stable")
        ranked = self.node_ids[order]
        k = np.minimum(np.searchsorted(ranked, ids), max(ranked.size - 1, 0))
        found = ranked[k] == ids if ranked.size else np.zeros(ids.size, dtype=bool)
        if not found.all():
            span = f"numbered {ranked[0]} to {ranked[-1]}" if self.numbering == "file" else \
                f"numbered by their 0-based index, 0 to {ranked.size - 1}"
            raise ValueError(f"{what} {int(ids[~found][0])} is not a node of mesh {self.source or ''} "
                             f"({ranked.size} nodes {span})")
        return order[k]

    @property
    def body_type(self) -> str:
        """The meshio type of the body cells (:data:`bladecase.fe.cells.BODY_TYPES` of ``dim``)."""
        for t in BODY_TYPES.get(self.dim, ()):
            if t in self.cells and len(self.cells[t]):
                return t
        raise ValueError(f"mesh {self.source or ''} has no {self.dim}-D body cells "
                         f"({', '.join(BODY_TYPES.get(self.dim, ()))})")

    @property
    def order(self) -> int:
        """Geometric order of the body cells (1 or 2)."""
        return KINDS[self.body_type].order

    def group(self, name: str) -> np.ndarray:
        """Node indices of group ``name``; ``ValueError`` naming the groups that exist."""
        if name not in self.groups:
            have = ", ".join(sorted(self.groups)) or "none"
            raise ValueError(f"mesh {self.source or ''} has no group {name!r} (groups: {have})")
        return self.groups[name]


# ----------------------------------------------------------------------------- reading



_ALIASES = {"tetra4": "tetra"}  # meshio's name for Abaqus C3D4H

#: Abaqus element types missing from meshio 5.3's table (plane stress/strain, solids).
_ABAQUS_EXTRA = {
    "CPS6": "triangle6", "CPS6M": "triangle6", "CPE3": "triangle", "CPE6M": "triangle6", "CPS3H": "triangle",
    "CPE4": "quad", "CPE4R": "quad", "CPS8": "quad8", "CPS8R": "quad8", "CPE8": "quad8", "CPE8R": "quad8",
    "C3D6H": "wedge", "C3D15H": "wedge15",
}


def load_mesh(path: str | os.PathLike, require: Sequence[str] = (), unit: str = "m",
              file_format: str | None = None) -> Mesh:
    """Read a mesh and its named groups from any file meshio reads.

    The body is ONE cell type (:data:`~bladecase.fe.cells.BODY_TYPES`), of first or second order: in 3-D
    tetrahedra (``tetra``, ``tetra10``), hexahedra (``hexahedron``, ``hexahedron20``, ``hexahedron27``) or wedges
    (``wedge``, ``wedge15``, ``wedge18``); in 2-D triangles (``triangle``, ``triangle6``) or quadrilaterals
    (``quad``, ``quad8``, ``quad9``).  Other body cells (e.g. pyramids) and several body cell types in one mesh
    (e.g. tetrahedra beside hexahedra or wedges) are refused.

    Parameters
    ----------
    path : path-like
        ``.msh`` (gmsh 2.2/4.1; a CalculiX ``.msh`` in Abaqus syntax is recognised by its content), ``.vtu``/``.vtk``,
        ``.inp`` (Abaqus, CalculiX: :mod:`bladecase.fe.abaqus`, includes, sets and ``*BOUNDARY`` read), ``.med``,
        ``.bdf`` (Nastran), ``.cdb`` (ANSYS archive, :mod:`bladecase.fe.cdb`: node and element components become
        groups), …
    require : sequence of str
        Group names that must exist and be non-empty (e.g. ``("root", "tip")``).
    unit : str
        Length unit of the file's coordinates (:data:`~bladecase.fe.mesh_checks.LENGTH_UNITS`: ``"m"``, ``"mm"``,
        ``"cm"``, ``"in"``, ``"ft"``): the points are scaled to metres.
    file_format : str, optional
        ``"abaqus"`` (also ``"calculix"``), ``"gmsh"``, ``"ansys"`` (an ANSYS ``.msh``), ``"ansys-cdb"`` or any
        format name meshio reads (:func:`mesh_formats`). Not given: from the suffix and the content.

    Returns
    -------
    Mesh
        See :func:`from_meshio` for what is kept and checked.

    Raises
    ------
    ValueError
        Unreadable file (the path and meshio's reason); no body cells of an
        accepted type (above: the message lists them); several body cell types
        (the counts, and the valid bodies) or mixed element orders; a 2-D mesh
        off the plane ``z = 0``; degenerate, inverted, twisted or collapsed
        elements (count and first offender); a required group missing or empty.

    Examples
    --------
    A strip written by :func:`save_mesh` reads back with its groups; a required group must exist:

    >>> import tempfile
    >>> from skfem import MeshTri
    >>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5))
    >>> points = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    >>> root = np.flatnonzero(points[:, 0] == 0)
    >>> folder = tempfile.TemporaryDirectory()
    >>> save_mesh(Mesh(points, {"triangle": t.oriented().t.T}, 2, {"root": root}), f"{folder.name}/strip.vtu")
    >>> mesh = load_mesh(f"{folder.name}/strip.vtu", require=("root",))
    >>> mesh.dim, mesh.body_type, len(mesh.points), mesh.group("root").tolist()
    (2, 'triangle', 105, [0, 1, 2, 3, 4])
    >>> load_mesh(f"{folder.name}/strip.vtu", require=("tip",))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    ValueError: mesh .../strip.vtu has no group 'tip' (groups: root)

    The elements are checked: without ``.oriented()``, half of scikit-fem's tensor triangles are clockwise
    (inverted):

    >>> save_mesh(Mesh(points, {"triangle": t.t.T}, 2, {"root": root}), f"{folder.name}/mixed.vtu")
    >>> load_mesh(f"{folder.name}/mixed.vtu")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    ValueError: mesh .../mixed.vtu has 80 inverted triangle element(s) (negative area); first: element 0, ...

    Hexahedra (and wedges, quadrilaterals) are bodies too, not simplices only:

    >>> import meshio
    >>> cube = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1.0]])
    >>> meshio.write(f"{folder.name}/cube.vtu", meshio.Mesh(cube, [("hexahedron", np.arange(8)[None])]))
    >>> load_mesh(f"{folder.name}/cube.vtu").body_type
    'hexahedron'
    >>> folder.cleanup()
    """
    import meshio

    source = check_input_file(path)  # a pipe or a device would hang the readers
    if unit not in LENGTH_UNITS:
        raise ValueError(f"mesh unit must be one of {', '.join(LENGTH_UNITS)}, got {unit!r}")
    head = _check_complete(source)
    _register_types()
    formats, why = reader_formats(source, head, file_format)
    reasons = []
    for fmt in formats:
        m, reason = _read_quietly(meshio, path, fmt)
        if m is not None:
            break
        reasons.append(f"{fmt or 'from the suffix'}: {reason}" if len(formats) > 1 else reason)
    else:
        tried = ", ".join(f or "from the suffix" for f in formats)
        named = "" if file_format else (f" Formats tried: {tried} ({why}); name the format with [mesh] format (e.g. "
                                        "\"abaqus\", \"gmsh\", \"ansys\", or any meshio format).")
        raise ValueError(f"cannot read mesh file {source!r} (corrupt, truncated or not a mesh?): "
                         f"{'; '.join(reasons)}.{named}")
    return from_meshio(m, source=source, require=require, unit=unit)


def mesh_formats() -> list[str]:
    """The format names :func:`load_mesh` takes as ``file_format`` (``[mesh] format``)."""
    from meshio import _helpers

    _register_types()
    return sorted(set(_helpers.reader_map) | set(FORMAT_ALIASES))


def _register_types() -> None:
    """Teach meshio's Abaqus reader the types it lacks, meshio 5.3 the dimension of the 15/18-node wedges (its gmsh
    reader fails on them without it) and the ANSYS archive format (``.cdb``, :mod:`bladecase.fe.cdb`); never
    overrides an entry."""
    from meshio import _mesh
    from meshio.abaqus import _abaqus

    for key, value in _ABAQUS_EXTRA.items():
        _abaqus.abaqus_to_meshio_type.setdefault(key, value)
    for key in ("wedge15", "wedge18"):
        _mesh.topological_dimension.setdefault(key, 3)
    from . import abaqus, cdb

    cdb.register()  # ANSYS archives (.cdb), which meshio does not read
    abaqus.register()  # Abaqus/CalculiX decks with includes, node numbers and *BOUNDARY


def from_meshio(m, source: str = "", require: Sequence[str] = (), unit: str = "m") -> Mesh:
    """Convert a ``meshio.Mesh`` to a checked :class:`Mesh`.

    * **Dimension**: 3 if the mesh has volume cells (tetrahedra, hexahedra,
      wedges: :data:`~bladecase.fe.cells.BODY_TYPES`), else 2 if it has
      triangles or quadrilaterals (which must then lie in ``z = 0``).
    * **Cells kept**: the body cells (one cell type, all blocks merged) and
      the lower-dimensional cells (``vertex``, ``line``, ``line3``, and
      ``triangle``, ``triangle6``, ``quad``, ``quad8``, ``quad9`` in 3-D), e.g.
      the faces of physical groups.  Other cell types of lower dimension are
      dropped, with a log message naming them; several body cell types (e.g.
      hexahedra and wedges, or tetrahedra and pyramids) are an error naming
      the counts: scikit-fem assembles one cell type per mesh.  gmsh's 18-node
      wedges (which meshio 5.3 leaves in gmsh's order) are put in VTK order.
    * **Nodes**: all points of the file are kept, with their indices, even the
      ones no kept cell uses (e.g. geometry vertices); points are padded to
      three columns and scaled from ``unit`` to metres; the file's node numbers
      (point data ``node_id``, kept by the Abaqus reader) become
      :attr:`Mesh.node_ids`; the material the file gives its body (``info["material"]``, set by the Abaqus and
      ANSYS archive readers) becomes :attr:`Mesh.material`.
    * **Groups** (node sets, unions when a name appears in several sources):
      gmsh physical groups (``cell_sets``, or ``field_data`` + ``cell_data
      ["gmsh:physical"]`` for MSH 2.2) → the nodes of their cells; Abaqus
      ``*NSET`` (``point_sets``) as they are and ``*ELSET`` (``cell_sets``) →
      the nodes of their elements; MED families (``point_tags``,
      ``cell_tags``); point-data masks ``group:<name>`` (``.vtu``/``.vtk``);
      Nastran property ids (``cell_data["nastran:ref"]``, the PID of each
      element) → ``pid_<id>``, the nodes of the elements of that property.
    * **Checks**: degenerate elements (``|volume| <= DEGENERATE_RTOL · mean``),
      inverted elements (negative signed volume of the straight element
      through the corner nodes) and, for ``tetra10``/``triangle6``, curved
      elements whose Jacobian is not positive at every corner node.  Hexahedra,
      wedges and quadrilaterals: the Jacobian of the straight cell at every
      corner (:func:`~bladecase.fe.quality.corner_jacobians`) must be positive
      (all negative: inverted; some: twisted or collapsed), and of the curved
      cell too for second-order ones.  Planar triangles and quadrilaterals, and
      wedges, that are ALL reversed are reoriented (corner and midside nodes);
      a mix is an error.  Errors name the count
      and the first offending element (its index among the body cells and
      its nodes).  One body: lines or triangles that use nodes no body cell uses (a stray planar
      part beside a solid) are an error naming the counts.
    """
    if not source:
        source = "<meshio mesh>"
    points = np.array(m.points, dtype=float)  # a copy: the meshio mesh is not modified
    if points.ndim != 2 or points.shape[1] not in (2, 3) or len(points) == 0:
        raise ValueError(f"mesh {source} has no usable points (array shape {points.shape})")
    if not np.all(np.isfinite(points)):
        bad = int((~np.isfinite(points)).any(axis=1).sum())
        raise ValueError(f"mesh {source} has {bad} point(s) with non-finite coordinates")
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    if unit not in LENGTH_UNITS:
        raise ValueError(f"mesh unit must be one of {', '.join(LENGTH_UNITS)}, got {unit!r}")
    points *= LENGTH_UNITS[unit]

    blocks = [(_ALIASES.get(b.type, b.type), np.asarray(b.data)) for b in m.cells]
    _check_blocks(blocks, len(points), source)
    present = {t for t, d in blocks if len(d)}
    btype, dim = _body_type(blocks, present, source)
    check_extent(points, source)
    if dim == 2:
        extent = float(np.ptp(points[:, :2], axis=0).max()) or 1.0
        zmax = float(np.abs(points[:, 2]).max())
        if zmax > 1e-12 * extent:
            raise ValueError(f"2-D mesh {source} does not lie in the plane z = 0 (max |z| = {zmax:.6g})")
        points[:, 2] = 0.0

    groups = file_groups(m, blocks, len(points), source)
    ids = file_node_ids(m, len(points), source)
    body = np.concatenate([d for t, d in blocks if t == btype]).astype(np.int64)
    if body.min() < 0 or body.max() >= len(points):
        raise ValueError(f"mesh {source}: {btype} cells refer to nodes outside 0..{len(points) - 1}")
    _check_one_body(blocks, body, btype, dim, source)
    if btype == "wedge18":
        body = _wedge18_in_vtk_order(points, body, source)
    body = _check_orientation(points, body, btype, dim, source)
    _check_coincident(points, body, btype, source, ids)  # after the cells' own checks (a collapsed cell: named there)
    cells = {btype: body}
    for d in range(dim - 1, -1, -1):  # boundary cells: faces, edges, vertices
        for t in BOUNDARY_TYPES[d]:
            if t in present:
                cells[t] = np.concatenate([c for tt, c in blocks if tt == t]).astype(np.int64)
    dropped = {t: sum(len(c) for tt, c in blocks if tt == t) for t in sorted(present - set(cells))}
    if dropped:
        log.info("mesh %s: %s dropped (cell types a %d-D model does not use)", source,
                 ", ".join(f"{n} {t} cell(s)" for t, n in dropped.items()), dim)
    info = getattr(m, "info", None)
    material = info.get("material") if isinstance(info, dict) and isinstance(info.get("material"), dict) else None
    mesh = Mesh(points=points, cells=cells, dim=dim, groups=groups, source=source, node_ids=ids, unit=unit,
                material=material)
    for name in require:
        if len(mesh.group(name)) == 0:
            raise ValueError(f"mesh {source}: group {name!r} is empty")
    return mesh


_ABAQUS_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]{0,79}$")


def save_mesh(mesh: Mesh, path: str | os.PathLike) -> None:
    """Write ``mesh`` with its groups, atomically, in a form :func:`load_mesh` reads back.

    * ``.vtu`` / ``.vtk``: all cells; each group as a ``uint8`` point-data
      mask ``group:<name>`` (1 = in the group), viewable in ParaView; the file's
      node numbers (:attr:`Mesh.node_ids`, when the mesh has them) as the point
      data ``node_id``.
    * ``.inp`` (Abaqus): nodes with their numbers (the file's, else 1-based), the
      body elements (``C3D4``, ``C3D10``, …, plane-stress ``CPS3``, ``CPS6``, …)
      and one ``*NSET`` per group (names: a letter then letters, digits, ``_``).

    gmsh ``.msh`` files come from :func:`bladecase.blade_mesh`.

    Examples
    --------
    A unit square of two triangles, written for Abaqus and read back (node numbers 1-based in the file):

    >>> import tempfile
    >>> from pathlib import Path
    >>> square = Mesh(points=np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]),
    ...               cells={"triangle": np.array([[0, 1, 2], [0, 2, 3]])}, dim=2,
    ...               groups={"root": np.array([0, 1])}, source="square")
    >>> folder = tempfile.TemporaryDirectory()
    >>> save_mesh(square, f"{folder.name}/square.inp")
    >>> Path(folder.name, "square.inp").read_text().splitlines()[7:12]
    ['*ELEMENT, TYPE=CPS3', '1, 1, 2, 3', '2, 1, 3, 4', '*NSET, NSET=root', '1, 2']
    >>> back = load_mesh(f"{folder.name}/square.inp")
    >>> back.cells["triangle"].tolist(), back.group("root").tolist()
    ([[0, 1, 2], [0, 2, 3]], [0, 1])
    >>> save_mesh(square, f"{folder.name}/square.stl")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    ValueError: save_mesh cannot write '.../square.stl': suffix '.stl', valid: .vtu, .vtk, .inp
    >>> folder.cleanup()
    """
    path = os.fspath(check_output_file(path))  # a folder, a device, a path under a file: named first
    suffix = os.path.splitext(path)[1].lower()
    if suffix in (".vtu", ".vtk"):
        import meshio

        data = {GROUP_PREFIX + name: _mask(nodes, len(mesh.points)) for name, nodes in mesh.groups.items()}
        if mesh.numbering == "file":
            data[NODE_ID_KEY] = mesh.node_ids
        out = meshio.Mesh(mesh.points, [(t, np.asarray(c)) for t, c in mesh.cells.items()], point_data=data)
        with atomic_path(path) as tmp:
            meshio.write(tmp, out, file_format="vtu" if suffix == ".vtu" else "vtk")
    elif suffix == ".inp":
        from .abaqus import ABAQUS_TYPES, abaqus_text

        if mesh.body_type not in ABAQUS_TYPES:
            valid = ", ".join(f"{k} ({v})" for k, v in ABAQUS_TYPES.items())
            raise ValueError(f"save_mesh cannot write {mesh.body_type} cells to Abaqus {path!r} (meshio reads no "
                             f"such element back); valid: {valid}; write .vtu or .vtk instead")
        for name in mesh.groups:
            if not _ABAQUS_NAME.match(name):
                raise ValueError(
                    f"group name {name!r} is not a valid Abaqus set name (a letter, then letters, digits, _)"
                )
        with atomic_path(path) as tmp:
            tmp.write_text(abaqus_text(mesh), encoding="ascii")
    else:
        raise ValueError(f"save_mesh cannot write {path!r}: suffix {suffix or '(none)'!r}, valid: .vtu, .vtk, .inp")


def _mask(nodes: np.ndarray, n: int) -> np.ndarray:
    mask = np.zeros(n, dtype=np.uint8)
    mask[nodes] = 1
    return mask


# ----------------------------------------------------------------------------- arrays (for .npz stage files)

def mesh_to_arrays(mesh: Mesh, prefix: str = "mesh/") -> dict[str, np.ndarray]:
    """The mesh as flat named arrays (for ``np.savez``): points, cells by type, groups, node numbers, unit."""
    out = {f"{prefix}points": mesh.points, f"{prefix}dim": np.array(mesh.dim),
           f"{prefix}source": np.array(mesh.source), f"{prefix}node_ids": mesh.node_ids,
           f"{prefix}unit": np.array(mesh.unit)}
    out.update({f"{prefix}cells/{t}": np.asarray(c) for t, c in mesh.cells.items()})
    out.update({f"{prefix}groups/{g}": np.asarray(n) for g, n in mesh.groups.items()})
    return out


def mesh_from_arrays(data, prefix: str = "mesh/", source: str = "data") -> Mesh:
    """Inverse of :func:`mesh_to_arrays` (``data``: a mapping such as an ``NpzFile``); ``ValueError`` naming
    ``source`` and the field when a field has the wrong type."""
    from ..io import npz_array, npz_scalar

    cells = {k[len(prefix) + 6:]: npz_array(data, k, source, 2, "int") for k in data if k.startswith(f"{prefix}cells/")}
    groups = {k[len(prefix) + 7:]: npz_array(data, k, source, 1, "int") for k in data
              if k.startswith(f"{prefix}groups/")}
    points = npz_array(data, f"{prefix}points", source, 2).astype(float)
    dim = npz_scalar(data, f"{prefix}dim", source, "int")
    if dim not in (2, 3) or points.shape[1:] != (3,) or not np.all(np.isfinite(points)):
        raise ValueError(f"{source}: the mesh must have dim 2 or 3 and finite (n, 3) points, got dim {dim}, points "
                         f"of shape {points.shape}")
    n = len(points)
    for kind, table in (("cells", cells), ("groups", groups)):
        for name, idx in table.items():
            if idx.size and (idx.min() < 0 or idx.max() >= n):
                raise ValueError(f"{source}: field '{prefix}{kind}/{name}' refers to nodes outside 0..{n - 1}")
    ids = npz_array(data, f"{prefix}node_ids", source, 1, "int") if f"{prefix}node_ids" in data else None
    unit = npz_scalar(data, f"{prefix}unit", source, "str") if f"{prefix}unit" in data else "m"
    try:  # files written before node numbers and units were kept have neither: the 0-based index, metres
        return Mesh(points=points, cells=cells, dim=dim, groups=groups,
                    source=npz_scalar(data, f"{prefix}source", source, "str"), node_ids=ids, unit=unit)
    except ValueError as exc:
        raise ValueError(f"{source}: field '{prefix}node_ids' or '{prefix}unit': {exc}") from None
