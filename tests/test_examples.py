"""The example scripts in ``examples/`` (seed paper Figs. 2–4 and a frequency–energy plot).

Every example's ``main(out_dir, resolution="low")`` must write valid, non-trivial
PNGs, and the numbers behind the figures must be right:

* the paper's mode (``examples/_paper.py``, shared by the scripts) — one
  admissible 2-ipp arc starts on the diagonal ``t₁ = T/2`` at T ≈ 13.33 (①) and
  ends at ``5T₂ = 13.72926332`` (②, to 1e-6 relative), where the impulses
  vanish and ``t₁ → 2T₂``, as in the paper;
* Fig. 2 — the pole-free numerator is ``s(t₁)·Π sin(ω_j T/2)``; the arc lies on
  its zero set;
* Fig. 3 — the trajectories stay behind the obstacle and touch it at the impacts,
  from ① to ②;
* Fig. 4 — the manifold samples the arc up to ②, the jumps are elastic at ``x₂ = d``;
* frequency–energy — ① has the energy of the 1-ipp orbit of period ``T/2``;
  at ② the energy is that of linear mode 2 grazing the obstacle.

``_paper`` computes the 2-ipp families once per system instance and
``_paper.two_dof()`` is one shared instance, so the examples (and these tests)
follow the families once, which keeps the file fast.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest
from conftest import load_example, run_forked

import bladecase as bc
from bladecase.nsm import ModalKernel

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
NAMES = ["fig2_impact_time_map", "fig3_trajectories", "fig4_manifold", "frequency_energy", "fig11_stability",
         "fig9_forced_response", "fig10_forced_response", "compare_models", "fig8_sensitivity"]
FIVE_T2 = 10 * np.pi / np.sqrt(3 + np.sqrt(5))  # 5 · 2π/ω₂ for chain(2, k=1, m=1/2): ω₂² = 3 + √5
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def ex(fig8_example):
    # fig8_sensitivity: the one instance tests/test_fig8.py checks the numbers of (conftest.py's fig8_example)
    return {name: fig8_example if name == "fig8_sensitivity" else load_example(name) for name in NAMES}


@pytest.fixture(scope="module")
def paper(ex):
    # the module the scripts import (they put examples/ on sys.path): one cache for all
    mod = ex[NAMES[0]].paper
    assert all(m.paper is mod for m in ex.values())
    return mod


@pytest.fixture(scope="module")
def sys2(paper):
    # the scripts' own shared instance, so that the cached families are reused
    s = paper.two_dof()
    assert s is paper.two_dof()
    assert (s.n, s.gap) == (2, 1.0) and np.allclose(s.spectrum.omega ** 2, [3 - np.sqrt(5), 3 + np.sqrt(5)])
    return s


def _check_png(path: Path, min_bytes: int = 15_000):
    path = Path(path)
    assert path.is_file(), path
    data = path.read_bytes()
    assert data[:8] == PNG_MAGIC, f"{path} is not a PNG"
    assert len(data) >= min_bytes, f"{path} is suspiciously small ({len(data)} bytes)"
    img = plt.imread(path)
    assert img.ndim == 3 and img.shape[0] > 300 and img.shape[1] > 400
    assert img[..., :3].std() > 0.02, f"{path} looks blank"


@pytest.mark.parametrize("name", NAMES)
def test_example_writes_pngs(ex, name, tmp_path):
    paths = ex[name].main(str(tmp_path), resolution="low")
    assert isinstance(paths, list) and paths
    for p in paths:
        assert Path(p).parent == tmp_path
        _check_png(p)
    assert not list(tmp_path.glob(".*")), "temporary files left behind (atomic write)"


_HELP_ALL = """
import contextlib, io, json, runpy, sys
out = {}
for path in sys.argv[1:]:
    sys.argv = [path, "--help"]
    buf = io.StringIO()
    code = None
    with contextlib.redirect_stdout(buf):
        try:
            runpy.run_path(path, run_name="__main__")
        except SystemExit as exc:
            code = exc.code
    out[path] = [code, buf.getvalue()]
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def cli_help():
    """``example.py --help`` of every example, each run as ``__main__`` in one forked child of this process
    (conftest's :func:`run_forked`: bladecase already imported, no interpreter start)."""
    import json

    paths = [str(EXAMPLES / f"{name}.py") for name in NAMES]
    code, output = run_forked(_HELP_ALL, *paths)
    assert code == 0, output
    return json.loads(output.strip().splitlines()[-1])


@pytest.mark.parametrize("name", NAMES)
def test_example_cli_help(name, cli_help):
    code, text = cli_help[str(EXAMPLES / f"{name}.py")]
    assert code in (0, None), text
    assert "--out" in text and "--low" in text


# --- the paper's mode (examples/_paper.py) ----------------------------------


def test_paper_mode_from_1_to_2(paper, sys2):
    assert paper.five_T2(sys2) == pytest.approx(FIVE_T2, rel=1e-14)
    assert paper.two_ipp_families(sys2) == paper.two_ipp_families()  # cached, same families
    family, arc = paper.paper_arc(sys2)
    assert arc.T_hi == pytest.approx(FIVE_T2, rel=1e-6) and arc.refined_hi
    mode = paper.paper_mode(sys2)
    assert len(mode.arcs) == 1 and mode.arcs[0].T_lo == arc.T_lo and mode.arcs[0].T_hi == arc.T_hi
    assert mode.k == 2 and mode.admissible.all() and np.all(np.diff(mode.T) > 0)
    assert len(mode.orbits) == arc.stop - arc.start + 2  # the arc's points, then ② at T_hi
    one, two = mode.orbits[0], mode.orbits[-1]
    # ①: on the diagonal t1 = T/2, T ≈ 13.33
    assert one.T == pytest.approx(13.3286, abs=1e-4) and one.impact_times[0] == pytest.approx(one.T / 2, rel=1e-3)
    # ②: T -> 5 T2 (resonant, excluded), impulses -> 0, t1 -> 2 T2
    assert two.T == arc.T_hi and two.T <= FIVE_T2
    assert two.impulses.max() < 0.01 and np.all(two.impulses >= 0)
    assert two.impact_times[0] == pytest.approx(2 * FIVE_T2 / 5, rel=1e-6)


# --- Fig. 2 -----------------------------------------------------------------


def test_fig2_numerator_is_pole_free_s(ex, sys2):
    f2 = ex["fig2_impact_time_map"]
    omega = sys2.spectrum.contact_modes[0]
    rng = np.random.default_rng(0)
    for T in (1.7, 4.2, 9.3, 13.5):
        t1 = rng.uniform(0, T, 7)
        s = ModalKernel.of(sys2, T).g_s(t1)[1]
        assert np.allclose(f2.numerator(sys2, t1, T), s * np.prod(np.sin(omega * T / 2)), rtol=1e-12, atol=1e-14)
    # finite at a resonant period, and the diagonal t1 = T/2 is always a root
    T2 = 2 * np.pi / omega[1]
    assert np.all(np.isfinite(f2.numerator(sys2, np.linspace(0, 5 * T2, 9), 5 * T2)))
    T = np.linspace(1, 14.5, 50)
    assert np.abs(f2.numerator(sys2, T / 2, T)).max() < 1e-14
    res = [r for r, i, j in f2.resonant_periods(sys2)]
    assert any(abs(r - FIVE_T2) < 1e-6 for r in res) and any(abs(r - 7.1887356) < 1e-6 for r in res)


def test_fig2_paper_arc(ex, paper, sys2):
    f2 = ex["fig2_impact_time_map"]
    arcs = f2.admissible_arcs(paper.two_ipp_families(sys2))
    assert len(arcs) >= 1
    ends = np.array([a["T_hi"] for a in arcs])
    assert np.min(np.abs(ends - FIVE_T2)) <= 1e-6 * FIVE_T2
    _, main = paper.paper_arc(sys2)
    (arc,) = [a for a in arcs if a["arc"] is main]
    assert arc["T_hi"] == pytest.approx(FIVE_T2, rel=1e-6)
    assert arc["T_hi"] <= FIVE_T2 * (1 + 1e-12)  # T = 5 T2 itself is resonant (excluded); the end converges to it
    # ① on the diagonal at T ≈ 13.33 (the paper's red curve starts there)
    i = int(np.argmin(arc["T"]))
    assert arc["T"][i] == pytest.approx(13.33, abs=0.01)
    assert arc["t1"][i] == pytest.approx(arc["T"][i] / 2, rel=1e-3)
    # the arc lies on the zero set: s(t1) = 0 along it
    for T, t1 in zip(arc["T"][::20], arc["t1"][::20]):
        assert abs(ModalKernel.of(sys2, T).g_s(t1)[1]) < 1e-8


# --- Fig. 3 -----------------------------------------------------------------


def test_fig3_trajectories_admissible(ex, paper, sys2):
    f3 = ex["fig3_trajectories"]
    mode = paper.paper_mode(sys2)
    arc = mode.arcs[0]
    orbits = f3.arc_orbits(mode.orbits, 6)
    assert len(orbits) == 6
    Ts = [o.T for o in orbits]
    assert Ts == sorted(Ts) and Ts[0] == pytest.approx(arc.T_lo) and Ts[-1] == arc.T_hi
    # the last one is ②: T -> 5 T2, impulses -> 0, t1 -> 2 T2
    assert Ts[-1] == pytest.approx(FIVE_T2, rel=1e-6) and orbits[-1].impulses.max() < 0.01
    assert orbits[-1].impact_times[0] == pytest.approx(2 * FIVE_T2 / 5, rel=1e-6)
    d = sys2.gap
    for o in orbits:
        assert o.admissible and o.k == 2 and np.all(o.impulses >= 0)
        t = np.linspace(0, o.T, 20001)
        x, v = o.state(t)
        assert x.shape == (2, t.size)
        assert x[1].max() <= d + 1e-9
        xi, vi = o.state(o.impact_times)
        assert np.allclose(xi[1], d, atol=1e-9, rtol=0)  # touches d at both impacts
        assert np.all(vi[1] <= 0)  # moving away after the impact


# --- Fig. 4 -----------------------------------------------------------------


def test_fig4_manifold_and_jumps(ex, paper, sys2):
    f4 = ex["fig4_manifold"]
    mode = paper.paper_mode(sys2)
    assert len(mode.arcs) == 1 and mode.admissible.all()
    sub = f4.evenly_spaced(mode, 15)
    assert 6 <= len(sub.orbits) <= 15
    T, theta, x, v = sub.manifold(len(sub.orbits), 40)
    assert x.shape == v.shape == (2, len(sub.orbits), 40)
    assert T.min() == pytest.approx(mode.arcs[0].T_lo) and T.max() == pytest.approx(mode.arcs[0].T_hi)
    assert np.all(np.diff(T) > 0) and T.max() == pytest.approx(FIVE_T2, rel=1e-6)
    assert x[1].max() <= sys2.gap + 1e-9
    for o in sub.orbits:
        jumps = f4.impact_jumps(o)  # (k, 2, 3): pre/post (x1, x2, x2dot)
        assert jumps.shape == (2, 2, 3)
        assert np.allclose(jumps[:, :, 1], sys2.gap, atol=1e-9)
        assert np.allclose(jumps[:, 0, 2], -jumps[:, 1, 2])
        # pre-impact velocity from the flow just before the impact
        xs, vs = o.state(np.nextafter(o.impact_times, 0))
        assert np.allclose(vs[1], jumps[:, 0, 2], atol=1e-6)
        assert np.allclose(xs[0], jumps[:, 0, 0], atol=1e-9)
    tris = f4.flight_triangles(T, theta, np.array([o.impact_times[0] for o in sub.orbits]))
    assert tris.shape[1] == 3 and tris.shape[0] > 1.5 * (T.size - 1) * (theta.size - 1)


# --- frequency–energy --------------------------------------------------------


def test_frequency_energy_numbers(ex, paper, sys2):
    fe = ex["frequency_energy"]
    bb, families = fe.compute(sys2, 200)
    assert families == paper.two_ipp_families(sys2)
    ends = [iv.T_hi for iv in bb.intervals]
    assert any(abs(e - FIVE_T2) < 1e-6 for e in ends)  # 1-ipp interval ending at 5 T2 (resonance)
    mode = paper.paper_mode(sys2)
    o1, o2 = mode.orbits[0], mode.orbits[-1]
    # ①: the 2-ipp orbit is the 1-ipp orbit of period T/2 counted twice — same energy
    assert o1.energy == pytest.approx(bc.orbit_1ipp(sys2, o1.T / 2).energy, rel=1e-6)
    assert o1.energy == pytest.approx(0.2886, abs=1e-3)
    assert np.all(np.diff(mode.energy) > -1e-9)  # energy grows from ① to ②
    # ②: the energy of linear mode 2 grazing the obstacle, ½(ω₂ d/|b₂|)²
    omega, b, _ = sys2.spectrum.contact_modes
    E_graze = 0.5 * (omega[1] * sys2.gap / abs(b[1])) ** 2
    assert E_graze == pytest.approx(4.736, abs=1e-3)
    assert mode.orbits[-2].energy < o2.energy <= E_graze and o2.energy == pytest.approx(E_graze, rel=1e-5)


def test_fig9_forced_one_impact_per_period(ex):
    """The n = 5 chain forced at T = 5.5 and 5.4 (F₀ = 1, C = 0.01 K) settles on one impact per forcing period,
    periodic to 1e-9, with energies above 100 rising towards the 1-ipp backbone's resonance at T = 5.231."""
    f9 = ex["fig9_forced_response"]
    res, _ = f9.sweeps(f9.system(), [(1.0, 0.01)], [5.5, 5.4], 500, progress=False)
    pts = {p.T: p for p in res[1.0, 0.01]}
    for T in (5.5, 5.4):
        assert pts[T].label == "1/1" and pts[T].residual < 1e-9
    assert pts[5.4].energy > pts[5.5].energy > 100
