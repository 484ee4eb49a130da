"""How hard each blade of a mistuned disk rubs (``[mistuning] force`` with ``clearance`` or a ``[casing]``): the
steady engine-order rub of every blade, each its own massless contact at its tip node, for the first
``contact_samples`` samples through the study's executor.

The disk is the reduced disk of :func:`~bladecase.reduction.disk.disk_model` (the sector with its tip node's mass
moved to its neighbours, one contact along the radius at the tip node, the family's modes of every nodal diameter
and the contacts' residual flexibility), each blade's stiffness scaled by the sample's deviations
(:mod:`bladecase.reduction.mistuning_disk`; the residual flexibility is the tuned one). Blade ``j`` is loaded at the
tip dof of the linear stage by ``force`` × ``e^{2πiej/N}``; the forcing frequency is, per sample, where the largest
linear tip excursion of that mistuned disk peaks over the family's band; the steady rub is flown by the exact
simulator with the load split off (:func:`~bladecase.nsm.massless.disk_forced.forced_contacts`). It writes
``mistuning_contact.csv`` (per sample: the frequency, whether it settled, each blade's peak contact force) and
``summary["mistuning"]["contact"]``.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from ... import log
from ...io import write_text
from ..executor import Executor
from ..schema import StudyError

__all__ = ["compute_contacts", "radial_response", "sample_contacts"]

#: Frequencies of the band scanned for the mistuned disk's linear resonance (the forcing frequency of a sample).
SCAN = 801

def radial_response(fe_model, axis, node: int) -> np.ndarray:
    """The sector dof vector ``r`` of the tip ``node``'s radial displacement about ``axis`` (``rᵀu``: how far the tip
    moves towards a casing of revolution)."""
    p = fe_model.mesh.points[node] - axis.origin
    radial = p - (p @ axis.direction) * axis.direction
    radial = radial / np.linalg.norm(radial)
    r = np.zeros(fe_model.n_dofs)
    here = np.flatnonzero(fe_model.dofs.node == node)
    r[here] = radial[fe_model.dofs.direction[here]]
    return r


def sample_contacts(delta, *, disk, coupling, load, residual, band, zeta: float, gap) -> dict:
    """One sample's task: the forcing frequency (the peak of the largest linear tip excursion over ``band``, Hz)
    and every blade's settled peak contact force there (:func:`~bladecase.nsm.massless.disk_forced.forced_contacts`)."""
    from ...nsm.massless.disk_forced import forced_contacts, linear_contacts
    from ...reduction.mistuning_disk import mistuned_disk

    system = mistuned_disk(disk, coupling, delta, gap=gap)
    w = 2 * np.pi * np.asarray(band, dtype=float)
    excursion = [np.abs(linear_contacts(system, load, residual, x, zeta)).max() for x in w]
    omega = float(w[int(np.argmax(excursion))])
    out = forced_contacts(system, load, residual, omega, zeta, periods=40, window=10, max_periods=800, rtol=1e-4)
    return {"frequency_hz": omega / (2 * np.pi), "settled": out.settled, "forces": out.peak_force.tolist(),
            "fraction": out.contact_fraction.tolist(), "periods": out.periods_run}


def compute_contacts(m: dict, clearance, fe_model, sector, axis, tip: dict, cells: np.ndarray, deltas: np.ndarray,
                     band, staging: Path, files: dict, executor: Executor, progress: bool) -> dict:
    """The contact stage (module docstring) with each blade's ``clearance`` (m; ``[mistuning] clearance`` or the
    ``[casing]``'s); returns ``summary["mistuning"]["contact"]``."""
    from ...reduction import Contact
    from ...reduction.disk import disk_model, massless_sector
    from ...reduction.mistuning_disk import blade_coupling, engine_order_load
    from ...reduction.mistuning_fe import blade_stiffness

    n = sector.sectors
    c = np.broadcast_to(np.asarray(clearance, dtype=float), (n,))
    radial = radial_response(fe_model, axis, tip["node"])
    normal = radial[np.flatnonzero(fe_model.dofs.node == tip["node"])]
    full = np.zeros(3)
    full[fe_model.dofs.direction[fe_model.dofs.node == tip["node"]]] = normal
    try:
        contact = Contact.at(fe_model, tip["node"], normal=full.tolist(), gap=float(c[0]))
        ms, W, gap = massless_sector(fe_model, sector, contact)
        disk = disk_model(ms, W, gap, count=1 + m["family"], casing=m["casing_stiffness"])
    except ValueError as exc:
        raise StudyError(f"[mistuning] force: the blades' tip contact at node {tip['node']}: {exc}") from None
    coupling = blade_coupling(disk, blade_stiffness(fe_model, cells))
    f = np.zeros(fe_model.n_dofs)
    f[tip["dof"]] = m["force"]
    load, residual = engine_order_load(disk, f, m["engine_order"])
    shared = {"disk": disk, "coupling": coupling, "load": load, "residual": residual, "band": np.linspace(
        band[0], band[-1], SCAN), "zeta": m["damping"], "gap": np.repeat(c, disk.per_blade)}
    count = min(m["contact_samples"], deltas.shape[0])
    tuned = sample_contacts(np.zeros(n), **shared)
    rows = executor.map(sample_contacts, list(deltas[:count]), shared=shared, desc="mistuned rub per sample",
                        progress=progress)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["sample", "frequency_hz", "settled"] + [f"force_{j}_n" for j in range(n)])
    for i, r in enumerate(rows):
        w.writerow([i, repr(r["frequency_hz"]), r["settled"]] + [repr(x) for x in r["forces"]])
    write_text(staging / "mistuning_contact.csv", buf.getvalue())
    files["mistuning_contact"] = "mistuning_contact.csv"
    top = np.array([max(r["forces"]) for r in rows])
    worst = int(np.argmax(top))
    ref = max(tuned["forces"])
    out = {"force_n": m["force"], "samples": count, "casing_stiffness": m["casing_stiffness"],
           "tuned_peak_force_n": ref, "tuned_frequency_hz": tuned["frequency_hz"], "tuned_forces_n": tuned["forces"],
           "largest_force_n": {"p50": float(np.percentile(top, 50)), "max": float(top.max())},
           "ratio_to_tuned": {"p50": float(np.percentile(top, 50) / ref) if ref > 0 else None,
                              "max": float(top.max() / ref) if ref > 0 else None},
           "worst_sample": worst, "worst_blade": int(np.argmax(rows[worst]["forces"])),
           "worst_forces_n": rows[worst]["forces"], "unsettled": int(sum(not r["settled"] for r in rows)),
           "touching_blades_p50": float(np.median([sum(x > 0 for x in r["forces"]) for r in rows]))}
    log.info("mistuned rub at a tip force of %.4g N (%d samples): the tuned disk's blades press %.4g N; mistuned, the "
             "hardest-pressing blade %.4g N (median) to %.4g N (sample %d, blade %d); %d did not settle", m["force"],
             count, ref, out["largest_force_n"]["p50"], out["largest_force_n"]["max"], worst, out["worst_blade"],
             out["unsettled"])
    return out
