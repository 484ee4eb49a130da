"""Abaqus input files written from a :class:`bladecase.fe.mesh.Mesh` (the decks CalculiX runs:
:mod:`bladecase.fe.calculix`), in the element types :mod:`bladecase.fe.abaqus` reads back."""

from __future__ import annotations

import os

import numpy as np

#: meshio body type → the Abaqus element :func:`abaqus_text` writes (one that :func:`read_abaqus` reads back).
ABAQUS_TYPES = {"tetra": "C3D4", "tetra10": "C3D10", "triangle": "CPS3", "triangle6": "CPS6",
                "hexahedron": "C3D8", "hexahedron20": "C3D20", "wedge": "C3D6", "wedge15": "C3D15",
                "quad": "CPS4", "quad8": "CPS8"}


def node_numbers(mesh) -> np.ndarray:
    """The numbers :func:`abaqus_text` gives the nodes of ``mesh``: the file's own when they are >= 1, else
    1-based indices."""
    return mesh.node_ids if mesh.numbering == "file" and mesh.node_ids.min() >= 1 else \
        np.arange(1, len(mesh.points) + 1)


def abaqus_text(mesh, groups: dict | None = None, scale: float = 1.0, digits: int | None = None) -> str:
    """An Abaqus input file of ``mesh`` (a :class:`bladecase.fe.mesh.Mesh`): its nodes with their numbers (the
    file's own, else 1-based; :func:`node_numbers`), coordinates times ``scale`` (all their digits, or
    ``digits`` significant ones: CalculiX reads at most 20 characters a field), the body elements and one
    ``*NSET`` per group of ``groups`` (default: the mesh's)."""
    btype = mesh.body_type
    numbers = node_numbers(mesh)
    groups = mesh.groups if groups is None else groups
    origin = os.path.basename(mesh.source) or "memory"
    lines = ["*HEADING", f"bladecase mesh from {origin}".encode("ascii", "replace").decode(), "*NODE"]
    num = repr if digits is None else f"{{:.{int(digits)}g}}".format
    lines += [f"{k}, {num(x)}, {num(y)}, {num(z)}" for k, (x, y, z) in zip(numbers.tolist(),
                                                                          (mesh.points * scale).tolist())]
    lines.append(f"*ELEMENT, TYPE={ABAQUS_TYPES[btype]}")
    for e, row in enumerate(mesh.cells[btype].tolist()):
        items = [str(e + 1)] + [str(numbers[v]) for v in row]
        lines += [", ".join(items[i : i + 16]) + ("," if i + 16 < len(items) else "") for i in range(0, len(items), 16)]
    for name, nodes in groups.items():
        lines.append(f"*NSET, NSET={name}")
        ids = [str(v) for v in numbers[np.asarray(nodes, dtype=np.int64)].tolist()]
        lines += [", ".join(ids[i : i + 16]) for i in range(0, len(ids), 16)]
    return "\n".join(lines) + "\n"
