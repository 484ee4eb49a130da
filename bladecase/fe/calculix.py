"""The FE model as a CalculiX deck, and CalculiX's frequencies back: check bladecase against an independent code.

:func:`calculix_deck` writes what :func:`~bladecase.fe.assemble` built — the mesh's nodes and body elements (the
element of the same order: ``C3D10`` for ``tetra10``, ``C3D20`` for ``hexahedron20``, ``CPS6``/``CPE6`` for a
plane model's ``triangle6``, …), the material, the clamped nodes (``*BOUNDARY``), and a ``*FREQUENCY`` step,
optionally after a ``*STATIC`` step under the centrifugal load of a rotation (``*DLOAD … CENTRIF``, then the
frequencies as a ``PERTURBATION`` of that state) — in SI units or in millimetres (N, mm, t, s: the usual units of
industrial decks). :func:`run_calculix` runs ``ccx`` on it and :func:`calculix_frequencies` reads the
frequencies from its ``.dat`` file.

What to expect: the same mesh and element give the same frequencies to the integration rule's difference
(CalculiX integrates ``C3D10`` with 4 points, bladecase with more: about ``4e-5`` on a 60k-dof blade; the same
rule agrees to CalculiX's printed digits; ``C3D20`` agrees to them as it is). CalculiX integrates the mass of
linear tetrahedra differently (0.6 % on coarse cells) and expands plane elements into a layer of 3-D elements
(about 1 % on a coarse plate): compare quadratic solids. Spinning, CalculiX's linear ``*STATIC`` step has no
spin softening: the frequencies differ by a few ``1e-4`` at speeds that double ``f1``; ``nlgeom=True`` is its
large-rotation static state.

>>> from skfem import MeshTet
>>> from bladecase.fe import Mesh, assemble
>>> t = MeshTet.init_tensor(np.linspace(0, 0.1, 6), np.linspace(0, 0.01, 2), np.linspace(0, 0.01, 2))
>>> bar = Mesh(t.p.T, {"tetra": t.t.T}, dim=3, groups={"root": np.flatnonzero(t.p[0] == 0)})
>>> deck = calculix_deck(assemble(bar, "steel", order=1), count=4, unit="mm")
>>> [line for line in deck.splitlines() if line.startswith("*")]  # doctest: +NORMALIZE_WHITESPACE
['*HEADING', '*NODE', '*ELEMENT, TYPE=C3D4, ELSET=EALL', '*NSET, NSET=CLAMPED', '*MATERIAL, NAME=STEEL',
 '*ELASTIC', '*DENSITY', '*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL', '*BOUNDARY', '*STEP', '*FREQUENCY',
 '*END STEP']
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np

from ..io import write_text
from .abaqus import ABAQUS_TYPES, abaqus_text, node_numbers
from .model import FEModel
from .rotation import RotationAxis
from .select import held_nodes

__all__ = ["UNITS", "calculix_deck", "calculix_frequencies", "run_calculix", "write_calculix"]

#: Deck units: length scale from metres, and the factors of the elastic modulus (Pa) and the density (kg/m³).
UNITS = {"m": (1.0, 1.0, 1.0), "mm": (1e3, 1e-6, 1e-12)}  # mm: N/mm² = MPa, t/mm³

#: Element order of each body cell type (the model's ``order`` must be it: the deck has the mesh's elements).
_ORDER = {"tetra": 1, "tetra10": 2, "hexahedron": 1, "hexahedron20": 2, "wedge": 1, "wedge15": 2, "triangle": 1,
          "triangle6": 2, "quad": 1, "quad8": 2}


def _name(text: str) -> str:
    """An Abaqus name from ``text``: letters, digits and ``_``, starting with a letter."""
    name = re.sub(r"[^A-Za-z0-9_]", "_", text).strip("_").upper() or "MATERIAL"
    return name if name[0].isalpha() else "M_" + name


def calculix_deck(model: FEModel, count: int = 20, *, speed: float | None = None, axis: RotationAxis | None = None,
                  nlgeom: bool = False, unit: str = "m") -> str:
    """The CalculiX input deck of ``model``'s lowest ``count`` natural frequencies (module docstring).

    Parameters
    ----------
    model : FEModel
        An assembled model whose element order is its mesh's (``order=2`` on ``tetra10``, ``order=1`` on
        ``tetra``): the deck has the mesh's elements — or P2 on linear tetrahedra or triangles: the deck then has
        their quadratic elements with straight edges (a midside node at every edge's middle), the same field.
    count : int
        Frequencies asked for (``*FREQUENCY``).
    speed : float or None
        Spin speed (rad/s) about ``axis``: a ``*STATIC`` step under ``CENTRIF`` first, the frequencies then a
        ``PERTURBATION`` of its state (3-D models only).
    axis : RotationAxis or None
        The rotation axis (a point and a direction, metres); required with ``speed``.
    nlgeom : bool
        The static step with large rotations (``*STEP, NLGEOM``).
    unit : {"m", "mm"}
        ``"m"``: SI. ``"mm"``: N, mm, t, s (coordinates × 1e3, modulus in MPa, density in t/mm³).

    Raises
    ------
    ValueError
        A model whose element order is not its mesh's, a cell type CalculiX has no element for, a bad ``count``,
        ``unit``, ``speed`` or ``axis``.
    """
    if not isinstance(model, FEModel):
        raise ValueError(f"model must be an FEModel (from bladecase.assemble), got {type(model).__name__}")
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
        raise ValueError(f"count must be an integer >= 1 (frequencies asked for), got {count!r}")
    if unit not in UNITS:
        raise ValueError(f"unit must be one of {', '.join(map(repr, UNITS))}, got {unit!r}")
    mesh = model.mesh
    btype = mesh.body_type
    if btype not in ABAQUS_TYPES:
        raise ValueError(f"CalculiX has no element for {btype} cells (valid: {', '.join(ABAQUS_TYPES)})")
    if _ORDER[btype] == 1 and model.order == 2 and btype in _EDGES:
        mesh = _quadratic(mesh)  # P2 on straight cells: the quadratic element with midside nodes at mid-edge
        btype = mesh.body_type
    if _ORDER[btype] != model.order:
        raise ValueError(f"the model has order {model.order} elements on a mesh of {btype} cells (order "
                         f"{_ORDER[btype]}): a deck has the mesh's elements, so CalculiX would solve another "
                         f"discretisation; assemble with order={_ORDER[btype]} or mesh with order {model.order}")
    if speed is not None:
        speed = float(speed)
        if not (np.isfinite(speed) and speed >= 0):
            raise ValueError(f"speed must be a finite number >= 0 (rad/s), got {speed!r}")
        if not isinstance(axis, RotationAxis):
            raise ValueError(f"a speed needs axis=RotationAxis(origin, direction), got {axis!r}")
        if model.dim != 3:
            raise ValueError("a spinning deck is written for 3-D models only (CalculiX's CENTRIF load on plane "
                             "elements acts in their plane only)")
    length, modulus, density = UNITS[unit]
    element = ABAQUS_TYPES[btype]
    if model.dim == 2 and model.plane == "strain":
        element = element.replace("CPS", "CPE")
    numbers = node_numbers(mesh)
    mesh = _oriented(mesh)  # CalculiX's elements: counter-clockwise (plane), of positive volume
    text = abaqus_text(mesh, groups={}, scale=length, digits=13)  # at most 20 characters a field
    text = text.replace(f"*ELEMENT, TYPE={ABAQUS_TYPES[btype]}\n", f"*ELEMENT, TYPE={element}, ELSET=EALL\n", 1)
    clamped = [str(v) for v in numbers[held_nodes(mesh, model.clamped)].tolist()]  # midside nodes of the face too
    lines = text.rstrip("\n").split("\n")
    lines[1] = f"bladecase FE model: {len(mesh.cells[btype])} {element}, {model.n_dofs} free dofs, units " + \
        ("N m kg s" if unit == "m" else "N mm t s") + \
        (" (bladecase's mass matrix is lumped, CalculiX's consistent)" if model.mass == "lumped" else "")
    lines += ["*NSET, NSET=CLAMPED"] + [", ".join(clamped[i:i + 16]) for i in range(0, len(clamped), 16)]
    mat = model.material
    name = _name(mat.name)
    lines += [f"*MATERIAL, NAME={name}", "*ELASTIC", f"{mat.E * modulus:.12g}, {mat.nu:.12g}", "*DENSITY",
              f"{mat.rho * density:.12g}", f"*SOLID SECTION, ELSET=EALL, MATERIAL={name}"]
    if model.dim == 2:
        lines.append(f"{model.thickness * length:.12g}")
    lines += ["*BOUNDARY", f"CLAMPED, 1, {model.dim}"]
    if speed:
        p = axis.origin * length
        d = axis.direction
        lines += ["*STEP" + (", NLGEOM" if nlgeom else ""), "*STATIC", "*DLOAD",
                  f"EALL, CENTRIF, {speed ** 2:.12g}, {p[0]:.12g}, {p[1]:.12g}, {p[2]:.12g}, {d[0]:.12g}, "
                  f"{d[1]:.12g}, {d[2]:.12g}", "*END STEP", "*STEP, PERTURBATION"]
    else:
        lines.append("*STEP")
    lines += ["*FREQUENCY", f"{int(count)}", "*END STEP"]
    return "\n".join(lines) + "\n"


#: Edges of the linear simplices in the order of their quadratic element's midside nodes (VTK = CalculiX).
_EDGES = {"tetra": ([(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)], "tetra10"),
          "triangle": ([(0, 1), (1, 2), (2, 0)], "triangle6")}


def _quadratic(mesh):
    """``mesh`` (linear tetrahedra or triangles) with a midside node at the middle of every edge: the straight
    quadratic cells whose displacement field is bladecase's P2 field on the linear mesh. New nodes are numbered
    after the mesh's."""
    import dataclasses

    btype = mesh.body_type
    pairs, quad = _EDGES[btype]
    cells = np.asarray(mesh.cells[btype], dtype=np.int64)
    edges = np.sort(np.stack([cells[:, list(e)] for e in pairs], axis=1), axis=2)  # (cells, edges, 2)
    unique, index = np.unique(edges.reshape(-1, 2), axis=0, return_inverse=True)
    n = len(mesh.points)
    points = np.vstack([mesh.points, 0.5 * (mesh.points[unique[:, 0]] + mesh.points[unique[:, 1]])])
    cells = np.hstack([cells, n + index.reshape(len(cells), len(pairs))])
    ids = None if mesh.node_ids is None else np.r_[mesh.node_ids, mesh.node_ids.max() + 1 + np.arange(len(unique))]
    return dataclasses.replace(mesh, points=points, cells={quad: cells}, node_ids=ids)


#: The node order of a cell turned over (corners reversed, midside nodes following their edges).
_FLIP = {"triangle": [0, 2, 1], "triangle6": [0, 2, 1, 5, 4, 3], "quad": [0, 3, 2, 1],
         "quad8": [0, 3, 2, 1, 7, 6, 5, 4], "tetra": [0, 2, 1, 3], "tetra10": [0, 2, 1, 3, 6, 5, 4, 7, 9, 8]}


def _oriented(mesh):
    """``mesh`` with its plane cells counter-clockwise and its tetrahedra of positive volume (CalculiX refuses
    the others: "nonpositive jacobian"); other cells as they are."""
    import dataclasses

    btype = mesh.body_type
    if btype not in _FLIP:
        return mesh
    cells = np.array(mesh.cells[btype])
    p = mesh.points
    a, b, c = (p[cells[:, k]] for k in (0, 1, 2))
    if btype.startswith("tetra"):
        turned = np.einsum("ij,ij->i", np.cross(b - a, c - a), p[cells[:, 3]] - a) < 0
    else:
        turned = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]) < 0
    if not turned.any():
        return mesh
    cells[turned] = cells[turned][:, _FLIP[btype]]
    return dataclasses.replace(mesh, cells={**mesh.cells, btype: cells})


def write_calculix(model: FEModel, path: str | os.PathLike, count: int = 20, **kwargs) -> Path:
    """Write :func:`calculix_deck` (same keywords) to ``path`` (suffix ``.inp``, written atomically)."""
    path = Path(path)
    if path.suffix != ".inp":
        raise ValueError(f"a CalculiX deck is an .inp file, got {str(path)!r}")
    write_text(path, calculix_deck(model, count, **kwargs))
    return path


def calculix_frequencies(dat: str | os.PathLike, count: int | None = None) -> np.ndarray:
    """The natural frequencies (Hz, cycles per time unit) of the last eigenvalue table of a CalculiX ``.dat``."""
    text = Path(dat).read_text(errors="replace")
    if "E I G E N V A L U E   O U T P U T" not in text:
        raise ValueError(f"{dat}: no eigenvalue output (did CalculiX run a *FREQUENCY step?)")
    table = text.split("E I G E N V A L U E   O U T P U T")[-1]
    rows = re.findall(r"^\s*\d+\s+([-+0-9.Ee]+)\s+([-+0-9.Ee]+)\s+([-+0-9.Ee]+)\s+([-+0-9.Ee]+)", table, re.M)
    f = np.array([float(r[2]) for r in rows])
    return f if count is None else f[:count]


def run_calculix(model: FEModel, folder: str | os.PathLike, count: int = 20, *, name: str = "model",
                 threads: int = 1, timeout: float = 3600, **kwargs) -> np.ndarray:
    """Write the deck of ``model`` into ``folder`` (as ``<name>.inp``), run ``ccx`` there and return its ``count``
    lowest frequencies (Hz). Keywords: those of :func:`calculix_deck`.

    Raises
    ------
    FileNotFoundError
        ``ccx`` is not installed (Debian/Ubuntu: ``apt-get install calculix-ccx``).
    RuntimeError
        CalculiX failed (its last output lines are in the message).
    """
    ccx = shutil.which("ccx")
    if ccx is None:
        raise FileNotFoundError("CalculiX (ccx) is not installed: apt-get install calculix-ccx, or put ccx on PATH")
    folder = Path(folder)
    write_calculix(model, folder / f"{name}.inp", count, **kwargs)
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), CCX_NPROC_EQUATION_SOLVER=str(threads))
    proc = subprocess.run([ccx, name], cwd=folder, capture_output=True, text=True, timeout=timeout, env=env)
    if proc.returncode != 0 or not (folder / f"{name}.dat").is_file():
        tail = "\n".join((proc.stdout + proc.stderr).strip().splitlines()[-8:])
        raise RuntimeError(f"CalculiX failed on {folder / (name + '.inp')} (exit {proc.returncode}):\n{tail}")
    return calculix_frequencies(folder / f"{name}.dat", count)
