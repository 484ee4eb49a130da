"""Seed paper, Fig. 4: a nonsmooth mode as an invariant manifold in (x₁, x₂, ẋ₂).

System: the 2-dof chain of the paper's Sec. 1.4 (``bladecase.chain(2, k=1,
m=1/2, gap=1)``).  The nonsmooth mode is the 2-ipp family whose admissible
arc runs from ① (T ≈ 13.33) to ② (T → 5T₂ ≈ 13.73) — the red curve of Fig. 2
and the trajectories of Fig. 3.  Its orbits sweep a two-dimensional invariant
manifold ``(T, t) ↦ (x, v)`` of the four-dimensional state space, sampled with
``Branch.manifold(n_orbits, n_times)`` and projected onto ``(x₁, x₂, ẋ₂)``
(the orbits of ``_paper.paper_mode``, from ① to the arc's end at 5T₂).

The manifold is smooth along each flight and torn along the impacts: at
``x₂ = d`` the contact velocity jumps from ``ẋ₂⁻`` to ``ẋ₂⁺ = -ẋ₂⁻`` (elastic
impact of the contact mass, ``x₁`` and ``ẋ₁`` continuous).  The surface is
therefore triangulated flight by flight (no triangle straddles an impact), the
jumps are drawn as red segments joining the pre- and post-impact states, and
one periodic orbit is highlighted in green, as in the paper.  The right panel
is the projection onto the contact plane ``(x₂, ẋ₂)``.

Run: ``python examples/fig4_manifold.py [--out DIR] [--low]``.
"""

from __future__ import annotations

import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection  # noqa: E402

import bladecase  # noqa: E402
from bladecase.io import save_figure  # noqa: E402
from bladecase.nsm import Arc, Branch  # noqa: E402

_HERE = str(pathlib.Path(__file__).resolve().parent)
if _HERE not in sys.path:  # for examples/_paper.py, also when the script is loaded by path (tests)
    sys.path.insert(0, _HERE)
import _paper as paper  # noqa: E402


def evenly_spaced(mode: Branch, n: int) -> Branch:
    """``n`` orbits of ``mode`` evenly spaced in state space, as a new :class:`bladecase.nsm.Branch`.

    The continuation takes small steps in ``T`` near ② (the orbits grow fast
    there), so sampling by index (what ``manifold()`` does by default) would
    crowd that end.  Here the orbits are picked evenly in the cumulative RMS
    distance between consecutive orbits (``mode.sample(n, spacing="state")``);
    the returned branch holds exactly those orbits, so ``manifold(n, ·)``
    samples all of them.
    """
    orbits = mode.sample(n, spacing="state")
    arc = Arc(0, len(orbits) - 1, mode.arcs[0].T_lo, mode.arcs[0].T_hi)
    return Branch(system=mode.system, k=mode.k, orbits=orbits, arcs=[arc])


def impact_jumps(orbit: bladecase.PeriodicOrbit) -> np.ndarray:
    """Pre- and post-impact points ``(x₁, x₂, ẋ₂)`` at each impact: shape ``(k, 2, 3)``.

    ``state(t_i)`` is the post-impact state; for the contact mass of a chain
    the pre-impact state has the same positions and ``ẋ₂⁻ = -ẋ₂⁺``.
    """
    x, v = orbit.state(orbit.impact_times)
    post = np.stack([x[0], x[1], v[1]], axis=-1)
    pre = post * np.array([1.0, 1.0, -1.0])
    return np.stack([pre, post], axis=1)


def flight_triangles(T: np.ndarray, theta: np.ndarray, t1: np.ndarray) -> np.ndarray:
    """Triangles of the ``(orbit, phase)`` grid that lie within one flight.

    Vertex ``(i, j)`` has index ``i·n_times + j``; its flight is 0 for
    ``θ_j T_i < t₁_i`` and 1 after.  Quads are not wrapped around ``θ = 1``
    (the impact at ``t = T``), and a triangle is kept only if its three
    vertices are in the same flight.
    """
    n_o, n_t = T.size, theta.size
    flight = (theta[None, :] * T[:, None] >= t1[:, None]).astype(int)
    tris = []
    for i in range(n_o - 1):
        for j in range(n_t - 1):
            a, b, c, dd = (i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)
            for tri in ((a, b, c), (a, c, dd)):
                if len({flight[p] for p in tri}) == 1:
                    tris.append([p[0] * n_t + p[1] for p in tri])
    return np.array(tris, dtype=int)


def _flights(orbit: bladecase.PeriodicOrbit) -> list[tuple[float, float]]:
    """``(start, end)`` of each flight; ``end`` is just before the impact, so
    ``state(end)`` is the pre-impact state."""
    bounds = np.concatenate([[0.0], orbit.impact_times])
    return [(a, np.nextafter(b, a)) for a, b in zip(bounds[:-1], bounds[1:])]


def shaded(tri_xyz: np.ndarray, rgba: np.ndarray, light=(-0.4, -0.5, 0.75)) -> np.ndarray:
    """Lambert-shade face colours ``rgba`` of triangles ``tri_xyz`` (``(m, 3, 3)``), two-sided."""
    span = np.ptp(tri_xyz.reshape(-1, 3), axis=0)
    p = tri_xyz / np.where(span > 0, span, 1.0)  # shade in the (unit-box) display scaling
    nrm = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-300)
    light = np.asarray(light) / np.linalg.norm(light)
    k = 0.5 + 0.5 * np.abs(nrm @ light)
    out = rgba.copy()
    out[:, :3] *= k[:, None]
    return out


ALPHA = 0.32
VIEW = dict(elev=18, azim=-30)


def main(out_dir: str = "results/examples", resolution: str = "full") -> list[pathlib.Path]:
    """Draw the Fig. 4 manifold; return the PNG paths written."""
    low = resolution == "low"
    n_orbits, n_times = (12, 60) if low else (60, 360)
    out = pathlib.Path(out_dir)
    system = paper.two_dof()
    d = system.gap
    mode = evenly_spaced(paper.paper_mode(system), n_orbits)
    T, theta, x, v = mode.manifold(len(mode.orbits), n_times)
    by_T = {o.T: o for o in mode.orbits}
    orbits = [by_T[t] for t in T]  # the sampled orbits (manifold() picks computed ones)
    t1 = np.array([o.impact_times[0] for o in orbits])
    print(f"manifold: {T.size} orbits × {theta.size} phases, T in [{T.min():.6f}, {T.max():.6f}]")

    P = np.stack([x[0], x[1], v[1]], axis=-1).reshape(-1, 3)  # (n_orbits·n_times, 3)
    tris = flight_triangles(T, theta, t1)
    Tv = np.repeat(T, theta.size)[tris].mean(axis=1)
    norm = plt.Normalize(T.min(), T.max())
    cmap = plt.get_cmap("viridis")

    fig = plt.figure(figsize=(14.5, 7.0), layout="constrained")
    gs = fig.add_gridspec(1, 2, width_ratios=[1.5, 1])
    ax = fig.add_subplot(gs[0], projection="3d", computed_zorder=False)
    az = fig.add_subplot(gs[1])

    surf = Poly3DCollection(P[tris], facecolors=shaded(P[tris], cmap(norm(Tv))), edgecolors="none",
                            alpha=ALPHA, zorder=1)
    ax.add_collection3d(surf)
    # impact tears: pre/post-impact states of every sampled orbit, and their jumps
    jumps = np.array([impact_jumps(o) for o in orbits])  # (n_orbits, k, 2, 3)
    step = max(1, T.size // 12)
    ax.add_collection3d(Line3DCollection(jumps[::step].reshape(-1, 2, 3), colors="red", lw=0.9, alpha=0.8,
                                         zorder=2))
    for kk in range(jumps.shape[1]):
        for side in range(2):
            ax.plot(*jumps[:, kk, side].T, color="red", lw=1.4, zorder=2)
    # iso-T curves: every step-th orbit of the sample, flight by flight
    for i in range(0, T.size, step):
        for a, b in _flights(orbits[i]):
            xs, vs = orbits[i].state(np.linspace(a, b, 300))
            ax.plot(xs[0], xs[1], vs[1], color=cmap(norm(T[i])), lw=0.8, alpha=0.9, zorder=3)
    # highlighted periodic orbit (green), flight by flight, with its jumps
    o = orbits[int(np.argmin(np.abs(T - (T.min() + 0.55 * (T.max() - T.min())))))]
    for a, b in _flights(o):
        xs, vs = o.state(np.linspace(a, b, 600))
        ax.plot(xs[0], xs[1], vs[1], color="limegreen", lw=2.6, zorder=4)
        az.plot(xs[1], vs[1], color="limegreen", lw=2.4, zorder=4)
    for pre, post in impact_jumps(o):
        ax.plot(*np.stack([pre, post]).T, color="red", lw=3.0, zorder=5)
        ax.scatter(*post, color="red", s=18, zorder=5)
        az.plot([pre[1], post[1]], [pre[2], post[2]], color="red", lw=3.0, zorder=5)

    lo, hi = P.min(axis=0), P.max(axis=0)
    pad = 0.04 * (hi - lo)
    ax.set(xlim=(lo[0] - pad[0], hi[0] + pad[0]), ylim=(lo[1] - pad[1], hi[1] + pad[1]),
           zlim=(lo[2] - pad[2], hi[2] + pad[2]))
    ax.set_xlabel(r"$x_1$")
    ax.set_ylabel(r"$x_2$")
    ax.set_zlabel(r"$\dot x_2$")
    ax.view_init(**VIEW)
    ax.set_box_aspect(None, zoom=1.0)
    ax.set_title("nonsmooth mode in $(x_1, x_2, \\dot x_2)$", fontsize=11)
    sm = plt.cm.ScalarMappable(norm=norm, cmap=cmap)
    fig.colorbar(sm, ax=ax, shrink=0.6, pad=0.08, label="period $T$ of the orbit")

    # contact-plane projection: a few orbits of the family and all the jumps
    for i in range(0, T.size, step):
        for a, b in _flights(orbits[i]):
            xs, vs = orbits[i].state(np.linspace(a, b, 400))
            az.plot(xs[1], vs[1], color=cmap(norm(T[i])), lw=0.9, alpha=0.8, zorder=2)
    az.plot(jumps[..., 1].reshape(-1), jumps[..., 2].reshape(-1), ".", color="red", ms=2.5, zorder=3)
    az.axvline(d, color="k", lw=2.0, zorder=1)
    az.axvspan(d, d + 0.2, color="0.85", zorder=0)
    az.text(d + 0.05, 0.5, "obstacle $x_2 = d$", rotation=90, va="center", ha="center", fontsize=9,
            transform=az.get_xaxis_transform())
    az.set_xlim(P[:, 1].min() - 0.1, d + 0.2)
    az.set_xlabel(r"$x_2$")
    az.set_ylabel(r"$\dot x_2$")
    az.grid(alpha=0.3)
    az.set_title("projection on the contact plane $(x_2, \\dot x_2)$", fontsize=11)
    from matplotlib.lines import Line2D

    handles = [
        Line2D([], [], color="limegreen", lw=2.4, label=f"periodic orbit, T = {o.T:.4f}"),
        Line2D([], [], color="red", lw=2.4, label=r"velocity jumps at $x_2 = d$ ($\dot x_2^+ = -\dot x_2^-$)"),
        Line2D([], [], color=cmap(0.5), lw=1.0, label="other orbits of the mode"),
    ]
    az.legend(handles=handles, loc="lower left", fontsize=8.5, framealpha=0.95)
    ax.legend(handles=handles[:2] + [Line2D([], [], color=cmap(0.5), lw=6, alpha=ALPHA,
                                            label="manifold (colour: period T)")],
              loc="upper left", fontsize=8.5, framealpha=0.9)
    fig.suptitle(f"Seed paper Fig. 4 — the 2-ipp nonsmooth mode ① → ② (T ∈ [{T.min():.4f}, {T.max():.4f}], "
                 f"5T₂ = {paper.five_T2(system):.4f}) as an invariant manifold, 2-dof chain", fontsize=12.5)
    path = out / "fig4_manifold.png"
    save_figure(fig, path, dpi=100 if low else 150)
    plt.close(fig)
    return [path]


if __name__ == "__main__":
    paper.run(main, __doc__)
