"""Seed paper, Fig. 11: long simulations from perturbed nonsmooth-mode orbits — and the Floquet verdict.

The paper (Sec. 2.6) starts the event-driven simulation from a slightly perturbed point of a
periodic orbit on the Poincaré section ``x_n = d`` (the contact position kept at ``d``), collects
``(x_{n-1}, ẋ_n⁻)`` at each of the first 5000 impacts, sees a bounded cloud and concludes "not a
proof, but the orbits tend to be Lyapunov stable".  A bounded cloud is no verdict: with restitution 1
the energy is conserved, so EVERY motion stays on its energy surface — the dashed curve on the
section bounds the cloud of any orbit, stable or not.  The verdict is Floquet's
(``bladecase.nsm.floquet``: monodromy from exact flights and saltation matrices).

System: the 2-dof chain of the paper's Sec. 1.4 (``bladecase.chain(2, k=1, m=1/2, gap=1)``).  Its
1-ipp backbone is scanned over the admissible arc below the first linear period T₁ = 7.1887; two
neighbouring admissible orbits of nearly the same energy are picked (:func:`pick_orbits`): the least
stable orbit of a window of flip instability between two stable stretches (multiplier -1.15 at
T ≈ 6.58) and the nearest linearly stable one.  Both are perturbed alike (relative 1e-4, seeded,
contact position kept at ``d``) and simulated over 5000 flights (400 with ``--low``).

Rows: the flight durations normalised by ``T`` (paper's Fig. 11 top: "more than half in [0.9T, 1.1T]"
holds for the unstable orbit too); the Poincaré section ``x₂ = d``, ``(x₁, ẋ₂⁻)`` coloured by impact
number, with the energy bound (paper's Fig. 11 bottom); the section up close in ``(x₁, ẋ₁)`` (``ẋ₂⁻``
follows from the energy), in units of the initial perturbation; the distance to the orbit on the section
against the impact number, with the Floquet prediction ``|μ|ᴺ``.

Run: ``python examples/fig11_stability.py [--out DIR] [--low]``.
"""

from __future__ import annotations

import pathlib
import sys
import warnings

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import bladecase  # noqa: E402
from bladecase.io import save_figure  # noqa: E402
from bladecase.nsm.floquet import branch_stability, floquet, stable_arcs  # noqa: E402

_HERE = str(pathlib.Path(__file__).resolve().parent)
if _HERE not in sys.path:  # for examples/_paper.py, also when the script is loaded by path (tests)
    sys.path.insert(0, _HERE)
import _paper as paper  # noqa: E402

PERTURBATION = 1e-4  # relative size of the initial perturbation (contact position kept at d)


def pick_orbits(system: bladecase.LinearSystem, count: int = 120) -> tuple[bladecase.PeriodicOrbit, ...]:
    """``(stable, unstable)``: two neighbouring admissible 1-ipp orbits of opposite Floquet verdicts.

    The backbone is scanned at ``count`` periods in ``[0.78, 0.995]·T₁`` (the admissible arc below the first
    linear period).  ``unstable`` is the least stable orbit of a window of instability lying between two
    stable runs of the scan (:func:`~bladecase.nsm.floquet.stable_arcs`); ``stable`` is the stable orbit
    nearest to it in ``T``.
    """
    T1 = float(system.spectrum.periods[0])
    branch = bladecase.backbone(system, np.linspace(0.78 * T1, 0.995 * T1, count))
    runs = stable_arcs(branch, stability=branch_stability(branch))
    windows = [range(a[1] + 1, b[0]) for a, b in zip(runs, runs[1:])
               if all(o is not None and o.admissible for o in branch.orbits[a[1] + 1: b[0]])]
    if not windows:
        raise RuntimeError("no window of instability between two stable runs of admissible orbits in the scan")
    unstable = max((branch.orbits[i] for w in windows for i in w), key=lambda o: floquet(o).max_modulus)
    stable_points = [i for a, b in runs for i in range(a, b + 1)]
    stable = min((branch.orbits[i] for i in stable_points), key=lambda o: abs(o.T - unstable.T))
    return stable, unstable


def perturbed_run(orbit: bladecase.PeriodicOrbit, flights: int, size: float = PERTURBATION, seed: int = 11):
    """Simulate ``flights`` flights from the orbit's post-impact state perturbed by ``size`` (relative) in
    every coordinate but the contact position; return ``(trajectory, z0, dz0)``."""
    system = orbit.system
    n = system.n
    x0, v0 = (z[:, 0] for z in orbit.state(0.0))
    z0 = np.concatenate([x0, v0])
    rng = np.random.default_rng(seed)
    dz = rng.standard_normal(2 * n)
    dz[n - 1] = 0.0  # x_n stays at d: the start is on the section
    dz *= size * np.linalg.norm(z0) / np.linalg.norm(dz)
    z = z0 + dz
    with warnings.catch_warnings():  # the run stops at `flights` impacts on purpose
        warnings.filterwarnings("ignore", message=".*max_impacts reached", category=RuntimeWarning)
        tr = bladecase.simulate(system, z[:n], z[n:], 10 * (flights + 1) * orbit.T, max_impacts=flights)
    return tr, z0, dz


def section_points(tr, system) -> tuple[np.ndarray, np.ndarray]:
    """``(x_{n-1}, ẋ_n⁻)`` at every impact (pre-impact velocity: ``v⁻ = v⁺ + Λ M⁻¹w``)."""
    minv_w = system.spectrum.phi @ system.spectrum.b
    v_pre = tr.v + np.outer(minv_w, tr.impulses)
    return tr.x[-2], v_pre[-1]


def energy_bound(system, energy: float, num: int = 400) -> tuple[np.ndarray, np.ndarray]:
    """The closed curve of section points ``(x_{n-1}, ẋ_n)`` that energy ``energy`` can just reach (diagonal
    ``M``, contact on the last dof): ``½ m_n ẋ_n² + ½ sᵀ S s = E``, ``s = (x_{n-1}, d)``, ``S`` the stiffness
    condensed on the last two dofs (the other positions at their energy minimum, their velocities 0)."""
    K = system.K.toarray() if hasattr(system.K, "toarray") else np.asarray(system.K)
    m_n = float(system.M.diagonal()[-1])
    n, d = system.n, system.gap
    y, s = np.arange(n - 2), np.array([n - 2, n - 1])
    S = K[np.ix_(s, s)] - K[np.ix_(s, y)] @ np.linalg.solve(K[np.ix_(y, y)], K[np.ix_(y, s)]) if n > 2 else K
    # ½ (S00 x² + 2 S01 x d + S11 d²) = E at v = 0: the ends of the curve
    a, b, c = S[0, 0], S[0, 1] * d, S[1, 1] * d * d - 2 * energy
    root = np.sqrt(max(b * b - a * c, 0.0))
    x = np.linspace((-b - root) / a, (-b + root) / a, num)
    v = np.sqrt(np.maximum(2 * energy - (a * x * x + 2 * b * x + S[1, 1] * d * d), 0.0) / m_n)
    return np.concatenate([x, x[::-1]]), np.concatenate([v, -v[::-1]])


def _column(axes, orbit, fl, flights: int) -> None:
    ax_h, ax_s, ax_z, ax_d = axes
    system = orbit.system
    n = system.n
    tr, z0, dz0 = perturbed_run(orbit, flights)
    durations = np.diff(np.concatenate([[0.0], tr.impact_times])) / orbit.T
    ax_h.hist(durations, bins=60, color="0.35")
    ax_h.ticklabel_format(axis="x", useOffset=False)
    ax_h.set_xlabel("free-flight duration / T")
    ax_h.set_ylabel("flights")
    inside = np.mean(np.abs(durations - 1) <= 0.1)
    ax_h.set_title(f"T = {orbit.T:.4f}, E = {orbit.energy:.4f}\n{fl.verdict}", fontsize=10,
                   color="tab:green" if fl.stable else "tab:red")
    ax_h.text(0.02, 0.95, f"{inside:.0%} of {durations.size} flights in [0.9T, 1.1T]", transform=ax_h.transAxes,
              va="top", fontsize=8.5, bbox=dict(fc="white", ec="none", alpha=0.8))

    x_sec, v_sec = section_points(tr, system)
    xs0, vs0 = section_points_of_orbit(orbit)
    order = np.arange(x_sec.size)
    bx, bv = energy_bound(system, orbit.energy)
    ax_s.plot(bx, bv, "--", color="0.4", lw=1.0, label="energy bound: every state of energy E")
    sc = ax_s.scatter(x_sec, v_sec, c=order, cmap="turbo", s=5, lw=0)
    ax_s.plot([xs0], [vs0], "*", ms=11, mfc="none", mec="k", label="periodic orbit")
    ax_s.set_xlabel(r"$x_1$ at impact")
    ax_s.set_ylabel(r"pre-impact velocity $\dot x_2^-$")
    ax_s.set_title(r"Poincaré section $x_2 = d$", fontsize=9.5)
    ax_s.legend(loc="lower left", fontsize=7.5)
    ax_s.figure.colorbar(sc, ax=ax_s, label="impact number", shrink=0.85)

    d0 = np.linalg.norm(dz0)
    dx, dv = tr.x[-2] - z0[n - 2], tr.v[-2] - z0[2 * n - 2]  # (x_{n-1}, ẋ_{n-1}) at the impacts
    far = np.flatnonzero(np.hypot(dx, dv) > 30 * d0)
    shown = order < (far[0] if far.size else order.size)
    ax_z.scatter(dx[shown] / d0, dv[shown] / d0, c=order[shown], cmap="turbo", s=4, lw=0,
                 vmin=0, vmax=max(order.size - 1, 1))
    ax_z.plot([0], [0], "k*", ms=9)
    ax_z.set_xlabel(r"$(x_1 - x_1^*)\,/\,|\delta z_0|$ at impact")
    ax_z.set_ylabel(r"$(\dot x_1 - \dot x_1^*)\,/\,|\delta z_0|$")
    ax_z.set_title(f"section up close in $(x_1, \\dot x_1)$: the {int(shown.sum())} impacts within 30 |δz₀|"
                   + ("\n(the cloud circles the periodic orbit of the perturbed energy, next to ★)" if fl.stable
                      else "\n(alternating sides: a flip)"), fontsize=9.5)

    Z = np.vstack([tr.x, tr.v])
    dist = np.linalg.norm(Z - z0[:, None], axis=0) / np.linalg.norm(z0)
    N = np.arange(1, dist.size + 1)
    ax_d.semilogy(N, dist, ".", ms=2.5, color="tab:blue", label="simulation")
    r0 = d0 / np.linalg.norm(z0)
    if not fl.stable:
        pred = r0 * fl.max_modulus ** N
        keep = pred <= 1
        ax_d.semilogy(N[keep], pred[keep], "-", color="tab:red", lw=1.2,
                      label=f"Floquet: {r0:.0e}·|μ|ᴺ, |μ| = {fl.max_modulus:.4f}")
    else:
        ax_d.axhline(r0, color="tab:green", lw=1.0, label=f"initial perturbation {r0:.0e}")
    ax_d.set_xlabel("impact number N")
    ax_d.set_ylabel("distance to the orbit\non the section (relative)")
    ax_d.set_ylim(min(dist.min(), r0) / 3, 10)
    ax_d.legend(loc="upper right", fontsize=7.5)
    for a in axes:
        a.grid(alpha=0.3)


def section_points_of_orbit(orbit) -> tuple[float, float]:
    """``(x_{n-1}, ẋ_n⁻)`` of the periodic orbit's impact at ``t = T``."""
    system = orbit.system
    x, v = (z[:, 0] for z in orbit.state(0.0))
    v_pre = v + (system.spectrum.phi @ system.spectrum.b) * orbit.impulses[-1]
    return float(x[-2]), float(v_pre[-1])


def main(out_dir: str = "results/examples", resolution: str = "full") -> list[pathlib.Path]:
    """Draw the Fig. 11 test for a stable and an unstable orbit; return the PNG paths written."""
    low = resolution == "low"
    flights = 400 if low else 5000
    out = pathlib.Path(out_dir)
    system = paper.two_dof()
    stable, unstable = pick_orbits(system, 60 if low else 120)
    fig, axes = plt.subplots(4, 2, figsize=(13.0, 16.0), height_ratios=[0.7, 1.5, 1.0, 0.9], layout="constrained")
    for col, orbit in enumerate((stable, unstable)):
        fl = floquet(orbit)
        print(f"T = {orbit.T:.6f}  E = {orbit.energy:.6f}  multipliers = {np.round(fl.nontrivial, 6).tolist()}  "
              f"{fl.verdict}")
        _column(axes[:, col], orbit, fl, flights)
    fig.suptitle("Seed paper Fig. 11 test on the 2-dof chain: perturbed 1-ipp orbits, "
                 f"{flights} flights each — left linearly stable, right unstable (Floquet)", fontsize=12)
    fig.supxlabel(
        "Both clouds stay bounded: with restitution 1 energy is conserved, so every motion stays inside the dashed "
        "energy bound — a bounded cloud alone is not a verdict.\nThe Floquet multipliers are: the unstable orbit's "
        "perturbation grows as |μ|ᴺ (bottom right) until it is as large as the motion itself.", fontsize=9.5)
    path = out / "fig11_stability.png"
    save_figure(fig, path, dpi=100 if low else 150)
    plt.close(fig)
    return [path]


if __name__ == "__main__":
    paper.run(main, __doc__)
