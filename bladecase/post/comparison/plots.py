"""Figures of a comparison study (issue 12): every model on shared axes, convergence with size, the contact spectrum.

- :func:`overlay_plot` — energy against frequency of every model's admissible arcs on one pair of axes: one colour
  per method, one line style per size, the reference thicker, the comparison periods marked;
- :func:`convergence_plot` — how far each model's energies at the comparison periods are from the reference's,
  and how much they change from one size to the next (observed order where the sizes converge monotonically);
  :func:`convergence_series` says whether there is anything to draw;
- :func:`spectral_plot` — the contact spectral measure ``b_j²`` at ``ω_j/2π``, FE and each model: the picture
  that explains why models disagree (what each keeps of the FE's impact mass and compliance).

Matplotlib :class:`~matplotlib.figure.Figure` objects (:func:`bladecase.post.plots.new_figure`) of a fixed size
(the legends inside it, never growing it), never pyplot. Units on every axis (SI by default: ``time_unit="s"``,
``energy_unit="J"``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..plots import axis_labels, new_figure
from .compare import FEReference, ModelResult, contact_spectrum, largest_model, model_matches
from .table import convergence_order, energy_columns, observed_order, period_labels

__all__ = ["convergence_plot", "convergence_series", "observed_order", "overlay_plot", "spectral_plot"]

#: Narrow-arc marker per size, the smallest first (cycled).
MARKERS = ("o", "s", "^", "D", "v", "P", "X")
#: Dash patterns of the sizes, the smallest first (the largest size is solid; cycled beyond).
DASHES = ((0, (1, 1.5)), (0, (4, 2)), (0, (6, 2, 1, 2)), (0, (10, 3)), (0, (6, 1.5, 1, 1.5, 1, 1.5)),
          (0, (1, 3)), (0, (2, 1)))


def _colour(i: int, n: int) -> str | tuple:
    if n <= 10:
        return f"C{i}"
    from matplotlib import colormaps

    return colormaps["tab20"](i % 20)


def _arcs(entry: ModelResult) -> list[tuple[int, np.ndarray, np.ndarray]]:
    """``(k, 1/T, E)`` of the computed points of every admissible arc of the model (the points of an arc are
    admissible by construction: nothing outside the arcs is read)."""
    out = []
    for br in entry.branches:
        T = br.T
        for a in br.arcs:
            t = np.asarray(T[a.start:a.stop + 1], dtype=float)
            E = np.array([np.nan if o is None else o.energy for o in br.orbits[a.start:a.stop + 1]], dtype=float)
            ok = np.isfinite(t) & np.isfinite(E) & (E > 0)
            if ok.any():
                out.append((br.k, 1.0 / t[ok], E[ok]))
    return out


def _limits(ax, arcs: list, linear: np.ndarray) -> None:
    f = np.concatenate([a[1] for a in arcs]) if arcs else linear
    E = np.concatenate([a[2] for a in arcs]) if arcs else np.array([1.0])
    if f.size:
        pad = 0.05 * max(f.max() - f.min(), 0.05 * f.max())
        ax.set_xlim(f.min() - pad, f.max() + pad)
    ax.set_ylim(E.min() / 3, E.max() * 3)


def _size_styles(sizes: list) -> dict:
    """Line style per size: the largest solid (``None``, an exact model, when there is one), the smaller ones
    dotted, dashed, dash-dotted… from the smallest up."""
    ordered = sorted(s for s in sizes if s is not None)
    if None not in sizes and ordered:
        ordered, top = ordered[:-1], {ordered[-1]: "-"}
    else:
        top = {None: "-"} if None in sizes else {}
    return {s: DASHES[i % len(DASHES)] for i, s in enumerate(ordered)} | top


def overlay_plot(results: Sequence[ModelResult], fe: FEReference | None = None, *, ax=None,
                 nonadmissible: bool = False, linear: bool = True, min_px: float = 1.0, title: str | None = None,
                 time_unit: str | None = "s", energy_unit: str | None = "J", periods: Sequence[float] = (),
                 reference: str | None = None):
    """Every model's nonsmooth modes on ONE pair of axes: energy (log) against frequency ``1/T``.

    One colour per method, one line style per size (the largest solid), a thinner line for each further impact
    (massless: contact phase) per period; the ``reference`` model (default: the largest,
    :func:`~.compare.largest_model`) thicker, on top. Admissible arcs are curves through their computed points;
    an arc spanning less than ``min_px`` pixels (both ways) is a hollow marker at its middle; non-admissible orbits
    are faint dots when ``nonadmissible``. ``linear``: the FE linear frequencies (else the first model's) in range,
    dashed, each labelled with its mode number; ``periods`` (s): the comparison periods, dotted. The legend names
    the methods, the sizes and each kind of mark — a fixed number of entries whatever the number of models
    (the figure keeps its size: 10 × 5.5 in).

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
    >>> [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    ['modal', 'size 3', 'thick: the reference (modal-3)', 'linear frequencies (modal-3)']
    """
    from matplotlib.lines import Line2D

    xlabel, ylabel = axis_labels(time_unit, energy_unit)
    results = list(results)
    fig, ax = (new_figure(figsize=(10.0, 5.5), layout="constrained"), None) if ax is None else (ax.figure, ax)
    ax = ax or fig.add_subplot()
    arcs = {e.name: _arcs(e) for e in results}
    lin_src = fe.frequencies if fe is not None else (
        contact_spectrum(results[0].reduced).frequencies if results else np.array([]))
    ax.set_yscale("log")
    _limits(ax, [a for v in arcs.values() for a in v], np.asarray(lin_src, float))
    methods = list(dict.fromkeys(e.method for e in results))
    colours = {m: _colour(i, len(methods)) for i, m in enumerate(methods)}
    sizes = sorted(dict.fromkeys(e.size for e in results), key=lambda s: (s is None, s or 0))
    styles = _size_styles(sizes)
    markers = {s: MARKERS[i % len(MARKERS)] for i, s in enumerate(sizes)}
    ref = reference if reference is not None else (largest_model(results).name if results else None)
    ks = sorted({a[0] for v in arcs.values() for a in v})
    narrow = False
    for e in results:
        c, thick = colours[e.method], e.name == ref
        if nonadmissible:
            for br in e.branches:
                bad = ~br.admissible & np.isfinite(br.energy) & (br.energy > 0)
                ax.plot(br.frequencies[bad], br.energy[bad], ".", ms=2, color=c, alpha=0.25)
        narrow |= _draw_arcs(ax, arcs[e.name], c, styles[e.size], markers[e.size], thick, min_px)
    handles = [Line2D([], [], color=colours[m], lw=2.0, label=m) for m in methods]
    handles += [Line2D([], [], color="0.3", ls=styles[s], lw=1.6, marker=markers[s] if narrow else "", mfc="none",
                       label="exact" if s is None else f"size {s}") for s in sizes]
    massless = bool(results) and all(contact_spectrum(e.reduced).contact_model == "massless" for e in results)
    handles += [Line2D([], [], color="0.3", lw=_width(k, False),
                       label=f"{k} contact phase{'s' if k > 1 else ''}" if massless else f"{k} ipp")
                for k in ks] if len(ks) > 1 else []
    if ref is not None:
        handles.append(Line2D([], [], color="0.3", lw=_width(ks[0] if ks else 1, True),
                              label=f"thick: the reference ({ref})"))
    if narrow:
        handles.append(Line2D([], [], color="0.3", marker="o", mfc="none", ls="none",
                              label="hollow marker: an arc narrower than a pixel"))
    if nonadmissible:
        handles.append(Line2D([], [], color="0.3", marker=".", ls="none", alpha=0.4, label="non-admissible orbits"))
    if linear:
        if _linear_lines(ax, np.asarray(lin_src, float)):
            handles.append(Line2D([], [], color="k", ls="--", lw=0.8, label="linear frequencies ("
                                  + ("FE" if fe is not None else results[0].name if results else "") + ")"))
    if _period_lines(ax, periods):
        handles.append(Line2D([], [], color="0.5", ls=":", lw=1.2, label="comparison periods (1/T)"))
    if not any(arcs.values()):
        ax.text(0.5, 0.5, "no admissible arc in any model", transform=ax.transAxes, ha="center", va="center")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title or "Nonsmooth modes of the compared models")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small",
              ncols=1 if len(handles) <= 16 else 2)
    return fig


def _width(k: int, thick: bool) -> float:
    return max(0.6, 1.8 - 0.5 * (k - 1)) + (1.4 if thick else 0.0)


def _draw_arcs(ax, arcs: list, colour, style, marker: str, thick: bool, min_px: float) -> bool:
    """Curves per k (NaN-separated, one line each), narrow arcs as hollow markers; True if any is narrow."""
    narrow = False
    for k in sorted({a[0] for a in arcs}):
        curves, dots = [], []
        for _, f, E in (a for a in arcs if a[0] == k):
            px = ax.transData.transform(np.c_[f, E])
            (dots if f.size == 1 or np.ptp(px, axis=0).max() < min_px else curves).append((f, E))
        z = 3 if thick else 2
        if curves:
            x = np.concatenate([np.r_[f, np.nan] for f, _ in curves])
            y = np.concatenate([np.r_[E, np.nan] for _, E in curves])
            ax.plot(x, y, ls=style, lw=_width(k, thick), color=colour, zorder=z)
        if dots:
            narrow = True
            ax.plot([np.mean(f) for f, _ in dots], [np.exp(np.mean(np.log(E))) for _, E in dots],
                    marker, ls="none", ms=8 if thick else 5, color=colour, mfc="none",
                    zorder=z)
    return narrow


def _linear_lines(ax, freqs: np.ndarray) -> bool:
    lo, hi = ax.get_xlim()
    inside = np.flatnonzero((freqs >= lo) & (freqs <= hi))
    for j in inside:
        ax.axvline(freqs[j], color="k", ls="--", lw=0.8)
        ax.text(freqs[j], 0.98, f" {j + 1}", transform=ax.get_xaxis_transform(), va="top", fontsize="small")
    return inside.size > 0


def _period_lines(ax, periods: Sequence[float]) -> bool:
    lo, hi = ax.get_xlim()
    f = [1.0 / float(p) for p in periods if p and lo <= 1.0 / float(p) <= hi]
    for x in f:
        ax.axvline(x, color="0.5", ls=":", lw=1.2, zorder=1)
    return bool(f)


def _reference_row(rows: list[dict]) -> dict | None:
    ref = next((r for r in rows if r.get("is_reference")), None)
    return ref if ref is not None or not rows else max(reversed(rows), key=lambda r: r.get("dofs") or 0)


def convergence_series(rows: Sequence[dict]) -> dict:
    """What :func:`convergence_plot` draws, from the rows of :func:`~.table.comparison_rows`:
    ``{"deviation": [(method, column, sizes, |E/E_ref − 1|)], "change": [(method, column, sizes, |ΔE|/E,
    words)]}`` — the energies' distance from the reference model's at each comparison period (every sized model
    but the reference, where both have an orbit) and their change from the previous size (methods with two sizes
    or more at a period; ``words``: :func:`~.table.convergence_order`). Empty lists: nothing to draw.

    >>> rows = [{"method": "modal", "size": s, "dofs": s, "energy_0.95T1_j": 2 + 5 * s**-2.0} for s in (8, 16, 32)]
    >>> [(m, c, s, w) for m, c, s, _, w in convergence_series(rows)["change"]]
    [('modal', 'energy_0.95T1_j', [16, 32], 'order 2')]
    >>> convergence_series([{"method": "modal", "size": 8, "energy_0.95T1_j": None}])
    {'deviation': [], 'change': []}
    """
    models = [r for r in rows if r.get("method") != "fe"]
    ref = _reference_row(models)
    columns = energy_columns(models[0] if models else {})
    sized = [r for r in models if r.get("size") is not None]
    out: dict = {"deviation": [], "change": []}
    for method in dict.fromkeys(r["method"] for r in sized):
        mine = sorted((r for r in sized if r["method"] == method), key=lambda r: r["size"])
        for c in columns:
            pts = [(r["size"], r[c]) for r in mine if r.get(c) is not None]
            dev = [(r["size"], abs(r[c] / ref[c] - 1)) for r in mine if r is not ref and r.get(c) is not None
                   and ref is not None and ref.get(c)]
            if dev:
                out["deviation"].append((method, c, *map(list, zip(*dev))))
            if len(pts) >= 2:
                s, E = (np.array(x, dtype=float) for x in zip(*pts))
                words = convergence_order(s, E)[1] if len(pts) >= 3 else ""
                out["change"].append((method, c, [int(x) for x in s[1:]], (np.abs(np.diff(E)) / np.abs(E[1:])).tolist(),
                                      words))
    return out


def _size_ticks(ax, sizes: list) -> None:
    """The sizes themselves as the ticks of a log size axis (plain integers, no minor labels)."""
    from matplotlib.ticker import FixedLocator, NullFormatter, NullLocator, StrMethodFormatter

    ax.xaxis.set_major_locator(FixedLocator(sizes))
    ax.xaxis.set_major_formatter(StrMethodFormatter("{x:.0f}"))
    ax.xaxis.set_minor_locator(NullLocator())
    ax.xaxis.set_minor_formatter(NullFormatter())


def convergence_plot(rows: Sequence[dict], *, title: str | None = None, tolerance: float | None = None):
    """How the models' energies at the comparison periods converge with size, log-log (rows of
    :func:`~bladecase.post.comparison.table.comparison_rows` or of its CSV; :func:`convergence_series`).

    Top: ``|E/E_ref − 1|`` against the size — how far each model is from the reference model (``is_reference``,
    else the largest), one colour per method, one marker per period, the ``tolerance`` as a dotted line; bottom:
    the change from the previous size ``|ΔE|/E``, labelled with the observed order only where three sizes
    converge monotonically (:func:`~.table.convergence_order`), else "not monotone". A panel without data
    is left out; with no data at all, one empty panel says so (a study skips the figure then).

    >>> rows = [{"method": "modal", "size": s, "dofs": s, "energy_0.95T1_j": 2 + 5 * s**-2.0} for s in (8, 16, 32)]
    >>> [ax.get_legend_handles_labels()[1] for ax in convergence_plot(rows).axes]
    [['modal, 0.95 T1'], ['modal, 0.95 T1: order 2']]
    """
    series = convergence_series(rows)
    panels = [k for k in ("deviation", "change") if series[k]] or ["deviation"]
    fig = new_figure(figsize=(7.0, 3.4 * len(panels) + 0.4), layout="constrained")
    axes = fig.subplots(len(panels), 1, sharex=True, squeeze=False)[:, 0]
    methods = list(dict.fromkeys(m for k in panels for m, *_ in series[k]))
    columns = list(dict.fromkeys(c for k in panels for _, c, *_ in series[k]))
    short = period_labels(columns)
    markers = "osD^v<>p*h"
    for ax, key in zip(axes, panels):
        for method, col, s, y, *words in series[key]:
            style = dict(color=_colour(methods.index(method), len(methods)),
                         marker=markers[columns.index(col) % len(markers)])
            label = f"{method}, {short[col]}" + (f": {words[0]}" if words and words[0] else "")
            ax.plot(s, np.maximum(y, 1e-16), "-" if key == "deviation" else "--", label=label, **style)
        if key == "deviation" and tolerance is not None and ax.lines:
            ax.axhline(tolerance, color="k", ls=":", lw=1.0, label=f"tolerance {100 * tolerance:g} %")
        if ax.lines:
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.legend(fontsize="small")
            _size_ticks(ax, sorted({x for k in panels for _, _, s, *_ in series[k] for x in s}))
        else:
            ax.text(0.5, 0.5, "no admissible orbit at the comparison periods in two sizes", transform=ax.transAxes,
                    ha="center")
        ax.grid(True, which="both", alpha=0.3)
        ax.set_ylabel("|E/E_ref − 1| (from the reference)" if key == "deviation"
                      else "|ΔE|/E (from the previous size)")
    axes[-1].set_xlabel("size (modes, Lanczos steps or fixed-interface modes)")
    axes[0].set_title(title or "Convergence with the model size")
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
