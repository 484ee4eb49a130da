"""Where a face contact really rubs: every node of the contact face over one period of an orbit.

A face contact (``[contact] face``) is one constraint on the mean normal displacement of its nodes; the casing
sees that mean.  The face itself tilts and bends: its leading- or trailing-edge corners can run well beyond the
clearance while the mean just touches.  :func:`tip_excursion` expands an orbit onto the face's nodes, finely
sampled over its period, and says how far beyond the clearance each node goes, which node goes farthest, when,
and how many nodes pass the clearance at all — the numbers a single averaged constraint cannot show.

>>> text = words({"mean_max_m": 2.8e-5, "node_max_m": 9.2e-5, "node_id": 17, "t_over_T": 0.1, "clearance_m": 1e-4,
...               "nodes_beyond": 12, "nodes": 40, "position_mm": [10.0, 30.0, 150.0]})
>>> text.split(", ")[:2]
['the face mean goes 28 µm beyond the 100 µm clearance', 'but 12 of its 40 nodes pass the clearance']
"""

from __future__ import annotations

import numpy as np

__all__ = ["SAMPLES", "tip_excursion", "words"]

#: Instants per period at which the face is sampled (the contact phases of the demo last a fifth of the period).
SAMPLES = 400


def tip_excursion(reduced, orbit, samples: int = SAMPLES) -> dict | None:
    """How far beyond the clearance the face's mean and each of its nodes go over one period of ``orbit``
    (``None`` for a single-node contact).

    Returns ``{"clearance_m", "mean_max_m", "node_max_m", "node", "node_id", "position_mm", "node_clearance_m",
    "t_over_T", "nodes_beyond", "nodes"}``: the largest ``ν·u − d`` of the face mean and of any node (each node
    with its own normal and clearance under a casing of revolution; m; negative: never reaches the clearance),
    the node reaching farthest (0-based index and the mesh file's number), its position (mm) and clearance, when
    (``t/T``), and how many of the face's nodes pass their clearance at some instant.
    """
    contact, model = reduced.contact, reduced.model
    if len(contact.nodes) < 2:
        return None
    nodes = np.asarray(contact.nodes, dtype=np.int64)
    d, _ = contact.node_clearances(model)  # each node's own clearance (a casing of revolution), else the gap
    times = np.linspace(0.0, orbit.T, samples, endpoint=False)
    x, _ = orbit.state(times)
    u = reduced.free_dofs(x)  # (n_free, samples)
    excess = contact.node_normal_map(model) @ u - d[:, None]  # (nodes, samples): ν_k·u_k − d_k
    gap = float(contact.gap)
    mean = contact.w(model) @ u
    k, j = np.unravel_index(int(np.argmax(excess)), excess.shape)
    node = int(nodes[k])
    return {"clearance_m": gap, "mean_max_m": float(mean.max() - gap), "node_max_m": float(excess[k, j]),
            "node": node, "node_id": int(model.mesh.node_ids[node]),
            "position_mm": (np.asarray(model.mesh.points[node], dtype=float) * 1e3).round(3).tolist(),
            "node_clearance_m": float(d[k]),
            "t_over_T": float(times[j] / orbit.T), "nodes_beyond": int((excess.max(axis=1) > 0).sum()),
            "nodes": int(nodes.size)}


def words(x: dict, nodes: bool = False) -> str:
    """The excursion in a sentence: what the face mean does, and what its nodes do; ``nodes``: the study computes
    the mode with every node a contact too (``[contact] points = "nodes"``), so the sentence points there instead
    of advising it."""
    um = 1e6
    mean = x["mean_max_m"] * um
    mean_words = (f"the face mean goes {mean:.0f} µm beyond the {x['clearance_m'] * um:.0f} µm clearance" if mean > 0.5
                  else f"the face mean reaches the {x['clearance_m'] * um:.0f} µm clearance" if mean > -0.5
                  else f"the face mean stays {-mean:.0f} µm short of the {x['clearance_m'] * um:.0f} µm clearance")
    if x["nodes_beyond"] == 0:
        return f"{mean_words}; none of its {x['nodes']} nodes passes the clearance"
    return (f"{mean_words}, but {x['nodes_beyond']} of its {x['nodes']} nodes pass the clearance, node "
            f"{x['node_id']} (at {', '.join(f'{c:.4g}' for c in x['position_mm'])} mm) by "
            f"{x['node_max_m'] * um:.0f} µm at t/T = {x['t_over_T']:.3f}: the casing sees the face's mean only, so "
            "where and how hard the tip rubs is not resolved by this contact model"
            + (" — the mode with every node a contact, computed beside it, resolves it" if nodes else
               " ([contact] points = \"nodes\" makes every node a contact)"))
