"""The whole disk against the casing in a cyclic study (``[cyclic] nonsmooth`` with a ``[contact]``): a
travelling-wave nonsmooth mode of the bladed disk, found in its reduced model and animated on the annulus.

The sector's contact (``[contact]``: a face's mean, or every node of it with ``points = "nodes"``; the massless
contact model; ``casing_stiffness`` for a compliant casing) is every blade's own: the reduced disk
(:func:`~bladecase.reduction.disk.disk_model`: ``modes`` cyclic modes per nodal diameter, the contacts' residual
flexibility restored) has ``N·m`` contacts. The wave of mode ``j`` of ``k`` nodal diameters (default: the mode of
``k`` that moves the contacts most along the casing normal for its energy) (``k > N/2``: the
backward wave of ``N − k``) is scaled until it grazes, then followed at the energies ``growth`` × its own
(:func:`~bladecase.nsm.massless.disk_modes.rotating_family`: shooting over ``T/N'`` against the blade shift). Each
orbit is flown one period in the whole disk without the symmetry (its return error); the last is flown
:data:`CHECK_PERIODS` periods and its Floquet multipliers computed in the whole disk, then animated on the annulus
(:func:`~bladecase.post.disk.annulus_orbit.write_annulus_orbit`). It writes ``disk_modes.csv`` (one row per orbit),
the annulus' VTK series and GIF/MP4 (``[output] formats``), and ``summary.json["cyclic"]["nonsmooth"]``.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from ... import log
from ...io import rows_csv, write_text
from ..schema import Study, StudyError
from ..stages import build_contact
from .cyclic_keys import NONSMOOTH_GROWTH, nonsmooth_checks

__all__ = ["CHECK_PERIODS", "compute_disk_modes"]

#: Periods the animated orbit is flown in the whole disk, without the symmetry, to check it comes back.
CHECK_PERIODS = 10

_COLUMNS = ("orbit", "T", "frequency_hz", "energy_j", "residual", "return_error_1T", "max_force_n", "touching")


def compute_disk_modes(study: Study, staging: Path, files: dict, *, model, sector) -> dict:
    """The stage (module docstring) on the FE ``model`` and its cyclic ``sector`` (about the study's speed when it
    has one); returns ``summary["cyclic"]["nonsmooth"]``. ``StudyError`` for a contact on a cyclic face, a wave
    that never touches the casing, or a family that Newton cannot start."""
    from ...nsm.massless.disk_modes import full_orbit, return_error, rotating_family
    from ...post.disk.annulus_orbit import write_annulus_orbit
    from ...reduction.disk import disk_model, massless_sector

    cy, o = study["cyclic"], study["output"]
    ns, N = cy["nonsmooth"], sector.sectors
    nonsmooth_checks(cy, study["contact"], N)
    k, mode, count = ns.get("diameter", 1), ns.get("mode"), ns.get("modes", 4)
    growth = [float(g) for g in ns.get("growth", NONSMOOTH_GROWTH)]
    start = time.perf_counter()
    contact = build_contact(study, model)
    nodes = study["contact"].get("points") == "nodes"
    try:
        ms, W, gap = massless_sector(model, sector, contact, nodes=nodes)
        disk = disk_model(ms, W, gap, count=count, casing=None if np.isinf(contact.casing) else contact.casing)
    except ValueError as exc:
        raise StudyError(f"[contact]: {exc}") from None
    built = time.perf_counter() - start
    log.info("the whole disk: %d sectors × %d contact%s, %d modes (%d per nodal diameter), built in %.2f s", N,
             disk.per_blade, "s" if disk.per_blade > 1 else "", disk.system.n, count, built)
    kk = min(k, N - k)
    if mode is None:
        mode = _touching_mode(disk, kk)
        log.info("[cyclic] nonsmooth: mode %d of nodal diameter %d, the one that moves the contacts most along the "
                 "casing normal for its energy", mode, kk)
    if mode > len(disk.diameters[kk].lam):
        raise StudyError(f"[cyclic] nonsmooth: mode = {mode}, but the disk keeps {len(disk.diameters[kk].lam)} "
                         f"modes of nodal diameter {kk}: raise nonsmooth's modes")
    P, n1 = disk.rotating(k)
    x0, v0, omega = disk.travelling_wave(k, mode - 1)
    if not np.abs(disk.system.W.T @ x0).max() > 1e-12 * np.abs(disk.system.W).max():
        raise StudyError(f"[cyclic] nonsmooth: mode {mode} of nodal diameter {kk} does not move the blades' contacts "
                         "along the casing normal: it never touches the casing (choose another mode)")
    try:
        family = rotating_family(disk.system, P, n1, x0, v0, 2 * math.pi / omega, growth=growth)
    except ValueError as exc:
        raise StudyError(f"[cyclic] nonsmooth: the travelling family of mode {mode} of nodal diameter {k} does not "
                         f"start ({exc})") from None
    rows = []
    for i, orbit in enumerate(family):
        error, lam = _flown(disk.system, orbit)
        rows.append({"orbit": i + 1, "T": float(orbit.T), "frequency_hz": float(orbit.frequency),
                     "energy_j": float(orbit.energy), "residual": float(orbit.residual),
                     "return_error_1T": error, "max_force_n": lam, "touching": bool(orbit.touching)})
    write_text(staging / "disk_modes.csv", rows_csv(rows, _COLUMNS))
    files["disk_modes"] = "disk_modes.csv"
    last = family[-1]
    back = return_error(disk.system, last.x0, last.v0, last.T, periods=CHECK_PERIODS)
    full = full_orbit(disk.system, last.x0, last.v0, last.T)
    section = {"diameter": k, "direction": "forward" if k < N / 2 else "backward", "mode": mode,
               "modes_per_diameter": count, "contacts": int(disk.system.m), "reduced_dofs": int(disk.system.n),
               "linear_frequency_hz": omega / (2 * math.pi), "fraction": n1, "orbits": rows,
               "check": {"periods": CHECK_PERIODS, "return_error": back},
               "stable": bool(full.stable()), "largest_multiplier": full.max_modulus,
               "seconds": {"model": built, "total": time.perf_counter() - start}, "animated": None}
    log.info("travelling wave of nodal diameter %d (%s), mode %d: %d orbits, %.6g → %.6g Hz; the last flown %d "
             "periods in the whole disk without the symmetry: back within %.1e; %s (largest |μ| %.6f)", k,
             section["direction"], mode, len(rows), rows[0]["frequency_hz"], rows[-1]["frequency_hz"], CHECK_PERIODS,
             back, "stable" if section["stable"] else "unstable", section["largest_multiplier"])
    if o["animate"] and any(f in o["formats"] for f in ("vtu", "gif", "mp4")):
        stem = f"disk_nd{k}_mode{mode}"
        section["animated"] = write_annulus_orbit(
            model, ms, disk, last, staging, o, stem=stem,
            title=f"{study.name}: travelling wave, ND {k}, {last.frequency:.1f} Hz")
        for key in ("pvd", "gif", "mp4"):
            if key in section["animated"]:
                files[f"disk_{key}"] = section["animated"][key]
    return section


def _touching_mode(disk, k: int) -> int:
    """The mode (1-based) of nodal diameter ``k`` whose wave moves the contacts most per unit energy
    (``max |Wᵀψ|/ω``): a blade's first bending mode barely moves its tip along a radial casing normal."""
    s = disk.system
    score = [np.abs(s.W[a]).max() / math.sqrt(s.S[a, a]) for a in (disk.index(k, i, 0)
                                                                  for i in range(len(disk.diameters[k].lam)))]
    return int(np.argmax(score)) + 1


#: Instants of a period at which an orbit's contact forces are sampled for ``disk_modes.csv``.
FORCE_SAMPLES = 500


def _flown(system, orbit) -> tuple[float, float]:
    """One period of ``orbit`` flown by the exact simulator in the whole disk: its return error (energy norm, as
    :func:`~bladecase.nsm.massless.disk_modes.return_error`) and its largest contact force (N, over
    :data:`FORCE_SAMPLES` instants)."""
    from ...nsm.massless.nodes import simulate_nodes

    tr = simulate_nodes(system, orbit.x0, orbit.v0, orbit.T)
    w, phi = system.modes
    M = system.M
    dq, dp = w * (phi.T @ M @ (tr.x_end - orbit.x0)), phi.T @ M @ (tr.v_end - orbit.v0)
    size = np.sqrt(np.sum((w * (phi.T @ M @ orbit.x0)) ** 2) + np.sum((phi.T @ M @ orbit.v0) ** 2))
    lam = tr.forces(np.linspace(0.0, orbit.T, FORCE_SAMPLES, endpoint=False))
    return float(np.sqrt(dq @ dq + dp @ dp) / size), float(lam.max())
