"""The mesh error of a study's headline figures: ``[convergence] meshes = [1, 0.7, 0.5]``.

The study is run again — mesh, FE model, contact, reduced model, search — on meshes whose element sizes are the
study's times each factor (``[geometry] size`` and ``tip_size``), with the same reduction and search, and the same
figures are read on each mesh at the same places:

* ``f1_hz``: the FE model's first natural frequency (at the operating speed with ``[rotation]``);
* ``band_lo_hz``, ``band_hi_hz``: the main family's admissible band (the family with the widest admissible arc,
  as the report's first line reads it);
* at one period ratio ``T/T₁`` (each mesh's own ``T₁``; the study's animated orbit's ratio, else the middle of the
  widest arc, or ``[convergence] ratio``), the backbone's admissible orbit of least energy: ``energy_j``,
  ``tip_amplitude_mm``, ``contact_force_n`` (the total normal force on the contact) and ``contact_fraction``.

A study that reads its mesh from a file (``[mesh] path``) is refined by splitting every cell
(:func:`bladecase.fe.refine_mesh`): each edge in ``n = round(1/factor)`` parts (0.5 → 2, each edge halved; 0.33 →
3), the new nodes on the cells' own (curved) isoparametric map, the named groups and so the contact face carried.
The sizes actually used, ``1/n``, are the ``h`` of the order and the extrapolation (``meshes`` in the summary; the
factors asked for are its ``requested``, the parts per edge its ``splits``).

For each figure, with ``h`` the element-size ratios, the grid convergence index (GCI; Roache 1998, in the
procedure of Celik et al. 2008, J. Fluids Eng. 130, 078001, and ASME V&V 20):

* **order established** — the three finest meshes converge monotonically (same sign of both changes) with an
  observed order ``p`` (``f = f₀ + C hᵖ`` solved exactly for unequal refinement ratios) in
  :data:`ORDER_RANGE`: the Richardson extrapolation ``f₀`` and the error of the study's own mesh
  ``1.25 |f(h_study) − f₀|`` (:data:`SAFETY`, Roache's factor when three meshes establish the order), relative to
  ``f₀``;
* **order not established** — oscillatory convergence (the changes alternate in sign: "not monotone"), changes
  that do not shrink under refinement (no positive order), or an order outside :data:`ORDER_RANGE` (the meshes are
  not in the asymptotic range): no extrapolation, and the error ``3 Δ`` (:data:`SAFETY_UNESTABLISHED`, Roache's
  factor when the order cannot be established), with ``Δ`` the range of the figure over all the meshes (the largest
  difference between two of them: the data range of Eça and Hoekstra's procedure), relative to the finest mesh's
  value.

Nothing here is fitted to a particular study: the two factors and the order range are the published rule's.

An estimate above :data:`FLAG` (2 %) is flagged in the report and the verdict.

>>> row = richardson([1.0, 0.7, 0.5], [210.5, 212.479, 213.094])
>>> round(row["order"], 2), round(row["extrapolated"], 2), round(100 * row["error"], 2)
(3.19, 213.41, 1.71)
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from ... import log
from ...fe import splits_for
from ..schema import Study, StudyError

__all__ = ["FIGURES", "FLAG", "SAFETY", "SAFETY_UNESTABLISHED", "convergence_stage", "estimate_words", "mesh_figures",
           "mesh_row", "mesh_size", "refined_mesh", "richardson", "scaled_study"]

#: An error estimate (relative) above which a figure is flagged.
FLAG = 0.02
#: Roache's safety factor of the grid-convergence index when three meshes establish the observed order.
SAFETY = 1.25
#: Roache's safety factor when they do not (oscillatory convergence, an order outside :data:`ORDER_RANGE`).
SAFETY_UNESTABLISHED = 3.0
#: Observed orders outside this range are not trusted (the meshes are not in the asymptotic range).
ORDER_RANGE = (0.5, 8.0)

#: The figures compared: key → (words, unit).
FIGURES = {
    "f1_hz": ("first natural frequency", "Hz"),
    "band_lo_hz": ("admissible band, lower end", "Hz"),
    "band_hi_hz": ("admissible band, upper end (below a resonance tongue)", "Hz"),
    "energy_j": ("energy at the ratio", "J"),
    "tip_amplitude_mm": ("tip amplitude at the ratio", "mm"),
    "contact_force_n": ("total contact force at the ratio", "N"),
    "contact_fraction": ("share of the period in contact at the ratio", ""),
}


def _order(h: Sequence[float], f: Sequence[float]) -> float | None:
    """The order ``p`` of ``f = f₀ + C hᵖ`` through three points (``h`` decreasing), ``None`` if not monotone."""
    from scipy.optimize import brentq

    (h1, h2, h3), (f1, f2, f3) = h, f
    d21, d32 = f2 - f1, f3 - f2
    if d32 == 0.0 or d21 == 0.0 or (d21 > 0) != (d32 > 0):
        return None
    ratio = d21 / d32

    def g(p: float) -> float:
        return (h1 ** p - h2 ** p) / (h2 ** p - h3 ** p) - ratio

    lo, hi = 1e-3, 30.0
    if g(lo) > 0 or g(hi) < 0:
        return None
    return float(brentq(g, lo, hi, xtol=1e-10))


def richardson(h: Sequence[float], values: Sequence[float | None], study_h: float | None = None) -> dict:
    """Observed order, Richardson extrapolation and the error estimate of one figure over meshes of sizes ``h``
    (any order; the three finest are used), for the mesh of size ``study_h`` (default the coarsest: the study's).

    Returns ``{"order", "extrapolated", "error", "monotone", "regime", "safety", "flag"}``: ``error`` the grid
    convergence index of the module, relative to the extrapolated value (or to the finest value when there is none);
    ``safety`` its factor, 1.25 (order established) or 3 (not); ``regime`` why: ``"asymptotic"`` (an order in
    :data:`ORDER_RANGE`), ``"oscillating"`` (not monotone), ``"not shrinking"`` (monotone, but the last change is
    not smaller than any positive order allows), ``"order out of range"``; ``None`` everywhere when fewer than three
    meshes have the figure.

    >>> r = richardson([0.5, 1.0, 0.7], [4.0 + 2 * 0.5**2, 6.0, 4.0 + 2 * 0.7**2], study_h=1.0)  # f = 4 + 2h²
    >>> round(r["order"], 9), round(r["extrapolated"], 9), round(r["error"], 9), r["flag"]
    (2.0, 4.0, 0.625, True)
    >>> r = richardson([1.0, 0.7, 0.5], [10.0, 10.4, 10.1])   # oscillates: 3 × the range 0.4, over 10.1
    >>> r["monotone"], r["order"], r["safety"], round(r["error"], 6)
    (False, None, 3.0, 0.118812)
    """
    pairs = sorted(((float(a), float(v)) for a, v in zip(h, values) if v is not None and math.isfinite(v)),
                   reverse=True)
    out = {"order": None, "extrapolated": None, "error": None, "monotone": None, "regime": None, "safety": None,
           "flag": None}
    if len(pairs) < 3:
        return out
    hs, fs = zip(*pairs)
    study_h = hs[0] if study_h is None else float(study_h)
    at = dict(pairs).get(study_h, fs[0])
    d21, d32 = fs[-2] - fs[-3], fs[-1] - fs[-2]
    monotone = d21 != 0.0 and d32 != 0.0 and (d21 > 0) == (d32 > 0)
    p = _order(hs[-3:], fs[-3:])
    if p is not None and ORDER_RANGE[0] <= p <= ORDER_RANGE[1]:
        h2, h3 = hs[-2], hs[-1]
        f0 = fs[-1] - (fs[-2] - fs[-1]) * h3 ** p / (h2 ** p - h3 ** p)
        scale = abs(f0) or abs(fs[-1]) or 1.0
        error = SAFETY * abs(at - f0) / scale
        out.update(order=p, extrapolated=f0, error=error, monotone=True, regime="asymptotic", safety=SAFETY)
    else:  # the order is not established: Roache's factor 3 on the data range
        spread = max(fs) - min(fs)
        scale = abs(fs[-1]) or 1.0
        h1, h2, h3 = hs[-3:]
        shrinking = monotone and d21 / d32 > math.log(h1 / h2) / math.log(h2 / h3)  # the ratio as the order → 0
        regime = "oscillating" if not monotone else "order out of range" if shrinking else "not shrinking"
        out.update(order=p, error=SAFETY_UNESTABLISHED * spread / scale, monotone=monotone, regime=regime,
                   safety=SAFETY_UNESTABLISHED)
    out["flag"] = out["error"] > FLAG
    return out


def estimate_words(figure: dict) -> str:
    """How a figure's error was estimated, in words: ``""`` when the order is established (1.25 × the distance from
    the Richardson extrapolation), else why not and the rule used instead.

    >>> estimate_words(richardson([1.0, 0.7, 0.5], [10.0, 10.4, 10.1]))
    'not monotone: 3 × the range over the meshes'
    >>> estimate_words(richardson([1.0, 0.7, 0.5], [10.0, 10.1, 10.5]))   # the second change is the larger
    'the changes do not shrink with the mesh: 3 × the range over the meshes'
    >>> estimate_words(richardson([1.0, 0.7, 0.5], [1.0, 1.5, 1.6]))   # order 4.4: established
    ''
    """
    if figure.get("safety") != SAFETY_UNESTABLISHED:
        return ""
    why = {"oscillating": "not monotone", "not shrinking": "the changes do not shrink with the mesh"}.get(
        figure.get("regime"), f"observed order {figure.get('order') or 0:.2g} outside {ORDER_RANGE[0]:g}–"
        f"{ORDER_RANGE[1]:g}")
    return f"{why}: 3 × the range over the meshes"


# ----------------------------------------------------------------------------- the meshes

def _quiet(study: Study) -> dict:
    """``study``'s config searching as the study does and writing nothing (no figures, animations, reference model,
    sweeps)."""
    config = {k: (dict(v) if isinstance(v, dict) else v) for k, v in study.config.items()}
    config["output"] = dict(config["output"], formats=[], animate=0, orbits=[], reference=False)
    for section in ("convergence", "rub", "forcing"):
        config.pop(section, None)
    if config.get("rotation"):
        config["rotation"] = dict(config["rotation"], speeds=[])
    return config


def scaled_study(study: Study, factor: float) -> Study:
    """``study`` on a mesh ``factor`` times as fine (element sizes × ``factor``), searching as the study does and
    writing nothing (no figures, animations, reference model, sweeps). A ``[mesh]`` file study is refined by
    :func:`refined_mesh` instead.

    >>> from bladecase.study.demo import demo_study
    >>> s = scaled_study(demo_study(), 0.5)
    >>> g = demo_study()["geometry"]
    >>> round(s["geometry"]["size"] / g["size"], 12), round(s["geometry"]["tip_size"] / g["tip_size"], 12)
    (0.5, 0.5)
    """
    if not study.parametric:
        raise StudyError("scaled_study: the study reads the mesh file [mesh] path; its finer meshes split the "
                         "file's cells (refined_mesh), they do not scale [geometry]")
    config = _quiet(study)
    g = config["geometry"]
    size = g["size"] if g["size"] is not None else study.geometry().default_size()
    g["size"] = size * factor
    if g.get("tip_size") is not None:
        g["tip_size"] = g["tip_size"] * factor
    return dataclasses.replace(study, config=config)


def mesh_size(study: Study, factor: float) -> float:
    """The element-size ratio actually used for ``factor``: ``factor`` itself for a ``[geometry]`` study, ``1/n``
    for a ``[mesh]`` file split in ``n`` parts per edge (:func:`bladecase.fe.refine.splits_for`).

    >>> from bladecase.study.demo import demo_study
    >>> mesh_size(demo_study(), 0.7)
    0.7
    """
    return float(factor) if study.parametric else 1.0 / splits_for(factor)


def refined_mesh(study: Study, factor: float):
    """The study (quiet, as :func:`scaled_study`) and its mesh file's mesh with every cell split in
    ``splits_for(factor)`` parts per edge (:func:`bladecase.fe.refine.refine_mesh`: the cells' own isoparametric
    map, the named groups — the contact face among them — carried)."""
    from ...fe import refine_mesh
    from ..stages import build_mesh

    quiet = dataclasses.replace(study, config=_quiet(study))
    n = splits_for(factor)
    mesh = refine_mesh(build_mesh(quiet), n)
    log.info("mesh %s: every edge split in %d (element size × 1/%d for the factor %g): %d nodes, %d cells", mesh.source,
             n, n, factor, len(mesh.points), len(mesh.cells[mesh.body_type]))
    return quiet, mesh


def mesh_figures(model, reduced, families, f1_hz: float, ratio: float | None, ipp: int) -> dict:
    """The figures of one mesh (see the module): ``model`` the FE model at the analysis' speed, ``reduced`` its
    reduced model and ``families`` the search's branches."""
    from ..documents import family_summary
    from ..render import orbit_engineering

    out: dict = {"dofs": int(model.n_dofs), "f1_hz": float(f1_hz)}
    arcs = [(i, a) for i, f in enumerate(families) for a in family_summary(f)["admissible_arcs"]]
    if arcs:
        main = max(arcs, key=lambda x: (x[1]["f_hi"] - x[1]["f_lo"]) / x[1]["f_hi"])[0]
        mine = family_summary(families[main])["admissible_arcs"]
        out.update(band_lo_hz=min(a["f_lo"] for a in mine),  # up to a resonance tongue: where it is robust
                   band_hi_hz=max(a.get("backbone_f_hi", a["f_hi"]) for a in mine))
    if ratio is None:
        return out
    T1 = 2 * np.pi / float(reduced.system.spectrum.contact_modes[0][0])
    T = ratio * T1
    orbits = []
    for fam in families:
        if fam.k != ipp:
            continue
        try:
            orbits += [o for o in fam.orbit_at(T) if o.admissible]
        except ValueError:
            continue
    if orbits:
        o = min(orbits, key=lambda o: o.energy)
        e = orbit_engineering(reduced, o)
        out.update(energy_j=float(o.energy), tip_amplitude_mm=e["tip_amplitude_mm"],
                   contact_force_n=e.get("contact_force_n"), contact_fraction=e.get("contact_fraction"))
    return out


def mesh_row(study: Study, factor: float, ratio: float | None, ipp: int) -> dict:
    """The figures of ``study`` run by itself on its mesh × ``factor`` (:func:`scaled_study`; the study's own
    search), read at ``T/T₁ = ratio`` on the ``ipp`` family: one row of the convergence table (``factor``, ``dofs``
    and the keys of :data:`FIGURES` that this mesh has).

    >>> from bladecase.study.schema import loads
    >>> strip = loads('study = {name = "s"}\\ngeometry = {kind = "plate", span = 0.1, chord = 0.02, size = 0.01}\\n'
    ...               'fem = {order = 1, thickness = 0.002}\\ncontact = {clearance = 1e-4, model = "massless", '
    ...               'casing_stiffness = 1e6, face = "tip", normal = [1.0, 0.0]}\\n'
    ...               'reduction = {method = "massless", size = 4}\\n'
    ...               'search = {ipp = [1], periods = [0.95, 1.0], scan = 4}\\n')
    >>> row = mesh_row(strip, 0.5, None, 1)
    >>> row["factor"], row["dofs"] > 0, round(row["f1_hz"], -1) > 0
    (0.5, True, True)
    """
    return _mesh_task(factor, study=study, ratio=ratio, ipp=ipp)


def _mesh_task(factor: float, *, study: Study, ratio: float | None, ipp: int) -> dict:
    """One mesh of the convergence study (a module-level task for the executor)."""
    from ...fe import natural_frequencies, stiffness_factor
    from ..rotation.stage import operating_point
    from ..stages import build_contact, build_mesh, build_model, build_reduced, search

    if study.parametric:
        s = scaled_study(study, factor)
        mesh = build_mesh(s)
    else:
        s, mesh = refined_mesh(study, factor)
    model = build_model(s, mesh)
    factor_k = stiffness_factor(model)
    contact = build_contact(s, model)
    model, contact, factor_k, _ = operating_point(s, model, contact, factor_k)
    f1 = float(natural_frequencies(model, 1, factor=factor_k)[0])
    reduced = build_reduced(s, model, contact, factor=factor_k)
    families = search(s, reduced.system, progress=False)
    return {"factor": float(factor), "size": mesh_size(study, factor),
            **mesh_figures(model, reduced, families, f1, ratio, ipp)}


def convergence_stage(study: Study, main: dict, ratio: float | None, ipp: int, executor, progress: bool = False
                      ) -> dict:
    """The ``convergence`` section of the summary: ``main`` the figures of the study's own mesh
    (:func:`mesh_figures`, factor 1), the other meshes run through ``executor`` (one task per mesh)."""
    c = study["convergence"]
    factors = sorted({float(x) for x in c["meshes"]}, reverse=True)
    others = [x for x in factors if x != 1.0]
    rows = executor.map(_mesh_task, others, shared={"study": study, "ratio": ratio, "ipp": ipp},
                        desc="meshes", progress=progress)
    by_factor = {1.0: {"factor": 1.0, "size": 1.0, **main}, **{r["factor"]: r for r in rows}}
    table = [by_factor[x] for x in sorted(by_factor, reverse=True)]
    h = [r["size"] for r in table]  # the sizes used: with a mesh file, 1/n (n parts per edge), not the factors
    figures = {}
    for key in FIGURES:
        values = [r.get(key) for r in table]
        if all(v is None for v in values):
            continue
        words, unit = FIGURES[key]
        if ratio is not None:
            words = words.replace("at the ratio", f"at T/T₁ = {ratio:.4g}")
        figures[key] = {"words": words, "unit": unit, "values": values, **richardson(h, values, study_h=1.0)}
    flagged = [k for k, f in figures.items() if f["flag"]]
    for k in flagged:
        f = figures[k]
        how = estimate_words(f)
        log.warning("mesh convergence: %s is off its mesh-converged value by up to %.2g %% on the study's mesh%s",
                    f["words"], 100 * f["error"], f" ({how})" if how else "")
    out = {"meshes": h, "dofs": [r["dofs"] for r in table], "ratio": ratio, "ipp": ipp, "flag": FLAG,
           "rows": table, "figures": figures, "flagged": flagged}
    if not study.parametric:
        out.update(refinement="split", requested=[r["factor"] for r in table], splits=[round(1 / x) for x in h])
    return out
