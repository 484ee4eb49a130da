"""The cyclic stage of a study: a tuned bladed disk's linear modes by nodal diameter, from one sector.

A study without a contact runs it (:func:`compute_linear`, called by :func:`~bladecase.study.run.run`) when its
``[geometry] kind`` is ``"sector"`` (the parametric sector of :func:`~bladecase.fe.sector.sector_mesh`), when it sets
a ``[cyclic]`` key, or when its mesh is a CalculiX/Abaqus deck with ``*CYCLIC SYMMETRY MODEL`` (its ``N``, axis and
``*TIE, CYCLIC SYMMETRY`` faces read as they are, :func:`~bladecase.fe.abaqus.read_cyclic`); otherwise the linear
modes and the Campbell diagram of :mod:`~bladecase.study.rotation.modes_run`.  It writes, through the same staging and
all-or-nothing publication as every run:

* ``cyclic.csv`` — one row per nodal diameter and mode: ``nd, mode, frequency_hz, multiplicity``;
* ``safe.png`` — the SAFE (ZZENF) diagram with the engine-order zig-zag at the SAFE speed;
* ``vtk/annulus_<stem>.pvd`` + ``vtk/annulus_<stem>/`` — the whole disk as one mesh with the expanded mode
  (``[cyclic] expand``), one period of a standing or a forward/backward travelling wave, ``[output] frames`` frames;
* with ``[cyclic] nonsmooth`` and a ``[contact]``: a travelling-wave nonsmooth mode of the whole disk against the
  casing, animated on the annulus (:mod:`bladecase.study.disk.nonsmooth`: ``disk_modes.csv``, ``vtk/disk_*.pvd``,
  ``animations/disk_*.gif``);
* with ``[rotation] speeds``: the Campbell diagram of every nodal diameter (``campbell_nd.png``);
* ``summary.json["cyclic"]`` and the report's words (which nodal diameter each engine order excites, the modes near
  the engine-order lines).
"""

from __future__ import annotations

import csv
import dataclasses
import io
import math
from pathlib import Path

import numpy as np

from ... import log
from ...fe import fe_sector, sector_mesh
from ...fe.centrifugal import to_rad_s
from ...fe.cyclic import cyclic_spectrum, engine_order_diameter, nodal_diameters, rotation_matrix, sector_angles
from ...fe.mesh_checks import LENGTH_UNITS
from ...fe.rotation import RotationAxis
from ...io import save_figure, write_text
from ..documents import model_summary, write_mesh
from ..executor import Executor
from ..rotation.modes_run import compute_modes
from ..schema import Study, StudyError
from ..stages import build_model, selected_nodes
from .cyclic_keys import check_diameters, cyclic_requested, expand_spec
from .mistuning_keys import mistuning_requested

__all__ = ["compute_cyclic", "compute_linear", "deck_cyclic", "engine_order_table"]

#: An engine order whose line passes within this fraction of a mode's frequency is "near" it (reported).
NEAR = 0.05


def deck_cyclic(study: Study) -> dict | None:
    """The cyclic records of the study's mesh file when it is a CalculiX/Abaqus deck that has them
    (:func:`~bladecase.fe.abaqus.read_cyclic`), else ``None``.

    >>> from bladecase.study.demo import demo_study
    >>> deck_cyclic(demo_study()) is None       # a parametric blade
    True
    """
    if study.parametric:
        return None
    from ...fe.abaqus import looks_like_abaqus, read_cyclic

    path, fmt = study.mesh_path(), (study["mesh"].get("format") or "").lower()
    if not path.is_file():
        return None
    if fmt in ("abaqus", "calculix") or (not fmt and (path.suffix.lower() == ".inp" or looks_like_abaqus(path))):
        return read_cyclic(path)
    return None


def compute_linear(study: Study, staging: Path, stage, progress: bool, executor: Executor) -> tuple[dict, list, dict]:
    """A run without a contact: the cyclic stage for a bladed disk (module docstring), else the linear modes and the
    Campbell diagram (:func:`~bladecase.study.rotation.modes_run.compute_modes`)."""
    deck = deck_cyclic(study)
    if cyclic_requested(study.config) or deck is not None:
        return compute_cyclic(study, staging, stage, progress, executor, deck)
    if mistuning_requested(study.config):
        raise StudyError(f"[mistuning]: mistuning is that of a bladed disk, but the mesh {study.mesh_path()} is not a "
                         "sector (no *CYCLIC SYMMETRY MODEL): give [cyclic] sectors = N (and [rotation] axis)")
    if not (study.config.get("rotation") or {}).get("speeds"):
        raise StudyError(f"[cyclic]: the mesh {study.mesh_path()} declares no *CYCLIC SYMMETRY MODEL: give [cyclic] "
                         "sectors = N (and [rotation] axis, the engine axis) for a sector mesh")
    return compute_modes(study, staging, stage, progress, executor)


def _with_clamp(study: Study, clamp) -> Study:
    return dataclasses.replace(study, config={**study.config, "fem": {**study["fem"], "clamp": clamp}})


def _sector_mesh(study: Study):
    g, geometry = study["geometry"], study.geometry()
    try:
        mesh = sector_mesh(geometry, size=g["size"], order=g["mesh_order"])
    except (ValueError, RuntimeError) as exc:
        raise StudyError(f"[geometry] {exc}") from None
    clamp = study["fem"]["clamp"]
    if clamp == "root" and "root" not in mesh.groups:
        log.info("[fem] clamp: the sector is clamped at its bore, group 'hub' (a disk sector has no 'root')")
        study = _with_clamp(study, "hub")
    elif isinstance(clamp, str) and clamp not in mesh.groups:
        raise StudyError(f"[fem] clamp: the sector mesh has no group {clamp!r} (groups: "
                         f"{', '.join(sorted(mesh.groups))})")
    return study, mesh, geometry


def _file_mesh(study: Study):
    """The study's mesh file (``[mesh]``), its clamp group checked (a disk has no contact group to check)."""
    from ...fe import load_mesh

    source, m = study.mesh_path(), study["mesh"]
    if not source.exists():
        raise StudyError(f"[mesh] path: no such file {str(source)!r}")
    mesh = load_mesh(source, unit=m.get("unit") or "m", file_format=m.get("format"))
    clamp = study["fem"]["clamp"]
    if isinstance(clamp, str) and clamp not in mesh.groups:
        raise StudyError(f"[fem] clamp: the mesh {mesh.source} has no group {clamp!r} (groups: "
                         f"{', '.join(sorted(mesh.groups)) or 'none'})")
    return mesh


def _setup(study: Study, mesh, deck: dict | None, geometry) -> dict:
    """N, the axis (m), the face groups and the tolerance (mesh unit) of the study's sector."""
    cy = study["cyclic"]
    unit = LENGTH_UNITS.get(mesh.unit, 1.0)
    if geometry is not None:
        n, axis, faces, tol = geometry.sectors, geometry.axis, ("left", "right"), None
        where = "the sector geometry"
    elif deck is not None:
        n = deck["sectors"]
        if cy["sectors"] is not None and cy["sectors"] != n:
            raise StudyError(f"[cyclic] sectors: the deck's *CYCLIC SYMMETRY MODEL has N={n}, got {cy['sectors']}: "
                             "leave [cyclic] sectors out (or give the same N)")
        a, b = (np.asarray(p, dtype=float) * unit for p in deck["axis"])
        try:
            axis = RotationAxis(a, b - a)
        except ValueError as exc:
            raise StudyError(f"the deck's *CYCLIC SYMMETRY MODEL axis ({deck['where']}): {exc}") from None
        faces, tol, where = (deck["left"], deck["right"]), deck.get("tol"), f"the deck ({deck['where']})"
        if deck.get("problem") and cy["left"] is None:
            raise StudyError(f"[cyclic] left, right: {deck['problem']} ({deck['where']})")
    else:
        n = cy["sectors"]
        if n is None:
            raise StudyError("[cyclic] sectors: required for a sector mesh without *CYCLIC SYMMETRY MODEL (N, the "
                             "number of sectors of the disk, >= 2)")
        r = study.config.get("rotation") or {}
        if r.get("axis") is None:
            raise StudyError("[rotation] axis: required for a cyclic study on a mesh file without *CYCLIC SYMMETRY "
                             "MODEL (the engine axis the sectors turn about: {origin = [x, y, z], direction = "
                             "[dx, dy, dz]}, m)")
        axis, faces, tol, where = RotationAxis(r["axis"]["origin"], r["axis"]["direction"]), (None, None), None, ""
    if cy["left"] is not None:
        faces, where = (cy["left"], cy["right"]), ""
    tol = cy["tol"] if cy["tol"] is not None else tol
    check_diameters(cy, n)
    for key, name in zip(("left", "right"), faces):
        if name is not None and name not in mesh.groups:
            whose = f"{where} names the {key} cyclic face {name!r}" if where else f"[cyclic] {key}: {name!r}"
            raise StudyError(f"{whose}, but the mesh {mesh.source} has no such node group (groups: "
                             f"{', '.join(sorted(mesh.groups)) or 'none'})")
    r = study.config.get("rotation") or {}
    if r.get("axis") is not None and (r.get("speeds") or r.get("speed") is not None):
        given = RotationAxis(r["axis"]["origin"], r["axis"]["direction"])
        off = np.linalg.norm(np.cross(given.origin - axis.origin, axis.direction))
        size = max(1.0, float(np.abs(mesh.points).max()))
        if abs(abs(float(given.direction @ axis.direction)) - 1) > 1e-9 or off > 1e-9 * size:
            raise StudyError(f"[rotation] axis: the disk turns about its cyclic axis (origin {axis.origin.tolist()}, "
                             f"direction {axis.direction.tolist()}, from {where or 'the study'}); got {r['axis']}")
    return {"sectors": n, "axis": axis, "left": faces[0], "right": faces[1], "tol": tol}


def _clamp_images(study: Study, mesh, setup: dict):
    """The clamp with the images, on the other cyclic face, of its face nodes (a deck clamps the independent face
    only: the tie carries the clamp to the dependent one, as CalculiX does)."""
    if setup["left"] is None:
        return study, mesh
    clamp = study["fem"]["clamp"]
    held = (mesh.group(clamp) if isinstance(clamp, str)
            else selected_nodes(study, mesh, clamp, "[fem] clamp", allow_all=False))
    left, right = mesh.group(setup["left"]), mesh.group(setup["right"])
    ax, alpha = setup["axis"], 2 * math.pi / setup["sectors"]
    R = rotation_matrix(ax.direction, alpha)
    radius = float(sector_angles(mesh.points, ax)[0].max())
    tol = 1e-6 * radius if setup["tol"] is None else setup["tol"] * LENGTH_UNITS.get(mesh.unit, 1.0)
    from scipy.spatial import cKDTree

    add = []
    for a, b, rot in ((left, right, R), (right, left, R.T)):
        src = np.intersect1d(a, held)
        if src.size and b.size:
            moved = (mesh.points[src] - ax.origin) @ rot.T + ax.origin
            d, j = cKDTree(mesh.points[b]).query(moved)
            add.append(b[j[d <= tol]])
    extra = np.setdiff1d(np.concatenate(add) if add else np.zeros(0, dtype=np.int64), held)
    if not extra.size:
        return study, mesh
    name = f"{clamp if isinstance(clamp, str) else 'clamp'}+cyclic"
    mesh = dataclasses.replace(mesh, groups={**mesh.groups, name: np.union1d(held, extra)})
    log.info("[fem] clamp: %d node(s) of the other cyclic face clamped with their images (the tie carries the "
             "clamp): group %r", extra.size, name)
    return _with_clamp(study, name), mesh


def _safe_speed(study: Study) -> float | None:
    """The SAFE diagram's speed (rad/s), ``None``: at rest."""
    cy, r = study["cyclic"], study.config.get("rotation") or {}
    unit = r.get("speed_unit") or "rpm"
    if cy["speed"] is not None:
        return to_rad_s(cy["speed"], unit)
    if r.get("speed") is not None:
        return to_rad_s(r["speed"], unit)
    return to_rad_s(max(r["speeds"]), unit) if r.get("speeds") else None


def engine_order_table(frequencies: dict, sectors: int, speed: float | None, orders) -> list[dict]:
    """Per engine order: the nodal diameter it excites, its frequency at ``speed`` (rad/s), and each mode of that
    diameter with the speed at which the order meets it and how near it is at ``speed``.

    >>> rows = engine_order_table({0: [100.0], 1: [120.0], 2: [150.0]}, 4, 2 * math.pi * 50, [1, 3])
    >>> [(r["order"], r["diameter"], r["frequency_hz"]) for r in rows]
    [(1, 1, 50.0), (3, 1, 150.0)]
    >>> rows[1]["modes"][0]["crossing_rpm"], rows[1]["modes"][0]["margin"]
    (2400.0, 0.25)
    """
    out = []
    for e in orders:
        k = engine_order_diameter(e, sectors)
        fe = e * speed / (2 * math.pi) if speed else None
        modes = []
        for j, f in enumerate(np.asarray(frequencies.get(k, []), dtype=float).tolist()):
            modes.append({"mode": j + 1, "frequency_hz": f, "crossing_rpm": 60.0 * f / e,
                          "margin": None if fe is None else (fe - f) / f})
        out.append({"order": int(e), "diameter": k, "frequency_hz": fe, "modes": modes,
                    "near": [m["mode"] for m in modes if m["margin"] is not None and abs(m["margin"]) <= NEAR]})
    return out


def _csv(spectrum: dict) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["nd", "mode", "frequency_hz", "multiplicity"])
    for k, m in spectrum.items():
        for j, f in enumerate(m.frequencies):
            w.writerow([k, j + 1, repr(float(f)), m.multiplicity])
    return buf.getvalue()


def _expand(study: Study, staging: Path, mesh, model, sector, spectrum: dict, spec: dict) -> dict:
    """``vtk/annulus_<stem>.pvd``: one period of the expanded mode on the whole disk (module docstring)."""
    from ...fe.cyclic_waves import annulus_field, annulus_mesh, annulus_nodes
    from ...post.vtk import write_time_series

    k, j, wave = spec["diameter"], spec["mode"] - 1, spec["wave"]
    modes = spectrum[k]
    disk, index = annulus_mesh(mesh, sector)
    frames = study["output"]["frames"]
    tau = 2 * math.pi * np.arange(frames + 1) / frames
    omega = float(np.sqrt(modes.lam[j]))
    u = np.stack([annulus_nodes(model, annulus_field(sector, modes, j, wave, phase=t), index) for t in tau], axis=-1)
    v = omega * np.stack([annulus_nodes(model, annulus_field(sector, modes, j, wave, phase=t + math.pi / 2), index)
                          for t in tau], axis=-1)
    top = float(np.linalg.norm(u, axis=1).max())
    scale = 0.05 * float(np.ptp(disk.points, axis=0).max()) / top if top > 0 else 1.0
    period = 2 * math.pi / omega
    stem = f"annulus_nd{k}_mode{j + 1}_{wave}"
    pvd = write_time_series(staging / "vtk", stem, disk, tau / (2 * math.pi) * period, scale * u, scale * v,
                            field_data={"period": period, "frequency_hz": omega / (2 * math.pi),
                                        "nodal_diameter": float(k), "scale": scale})
    log.info("the whole disk (%d nodes) with mode %d of nodal diameter %d as a %s wave: %s (%d frames over a period)",
             len(disk.points), j + 1, k, wave, pvd.name, frames)
    return {"file": f"vtk/{pvd.name}", "diameter": k, "mode": j + 1, "wave": wave, "frames": frames,
            "frequency_hz": omega / (2 * math.pi), "disk_nodes": len(disk.points), "scale": scale}


def compute_cyclic(study: Study, staging: Path, stage, progress: bool, executor: Executor,
                   deck: dict | None = None) -> tuple[dict, list, dict]:
    """The cyclic stage (module docstring), writing into ``staging``; returns the summary (without timings), no
    families and no models, as the run's own ``_compute``."""
    o, cy = study["output"], study["cyclic"]
    files: dict[str, object] = {}
    with stage("mesh"):
        geometry = None
        if study.parametric:
            study, mesh, geometry = _sector_mesh(study)
        else:
            mesh = _file_mesh(study)
        setup = _setup(study, mesh, deck, geometry)
        study, mesh = _clamp_images(study, mesh, setup)
        write_mesh(mesh, staging, files, "gmsh" if study.parametric else mesh.source, "sector mesh",
                   f"; a disk of {setup['sectors']} sectors")
    with stage("assemble"):
        model = build_model(study, mesh)
        sector = fe_sector(model, setup["sectors"], setup["axis"], left=setup["left"], right=setup["right"],
                           tol=setup["tol"])
        log.info("cyclic faces: %d matched node pairs (%s)", len(sector.pairs),
                 f"groups {setup['left']!r} and {setup['right']!r}" if setup["left"] else "found by the sector angle")
    n = setup["sectors"]
    ks = cy["diameters"] or nodal_diameters(n)
    speed = _safe_speed(study)
    with stage("cyclic"):
        solved = sector
        static = (study.config.get("rotation") or {}).get("static", "auto")
        if (speed or (study.config.get("rotation") or {}).get("speeds")) and static in ("second-order", "nonlinear"):
            log.warning("[rotation] static = %r: a disk's centrifugal state is its linear prestress (stress stiffening "
                        "and spin softening about the linear static state, the sector's faces tied)", static)
        if speed:
            from ...fe.cyclic_spin import cyclic_spin

            solved = cyclic_spin(model, sector, speed).sector
        spectrum = cyclic_spectrum(solved, cy["modes"], diameters=sorted(ks))
        for k, m in spectrum.items():
            log.info("nodal diameter %d: %s Hz (×%d, %d unknowns, %.2f s)", k,
                     ", ".join(f"{f:.2f}" for f in m.frequencies), m.multiplicity, m.size, m.seconds)
        write_text(staging / "cyclic.csv", _csv(spectrum))
        files["cyclic"] = "cyclic.csv"
        freq = {k: m.frequencies for k, m in spectrum.items()}
        orders = (cy["engine_orders"] or (study.config.get("rotation") or {}).get("engine_orders")
                  or list(range(1, n + 1)))
        table = engine_order_table(freq, n, speed, orders)
        if "png" in o["formats"]:
            from ...post.disk.safe_plot import safe_figure

            save_figure(safe_figure(freq, n, speed=speed, title=f"{study.name}: SAFE diagram, {n} sectors"),
                        staging / "safe.png", dpi=150)
            files["safe"] = "safe.png"
        expanded = None
        if "vtu" in o["formats"]:
            expanded = _expand(study, staging, mesh, model, solved, spectrum, expand_spec(cy, n))
            files["annulus"] = expanded["file"]
    nonsmooth = None
    if cy["nonsmooth"]:
        from .nonsmooth import compute_disk_modes

        with stage("nonsmooth"):
            nonsmooth = compute_disk_modes(study, staging, files, model=model, sector=solved)
    disk_rub = None
    if (study.config.get("rub") or {}).get("speeds"):
        from .rub import compute_disk_rub

        with stage("rub"):
            disk_rub = compute_disk_rub(study, staging, files, model=model, sector=solved, executor=executor,
                                        progress=progress)
    mistuning = None
    if mistuning_requested(study.config):
        from .mistuning import compute_mistuning

        with stage("mistuning"):
            mistuning = compute_mistuning(study, staging, files, fe_model=model, mesh=mesh, sector=solved,
                                          axis=setup["axis"], geometry=geometry, executor=executor, progress=progress,
                                          spectrum=spectrum)
    campbell = None
    r = study.config.get("rotation") or {}
    if r.get("speeds"):
        with stage("campbell"):
            campbell = _campbell(study, model, sector, ks, staging, files)
    files["log"] = "run.log"
    from ... import __version__

    lowest = np.sort(np.concatenate([np.repeat(m.frequencies, m.multiplicity) for m in spectrum.values()]))
    section = {
        "sectors": n, "axis": {"origin": setup["axis"].origin.tolist(), "direction": setup["axis"].direction.tolist()},
        "faces": {"left": setup["left"], "right": setup["right"], "pairs": int(len(sector.pairs)),
                  "from": "deck" if deck is not None and not cy["left"] else "study" if cy["left"]
                  else "geometry" if geometry is not None else "sector angle"},
        "speed_rad_s": speed, "speed_rpm": None if speed is None else speed * 60 / (2 * math.pi),
        "diameters": [{"nd": k, "frequencies_hz": m.frequencies.tolist(), "multiplicity": m.multiplicity,
                       "unknowns": m.size, "seconds": m.seconds} for k, m in spectrum.items()],
        "engine_orders": table, "expanded": expanded, "campbell": campbell, "nonsmooth": nonsmooth,
        "rub": disk_rub,
    }
    summary = {
        "study": study.name, "source": study.source, "bladecase_version": __version__,
        "model": model_summary(mesh, model, lowest[:study["fem"]["frequencies"]],
                               "gmsh (parametric [geometry])" if study.parametric else str(study.mesh_path())),
        "contact": None, "rotation": None, "campbell": None, "reduction": None, "reference": None,
        "compare": [], "search": None, "families": [], "forcing": None, "rub": None, "casing_sweep": None,
        "nodal_modes": None, "comparison": None, "convergence": None, "validity": None, "cyclic": section,
        "mistuning": mistuning, "files": files,
    }
    return summary, [], {}


def _campbell(study: Study, model, sector, ks, staging: Path, files: dict) -> dict:
    """The Campbell diagram of every nodal diameter (:func:`~bladecase.fe.cyclic_spin.cyclic_campbell`) and
    ``campbell_nd.png``."""
    from ...fe.cyclic_spin import cyclic_campbell
    from ..rotation.stage import speeds

    w = speeds(study)
    count = study["cyclic"]["modes"]
    table = cyclic_campbell(model, sector, w, count=count, diameters=sorted(ks))
    if "png" in study["output"]["formats"]:
        from ...post.disk.safe_plot import campbell_nd_figure

        orders = study["rotation"]["engine_orders"] or study["cyclic"]["engine_orders"]
        save_figure(campbell_nd_figure(w, table, sector.sectors, orders=orders,
                                       title=f"{study.name}: Campbell diagram per nodal diameter"),
                    staging / "campbell_nd.png", dpi=150)
        files["campbell_nd"] = "campbell_nd.png"
    return {"speeds_rad_s": w.tolist(), "frequencies_hz": {str(k): v.tolist() for k, v in table.items()}}
