"""VTK results for ParaView: a periodic orbit on the mesh, and the invariant manifold of a nonsmooth mode.

* :func:`write_time_series` — one ``.vtu`` per frame (reference mesh, body
  cells, ``displacement``/``velocity`` point data, the groups as masks) and a
  ParaView ``.pvd`` collection that indexes them by time::

      directory/stem.pvd
      directory/stem/stem_0000.vtu
      directory/stem/stem_0001.vtu
      …

  Open ``stem.pvd`` in ParaView, apply *Warp By Vector* (``displacement``)
  and press *Play*.  :func:`read_time_series` lists the frames of a ``.pvd``.
* :func:`write_manifold` — the samples of an invariant manifold (one row of
  points per orbit, one column per phase) as a quad surface.

Every file is written atomically: a reader, or a crash, never sees a
half-written result (frames go to a temporary folder renamed into place, the
``.pvd`` is renamed into place last).

The frames are written by VTK's XML writer (``pyvista.UnstructuredGrid.save``,
binary, zlib-compressed), which writes point data and field data alike; the
manifold by meshio.  The ``.pvd`` is a short XML text written here.  To show
the field of a model at all its nodes, on its curved cells, write it on
:func:`bladecase.post.grid.fe_grid` (quadratic cells whole: ``tetra10``,
``hexahedron20``/``27``, ``wedge15``/``18``, ``triangle6``, ``quad8``/``9``, the
points and cells of ``mesh.vtu``) with :func:`bladecase.post.grid.nodal_field`.
"""

from __future__ import annotations

import os
import shutil
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from ..fe.mesh import GROUP_PREFIX, Mesh
from ..io import atomic_path, replace_dir
from .grid import vtk_cells

#: Point-data names :func:`write_time_series` writes itself (plus ``group:<name>``).
TIME_SERIES_ARRAYS = ("displacement", "velocity", "displacement_magnitude")

#: Point-data names :func:`write_manifold` writes itself.
MANIFOLD_ARRAYS = ("orbit", "phase_index")

#: dtypes the ``.vtu`` writers accept as they are.
_VTU_DTYPES = frozenset(
    np.dtype(t) for t in (np.float32, np.float64, np.int8, np.int16, np.int32, np.int64,
                          np.uint8, np.uint16, np.uint32, np.uint64)
)


# ----------------------------------------------------------------------------- time series


def write_time_series(
    directory: str | os.PathLike,
    stem: str,
    mesh: Mesh,
    times: np.ndarray,
    u: np.ndarray,
    v: np.ndarray,
    *,
    point_data: dict[str, np.ndarray] | None = None,
    field_data: dict[str, float] | None = None,
    frame_data: dict[str, np.ndarray] | None = None,
) -> Path:
    """Write a time series of fields on ``mesh`` as a ParaView ``.pvd`` collection of ``.vtu`` frames.

    Parameters
    ----------
    directory : path-like
        Output folder (created if missing).
    stem : str
        Plain file name (no path separator): the collection is
        ``directory/stem.pvd``, the frames ``directory/stem/stem_0000.vtu`` …
    mesh : Mesh
        The reference configuration; only its body cells (``mesh.body_type``,
        any type of :data:`~bladecase.post.grid.VTK_CELL_TYPES`: tetrahedra, hexahedra, wedges,
        triangles, quadrilaterals, of first or second order) are written,
        quadratic cells with all their nodes (e.g. the grid of
        :func:`bladecase.post.grid.fe_grid`).
    times : (F,) array_like
        Time of each frame (s), finite and non-decreasing, ``F >= 1``.
    u, v : (n_nodes, mesh.dim, F) array_like
        Displacements and velocities of the nodes, finite.
    point_data : dict[str, array_like], optional
        Extra per-node arrays, constant in time, ``(n_nodes,)`` or
        ``(n_nodes, c)`` (e.g. a mode shape, the contact node mask).
    field_data : dict[str, float], optional
        Finite real scalars recorded in every frame (e.g. ``period``,
        ``energy``).
    frame_data : dict[str, array_like], optional
        Extra per-node scalars that change from frame to frame,
        ``(n_nodes, F)`` (e.g. each contact node's gap to the casing and
        its contact pressure; NaN where a node has none).

    Returns
    -------
    Path
        The ``.pvd`` file.

    Notes
    -----
    Each frame holds the reference points ``(n_nodes, 3)``, the body cells
    (quadratic cells as quadratic VTK cells, :func:`~bladecase.post.grid.vtk_cells`), the point data
    ``displacement`` and ``velocity`` (``(n_nodes, 3)``: planar fields get a
    zero ``z`` component, so ParaView's *Warp By Vector* works),
    ``displacement_magnitude``, the extra ``point_data``, each group as a
    ``uint8`` mask ``group:<name>`` (as :func:`bladecase.save_mesh`), and
    the field data ``time`` and ``field_data`` (one-tuple arrays).

    The frames are written into a temporary folder beside the target which is
    then renamed to ``directory/stem`` (an older ``directory/stem`` folder is
    moved aside, then deleted); the ``.pvd`` is renamed into place last.  On
    any error nothing new is left behind and a previous complete result is
    kept.

    Raises
    ------
    ValueError
        A bad ``stem``, inconsistent shapes, non-finite values, decreasing
        times, bad ``point_data``/``field_data``; the message names the
        argument and what is valid.

    Examples
    --------
    One quadratic triangle moving rigidly along ``x``, three frames:

    >>> import tempfile
    >>> import numpy as np
    >>> from bladecase.fe import Mesh
    >>> from bladecase.post.vtk import read_time_series, write_time_series
    >>> tri6 = Mesh(points=np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [.5, 0, 0], [.5, .5, 0], [0, .5, 0]]),
    ...             cells={"triangle6": np.array([[0, 1, 2, 3, 4, 5]])}, dim=2)
    >>> t = np.array([0.0, 0.5, 1.0])
    >>> u = np.zeros((6, 2, 3)); u[:, 0] = np.sin(t)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     pvd = write_time_series(folder, "orbit", tri6, t, u, np.zeros_like(u), field_data={"period": 1.0})
    ...     times, files = read_time_series(pvd)
    ...     names = [f.name for f in files]
    >>> pvd.name, times.tolist(), names
    ('orbit.pvd', [0.0, 0.5, 1.0], ['orbit_0000.vtu', 'orbit_0001.vtu', 'orbit_0002.vtu'])
    """
    stem = _check_stem(stem)
    directory = Path(directory)
    body_type = mesh.body_type
    body = np.asarray(mesh.cells[body_type], dtype=np.int64)
    points = np.ascontiguousarray(mesh.points, dtype=float)
    n_nodes, dim = len(points), mesh.dim
    times = _check_times(times)
    n_frames = len(times)
    u = _check_field("u", u, (n_nodes, dim, n_frames))
    v = _check_field("v", v, (n_nodes, dim, n_frames))
    extra = _check_point_data(point_data, (n_nodes,), "(n_nodes,) or (n_nodes, c)", TIME_SERIES_ARRAYS,
                              reserved_prefix=GROUP_PREFIX)
    scalars = _check_field_data(field_data)
    varying = _check_point_data(frame_data, (n_nodes, n_frames), "(n_nodes, n_frames)", TIME_SERIES_ARRAYS
                                + tuple(extra), reserved_prefix=GROUP_PREFIX)
    varying = {name: np.asarray(a, dtype=float) for name, a in varying.items()}
    target = directory / stem
    if target.exists() and not target.is_dir():
        raise ValueError(f"cannot write the frames of stem {stem!r}: {target} exists and is not a folder")

    constant = dict(extra)
    for name, nodes in mesh.groups.items():
        mask = np.zeros(n_nodes, dtype=np.uint8)
        mask[np.asarray(nodes, dtype=np.int64)] = 1
        constant[GROUP_PREFIX + name] = mask
    width = max(4, len(str(n_frames - 1)))
    names = [f"{stem}_{j:0{width}d}.vtu" for j in range(n_frames)]
    grid = _vtk_grid(points, body_type, body)

    directory.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{stem}.tmp-", dir=directory))
    try:
        for j in range(n_frames):
            disp = np.zeros((n_nodes, 3))
            vel = np.zeros((n_nodes, 3))
            disp[:, :dim] = u[:, :, j]
            vel[:, :dim] = v[:, :, j]
            grid.point_data.clear()
            grid.field_data.clear()
            for name, a in {"displacement": disp, "velocity": vel,
                            "displacement_magnitude": np.sqrt(np.einsum("ij,ij->i", disp, disp)), **constant,
                            **{name: a[:, j] for name, a in varying.items()}}.items():
                grid.point_data[name] = a
            for name, x in {"time": float(times[j]), **scalars}.items():
                grid.field_data[name] = np.array([x], dtype=np.int64 if isinstance(x, int) else float)
            _save(grid, tmp / names[j])
        _make_ordinary(tmp)
        pvd = directory / f"{stem}.pvd"
        text = _pvd_text(times, [f"{stem}/{name}" for name in names])
        with atomic_path(pvd) as pvd_tmp:
            pvd_tmp.write_text(text, encoding="utf-8")
            replace_dir(tmp, target)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return pvd


def _vtk_grid(points: np.ndarray, body_type: str, body: np.ndarray):
    """A ``pyvista.UnstructuredGrid`` of the body cells as ``mesh.vtu`` holds them (meshio cell type -> VTK cell
    type and node order, :func:`~bladecase.post.grid.vtk_cells`)."""
    import pyvista as pv

    name, cells = vtk_cells(body_type, body)
    return pv.UnstructuredGrid({pv.CellType[name]: cells}, points)


def _save(grid, path: Path) -> None:
    """Write ``grid`` as a binary ``.vtu`` (VTK's XML writer through pyvista); ``OSError`` if nothing was written."""
    grid.save(path, binary=True)
    if not path.is_file() or path.stat().st_size == 0:
        raise OSError(f"the VTK writer wrote nothing to {path}")


def read_time_series(pvd: str | os.PathLike) -> tuple[np.ndarray, list[Path]]:
    """The times and frame files of a ParaView ``.pvd`` collection.

    Parameters
    ----------
    pvd : path-like
        A ``.pvd`` file (e.g. from :func:`write_time_series`).

    Returns
    -------
    times : (F,) ndarray
        The ``timestep`` of each ``DataSet``, in file order.
    files : list of Path
        The ``file`` of each ``DataSet``, resolved against the folder of
        ``pvd`` (whether they exist is not checked).

    Raises
    ------
    ValueError
        Not an XML ``VTKFile`` of type ``Collection``, or a ``DataSet``
        without ``file`` or with a non-numeric ``timestep``.
    """
    pvd = Path(pvd)
    try:
        root = ET.parse(pvd).getroot()
    except ET.ParseError as exc:
        raise ValueError(f"{pvd} is not a valid .pvd file (XML error: {exc})") from None
    collection = root.find("Collection")
    if root.tag != "VTKFile" or root.get("type") != "Collection" or collection is None:
        raise ValueError(f"{pvd} is not a .pvd file (expected <VTKFile type=\"Collection\"><Collection>…)")
    times, files = [], []
    for k, item in enumerate(collection.iter("DataSet")):
        if "file" not in item.attrib:
            raise ValueError(f"{pvd}: DataSet {k} has no 'file' attribute")
        try:
            times.append(float(item.get("timestep", "0")))
        except ValueError:
            raise ValueError(f"{pvd}: DataSet {k} has a non-numeric timestep {item.get('timestep')!r}") from None
        files.append((pvd.parent / item.get("file")).resolve())
    return np.array(times, dtype=float), files


def _pvd_text(times: np.ndarray, files: list[str]) -> str:
    rows = "".join(
        f'    <DataSet timestep="{float(t)!r}" group="" part="0" file={quoteattr(f)}/>\n'
        for t, f in zip(times.tolist(), files)
    )
    return (
        '<?xml version="1.0"?>\n'
        '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
        f"  <Collection>\n{rows}  </Collection>\n"
        "</VTKFile>\n"
    )


def _make_ordinary(folder: Path) -> None:
    """``mkdtemp`` makes 0700 folders; results are ordinary folders (umask permissions)."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(folder, 0o777 & ~umask)


# ----------------------------------------------------------------------------- manifold


def write_manifold(
    path: str | os.PathLike,
    coords: np.ndarray,
    *,
    point_data: dict[str, np.ndarray] | None = None,
    closed: bool = True,
) -> Path:
    """Write the samples of an invariant manifold as a quad surface (``.vtu``).

    Parameters
    ----------
    path : path-like
        Output ``.vtu`` file (folders created if missing), written atomically.
    coords : (n_orbits, n_times, 3) array_like
        Point coordinates of the samples (a projection chosen by the caller):
        row ``i`` is orbit ``i`` of the family, column ``j`` its ``j``-th
        phase.  ``n_orbits >= 2``, ``n_times >= 2``, finite.
    point_data : dict[str, array_like], optional
        Arrays ``(n_orbits, n_times)`` or ``(n_orbits, n_times, c)``
        (e.g. energy, frequency, a velocity).
    closed : bool
        The phases wrap around: quads also join the last phase to the first.

    Returns
    -------
    Path
        ``path``.

    Notes
    -----
    Point ``i * n_times + j`` is ``coords[i, j]``.  Quad ``(i, j)`` has the
    points ``(i, j), (i+1, j), (i+1, j+1), (i, j+1)`` (``j+1`` taken modulo
    ``n_times`` when closed): ``(n_orbits-1) * n_times`` quads when closed,
    ``(n_orbits-1) * (n_times-1)`` otherwise.  Besides ``point_data`` (flattened
    the same way, components kept) the file has the ``int32`` point data
    ``orbit`` (``i``) and ``phase_index`` (``j``).

    Raises
    ------
    ValueError
        A suffix other than ``.vtu``, a bad ``coords`` shape or non-finite
        coordinates, bad ``point_data``.
    """
    import meshio

    path = Path(path)
    if path.suffix.lower() != ".vtu":
        raise ValueError(f"write_manifold writes .vtu files; path {str(path)!r} has suffix {path.suffix or '(none)'!r}")
    coords = _as_real("coords", coords)
    if coords.ndim != 3 or coords.shape[2] != 3 or coords.shape[0] < 2 or coords.shape[1] < 2:
        raise ValueError(
            f"coords must have shape (n_orbits, n_times, 3) with n_orbits >= 2 and n_times >= 2; got {coords.shape}"
        )
    _check_finite("coords", coords, ("orbit", "phase", "component"))
    n_orbits, n_times = coords.shape[:2]
    data = {
        name: a.reshape(n_orbits * n_times, *a.shape[2:])
        for name, a in _check_point_data(
            point_data, (n_orbits, n_times), "(n_orbits, n_times) or (n_orbits, n_times, c)", MANIFOLD_ARRAYS
        ).items()
    }
    orbit, phase = np.meshgrid(np.arange(n_orbits, dtype=np.int32), np.arange(n_times, dtype=np.int32), indexing="ij")
    data["orbit"] = orbit.ravel()
    data["phase_index"] = phase.ravel()
    out = meshio.Mesh(coords.reshape(-1, 3), [("quad", manifold_quads(n_orbits, n_times, closed))], point_data=data)
    with atomic_path(path) as tmp:
        meshio.write(tmp, out, file_format="vtu")
    return path


def manifold_quads(n_orbits: int, n_times: int, closed: bool = True) -> np.ndarray:
    """Quad connectivity of an ``n_orbits × n_times`` grid of points (see :func:`write_manifold`).

    Returns
    -------
    (n_quads, 4) int64 ndarray
        Rows ``[(i, j), (i+1, j), (i+1, j'), (i, j')]`` with point ``(i, j)``
        numbered ``i * n_times + j`` and ``j' = j + 1`` (modulo ``n_times``
        when ``closed``), orbit-major.
    """
    i = np.arange(n_orbits - 1)[:, None]
    j = np.arange(n_times if closed else n_times - 1)[None, :]
    jn = (j + 1) % n_times
    a, b = i * n_times, (i + 1) * n_times
    quads = np.stack(np.broadcast_arrays(a + j, b + j, b + jn, a + jn), axis=-1)
    return quads.reshape(-1, 4).astype(np.int64)


# ----------------------------------------------------------------------------- checks


def _check_stem(stem) -> str:
    bad = (
        not isinstance(stem, str)
        or stem in ("", ".", "..")
        or any(c in stem for c in ("/", "\\", "\0"))
        or any(s and s in stem for s in (os.sep, os.altsep))
    )
    if bad:
        raise ValueError(f"stem must be a plain, non-empty file name without path separators; got {stem!r}")
    return stem


def _as_real(name: str, a) -> np.ndarray:
    a = np.asarray(a)
    if a.dtype.kind not in "biuf":
        raise ValueError(f"{name} must be a real numeric array; got dtype {a.dtype}")
    return a.astype(float, copy=False)


def _check_finite(name: str, a: np.ndarray, axes: tuple[str, ...]) -> None:
    finite = np.isfinite(a)
    if not finite.all():
        first = np.unravel_index(int(np.argmin(finite)), a.shape)
        where = ", ".join(f"{ax} {k}" for ax, k in zip(axes, first))
        raise ValueError(
            f"{name} must be finite; it has {int(a.size - finite.sum())} non-finite value(s), first at {where}"
        )


def _check_times(times) -> np.ndarray:
    times = _as_real("times", times)
    if times.ndim != 1 or len(times) < 1:
        raise ValueError(f"times must be a 1-D array of F >= 1 frame times; got shape {times.shape}")
    _check_finite("times", times, ("frame",))
    down = np.flatnonzero(np.diff(times) < 0)
    if len(down):
        j = int(down[0])
        raise ValueError(
            f"times must be non-decreasing; times[{j + 1}] = {times[j + 1]!r} < times[{j}] = {times[j]!r}"
        )
    return times


def _check_field(name: str, a, shape: tuple[int, int, int]) -> np.ndarray:
    a = _as_real(name, a)
    if a.shape != shape:
        raise ValueError(
            f"{name} must have shape (n_nodes, mesh.dim, F) = {shape} (nodes of the mesh, its dimension, "
            f"len(times)); got {a.shape}"
        )
    _check_finite(name, a, ("node", "component", "frame"))
    return a


def _check_point_data(
    point_data, lead: tuple[int, ...], valid: str, reserved: tuple[str, ...], reserved_prefix: str | None = None
) -> dict[str, np.ndarray]:
    """Validated copies of extra point-data arrays, with dtypes the ``.vtu`` writer takes."""
    out = {}
    for name, a in (point_data or {}).items():
        if not isinstance(name, str) or not name:
            raise ValueError(f"point_data names must be non-empty strings; got {name!r}")
        if name in reserved or (reserved_prefix and name.startswith(reserved_prefix)):
            taken = ", ".join(reserved) + (f", {reserved_prefix}<name>" if reserved_prefix else "")
            raise ValueError(f"point_data name {name!r} is reserved (written by bladecase: {taken})")
        a = np.asarray(a)
        if a.shape[: len(lead)] != lead or a.ndim not in (len(lead), len(lead) + 1) or 0 in a.shape:
            raise ValueError(f"point_data[{name!r}] must have shape {valid} with {lead}; got {a.shape}")
        if a.dtype == bool:
            a = a.astype(np.uint8)
        elif a.dtype not in _VTU_DTYPES:
            if a.dtype.kind in "iu":
                a = a.astype(np.int64)
            elif a.dtype.kind == "f":
                a = a.astype(float)
            else:
                raise ValueError(f"point_data[{name!r}] must be real numbers or booleans; got dtype {a.dtype}")
        out[name] = np.ascontiguousarray(a)
    return out


def _check_field_data(field_data) -> dict[str, float | int]:
    out: dict[str, float | int] = {}
    for name, x in (field_data or {}).items():
        if not isinstance(name, str) or not name:
            raise ValueError(f"field_data names must be non-empty strings; got {name!r}")
        if name == "time":
            raise ValueError("field_data name 'time' is reserved (the frame's time is written by bladecase)")
        a = np.asarray(x)
        if a.ndim != 0 or a.dtype.kind not in "biuf" or not np.isfinite(a):
            raise ValueError(f"field_data[{name!r}] must be a finite real scalar; got {x!r}")
        out[name] = int(a) if a.dtype.kind in "biu" else float(a)
    return out
