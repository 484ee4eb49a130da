"""Figures of a comparison study (issue 12): every model on shared axes, convergence with size, the contact spectrum.

- :func:`overlay_plot` — energy against frequency of every model's admissible arcs, one colour per model;
- :func:`convergence_plot` — the energies at the common periods against the size, per method;
- :func:`spectral_plot` — the contact spectral measure ``b_j²`` at ``ω_j/2π``, FE and each model: the picture
  that explains why models disagree (what each keeps of the FE's impact mass and compliance).

Matplotlib :class:`~matplotlib.figure.Figure` objects (:func:`bladecase.post.plots.new_figure`), never pyplot.
Every mark has a legend entry; units on every axis (SI by default: ``time_unit="s"``, ``energy_unit="J"``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .compare import FEReference, ModelResult, contact_spectrum, model_matches
from .plots import axis_labels, new_figure

__all__ = ["convergence_plot", "observed_order", "overlay_plot", "spectral_plot"]

#: Line style and narrow-arc marker per number of impacts per period (cycled).
STYLES = (("-", "o"), ("--", "s"), ("-.", "^"), (":", "D"))


def _colour(i: int, n: int) -> str | tuple:
    if n <= 10:
        return f"C{i}"
    from matplotlib import colormaps

    return colormaps["tab20"](i % 20)


def _arcs(entry: ModelResult) -> list[tuple[int, np.ndarray, np.ndarray]]:
    """``(k, 1/T, E)`` of the computed admissible points of every arc of the model."""
    out = []
    for br in entry.branches:
        T, E, adm = br.T, br.energy, br.admissible
        for a in br.arcs:
            sl = slice(a.start, a.stop + 1)
            ok = adm[sl] & np.isfinite(E[sl]) & (E[sl] > 0)
            if ok.any():
                out.append((br.k, 1.0 / T[sl][ok], E[sl][ok]))
    return out


def _limits(ax, arcs: list, linear: np.ndarray) -> None:
    f = np.concatenate([a[1] for a in arcs]) if arcs else linear
    E = np.concatenate([a[2] for a in arcs]) if arcs else np.array([1.0])
    if f.size:
        pad = 0.05 * max(f.max() - f.min(), 0.05 * f.max())
        ax.set_xlim(f.min() - pad, f.max() + pad)
    ax.set_ylim(E.min() / 3, E.max() * 3)


def overlay_plot(results: Sequence[ModelResult], fe: FEReference | None = None, *, ax=None,
                 nonadmissible: bool = False, linear: bool = True, min_px: float = 1.0, title: str | None = None,
                 time_unit: str | None = "s", energy_unit: str | None = "J"):
    """Every model's nonsmooth modes on ONE pair of axes: energy (log) against frequency ``1/T``.

    One colour per model, one line style per number of impacts per period. Admissible arcs are curves through
    their computed points; an arc spanning less than ``min_px`` pixels (both ways) is a marker at its middle;
    non-admissible orbits are faint dots when ``nonadmissible``. ``linear``: the FE linear frequencies (else the
    first model's) in range, dashed, each labelled with its mode number. Every kind of mark has a legend entry
    naming its model.

    >>> from bladecase.nsm import backbone
    >>> from bladecase.reduction import Contact, reduce
    >>> from skfem import MeshTri
    >>> from bladecase.fe import Mesh, assemble
    >>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 11), np.linspace(0, 0.02, 3))
    >>> p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    >>> strip = assemble(Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 0] == 0)}),
    ...                  "steel", order=1, thickness=0.002)
    >>> r = reduce(strip, Contact.nearest(strip, (0.1, 0.02), normal=(0.0, 1.0), gap=1e-4), "modal", 3)
    >>> T1 = 2 * np.pi / r.system.spectrum.omega[0]
    >>> fig = overlay_plot([ModelResult(r, [backbone(r.system, np.linspace(0.9, 0.999, 12) * T1)])])
    >>> fig.axes[0].get_legend_handles_labels()[1]
    ['modal-3: 1 ipp, admissible (2 arcs)', 'linear frequencies (modal-3)']
    """
    xlabel, ylabel = axis_labels(time_unit, energy_unit)
    results = list(results)
    fig, ax = (new_figure(figsize=(8.5, 5.0), layout="constrained"), None) if ax is None else (ax.figure, ax)
    ax = ax or fig.add_subplot()
    arcs = {e.name: _arcs(e) for e in results}
    lin_src = fe.frequencies if fe is not None else (
        contact_spectrum(results[0].reduced).frequencies if results else np.array([]))
    ax.set_yscale("log")
    _limits(ax, [a for v in arcs.values() for a in v], np.asarray(lin_src, float))
    for i, e in enumerate(results):
        c = _colour(i, len(results))
        if nonadmissible:
            for br in e.branches:
                bad = ~br.admissible & np.isfinite(br.energy) & (br.energy > 0)
                ax.plot(br.frequencies[bad], br.energy[bad], ".", ms=2, color=c, alpha=0.25,
                        label=f"{e.name}: non-admissible orbits" if bad.any() else None)
        _draw_arcs(ax, e.name, arcs[e.name], c, min_px)
    if linear:
        _linear_lines(ax, np.asarray(lin_src, float), "FE" if fe is not None else results[0].name if results else "")
    if not any(arcs.values()):
        ax.text(0.5, 0.5, "no admissible arc in any model", transform=ax.transAxes, ha="center", va="center")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title or "Nonsmooth modes of the compared models")
    ax.grid(True, which="both", alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    return fig


def _draw_arcs(ax, name: str, arcs: list, colour, min_px: float) -> None:
    """Curves per k (NaN-separated), narrow arcs as markers: one legend entry each."""
    for k in sorted({a[0] for a in arcs}):
        ls, marker = STYLES[(k - 1) % len(STYLES)]
        curves, dots = [], []
        for _, f, E in (a for a in arcs if a[0] == k):
            px = ax.transData.transform(np.c_[f, E])
            (dots if f.size == 1 or np.ptp(px, axis=0).max() < min_px else curves).append((f, E))
        if curves:
            x = np.concatenate([np.r_[f, np.nan] for f, _ in curves])
            y = np.concatenate([np.r_[E, np.nan] for _, E in curves])
            ax.plot(x, y, ls, lw=1.8, color=colour,
                    label=f"{name}: {k} ipp, admissible ({len(curves)} arc{'s' if len(curves) > 1 else ''})")
        if dots:
            ax.plot([np.mean(f) for f, _ in dots], [np.exp(np.mean(np.log(E))) for _, E in dots], marker, ls="none",
                    ms=5, color=colour, mfc="none", label=f"{name}: {k} ipp, arcs narrower than a pixel ({len(dots)})")


def _linear_lines(ax, freqs: np.ndarray, source: str) -> None:
    lo, hi = ax.get_xlim()
    inside = np.flatnonzero((freqs >= lo) & (freqs <= hi))
    for n, j in enumerate(inside):
        ax.axvline(freqs[j], color="k", ls="--", lw=0.8, label=f"linear frequencies ({source})" if n == 0 else None)
        ax.text(freqs[j], 0.98, f" {j + 1}", transform=ax.get_xaxis_transform(), va="top", fontsize="small")


def observed_order(sizes, values) -> float | None:
    """Observed convergence order ``p`` of ``values`` (``E(s) ≈ E∞ + C s^-p``) from 3 or more sizes: minus the
    least-squares slope of ``log|E_{i+1} − E_i|`` against ``log s_{i+1}`` (exact for sizes in geometric
    progression); ``None`` with fewer than two non-zero changes.

    >>> s = np.array([8.0, 16.0, 32.0, 64.0])
    >>> round(observed_order(s, 2.0 + 5.0 * s**-1.5), 12)
    1.5
    """
    s, v = np.asarray(sizes, float), np.asarray(values, float)
    ok = np.isfinite(s) & np.isfinite(v)
    s, v = s[ok], v[ok]
    if s.size < 3:
        return None
    d = np.abs(np.diff(v[np.argsort(s)]))
    x = np.sort(s)[1:]
    keep = d > 0
    if keep.sum() < 2:
        return None
    return float(-np.polyfit(np.log(x[keep]), np.log(d[keep]), 1)[0])


def convergence_plot(rows: Sequence[dict], *, energy_unit: str | None = "J", title: str | None = None):
    """Energies at the common periods against the size, per method, log-log (rows of
    :func:`~bladecase.post.compare_table.comparison_rows` or of its CSV).

    Top: the energy ``E`` at each ``f × T1`` (one colour per method, one marker per period); bottom: the change
    from the previous size ``|ΔE|/E``, whose slope is the observed order (:func:`observed_order`, in the legend
    when computable). Models without a size (exact massless) and periods without an admissible orbit are left out.

    >>> rows = [{"method": "modal", "size": s, "energy_0.95T1": 2 + 5 * s**-2.0} for s in (8, 16, 32)]
    >>> convergence_plot(rows).axes[0].get_legend_handles_labels()[1]
    ['modal, 0.95 T1 (order 2.0)']
    """
    rows = [r for r in rows if r.get("method") != "fe" and r.get("size") is not None]
    columns = [k for k in (rows[0] if rows else {}) if k.startswith("energy_")]
    fig = new_figure(figsize=(7.0, 6.5), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True)
    methods = list(dict.fromkeys(r["method"] for r in rows))
    markers = "osD^v<>p*h"
    for i, method in enumerate(methods):
        mine = sorted((r for r in rows if r["method"] == method), key=lambda r: r["size"])
        for j, col in enumerate(columns):
            pts = [(r["size"], r[col]) for r in mine if r.get(col) is not None]
            if not pts:
                continue
            s, E = np.array(pts, dtype=float).T
            p = observed_order(s, E)
            at = col.removeprefix("energy_").replace("T1", " T1")
            label = f"{method}, {at}" + (f" (order {p:.1f})" if p is not None else "")
            style = dict(color=_colour(i, len(methods)), marker=markers[j % len(markers)])
            top.plot(s, E, "-", label=label, **style)
            if s.size >= 2:
                bottom.plot(s[1:], np.abs(np.diff(E)) / np.abs(E[1:]), "--", **style)
    if not top.lines:
        top.text(0.5, 0.5, "no admissible orbit at the common periods", transform=top.transAxes, ha="center")
    for ax in (top, bottom):
        if ax.lines:
            ax.set_xscale("log")
            ax.set_yscale("log")
        ax.grid(True, which="both", alpha=0.3)
    top.set_ylabel(axis_labels(None, energy_unit)[1])
    bottom.set_ylabel("change from the previous size |ΔE|/E")
    bottom.set_xlabel("size (modes, Lanczos steps or fixed-interface modes)")
    top.set_title(title or "Convergence with the model size")
    if top.lines:
        top.legend(fontsize="small")
    return fig


def spectral_plot(results: Sequence[ModelResult], fe: FEReference | None = None, *, ax=None,
                  time_unit: str | None = "s", mass_unit: str | None = "kg", title: str | None = None):
    """The contact spectral measure ``b_j²`` against ``ω_j/2π``, log-log: FE (black) and each model (one colour).

    Its sum is the inverse impact mass ``1/Σb²`` and, weighted by ``1/ω²``, the static compliance (the legend
    gives both, and the massless model's ``k_c``): a model that misses the FE's high-frequency weight keeps a
    heavier contact node. With ``fe``, modes with no FE counterpart (:func:`~.compare.model_matches`) are hollow
    and have their own legend entry.
    """
    results = list(results)
    fig, ax = (new_figure(figsize=(8.0, 5.0), layout="constrained"), None) if ax is None else (ax.figure, ax)
    ax = ax or fig.add_subplot()
    if fe is not None:
        s = contact_spectrum(fe)
        ax.plot(s.frequencies, s.b2, "k_", ms=14, mew=2, ls="none",
                label=f"FE ({s.b2.size} lowest modes; impact mass {s.impact_mass:.3g}, "
                      f"compliance {s.static_compliance:.3g})")
    markers = "osD^v<>p*h"
    hollow = False
    for i, e in enumerate(results):
        s = contact_spectrum(e.reduced)
        c, m = _colour(i, len(results)), markers[i % len(markers)]
        keep = s.b2 > 0
        artefact = np.zeros(s.b2.size, dtype=bool)
        if fe is not None:
            artefact[[x.index for x in model_matches(e.reduced, fe) if x.artefact]] = True
        what = (f"impact mass {s.impact_mass:.3g}" if s.impact_mass is not None else f"k_c {s.kc:.3g}")
        ax.plot(s.frequencies[keep & ~artefact], s.b2[keep & ~artefact], m, ls="none", color=c, alpha=0.8,
                label=f"{e.name} ({what}, compliance {s.static_compliance:.3g})")
        if (keep & artefact).any():
            hollow = True
            ax.plot(s.frequencies[keep & artefact], s.b2[keep & artefact], m, ls="none", color=c, mfc="none", ms=9)
    if hollow:
        ax.plot([], [], "o", ls="none", color="0.4", mfc="none", ms=9, label="hollow: no FE counterpart (artefact)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    freq = axis_labels(time_unit)[0].replace("frequency 1/T", "linear frequency ω_j/2π")
    ax.set_xlabel(freq)
    ax.set_ylabel("contact participation b_j² = (wᵀφ_j)²" + (f" (1/{mass_unit})" if mass_unit else ""))
    ax.set_title(title or "Contact spectral measure: what each model keeps")
    ax.grid(True, which="both", alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="small", loc="best")
    return fig
