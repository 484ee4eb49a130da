"""Named node groups of a mesh file, from every source meshio exposes (see :func:`bladecase.fe.mesh.from_meshio`)."""

from __future__ import annotations

import numpy as np

from .cells import cell_dim as _cell_dim

#: Prefix of the ``.vtu``/``.vtk`` point-data arrays that carry named node groups:
#: ``group:root`` is a per-node mask (non-zero = in the group).
GROUP_PREFIX = "group:"


def _check_data(m, blocks, n_points: int, source: str) -> None:
    """Point data of one value per point and cell data of one value per cell of each block: a shorter array
    is a truncated or corrupt file (its groups would silently lose nodes)."""
    for key, values in (getattr(m, "point_data", None) or {}).items():
        if len(np.asarray(values)) != n_points:
            raise ValueError(f"mesh {source}: point data {key!r} has {len(np.asarray(values))} values for "
                             f"{n_points} points (a truncated or corrupt file?)")
    for key, per_block in (getattr(m, "cell_data", None) or {}).items():
        per_block = list(per_block)
        sizes = [len(np.asarray(v)) for v in per_block]
        if len(per_block) != len(blocks) or any(k != len(d) for k, (_, d) in zip(sizes, blocks)):
            expected = [len(d) for _, d in blocks]
            raise ValueError(f"mesh {source}: cell data {key!r} has {sizes} values for cell blocks of {expected} "
                             "cells (a truncated or corrupt file?)")


def file_groups(m, blocks, n_points: int, source: str) -> dict[str, np.ndarray]:
    """Named node sets from every source meshio exposes (see :func:`bladecase.fe.mesh.from_meshio`)."""
    found: dict[str, list[np.ndarray]] = {}
    _check_data(m, blocks, n_points, source)

    def add(name, nodes):
        found.setdefault(str(name), []).append(np.asarray(nodes, dtype=np.int64).ravel())

    cell_sets = {k: v for k, v in (getattr(m, "cell_sets", None) or {}).items() if not k.startswith("gmsh:")}
    for name, per_block in cell_sets.items():
        add(name, [])
        for (t, data), idx in zip(blocks, per_block):
            if idx is not None and len(idx):
                idx = np.asarray(idx).ravel()
                if idx.dtype.kind not in "iu" or idx.min() < 0 or idx.max() >= len(data):
                    raise ValueError(f"mesh {source}: cell set {name!r} refers to {t} cells outside 0..{len(data) - 1}"
                                     " (a truncated or corrupt file?)")
                add(name, data[idx.astype(np.int64)])
    # gmsh MSH 2.2: physical names in field_data, tags in cell_data (no cell_sets).
    physical = (getattr(m, "cell_data", None) or {}).get("gmsh:physical")
    if physical is not None:
        for name, value in (getattr(m, "field_data", None) or {}).items():
            if name in cell_sets or np.size(value) != 2:
                continue
            tag, gdim = (int(v) for v in np.ravel(value))
            add(name, [])
            for (t, data), tags in zip(blocks, physical):
                if _cell_dim(t) == gdim:
                    add(name, data[np.asarray(tags) == tag])
    for name, nodes in (getattr(m, "point_sets", None) or {}).items():
        add(name, nodes)
    for (_, data), ids in zip(blocks, (getattr(m, "cell_data", None) or {}).get("nastran:ref") or []):
        ids = np.asarray(ids).ravel()
        for pid in np.unique(ids) if ids.size == len(data) else ():
            add(f"pid_{int(pid)}", data[ids == pid])
    point_data = getattr(m, "point_data", None) or {}
    for key, mask in point_data.items():
        if key.startswith(GROUP_PREFIX):
            add(key[len(GROUP_PREFIX):], np.flatnonzero(np.asarray(mask).ravel()))
    # MED families: family id -> group names, on nodes and on cells.
    fam = point_data.get("point_tags")
    for tag, names in (getattr(m, "point_tags", None) or {}).items():
        if fam is not None:
            for name in names:
                add(name, np.flatnonzero(np.asarray(fam) == tag))
    cell_fam = (getattr(m, "cell_data", None) or {}).get("cell_tags")
    for tag, names in (getattr(m, "cell_tags", None) or {}).items():
        if cell_fam is not None:
            for name in names:
                for (_, data), tags in zip(blocks, cell_fam):
                    add(name, data[np.asarray(tags) == tag])

    groups = {}
    for name, parts in found.items():
        nodes = np.unique(np.concatenate(parts)) if parts else np.zeros(0, dtype=np.int64)
        if len(nodes) and (nodes[0] < 0 or nodes[-1] >= n_points):
            raise ValueError(f"mesh {source}: group {name!r} refers to nodes outside 0..{n_points - 1}")
        groups[name] = nodes
    return groups


#: The point-data key of a mesh file's own node numbers (written by the Abaqus reader and by ``save_mesh``).
NODE_ID_KEY = "node_id"


def file_node_ids(m, n_points: int, source: str) -> np.ndarray:
    """The node numbers of the file (point data :data:`NODE_ID_KEY`: unique integers >= 0, one per point), else
    the 0-based point index (formats that keep no node numbers: gmsh, VTK without it, MED, Nastran)."""
    from .. import log

    ids = (getattr(m, "point_data", None) or {}).get(NODE_ID_KEY)
    if ids is None:
        return np.arange(n_points, dtype=np.int64)
    ids = np.asarray(ids).ravel()
    whole = ids.dtype.kind in "iu" or (ids.dtype.kind == "f" and np.all(np.isfinite(ids))
                                       and np.all(ids == np.round(ids)))
    if ids.size != n_points or not whole or (ids.size and ids.min() < 0) or np.unique(ids).size != ids.size:
        log.info("mesh %s: point data %r is not one distinct integer >= 0 per node: nodes are numbered by their "
                 "0-based index", source, NODE_ID_KEY)
        return np.arange(n_points, dtype=np.int64)
    return ids.astype(np.int64)
