"""The example scripts in ``examples/`` (seed paper Figs. 2–4 and a frequency–energy plot).

Every example's ``main(out_dir, resolution="low")`` must write valid, non-trivial
PNGs, and the numbers behind the figures must be right:

* Fig. 2 — the pole-free numerator is ``s(t₁)·Π sin(ω_j T/2)``; one admissible
  2-ipp arc starts on the diagonal ``t₁ = T/2`` at T ≈ 13.33 (①) and ends within
  1 % of ``5T₂ = 13.7293`` (②), as in the paper;
* Fig. 3 — the trajectories stay behind the obstacle and touch it at the impacts;
  the branch, completed beyond the end of the continuation with ``orbits_kipp``,
  reaches ② (T → 5T₂, impulses → 0, t₁ → 2T₂);
* Fig. 4 — the manifold samples the arc, the jumps are elastic at ``x₂ = d``;
* frequency–energy — ① has the energy of the 1-ipp orbit of period ``T/2``;
  towards ② the energy tends to that of linear mode 2 grazing the obstacle.

``bladecase.nonsmooth_mode`` is memoised for the module (every example follows
the same families; the function is deterministic), which keeps the file fast.
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

import bladecase as bc
from bladecase.nsm import _Modal

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
NAMES = ["fig2_impact_time_map", "fig3_trajectories", "fig4_manifold", "frequency_energy"]
FIVE_T2 = 5 * 2.745852661  # 5 · 2π/ω₂ for chain(2, k=1, m=1/2)
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _load(name: str):
    spec = importlib.util.spec_from_file_location(f"bladecase_example_{name}", EXAMPLES / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module", autouse=True)
def memo_nonsmooth_mode():
    cache = {}
    original = bc.nonsmooth_mode

    def cached(system, k, T_range, **kw):
        key = (id(system), system.n, system.gap, k, tuple(T_range), tuple(sorted(kw.items())))
        if key not in cache:
            cache[key] = original(system, k, T_range, **kw)
        return cache[key]

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(bc, "nonsmooth_mode", cached)
        yield


@pytest.fixture(scope="module")
def ex():
    return {name: _load(name) for name in NAMES}


@pytest.fixture(scope="module")
def sys2():
    # one shared instance, so that the memoised families are reused across examples
    s = bc.chain(2, k=1.0, m=0.5, gap=1.0)
    return s


@pytest.fixture(scope="module", autouse=True)
def shared_system(ex, sys2):
    with pytest.MonkeyPatch.context() as mp:
        for mod in ex.values():
            mp.setattr(mod, "two_dof", lambda: sys2)
        yield


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


@pytest.mark.parametrize("name", NAMES)
def test_example_cli_help(name):
    r = subprocess.run([sys.executable, str(EXAMPLES / f"{name}.py"), "--help"], capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 0, r.stderr
    assert "--out" in r.stdout and "--low" in r.stdout


# --- Fig. 2 -----------------------------------------------------------------


def test_fig2_numerator_is_pole_free_s(ex, sys2):
    f2 = ex["fig2_impact_time_map"]
    omega = sys2.spectrum.contact_modes[0]
    rng = np.random.default_rng(0)
    for T in (1.7, 4.2, 9.3, 13.5):
        t1 = rng.uniform(0, T, 7)
        s = _Modal.of(sys2, T).g_s(t1)[1]
        assert np.allclose(f2.numerator(sys2, t1, T), s * np.prod(np.sin(omega * T / 2)), rtol=1e-12, atol=1e-14)
    # finite at a resonant period, and the diagonal t1 = T/2 is always a root
    T2 = 2 * np.pi / omega[1]
    assert np.all(np.isfinite(f2.numerator(sys2, np.linspace(0, 5 * T2, 9), 5 * T2)))
    T = np.linspace(1, 14.5, 50)
    assert np.abs(f2.numerator(sys2, T / 2, T)).max() < 1e-14
    res = [r for r, i, j in f2.resonant_periods(sys2)]
    assert any(abs(r - FIVE_T2) < 1e-6 for r in res) and any(abs(r - 7.1887356) < 1e-6 for r in res)


def test_fig2_paper_arc(ex, sys2):
    f2 = ex["fig2_impact_time_map"]
    arcs = f2.admissible_arcs(f2.two_ipp_families(sys2))
    assert len(arcs) >= 1
    ends = np.array([a["T_hi"] for a in arcs])
    assert np.min(np.abs(ends - FIVE_T2)) <= 0.01 * FIVE_T2
    arc = f2.paper_arc(arcs, sys2)
    assert arc["T_hi"] == pytest.approx(FIVE_T2, rel=0.01)
    assert arc["T_hi"] <= FIVE_T2 * (1 + 1e-9)  # T = 5 T2 itself is resonant (excluded); the end converges to it
    # ① on the diagonal at T ≈ 13.33 (the paper's red curve starts there)
    i = int(np.argmin(arc["T"]))
    assert arc["T"][i] == pytest.approx(13.33, abs=0.01)
    assert arc["t1"][i] == pytest.approx(arc["T"][i] / 2, rel=1e-3)
    # the arc lies on the zero set: s(t1) = 0 along it
    for T, t1 in zip(arc["T"][::20], arc["t1"][::20]):
        assert abs(_Modal.of(sys2, T).g_s(t1)[1]) < 1e-8


# --- Fig. 3 -----------------------------------------------------------------


def test_fig3_trajectories_admissible(ex, sys2):
    f3 = ex["fig3_trajectories"]
    fam, arc = f3.paper_family(sys2)
    assert arc.T_hi == pytest.approx(FIVE_T2, rel=0.01)
    every = f3.mode_orbits(fam, arc, sys2)
    # the arc (continuation, plus per-T solves closer to 5 T2) reaches ② (impulses -> 0)
    ext = [max(every, key=lambda o: o.T)]
    assert ext[-1].T == pytest.approx(FIVE_T2, rel=1e-4) and ext[-1].impulses.max() < 0.01
    assert ext[-1].impact_times[0] == pytest.approx(2 * FIVE_T2 / 5, rel=1e-3)  # t1 -> 2 T2
    orbits = f3.arc_orbits(every, 6)
    assert len(orbits) == 6
    Ts = [o.T for o in orbits]
    assert Ts == sorted(Ts) and Ts[0] == pytest.approx(arc.T_lo) and Ts[-1] == ext[-1].T
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


def test_fig4_manifold_and_jumps(ex, sys2):
    f4 = ex["fig4_manifold"]
    mode = f4.paper_mode(sys2)
    assert len(mode.arcs) == 1 and mode.admissible.all()
    sub = f4.evenly_spaced(mode, 15)
    assert 6 <= len(sub.orbits) <= 15
    T, theta, x, v = sub.manifold(len(sub.orbits), 40)
    assert x.shape == v.shape == (2, len(sub.orbits), 40)
    assert T.min() == pytest.approx(mode.arcs[0].T_lo) and T.max() == pytest.approx(mode.arcs[0].T_hi)
    assert np.all(np.diff(T) > 0) and T.max() == pytest.approx(FIVE_T2, rel=1e-4)
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


def test_frequency_energy_numbers(ex, sys2):
    fe = ex["frequency_energy"]
    bb, families = fe.compute(sys2, 200)
    ends = [iv.T_hi for iv in bb.intervals]
    assert any(abs(e - FIVE_T2) < 1e-6 for e in ends)  # 1-ipp interval ending at 5 T2 (resonance)
    fam, arc = min(((f, a) for f in families for a in f.arcs), key=lambda fa: abs(fa[1].T_hi - FIVE_T2))
    o1 = fam.orbits[arc.start]
    # ①: the 2-ipp orbit is the 1-ipp orbit of period T/2 counted twice — same energy
    assert o1.energy == pytest.approx(bc.orbit_1ipp(sys2, o1.T / 2).energy, rel=1e-6)
    assert o1.energy == pytest.approx(0.2886, abs=1e-3)
    assert np.all(np.diff(fam.energy[arc.start: arc.stop + 1]) > -1e-9)  # energy grows from ① to ②
    # ②: towards the energy of linear mode 2 grazing the obstacle, ½(ω₂ d/|b₂|)²
    last = fam.orbits[arc.stop]
    ext = fe.grazing_extension(sys2, last, FIVE_T2)
    omega, b, _ = sys2.spectrum.contact_modes
    E_graze = 0.5 * (omega[1] * sys2.gap / abs(b[1])) ** 2
    assert E_graze == pytest.approx(4.736, abs=1e-3)
    assert last.energy < ext[-1].energy < E_graze and ext[-1].energy == pytest.approx(E_graze, rel=0.02)
