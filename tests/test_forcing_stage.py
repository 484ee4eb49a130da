"""The forcing stage (bladecase.study.forcing.stage): linear steady state against the closed form, a sweep with
impacts on the plate study's reduced model (CSV, figure, classes confirmed by re-simulation), refusals."""

from __future__ import annotations

import csv

import numpy as np
import pytest
from _studies import PLATE, ROOT, absolute

from bladecase.nsm import chain
from bladecase.nsm.damping import Damping
from bladecase.nsm.sweep import forced_point
from bladecase.post.forcing.plots import forced_response_plot
from bladecase.post.outputs import FORMATS
from bladecase.reduction import reduce
from bladecase.reduction.loads import project_load
from bladecase.study.forcing.stage import build_load, forced_response, forced_scene, forcing_frequencies, steady_orbit
from bladecase.study.schema import loads
from bladecase.study.stages import build_contact, build_mesh, build_model, build_reduced, search


@pytest.fixture(scope="module")
def plate():
    study = loads(absolute(PLATE).replace("size = 10", "size = 4") + "[output]\nframes = 6\n")
    mesh = build_mesh(study)
    model = build_model(study, mesh)
    contact = build_contact(study, model)
    reduced = build_reduced(study, model, contact)
    return study, reduced, search(study, reduced.system)


def _harmonic(system, damping, load, amplitude, T):
    """Closed-form steady state x(t) = Re(X e^{iΩt}), (K − Ω²M + iΩC) X = F₀ f."""
    M = system.M.toarray() if hasattr(system.M, "toarray") else np.asarray(system.M)
    K = system.K.toarray() if hasattr(system.K, "toarray") else np.asarray(system.K)
    Om = 2 * np.pi / T
    return np.linalg.solve(K - Om**2 * M + 1j * Om * damping.matrix(system), amplitude * np.asarray(load, float)), Om


def test_linear_steady_state_matches_closed_form():
    s = chain(3, k=1.0, m=1 / 3, gap=1e3)                  # never reaches the obstacle
    damping, load, T = Damping(zeta=0.05), np.array([1.0, -0.5, 2.0]), 3.1
    pt = forced_point(s, T, damping=damping, amplitude=0.7, load=load, n_periods=300)
    assert pt.label == "0/1"
    orbit = steady_orbit(s, pt, damping=damping, amplitude=0.7, load=load)
    X, Om = _harmonic(s, damping, load, 0.7, T)
    t = np.linspace(0, T, 17)
    x, v = orbit.state(t)
    ref_x = np.real(X[:, None] * np.exp(1j * Om * t))
    ref_v = np.real(1j * Om * X[:, None] * np.exp(1j * Om * t))
    assert np.abs(x - ref_x).max() <= 1e-6 * np.abs(X).max()
    assert np.abs(v - ref_v).max() <= 1e-6 * Om * np.abs(X).max()
    lo, hi = orbit.contact_range()
    amp = abs(s.w @ X)
    assert abs(hi - amp) <= 1e-6 * amp and abs(lo + amp) <= 1e-6 * amp
    assert orbit.k == 0 and orbit.return_error <= 1e-8


def test_stage_linear_plate_matches_closed_form(plate, tmp_path):
    """No contact reached: the stage's contact amplitude is |wᵀX| of the harmonic response of the reduced model
    to the projected load, to 1e-6."""
    _, reduced, families = plate
    forcing = {"ratio": 0.05, "amplitude": 5.0, "frequencies": [0.9, 1.1], "points": 3, "periods": 120}
    out = forced_response(reduced, families, forcing, folder=tmp_path)
    c = out["points"]
    assert c["label"] == ["0/1"] * 3 and out["classes"] == {"0/1": 3}
    f_r = project_load(reduced, build_load(reduced, forcing)[0])
    for f_hz, amp in zip(c["frequency_hz"], c["contact_amplitude_m"]):
        X, _ = _harmonic(reduced.system, Damping(zeta=0.05), f_r, 5.0, 1 / f_hz)
        exact = abs(reduced.system.w @ X)
        assert abs(amp - exact) <= 1e-6 * exact
        assert exact < 0.2 * reduced.system.gap
    f1 = reduced.system.spectrum.contact_modes[0][0] / (2 * np.pi)
    assert np.allclose(c["frequency_hz"], f1 * np.array([0.9, 1.0, 1.1]), rtol=1e-14)
    assert (tmp_path / "forced.csv").exists() and not (tmp_path / "forced_response.png").exists()
    assert "3 without contact" in out["words"]


def test_stage_with_contact(plate, tmp_path):
    study, reduced, families = plate
    forcing = {"ratio": 0.03, "amplitude": 900.0, "frequencies": [0.96, 1.04], "points": 2, "periods": 100}
    out = forced_response(reduced, families, forcing, folder=tmp_path, figures=True, title="plate")
    c = out["points"]
    with open(tmp_path / "forced.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 2 and rows[0]["label"] == c["label"][0]
    assert float(rows[1]["frequency_hz"]) == pytest.approx(c["frequency_hz"][1], rel=1e-11)
    assert (tmp_path / "forced_response.png").stat().st_size > 10_000
    assert out["files"] == {"csv": "forced.csv", "figure": "forced_response.png"}
    impacting = [i for i, lab in enumerate(c["label"]) if "/" in lab and not lab.startswith("0/")]
    assert impacting, c["label"]
    for i in impacting:   # the class is confirmed by re-simulating one cycle from the end state
        assert c["return_error"][i] <= 1e-6
        assert c["resimulated_contacts"][i] == c["k"][i]
        assert abs(c["contact_max_m"][i] - reduced.system.gap) <= 1e-9 * reduced.system.gap
    orbit = out["orbits"][impacting[0]]
    x0, v0 = orbit.state([0.0])
    x1, v1 = orbit.trajectory.state([orbit.T])
    assert np.linalg.norm(x1 - x0) <= 1e-5 * np.linalg.norm(x0)
    assert out["peak"]["energy_j"] == max(c["energy_j"])
    scene = forced_scene(study, reduced, orbit, "forced_0")
    assert scene.u.shape[2] == 6 and scene.times[-1] < orbit.T
    assert int(scene.impact.sum()) == min(orbit.k, 6)
    assert FORMATS.write(["vtu"], "orbit", scene, tmp_path) == {"pvd": "vtk/forced_0.pvd"}
    assert "The forced peak at" in out["words"]
    fig = forced_response_plot(c["frequency_hz"], c["energy_j"], c["label"], backbones=families)
    names = fig.axes[0].get_legend_handles_labels()[1]
    assert "1-ipp nonsmooth mode (admissible arcs)" in names and f"{c['k'][impacting[0]]} impacts / 1 period" in names


def test_engine_order_rpm(plate):
    _, reduced, _ = plate
    forcing = {"ratio": 0.01, "amplitude": 1.0, "engine_order": 4, "frequencies": [24000.0, 25000.0],
               "frequency_unit": "rpm", "points": 3}
    assert np.allclose(forcing_frequencies(reduced, forcing), [1600.0, 1633.3333333333333, 1666.6666666666667],
                       rtol=1e-14)
    assert build_load(reduced, forcing)[1].endswith("engine order 4")


def test_pressure_load_spec(plate):
    _, reduced, _ = plate
    f, words = build_load(reduced, {"ratio": 0.01, "amplitude": 1.0, "load": "pressure", "group": "tip"})
    # the plate's tip edge (y = 0.1, 20 mm wide, 2 mm thick), 1 Pa pushing in: −y total 0.02 × 0.002 N
    assert abs(float(f[reduced.model.dofs.direction == 1].sum()) + 4e-5) <= 1e-15
    assert "pressure" in words


@pytest.mark.parametrize("bad, match", [
    ({"amplitude": 1.0}, "exactly one damping"),
    ({"ratio": 0.01, "rayleigh": [0.0, 1.0], "amplitude": 1.0}, "exactly one damping"),
    ({"ratio": 0.01}, "amplitude: required"),
    ({"ratio": 0.01, "amplitude": 1.0, "frequency_unit": "rpm"}, "needs an engine_order"),
    ({"ratio": 0.01, "amplitude": 1.0, "load": "pressure"}, "group"),
    ({"ratio": 0.01, "amplitude": 1.0, "colour": 1}, "unknown key"),
    ({"ratio": 0.01, "amplitude": 1.0, "frequencies": [2.0, 1.0]}, "0 < lower < upper"),
    ({"ratio": 0.01, "amplitude": 1.0, "periods": 8}, "at least 2 × max_p"),
    ({"ratio": 0.01, "amplitude": 1.0, "load": "pressure", "group": "root"}, r"\[forcing\] load: .*clamped dofs only"),
    ({"ratio": 0.01, "amplitude": 1.0, "node": 0, "load_direction": [0, 1]}, r"\[forcing\] node 0 has no free dof"),
])
def test_bad_settings(plate, bad, match):
    _, reduced, families = plate
    with pytest.raises(ValueError, match=match):
        forced_response(reduced, families, bad)


def test_massless_stage_runs_and_loads_the_contact_dofs(plate, tmp_path):
    """The massless contact model (4 modes + attachment): the default load sits on the massless contact node, so
    it enters as the condensed load plus its static contact displacement g = w_cᵀK_cc⁻¹f_c; the state with contact
    phases is confirmed by re-simulation and touches the casing exactly."""
    from bladecase.study.forcing.stage import contact_load

    _, reduced, _ = plate
    massless = reduce(reduced.model, reduced.contact, "massless", 4)
    f, _ = build_load(massless, {"ratio": 0.03, "amplitude": 1.0})
    K, w = massless.model.K.tocsc(), massless.contact.w(massless.model)
    c = np.flatnonzero(w)
    g_direct = float(w[c] @ np.linalg.solve(K[c][:, c].toarray(), f[c]))
    assert g_direct > 0 and abs(contact_load(massless, f) - g_direct) <= 1e-12 * g_direct
    assert contact_load(reduced, f) == 0.0  # Newton's model: the load is just a load
    out = forced_response(massless, [], {"ratio": 0.03, "amplitude": 900.0, "frequencies": [0.96, 1.04],
                                         "points": 2, "periods": 100}, folder=tmp_path)
    pts = out["points"]
    assert pts["label"] == ["1/1", "0/1"], pts["label"]
    assert pts["return_error"][0] <= 1e-8 and pts["resimulated_contacts"][0] == pts["k"][0] == 1
    assert pts["contact_max_m"][0] == massless.system.gap and pts["contact_max_m"][1] < massless.system.gap
    assert "1 periodic with contact phases (1 × 1/1 contact phases per forcing periods)" in out["words"]
    assert (tmp_path / "forced.csv").stat().st_size > 100
    with pytest.raises(ValueError, match="restitution: Newton's contact model only"):
        forced_response(massless, [], {"ratio": 0.01, "amplitude": 1.0, "restitution": 0.8})


def test_a_study_with_forcing_writes_the_forced_response_and_animates_a_steady_state(tmp_path):
    """[forcing] end to end through bladecase.study.run: forced.csv, the plot over the backbone, a steady state
    animated like a mode, the report's section, and every state with impacts re-simulated back to itself."""
    from _studies import PLATE, ROOT

    from bladecase.study import run
    from bladecase.study.schema import loads

    # [output] animate = 0: no nonsmooth mode animated (not asserted; tests/test_pipeline.py animates them); the
    # forced state is still animated ([forcing] animate = 1 by default), in a small window: its GIF is only sized
    text = PLATE.replace("size = 10", "size = 4") + (
        '\n[output]\nformats = ["png", "gif"]\nanimate = 0\nwindow = [160, 120]\nreference = false\nframes = 6\n'
        '[forcing]\nratio = 0.03\namplitude = 900.0\nfrequencies = [0.9, 1.1]\npoints = 7\nperiods = 150\n'
        'direction = "up"\n')
    result = run(loads(text, base=ROOT), out=tmp_path / "out", progress=False)
    out = result.directory
    section = result.summary["forcing"]
    assert (out / "forced.csv").stat().st_size > 100 and (out / "forced_response.png").stat().st_size > 10_000
    pts = section["points"]
    assert len(pts["frequency_hz"]) == 7 and "timings_s" in result.summary
    impacting = [i for i, lab in enumerate(pts["label"]) if "/" in lab and not lab.startswith("0/")]
    assert impacting, pts["label"]  # 900 N at the contact drives the plate into the casing near resonance
    assert all(pts["return_error"][i] <= 1e-6 for i in impacting)
    anim = result.summary["files"]["forced_animations"]
    assert len(anim) == 1 and (out / anim[0]["gif"]).stat().st_size > 1000
    assert "## Forced response" in (out / "report.md").read_text()


#: The plate with the massless contact model, forced hard enough to touch the casing near resonance.
MASSLESS_FORCED = PLATE.replace("size = 10", "size = 4").replace("[contact]\n", '[contact]\nmodel = "massless"\n'
                                                                 ).replace('method = "modal"', 'method = "massless"'
                                                                           ).replace("periods = [0.5, 0.9999]",
                                                                                     "periods = [0.8, 1.001]") + (
    '\n[output]\nformats = ["png", "gif"]\nanimate = 1\nwindow = [160, 120]\nreference = false\nframes = 6\n'
    'manifold = false\n[forcing]\nratio = 0.03\namplitude = 900.0\nfrequencies = [0.9, 1.1]\npoints = 5\n'
    'periods = 100\n')


@pytest.fixture(scope="module")
def massless_forced_run(tmp_path_factory):
    """``(RunResult, forced steady states)`` of the massless forced plate study run once through
    bladecase.study.run; the run drops the steady states (:class:`ForcedOrbit`) from its summary, so the
    forcing stage's answer is kept on its way.  A massless mode is animated too (the render path of contact
    phases), in a small window: the GIFs are only sized."""
    import importlib

    from bladecase.study import run

    run_module = importlib.import_module("bladecase.study.run")  # (bladecase.study.run is the function)
    kept = []
    real = run_module.forced_response

    def keep(*args, **kwargs):
        section = real(*args, **kwargs)
        kept.append(section["orbits"])
        return section

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(run_module, "forced_response", keep)
        result = run(loads(MASSLESS_FORCED, base=ROOT), out=tmp_path_factory.mktemp("massless") / "out",
                     progress=False)
    assert len(kept) == 1
    return result, kept[0]


def test_a_massless_study_with_forcing(massless_forced_run):
    """[forcing] with [contact] model = "massless" through bladecase.study.run: the steady states with contact
    phases are re-simulated back to themselves and one is animated; restitution is refused by the schema."""
    from bladecase.study import StudyError

    result, _ = massless_forced_run
    pts = result.summary["forcing"]["points"]
    touching = [i for i, lab in enumerate(pts["label"]) if "/" in lab and not lab.startswith("0/")]
    assert touching, pts["label"]
    assert all(pts["return_error"][i] <= 1e-6 and pts["resimulated_contacts"][i] == pts["k"][i] for i in touching)
    anim = result.summary["files"]["forced_animations"]
    assert len(anim) == 1 and (result.directory / anim[0]["gif"]).stat().st_size > 1000
    with pytest.raises(StudyError, match="restitution: Newton's contact model only"):
        loads(MASSLESS_FORCED + "restitution = 0.9\n", base=ROOT)


def test_forced_massless_frames_hold_the_contact_at_the_casing(massless_forced_run):
    """A load on the massless contact dofs moves them (F K_cc⁻¹f_c) and the multiplier: in every frame of the
    animated steady state the contact displacement wᵀx of the FE field stays at or below the gap, on it while
    in contact (before the correction the frames were off by ~3 % of the gap).

    The steady states are the forcing stage's of the study run above (its reduced model: the FE model's
    stiffness factor, as the stages build it); the frames are drawn here, 24 of them."""
    result, orbits = massless_forced_run
    study = loads(MASSLESS_FORCED.replace('formats = ["png", "gif"]', "formats = []").replace(
        "frames = 6", "frames = 24"), base=ROOT)
    assert study["output"]["frames"] == 24
    reduced = next(iter(result.models.values())).reduced
    model, contact = reduced.model, reduced.contact
    assert reduced.method == "massless" and reduced.size == 4
    labels = result.summary["forcing"]["points"]["label"]
    assert len(orbits) == len(labels)
    pick = next(i for i, lab in enumerate(labels)
                if "/" in lab and not lab.startswith("0/") and orbits[i] is not None)
    scene = forced_scene(study, reduced, orbits[pick], "s")
    w = contact.w(model)
    x, _ = orbits[pick].state(scene.times)
    x_free = reduced.free_dofs(x)
    from bladecase.post.grid import fe_grid

    grid = fe_grid(model)
    u_scene = scene.u.reshape(len(grid.points) * model.dim, -1)[model.dofs.fe_index]
    y = w @ u_scene
    gap = contact.gap
    assert y.max() <= gap * (1 + 1e-9)
    closed = orbits[pick]._contact(scene.times) >= gap * (1 - 1e-12)
    assert closed.any() and np.allclose(y[closed], gap, rtol=1e-9)
    # the unforced slaving misplaces them: the correction is not nothing
    assert np.abs(w @ x_free - y).max() > 1e-3 * gap
