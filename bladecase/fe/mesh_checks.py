"""Checks of a mesh where it enters: the file itself (a regular, complete file), the coordinates' extent, the
cells' node references, coincident (unmerged) nodes, stray lower-dimensional cells.  Each raises
``ValueError`` naming the file and what is wrong; :mod:`bladecase.fe.mesh` calls them.
"""

from __future__ import annotations

import os
import stat

import numpy as np

from .cells import BOUNDARY_TYPES

__all__ = ["COINCIDENT_RTOL", "EXTENT_RANGE", "check_extent", "check_input_file"]

#: Accepted bounding-box extent of a mesh (its largest side), in metres with the SI material presets: 1 µm to
#: 10 km.  A turbomachine blade is millimetres to a metre or two, so this leaves room for any part and for meshes
#: in millimetres, while catching the unit mistakes and corrupt files that make the pipeline fail obscurely: far
#: outside, the matrices over- or underflow (``K ~ E·L``, ``M ~ ρ·L³``; L = 1e±150 gives inf or 0, reported by
#: ARPACK as internals) and the relative tolerances of the pipeline (node matching at 1e-9 of the extent,
#: eigenvalues ``ω² ~ E/(ρL²)``) lose their meaning.
EXTENT_RANGE = (1e-6, 1e4)

#: Largest accepted ``|coordinate|`` as a multiple of ``EXTENT_RANGE[1]``: a part far from the origin loses the
#: digits of its small features (double precision: 1e-16 of the offset).
_OFFSET_FACTOR = 10.0

def check_extent(points: np.ndarray, source: str) -> float:
    """The bounding-box extent (largest side) of ``points``; ``ValueError`` naming ``source`` unless the
    coordinates are finite, the extent is within :data:`EXTENT_RANGE` and no coordinate is beyond
    ``10 × EXTENT_RANGE[1]``.

    >>> check_extent(np.array([[0.0, 0, 0], [0.1, 0.02, 0]]), "plate")
    0.1
    >>> check_extent(np.array([[0.0, 0, 0], [1e150, 2e149, 0]]), "plate")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    ValueError: mesh plate is 1e+150 across (bounding box 1e+150 x 2e+149 x 0): its extent must be between 1e-06 ...
    """
    points = np.asarray(points, dtype=float)
    if not np.all(np.isfinite(points)):
        bad = int((~np.isfinite(points)).reshape(len(points), -1).any(axis=1).sum())
        raise ValueError(f"mesh {source} has {bad} point(s) with non-finite coordinates (inf or NaN)")
    sides = np.ptp(points, axis=0) if len(points) else np.zeros(3)
    extent = float(sides.max(initial=0.0))
    lo, hi = EXTENT_RANGE
    box = " x ".join(f"{d:.3g}" for d in sides)
    if extent == 0.0:
        raise ValueError(f"mesh {source}: all its {len(points)} points coincide (bounding box {box}): "
                         "a degenerate mesh (coordinates lost or all zero?)")
    if not lo <= extent <= hi:
        raise ValueError(f"mesh {source} is {extent:.3g} across (bounding box {box}): its extent must be between "
                         f"{lo:g} and {hi:g} (metres, with SI material constants): a unit mistake, or corrupt "
                         "coordinates?")
    far = float(np.abs(points).max())
    if far > _OFFSET_FACTOR * hi:
        raise ValueError(f"mesh {source} has a coordinate {far:.3g} far from the origin (at most "
                         f"{_OFFSET_FACTOR * hi:g}, for an extent of {extent:.3g}): double precision loses its small "
                         "features; move it near the origin")
    return extent


def check_input_file(path, what: str = "mesh file") -> str:
    """``path`` as a string if it is an existing, non-empty regular file; ``ValueError`` otherwise.

    A pipe, a device (``/dev/zero``) or a socket would make the readers hang or read forever: they are refused
    before anything opens them.
    """
    try:
        source = os.fspath(path)
    except TypeError:
        raise ValueError(f"{what} must be a path, got {type(path).__name__}") from None
    try:
        st = os.stat(source)
    except FileNotFoundError:
        raise ValueError(f"cannot read {what} {source!r}: not found (no such file)") from None
    except (OSError, ValueError) as exc:  # ValueError: an embedded NUL
        from ..io import os_reason

        reason = os_reason(exc) if isinstance(exc, OSError) else str(exc)
        raise ValueError(f"cannot read {what} {source!r}: {reason}") from None
    if stat.S_ISDIR(st.st_mode):
        raise ValueError(f"{what} {source!r} is a folder, not a file")
    if not stat.S_ISREG(st.st_mode):
        raise ValueError(f"{what} {source!r} is not a regular file (a pipe, device or socket): give a file on disk")
    if st.st_size == 0:
        raise ValueError(f"{what} {source!r} is empty (0 bytes)")
    if not os.access(source, os.R_OK):
        raise ValueError(f"cannot read {what} {source!r}: permission denied")
    return source


#: Text formats without an end marker: a file that does not end with a line break was cut.
_LINE_FORMATS = (".inp", ".cdb", ".bdf", ".nas", ".fem")


def _check_complete(source: str) -> bytes:
    """Refuse a file cut short where its format shows it (an XML VTK file not closed, a gmsh file not ending with
    an ``$End…`` line, a text format without its final line break); return the file's first bytes."""
    with open(source, "rb") as fh:
        head = fh.read(256)
        size = fh.seek(0, os.SEEK_END)
        fh.seek(max(0, size - 4096))
        tail = fh.read()
    end = tail.rstrip(b" \t\r\n\x00")
    last_bytes = end.rsplit(b"\n", 1)[-1][-60:]
    last = last_bytes.decode("ascii") if last_bytes.isascii() and last_bytes.decode("ascii").isprintable() \
        else "binary data"
    cut = f"mesh file {source!r} is truncated or corrupt"
    if head.lstrip().startswith(b"<?xml") or b"<VTKFile" in head:
        if not end.endswith(b"</VTKFile>"):
            raise ValueError(f"{cut}: an XML VTK file ends with its closing tag </VTKFile>, this one ends "
                             f"after {size} bytes with {last!r}")
    elif head.startswith(b"$MeshFormat"):
        if not last.startswith("$End"):
            raise ValueError(f"{cut}: a gmsh file ends with a section's closing line ($EndElements, …), this one "
                             f"ends after {size} bytes with {last!r}")
    elif source.lower().endswith(_LINE_FORMATS) and not tail.endswith((b"\n", b"\r")):
        raise ValueError(f"{cut}: it does not end with a line break (its last line: {last!r}); if the file is "
                         "complete, end it with a line break")
    return head


def _check_blocks(blocks, n_points: int, source: str) -> None:
    """Every cell block an integer array of one row per cell, its node indices within ``0..n_points - 1``
    (a corrupt or truncated file gives cells that refer to missing points)."""
    for t, data in blocks:
        if not len(data):
            continue
        if data.ndim != 2 or data.dtype.kind not in "iu":
            raise ValueError(f"mesh {source}: its {t} cells are not a table of node indices (array of shape "
                             f"{data.shape}, dtype {data.dtype}): a corrupt file?")
        lo, hi = int(data.min()), int(data.max())
        if lo < 0 or hi >= n_points:
            bad = lo if lo < 0 else hi
            row = int(np.flatnonzero((data < 0).any(axis=1) | (data >= n_points).any(axis=1))[0])
            raise ValueError(f"mesh {source}: {t} cell {row} refers to node {bad}, but the file has {n_points} "
                             f"points (0..{n_points - 1}): a truncated or corrupt file?")


#: Nodes of the body closer than this fraction of the mesh extent are coincident (:func:`_check_coincident`).
COINCIDENT_RTOL = 1e-10


def _check_coincident(points: np.ndarray, body: np.ndarray, btype: str, source: str) -> None:
    """Refuse distinct body nodes at the same place (an unmerged mesh): the cells on either side would not be
    connected, a crack that silently lowers the frequencies (or a loose part, reported only as a singular ``K``)."""
    from scipy.spatial import cKDTree

    used = np.unique(body)
    x = points[used]
    extent = float(np.ptp(x, axis=0).max()) if len(x) else 0.0
    pairs = cKDTree(x).query_pairs(COINCIDENT_RTOL * extent, output_type="ndarray") if extent > 0 else ()
    if len(pairs):
        a, b = (int(used[k]) for k in pairs[np.lexsort(pairs.T[::-1])][0])
        raise ValueError(f"mesh {source} has {len(pairs)} pair(s) of coincident nodes used by its {btype} cells "
                         f"(within {COINCIDENT_RTOL:g} x the extent); first: nodes {a} and {b} at "
                         f"{points[a].tolist()}: the cells on either side are not connected (an unmerged mesh: "
                         "merge duplicate nodes, e.g. gmsh's Coherence, before exporting)")


def _check_one_body(blocks, body: np.ndarray, btype: str, dim: int, source: str) -> None:
    """Refuse lower-dimensional cells off the body (e.g. 988 triangles beside one stray tetrahedron).

    The faces and edges of a mesh (physical groups) lie on its body's nodes; cells that use other nodes
    are a second body of lower dimension, which the model would silently drop.
    """
    on_body = np.zeros(int(body.max()) + 1, dtype=bool)
    on_body[body.ravel()] = True
    stray: dict[str, tuple[int, int]] = {}
    for d in range(1, dim):
        for t in BOUNDARY_TYPES[d]:
            data = [np.asarray(c, dtype=np.int64) for tt, c in blocks if tt == t and len(c)]
            if not data:
                continue
            cells = np.concatenate(data)
            inside = cells < on_body.size
            off = ~(inside & on_body[np.where(inside, cells, 0)])
            bad = off.any(axis=1)
            if bad.any():
                stray[t] = (int(bad.sum()), int(np.unique(cells[off]).size))
    if stray:
        what = ", ".join(f"{n} {t} cell(s) ({k} node(s) no {btype} uses)" for t, (n, k) in stray.items())
        raise ValueError(f"mesh {source} mixes dimensions: {len(body)} {btype} cell(s) form the {dim}-D body, and "
                         f"{what} lie off it: a model has one body of one dimension; remove the stray cells of "
                         f"one dimension (e.g. export only the {dim}-D region, or only the planar one)")
