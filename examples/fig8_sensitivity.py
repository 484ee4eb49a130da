"""Seed paper, Fig. 8, and the admissible periods against the number of dofs: nonsmooth modes are sensitive to it.

System: the paper's chain of Sec. 2 ("in all the computations, k = 1, m = 1/N and d = 1"):
``bladecase.chain(n, k=1, m=1/n, gap=1)``, Newton's impact law on the last mass.

(a) Fig. 8: the 1-ipp orbit ``x_n(t)`` over one period for ``n = 100`` and ``n = 101`` at the SAME period ``T``.
``T`` is not given in the paper; it is found here by computation (:func:`find_fig8_period`): among the periods
of a scan of ``[0.9, 0.9999]·T₁(100)`` where the ``n = 100`` orbit is certified admissible and the ``n = 101``
orbit is not, the one where ``n = 101`` violates ``x_n <= d`` the most.

(b) The measure of the admissible set of periods in the window ``T ∈ [0.99, 0.9999]·T₁`` (``T₁``: the model's
own first linear period), as a fraction of the window, against ``n``:

* Newton model, ``n = 2…200``: the admissible arcs of the 1-ipp backbone (:func:`bladecase.backbone`, ends
  refined by bisection to 1e-9 T). An admissible interval never contains a resonant period ``2πm/ω_j``, and the
  window holds ≈ n²/120 of them; the scan puts two periods in every gap between consecutive resonances (at 0.5
  and 0.999 of the gap: the admissible stretch of a gap, when there is one, reaches up to the gap's upper
  resonance), so every admissible stretch is found unless it is shorter than 0.1 % of its gap.
* Massless contact model, ``n = 4…200``: the last mass is massless, its mass ``1/n`` moved to the three masses
  before it keeping the total mass and the centre of mass (:func:`massless_chain`; ``n = 2, 3`` have too few
  neighbours to keep both), the contact condensed (theory §8). Its one-contact-phase mode is followed from
  grazing at its open-phase period ``T₁`` (:func:`bladecase.nsm.massless.branches.massless_modes`); the
  measure is the part of the window covered by the admissible arc that starts at grazing (end refined to 1e-9 T).

Run: ``python examples/fig8_sensitivity.py [--out DIR] [--low]`` (``--low``: a few ``n`` only; the full scan
takes minutes).
"""

from __future__ import annotations

import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import bladecase  # noqa: E402
from bladecase.io import save_figure  # noqa: E402
from bladecase.nsm.massless.branches import massless_modes  # noqa: E402
from bladecase.nsm.massless.model import MasslessSystem, condense, redistribute_mass  # noqa: E402

_HERE = str(pathlib.Path(__file__).resolve().parent)
if _HERE not in sys.path:  # for examples/_paper.py, also when the script is loaded by path (tests)
    sys.path.insert(0, _HERE)
import _paper as paper  # noqa: E402

WINDOW = (0.99, 0.9999)  # the window of periods, in units of the model's first linear period T₁
FIG8_RANGE = (0.9, 0.9999)  # where the Fig. 8 period is searched, in units of T₁(n = 100)
GAP_POINTS = (0.5, 0.999)  # scan points inside each gap between consecutive resonant periods
LOW_N = (5, 10, 20, 50, 100, 101)


def newton_chain(n: int) -> bladecase.LinearSystem:
    """The paper's chain: ``k = 1``, ``m = 1/n``, ``d = 1``, Newton's impact law on the last mass."""
    return bladecase.chain(n, k=1.0, m=1.0 / n, gap=1.0)


def massless_chain(n: int) -> MasslessSystem:
    """The same chain with a massless last mass: its ``1/n`` moved to masses ``n-3, n-2, n-1`` (total mass and
    centre of mass kept, smallest change), the contact dof condensed (``n >= 4``)."""
    if n < 4:
        raise ValueError(f"the massless chain needs n >= 4 (three neighbours keep mass and centre of mass), got {n}")
    K = newton_chain(n).K.toarray()
    masses = redistribute_mass(np.full(n, 1.0 / n), np.arange(n, dtype=float), n - 1, np.arange(n - 4, n - 1))
    w = np.zeros(n)
    w[-1] = 1.0
    return condense(np.diag(masses), K, w, 1.0)


def resonances(omega: np.ndarray, T_lo: float, T_hi: float) -> np.ndarray:
    """Sorted resonant periods ``2πm/ω_j`` (``m >= 1``) strictly inside ``(T_lo, T_hi)``."""
    m_lo = np.floor(omega * T_lo / (2 * np.pi)) + 1
    m_hi = np.ceil(omega * T_hi / (2 * np.pi)) - 1
    parts = [2 * np.pi * np.arange(lo, hi + 1) / w for lo, hi, w in zip(m_lo, m_hi, omega) if hi >= lo]
    return np.unique(np.concatenate(parts)) if parts else np.empty(0)


def _covered(arcs, a: float, b: float) -> float:
    """Fraction of ``[a, b]`` covered by the union of intervals ``arcs`` (pairs ``(lo, hi)``)."""
    total, reach = 0.0, a
    for lo, hi in sorted((max(lo, a), min(hi, b)) for lo, hi in arcs):
        if hi > reach and hi > lo:
            total += hi - max(lo, reach)
            reach = hi
    return total / (b - a)


def newton_measure(n: int, window: tuple[float, float] = WINDOW) -> tuple[float, bladecase.Branch]:
    """``(fraction, backbone)``: the part of ``window·T₁`` covered by the admissible 1-ipp arcs of the chain."""
    system = newton_chain(n)
    omega = system.spectrum.contact_modes[0]
    T1 = 2 * np.pi / float(omega.min())
    a, b = window[0] * T1, window[1] * T1
    edges = np.concatenate([[a], resonances(omega, a, b), [b]])
    periods = (edges[:-1, None] + np.diff(edges)[:, None] * np.asarray(GAP_POINTS)[None, :]).ravel()
    branch = bladecase.backbone(system, np.concatenate([periods, [a, b]]))
    return _covered([(iv.T_lo, iv.T_hi) for iv in branch.intervals], a, b), branch


def massless_measure(n: int, window: tuple[float, float] = WINDOW) -> tuple[float, tuple[float, float]]:
    """``(fraction, (T_lo, T_hi))``: the part of ``window·T₁`` covered by the admissible arc of the one-phase
    mode that starts at grazing (``T₁``: first open-phase period), and that arc."""
    system = massless_chain(n)
    T1 = 2 * np.pi / float(system.open.omega[0])
    a, b = window[0] * T1, window[1] * T1
    points = 100
    while True:
        (branch,) = massless_modes(system, (a, T1 * (1 + 1e-6)), max_points=points)[:1] or (None,)
        if branch is None or not branch.arcs or branch.arcs[0].start != 0:
            return 0.0, (T1, T1)  # not admissible next to grazing
        arc = branch.arcs[0]
        if arc.stop < len(branch.orbits) - 1 or len(branch.orbits) < points or points >= 12800:
            return _covered([(arc.T_lo, arc.T_hi)], a, b), (arc.T_lo, arc.T_hi)
        points *= 2  # the arc runs on past the points followed: follow further


def find_fig8_period(count: int = 400, pair: tuple[int, int] = (100, 101)):
    """``(T, orbit_a, orbit_b)``: a period of a scan of ``FIG8_RANGE·T₁(pair[0])`` (``count`` periods) where the
    1-ipp orbit of the ``pair[0]`` chain is certified admissible and that of ``pair[1]`` is not, violating
    ``x_n <= d`` the most."""
    sa, sb = newton_chain(pair[0]), newton_chain(pair[1])
    T1 = float(sa.spectrum.periods[0])
    best = None
    for T in np.linspace(FIG8_RANGE[0] * T1, FIG8_RANGE[1] * T1, count):
        try:
            oa, ob = bladecase.orbit_1ipp(sa, T), bladecase.orbit_1ipp(sb, T)
        except ValueError:  # resonant period
            continue
        if oa.admissible and not ob.admissible and np.all(ob.impulses >= 0) and (
                best is None or ob.max_violation > best[2].max_violation):
            best = (float(T), oa, ob)
    if best is None:
        raise RuntimeError(f"no period of the scan with n = {pair[0]} admissible and n = {pair[1]} not")
    return best


def draw_fig8(T: float, oa, ob, path: pathlib.Path, dpi: int) -> None:
    t = np.linspace(0.0, T, 8001)
    fig, ax = plt.subplots(figsize=(10.0, 5.2), layout="constrained")
    for o, color in ((oa, "tab:blue"), (ob, "tab:red")):
        verdict = "admissible" if o.admissible else f"violates x_n <= d by {o.max_violation:.4f}"
        ax.plot(t / T, o.contact(t), color=color, lw=1.0, label=f"n = {o.system.n}: {verdict}")
    ax.axhline(1.0, color="k", lw=1.5, label="obstacle d = 1")
    tv = ob.max_violation_time
    ax.plot([tv / T], [1.0 + ob.max_violation], "o", mfc="none", mec="tab:red", ms=10)
    ax.annotate(f"x_n - d = {ob.max_violation:.4f}", (tv / T, 1.0 + ob.max_violation), xytext=(-150, 6),
                textcoords="offset points", color="tab:red")
    ax.set_xlabel("t / T")
    ax.set_ylabel(r"$x_n(t)$")
    ax.set_title(f"Seed paper Fig. 8: 1-ipp orbits of chain(n, k=1, m=1/n, d=1) at the same T = {T:.6f} "
                 f"(= {T / float(oa.system.spectrum.periods[0]):.5f} T₁(100))", fontsize=10.5)
    ax.legend(loc="lower right")
    ax.grid(alpha=0.3)
    save_figure(fig, path, dpi=dpi)
    plt.close(fig)


def draw_measure(newton: dict, massless: dict, path: pathlib.Path, dpi: int) -> None:
    fig, ax = plt.subplots(figsize=(10.0, 5.2), layout="constrained")
    for data, style, label in ((newton, "o-", "Newton: admissible 1-ipp arcs of the backbone"),
                               (massless, "s-", "massless: admissible one-phase arc from grazing")):
        ns = np.array(sorted(data))
        ax.plot(ns, [data[n] for n in ns], style, ms=3, lw=0.8, label=label)
    ax.set_xlabel("number of dofs n")
    ax.set_ylabel("admissible fraction of the window")
    ax.set_ylim(-0.03, 1.03)
    ax.set_title(f"Measure of the admissible periods in T ∈ [{WINDOW[0]}, {WINDOW[1]}]·T₁, "
                 "chain(n, k=1, m=1/n, d=1)", fontsize=10.5)
    ax.legend()
    ax.grid(alpha=0.3)
    save_figure(fig, path, dpi=dpi)
    plt.close(fig)


def main(out_dir: str = "results/examples", resolution: str = "full") -> list[pathlib.Path]:
    """Draw Fig. 8 and the admissible-measure scan; print the numbers; return the PNG paths written."""
    if resolution not in ("low", "full"):
        raise ValueError(f"resolution must be 'low' or 'full', got {resolution!r}")
    low = resolution == "low"
    out = pathlib.Path(out_dir)
    T, oa, ob = find_fig8_period(120 if low else 400)
    print(f"Fig. 8: T = {T:.9f}: n = 100 admissible ({oa.admissible}), n = 101 violates x_n <= d by "
          f"{ob.max_violation:.6f} at t = {ob.max_violation_time / T:.4f} T")
    paths = [out / "fig8_sensitivity.png", out / "fig8_admissible_measure.png"]
    draw_fig8(T, oa, ob, paths[0], 100 if low else 150)
    newton = {n: newton_measure(n)[0] for n in (LOW_N if low else range(2, 201))}
    massless = {n: massless_measure(n)[0] for n in (LOW_N if low else range(4, 201))}
    print(f"measure of the admissible periods in [{WINDOW[0]}, {WINDOW[1]}]·T₁")
    print("    n   newton  massless")
    for n in sorted(set(newton) | set(massless)):
        cells = [f"{d[n]:8.4f}" if n in d else f"{'—':>8}" for d in (newton, massless)]
        print(f"  {n:3d} {cells[0]} {cells[1]}")
    draw_measure(newton, massless, paths[1], 100 if low else 150)
    return paths


if __name__ == "__main__":
    paper.run(main, __doc__)
