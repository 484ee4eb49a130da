"""Checks of a mesh where it enters: the file itself (a regular, complete file; the reader its suffix and content
call for), the coordinates' extent and length unit, the cells' node references and body type, coincident
(unmerged) nodes, stray lower-dimensional cells — and, once a model is built, whether its mass and first frequency
are those of a blade (:func:`plausibility`).  Each check raises ``ValueError`` naming the file and what is wrong;
:mod:`bladecase.fe.mesh` calls them.
"""

from __future__ import annotations

import os
import stat
from contextlib import redirect_stderr, redirect_stdout
from io import StringIO

import numpy as np

from .. import log
from .cells import BODY_TYPES, BOUNDARY_TYPES, GMSH_WEDGE18, KINDS
from .cells import cell_dim as _cell_dim

__all__ = ["BLADE_F1_HZ", "BLADE_MASS_KG", "COINCIDENT_RTOL", "EXTENT_RANGE", "LENGTH_UNITS", "check_extent",
           "check_input_file", "plausibility", "thin_plate"]

#: Length units of a mesh file's coordinates (``[mesh] unit``) in metres: the points are scaled to metres when read.
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "in": 0.0254, "ft": 0.3048}

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


def _check_coincident(points: np.ndarray, body: np.ndarray, btype: str, source: str, ids=None) -> None:
    """Refuse distinct body nodes at the same place (an unmerged mesh): the cells on either side would not be
    connected, a crack that silently lowers the frequencies (or a loose part, reported only as a singular ``K``)."""
    from scipy.spatial import cKDTree

    used = np.unique(body)
    x = points[used]
    extent = float(np.ptp(x, axis=0).max()) if len(x) else 0.0
    pairs = cKDTree(x).query_pairs(COINCIDENT_RTOL * extent, output_type="ndarray") if extent > 0 else ()
    if len(pairs):
        a, b = (int(used[k]) for k in pairs[np.lexsort(pairs.T[::-1])][0])
        name = (lambda k: k) if ids is None else (lambda k: int(ids[k]))
        raise ValueError(f"mesh {source} has {len(pairs)} pair(s) of coincident nodes used by its {btype} cells "
                         f"(within {COINCIDENT_RTOL:g} x the extent); first: nodes {name(a)} and {name(b)} at "
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


#: Total mass (kg) a blade may plausibly have: from a tenth of a gram (the smallest compressor blades and test
#: specimens weigh about a gram) to a tonne (the heaviest turbine blades — last-stage steam, large fan — weigh tens of
#: kilograms).  A length-unit slip between millimetres and metres multiplies the mass by 1e9 (1e6 in 2-D), which
#: throws any blade of this range out of it.
BLADE_MASS_KG = (1e-4, 1e3)

#: First natural frequency (Hz) a blade may plausibly have: from 1 Hz (the longest metal blades bend at tens of Hz)
#: to 100 kHz (small compressor blades: a few kHz).  The millimetre/metre slip multiplies it by 1e-3 (or 1e3), a
#: modulus in MPa given as Pa by 1e-3.
BLADE_F1_HZ = (1.0, 1e5)


def plausibility(mass_kg: float, f1_hz: float | None = None, *, unit: str = "m", source: str = "mesh", dim: int = 3,
                 E: float | None = None) -> str | None:
    """A sentence when the total mass or the first frequency is far outside what a blade can be
    (:data:`BLADE_MASS_KG`, :data:`BLADE_F1_HZ`), naming the likely slip; ``None`` when both are plausible.

    ``unit``: the mesh's ``[mesh] unit``; ``source``: ``"mesh"`` (a mesh file) or ``"geometry"`` (a parametric
    blade); ``E``: the modulus (Pa), to recognise one given in MPa.

    >>> print(plausibility(1.2e8, 0.345))  # doctest: +NORMALIZE_WHITESPACE
    implausible for a blade: total mass 1.2e+08 kg (a blade weighs 0.0001 to 1000 kg), first frequency 0.345 Hz
    (a blade's is 1 to 100000 Hz): the mesh looks like millimetres: set [mesh] unit = "mm" (the mass would be
    0.12 kg, the first frequency 345 Hz)
    >>> plausibility(0.12, 345.0) is None
    True
    """
    (m_lo, m_hi), (f_lo, f_hi) = BLADE_MASS_KG, BLADE_F1_HZ
    heavy, light = mass_kg > m_hi, mass_kg < m_lo
    slow, fast = f1_hz is not None and f1_hz < f_lo, f1_hz is not None and f1_hz > f_hi
    if not (heavy or light or slow or fast):
        return None
    what = []
    if heavy or light:
        what.append(f"total mass {mass_kg:.3g} kg (a blade weighs {m_lo:g} to {m_hi:g} kg)")
    if slow or fast:
        what.append(f"first frequency {f1_hz:.3g} Hz (a blade's is {f_lo:g} to {f_hi:g} Hz)")
    return f"implausible for a blade: {', '.join(what)}: {_likely_slip(mass_kg, f1_hz, unit, source, dim, E)}"


def _likely_slip(mass: float, f1: float | None, unit: str, source: str, dim: int, E: float | None) -> str:
    """What most likely went wrong: the unit that would bring the mass (and the frequency) back, else what to check."""
    (m_lo, m_hi), (f_lo, f_hi) = BLADE_MASS_KG, BLADE_F1_HZ
    if not m_lo <= mass <= m_hi:
        given = LENGTH_UNITS.get(unit, 1.0)
        for name in ("mm", "m", "cm", "in", "ft"):
            if name == unit:
                continue
            r = LENGTH_UNITS[name] / given  # lengths scale by r
            m2, f2 = mass * r ** dim, (None if f1 is None else f1 / r)
            if m_lo <= m2 <= m_hi and (f2 is None or f_lo <= f2 <= f_hi):
                then = f"the mass would be {m2:.3g} kg" + ("" if f2 is None else f", the first frequency {f2:.3g} Hz")
                if source == "geometry":
                    return (f"the [geometry] lengths look like {_UNIT_WORDS[name]}: give them in metres (a 150 mm "
                            f"span is span = 0.15) ({then})")
                fix = 'leave [mesh] unit out (or unit = "m")' if name == "m" else f'set [mesh] unit = "{name}"'
                return f"the mesh looks like {_UNIT_WORDS[name]}: {fix} ({then})"
        what = "the [geometry] lengths (metres)" if source == "geometry" else "the mesh's length unit ([mesh] unit)"
        return f"check {what}, [fem] thickness in 2-D (metres), and [material] rho (kg/m³)"
    if E is not None and E < 1e7:
        return (f"[material] E = {E:g} Pa is a rubber's stiffness: a modulus in MPa? Give it in Pa (E = {E * 1e6:.4g}) "
                "with rho in kg/m³")
    return "check [material] E (Pa) and rho (kg/m³), and the clamp ([fem] clamp)"


def thin_plate(thickness: float, size: float) -> str | None:
    """A sentence when a plane-stress thickness (m) exceeds the plate's largest in-plane size (m): a thickness typed
    in millimetres as metres (the frequencies do not show it: thickness scales the stiffness and the mass alike).

    >>> print(thin_plate(2.0, 0.1))  # doctest: +NORMALIZE_WHITESPACE
    [fem] thickness = 2 m is more than the plate's largest in-plane size, 0.1 m: plane stress is for a thin plate;
    a thickness in millimetres? (2 mm is thickness = 0.002)
    """
    if thickness <= size:
        return None
    return (f"[fem] thickness = {thickness:g} m is more than the plate's largest in-plane size, {size:.3g} m: plane "
            f"stress is for a thin plate; a thickness in millimetres? ({thickness:g} mm is thickness = "
            f"{thickness * 1e-3:g})")


_UNIT_WORDS = {"m": "metres already", "mm": "millimetres", "cm": "centimetres", "in": "inches", "ft": "feet"}


class DeckError(ValueError):
    """A file that one of bladecase's own readers (Abaqus/CalculiX decks, ANSYS archives) cannot read; the message
    names the file and the line. The readers' errors derive from it, so that reading a mesh needs no import of the
    formats it tries."""

    #: raised as it is even when the study names the format (False: its message becomes that format's reason, told
    #: with the others')
    final_when_named = True


#: A format's sniffer (meshio format name → ``path -> bool``: the file's beginning is in that format), registered by
#: the format's reader module (``register()``) where it teaches meshio the format.
SNIFFERS: dict = {}


def _sniff(name: str, source: str) -> bool:
    return bool(SNIFFERS[name](source)) if name in SNIFFERS else False


#: ``file_format`` names that are not meshio's: the Abaqus/CalculiX deck reader (:mod:`bladecase.fe.abaqus`).
FORMAT_ALIASES = {"abaqus": "abaqus-deck", "calculix": "abaqus-deck", "inp": "abaqus-deck", "cdb": "ansys-cdb"}


def reader_formats(source: str, head: bytes, file_format: str | None) -> tuple[list, str]:
    """The meshio formats to try in order on ``source`` (``None``: from the suffix), and why (for the message when
    all fail): ``file_format`` (:data:`FORMAT_ALIASES` or a meshio name) if given; else ``.inp`` → the Abaqus deck
    reader; ``.msh`` → gmsh with a gmsh header, the Abaqus reader with Abaqus keyword lines (CalculiX), else gmsh
    then ANSYS; a suffix meshio does not know with Abaqus keyword lines → the Abaqus reader."""
    from meshio import _helpers

    if file_format is not None:
        name = FORMAT_ALIASES.get(file_format.lower(), file_format.lower())
        if name not in _helpers.reader_map:
            valid = sorted(set(_helpers.reader_map) | set(FORMAT_ALIASES))
            raise ValueError(f"unknown mesh format {file_format!r}; valid: {', '.join(valid)}")
        return [name], "as named"
    suffix = os.path.splitext(source)[1].lower()
    if suffix == ".inp":
        return ["abaqus-deck"], "from the suffix .inp"
    if suffix == ".msh":
        if head.startswith(b"$MeshFormat"):
            return ["gmsh"], "a gmsh header"
        if _sniff("abaqus-deck", source):
            return ["abaqus-deck"], "Abaqus keyword lines (*NODE, *ELEMENT) in a .msh file, as CalculiX writes"
        # ".msh" is also an ANSYS suffix: gmsh first, then ANSYS (not for a gmsh file).
        return ["gmsh", "ansys"], "the suffix .msh; no gmsh header, no Abaqus *NODE/*ELEMENT line"
    if suffix not in _helpers.extension_to_filetypes and _sniff("abaqus-deck", source):
        return ["abaqus-deck"], f"Abaqus keyword lines in a {suffix or 'suffix-less'} file"
    return [None], f"the suffix {suffix or '(none)'}"


#: meshio simplex cell types by topological dimension.
_SIMPLEX = {0: ("vertex",), 1: ("line", "line3"), 2: ("triangle", "triangle6"), 3: ("tetra", "tetra10")}


def _body_type(blocks, present: set, source: str) -> tuple[str, int]:
    """``(body cell type, dimension)``: the one accepted cell type of the highest dimension; ``ValueError``
    naming the counts when that dimension has several cell types, or none that a model accepts."""
    dim = max((d for d in (3, 2) if any(_cell_dim(t) == d for t in present)), default=0)
    body_types = sorted(t for t in present if _cell_dim(t) == dim)
    if not body_types or not set(body_types) & set(BODY_TYPES[dim]):
        found = ", ".join(sorted(present)) or "none"
        raise ValueError(f"mesh {source} has no volume cells ({', '.join(BODY_TYPES[3])}) nor planar cells "
                         f"({', '.join(BODY_TYPES[2])}); cell types: {found}")
    if len(body_types) == 1:
        return body_types[0], dim
    if len({KINDS[t].family if t in KINDS else t for t in body_types}) == 1:
        raise ValueError(f"mesh {source} mixes element orders ({', '.join(body_types)}); use one order")
    counts = ", ".join(f"{sum(len(c) for tt, c in blocks if tt == t)} {t}" for t in body_types)
    simplex = [t for t in body_types if t in _SIMPLEX[dim]]
    other = [t for t in body_types if t not in _SIMPLEX[dim]]
    what = (f"non-simplex {dim}-D cells ({', '.join(other)}) beside {', '.join(simplex)} cells" if simplex
            else f"{dim}-D cell types")
    unknown = [t for t in body_types if t not in KINDS]
    note = f"; {', '.join(unknown)} cells have no scikit-fem element" if unknown else ""
    valid = "; ".join(" or ".join(t for t in BODY_TYPES[dim] if KINDS[t].family == f)
                      for f in dict.fromkeys(KINDS[t].family for t in BODY_TYPES[dim]))
    raise ValueError(f"mesh {source} mixes {what} ({counts} cells){note}: a model has one body cell type "
                     f"(scikit-fem assembles one per mesh); valid bodies: {valid}. Remesh with one type (e.g. "
                     f"split the cells into tetrahedra), or export each part separately")


def _wedge18_in_vtk_order(points: np.ndarray, body: np.ndarray, source: str) -> np.ndarray:
    """18-node wedges in VTK order: gmsh's order (which meshio 5.3 keeps) is recognised by its midside nodes
    sitting on other edges, and permuted."""
    parents = KINDS["wedge18"].parents[6:15]

    def misfit(cells):
        mids = np.stack([points[cells[:, list(p)]].mean(axis=1) for p in parents], axis=1)
        return float(np.abs(points[cells[:, 6:15]] - mids).sum())

    gmsh = body[:, list(GMSH_WEDGE18)]
    if misfit(gmsh) < misfit(body):
        log.info("mesh %s: 18-node wedges in gmsh node order, put in VTK order", source)
        return gmsh
    return body


def _read_quietly(meshio, path, file_format):
    """``(meshio.Mesh, None)`` or ``(None, reason)``; meshio's prints and ``sys.exit`` are captured."""
    out = StringIO()
    try:
        with redirect_stdout(out), redirect_stderr(out):
            return meshio.read(path, file_format=file_format), None
    except (Exception, SystemExit) as exc:  # meshio raises ReadError, KeyError, …, or exits
        said = " ".join(out.getvalue().split())
        if isinstance(exc, DeckError) and (exc.final_when_named or file_format is None):
            raise type(exc)(str(exc)) from None  # names the file, the line and the field already
        text = ("" if isinstance(exc, SystemExit) else str(exc) if isinstance(exc, DeckError)  # names file and line
                else _nastran_reason(exc) if _is_nastran(path, file_format) and isinstance(exc, KeyError)
                else f"{type(exc).__name__}: {exc}".rstrip(": "))
        return None, " ".join(filter(None, [text, said])) or type(exc).__name__


def _is_nastran(path, file_format) -> bool:
    return file_format == "nastran" or (file_format is None and str(path).lower().endswith((".bdf", ".fem", ".nas")))


def _nastran_reason(exc: KeyError) -> str:
    """meshio's ``KeyError`` of a Nastran deck: an element names a GRID the deck does not define."""
    grid = exc.args[0] if exc.args else "?"
    return (f"an element names GRID {grid}, which the deck does not define (every node of an element needs its GRID "
            "card; an INCLUDE with the GRIDs is not read)")
