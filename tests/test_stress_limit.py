"""The elastic limit: ``[material] yield_strength`` cuts the admissible arcs (the every-node family, the Campbell
bands) where an orbit's peak von Mises stress exceeds it, and the report, the summary and the verdict say where and
why.

Checked: the stress of many displacements at once (:func:`bladecase.fe.stress.stress_modes`) is each one's
:func:`~bladecase.fe.stress.nodal_stress`; the nodal stress of a tip-loaded cantilever against beam theory; an orbit's
peak von Mises from the basis' stresses equals the nodal stress of the orbit expanded to the mesh at the same instant
(and the per-orbit expansion's, and every node's: the peak evaluates only the nodes whose stress bound reaches it),
the centrifugal prestress added at speed; on the massless plate strip (steel, its backbone's peak von Mises 55.7 MPa
at grazing → 89 MPa at the arc's top), a yield strength of 70 MPa cuts the arc at the last orbit below it, the
every-node family at its first orbit beyond, and at 8000 rpm (the prestress alone above it) the Campbell band whole;
the report, summary and verdict say so; a yield strength typed in MPa is refused with the value in Pa.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse.linalg import spsolve
from skfem import MeshTet
from test_convergence import STRIP

from bladecase.fe import Mesh, assemble
from bladecase.fe.stress import fe_node_points, nodal_stress, stress_modes, von_mises
from bladecase.post.report import report
from bladecase.study import run
from bladecase.study.schema import StudyError, loads
from bladecase.study.stress_limit import OrbitStress, orbit_stress, orbit_times

YIELD = 7e7  # Pa: inside the strip's backbone (55.7 → 89 MPa)


def _with_yield(text: str, yield_strength: float):
    return loads(text.replace('material = {preset = "steel"}',
                              f'material = {{preset = "steel", yield_strength = {yield_strength!r}}}'))


def _study(yield_strength: float):
    return _with_yield(STRIP, yield_strength)


@pytest.fixture(scope="module")
def cut(tmp_path_factory):
    return run(_study(YIELD), tmp_path_factory.mktemp("yield") / "out", progress=False)


@pytest.fixture(scope="module")
def bar():
    """A P2 steel bar, 0.1 × 0.01 × 0.01 m, 4 × 1 × 1 boxes of 6 tetrahedra, clamped at x = 0."""
    t = MeshTet.init_tensor(np.linspace(0, 0.1, 5), *2 * [np.linspace(0, 0.01, 2)])
    return assemble(Mesh(t.p.T, {"tetra": t.t.T}, dim=3, groups={"root": np.flatnonzero(t.p[0] == 0)}), "steel",
                    order=2)


def test_stress_modes_are_each_vectors_nodal_stress(bar):
    """Random displacements (P2, every component of the tensor non-zero): to round-off of the largest value."""
    V = np.random.default_rng(3).standard_normal((bar.n_dofs, 5)) * 1e-4
    S = stress_modes(bar, V)
    for j in range(V.shape[1]):
        s = nodal_stress(bar, V[:, j])
        want = np.stack([s[:, 0, 0], s[:, 1, 1], s[:, 2, 2], s[:, 0, 1], s[:, 1, 2], s[:, 2, 0]], axis=1)
        assert np.abs(S[j] - want).max() <= 1e-12 * np.abs(want).max()
    with pytest.raises(ValueError, match=rf"vectors must be a finite \({bar.n_dofs}, k\) array"):
        stress_modes(bar, V[:-1])


def test_a_cantilever_against_beam_theory():
    """A steel cantilever, L = 0.2 m, 20 × 20 mm section (P2, 20 × 2 × 2 boxes of 6 tetrahedra), 100 N on its free
    end: σ_xx = −M y / I with M = P (L − x) on the top and bottom fibres, away from the clamp (≥ 2.5 depths) and the
    loaded end (≥ 4 depths), x in [0.05, 0.12] m. Measured 1.43 % (0.36 % with 40 × 4 × 4 boxes: it converges)."""
    L, c, P = 0.2, 0.01, 100.0
    m = MeshTet.init_tensor(np.linspace(0, L, 21), *2 * [np.linspace(-c, c, 3)])
    beam = assemble(Mesh(m.p.T, {"tetra": m.t.T}, dim=3, groups={"root": np.flatnonzero(m.p[0] == 0)}), "steel",
                    order=2)
    tip = (np.abs(beam.dofs.coords[:, 0] - L) < 1e-12) & (beam.dofs.direction == 1)
    u = spsolve(beam.K.tocsc(), np.where(tip, P / tip.sum(), 0.0))
    s, X = nodal_stress(beam, u), fe_node_points(beam)
    fibre = (np.abs(np.abs(X[:, 1]) - c) < 1e-12) & (X[:, 0] > 0.05 - 1e-9) & (X[:, 0] < 0.12 + 1e-9)
    exact = -P * (L - X[fibre, 0]) * X[fibre, 1] / ((2 * c) ** 4 / 12)
    assert fibre.sum() >= 40
    assert np.abs(s[fibre, 0, 0] / exact - 1).max() < 0.02


def test_the_peak_is_the_expanded_orbits_stress(cut):
    """The fast path (the basis' stresses combined) against the orbit expanded to the mesh (its free-dof
    displacement at the peak's instant, :func:`nodal_stress`): equal to 1e-10; at other sampled instants the
    expanded stress stays below the peak; the per-orbit expansion (no basis stresses) gives the same peak."""
    reduced = next(iter(cut.models.values())).reduced
    fam = cut.families[0]
    orbit = fam.orbits[cut.summary["validity"]["stress_cuts"][0]["orbit_beyond"]]
    fast = orbit_stress(reduced)
    peak = fast.peak(orbit)
    t = peak["t_over_T"] * orbit.T
    x, _ = orbit.state([t])
    vm = von_mises(nodal_stress(reduced.model, reduced.free_dofs(x)[:, 0]))
    assert peak["von_mises_pa"] == pytest.approx(vm.max(), rel=1e-10)
    assert np.allclose(np.asarray(peak["at_mm"]) / 1e3, fe_node_points(reduced.model)[np.argmax(vm)], atol=1e-6)
    times = orbit_times(orbit)
    x, _ = orbit.state(times[:: max(1, times.size // 12)])
    U = reduced.free_dofs(x)
    assert max(von_mises(nodal_stress(reduced.model, U[:, j])).max() for j in range(U.shape[1])) <= \
        peak["von_mises_pa"] * (1 + 1e-12)
    slow = OrbitStress(reduced, None, fast.points)
    assert slow(orbit) == pytest.approx(peak["von_mises_pa"], rel=1e-10)
    # the peak evaluates few nodes (their stress bounds): every node evaluated gives the same, along the family
    for o in [o for o in fam.orbits if o is not None and o.admissible][::6]:
        x, _ = o.state(orbit_times(o))
        assert fast(o) == pytest.approx(np.sqrt(fast.mises_squared(x).max()), rel=1e-12)


def test_a_low_yield_cuts_the_arc_and_says_so(cut):
    s = cut.summary
    v = s["validity"]
    assert v["yield_strength_pa"] == YIELD and v["cuts"] == [] and len(v["stress_cuts"]) == 1
    c = v["stress_cuts"][0]
    assert c["von_mises_cut"] <= YIELD < c["von_mises_beyond"]
    (arc,) = s["families"][0]["admissible_arcs"]
    assert arc["f_hi"] == pytest.approx(1 / c["T_cut"], rel=1e-12) and arc["f_lo"] < arc["f_hi"]
    # the orbits left on the arc next to the cut (the most stressed: the stress grows along the backbone) are within
    # the limit, measured again
    fam = cut.families[0]
    stress = orbit_stress(next(iter(cut.models.values())).reduced)
    ends = [j for j in range(fam.arcs[0].start, fam.arcs[0].stop + 1) if fam.orbits[j].admissible][-3:]
    kept = [stress(fam.orbits[j]) for j in ends]
    assert len(kept) == 3 and max(kept) <= YIELD and kept[-1] == pytest.approx(c["von_mises_cut"], rel=1e-12)
    text = report(s)
    assert "**Cut at the elastic limit:**" in text and f"{1 / c['T_cut']:.6g} Hz" in text and "70 MPa" in text
    assert "cut_at_yield_strength" in s["verdict"]["reasons"]
    assert "peak von Mises stress exceeds the yield strength, 70 MPa" in s["verdict"]["trust"]
    log = (cut.directory / "run.log").read_text()
    assert "cut at the elastic limit" in log and "above [material] yield_strength = 70 MPa" in log


@pytest.mark.parametrize("value, words", [
    (880.0, r"\[material\] yield_strength: must be a stress in Pa in \[10000, 1e\+11\]; 880 looks like MPa: .*"
            r"give yield_strength = 8\.8e\+08 \(Pa\)"),
    (-1.0, r"\[material\] yield_strength: must be in \[10000, 1e\+11\] \(Pa\)"),
])
def test_a_yield_strength_in_mpa_is_refused(value, words):
    with pytest.raises(StudyError, match=words):
        _study(value)


def test_the_every_node_family_is_cut_at_the_yield(tmp_path):
    """``points = "nodes"``: the family (its peak von Mises 55.7 → 70.6 MPa over its first six orbits) stops at its
    last orbit below 70 MPa; the first dropped is beyond it, by the orbit expanded to the mesh (the nodes' forces'
    shapes included) at its peak instant; the report says where and why."""
    from bladecase.nsm.massless.nodal_modes import nodal_family
    from bladecase.post.nodal.report import nodal_report
    from bladecase.reduction.nodes import nodal_model
    from bladecase.study.nodal.stage import nodal_stage
    from bladecase.study.stages import build_contact, build_mesh, build_model

    study = loads(STRIP.replace('model = "massless"', 'model = "massless"\npoints = "nodes"').replace(
        'material = {preset = "steel"}', f'material = {{preset = "steel", yield_strength = {YIELD!r}}}'))
    model = build_model(study, build_mesh(study))
    contact = build_contact(study, model)
    section = nodal_stage(study, model, contact, [], None, folder=tmp_path, figures=False)
    c = section["validity"]["stress_cut"]
    k = c["index"]
    assert section["orbits"] == k >= 2 and section["end"]["kind"] == "yield_strength"
    assert c["von_mises_cut_pa"] <= YIELD < c["von_mises_beyond_pa"]
    nodal = nodal_model(model, contact, 8, residual=True)
    family = nodal_family(nodal.system, 0, through_resonances=True,  # the same, up to the first orbit beyond
                          energy_max=c["energy_beyond_j"] * (1 + 1e-9))
    beyond = family.orbits[k]
    assert beyond.frequency == pytest.approx(c["frequency_beyond_hz"], rel=1e-9)
    x, _ = beyond.state([c["t_over_T"] * beyond.T])
    vm = von_mises(nodal_stress(model, nodal.free_dofs(x)[:, 0]))
    assert vm.max() == pytest.approx(c["von_mises_beyond_pa"], rel=1e-10)
    text = "\n".join(nodal_report(section))
    assert "**The family is cut at the elastic limit**" in text and "above the yield strength 70 MPa" in text


def test_at_speed_the_centrifugal_prestress_is_added():
    """At 8000 rpm about an axis 0.3 m below the root the steady centrifugal stress is added at every instant: the
    peak equals the von Mises of (prestress + the orbit's stress expanded to the mesh) at its instant, to 1e-10."""
    from bladecase.fe.rotation import spun_state

    text = STRIP + "[rotation]\nspeed = 8000\naxis = {origin = [0, -0.3, 0], direction = [0, 0, 1]}\n"
    from bladecase.fe import stiffness_factor
    from bladecase.study.rotation.stage import operating_point
    from bladecase.study.stages import build_contact, build_mesh, build_model, build_reduced, search

    study = loads(text.replace("scan = 8", "scan = 4"))
    model = build_model(study, build_mesh(study))
    model, contact, factor, _ = operating_point(study, model, build_contact(study, model), stiffness_factor(model))
    reduced = build_reduced(study, model, contact, factor=factor)
    orbit = next(o for f in search(study, reduced.system, progress=False) for o in f.orbits
                 if o is not None and o.admissible)
    stress = orbit_stress(reduced)
    assert stress.steady is not None
    peak = stress.peak(orbit)
    x, _ = orbit.state([peak["t_over_T"] * orbit.T])
    u0 = spun_state(reduced.model)[2]
    total = nodal_stress(reduced.model, u0) + nodal_stress(reduced.model, reduced.free_dofs(x)[:, 0])
    assert peak["von_mises_pa"] == pytest.approx(von_mises(total).max(), rel=1e-10)
    vibration = von_mises(nodal_stress(reduced.model, reduced.free_dofs(x)[:, 0])).max()
    assert abs(peak["von_mises_pa"] - vibration) > 0.01 * vibration  # the prestress matters here


def test_a_campbell_band_is_cut_at_the_yield():
    """At 8000 rpm the centrifugal prestress alone exceeds 70 MPa: no orbit of the band is within the elastic limit,
    the band is dropped, and the summary's entry, the log and the report say where and why."""
    from bladecase.post.rotation.report import _cut_lines
    from bladecase.study.executor import SerialExecutor
    from bladecase.study.rotation.stage import campbell_stage
    from bladecase.study.stages import build_contact, build_mesh, build_model

    text = STRIP.replace("scan = 8", "scan = 4").replace("periods = [0.95, 1.0]", "periods = [0.995, 1.0]") + \
        "[rotation]\nspeeds = [8000]\naxis = {origin = [0, -0.3, 0], direction = [0, 0, 1]}\n"
    study = _with_yield(text, YIELD)
    model = build_model(study, build_mesh(study))
    _, section = campbell_stage(study, model, build_contact(study, model), SerialExecutor())
    (cut,) = section["band_stress_cuts"]
    assert section["bands"] == [None] and cut["high_hz"] is None and cut["f_cut_hz"] is None
    assert cut["von_mises_beyond_pa"] > YIELD and cut["yield_strength_pa"] == YIELD
    text = "\n".join(_cut_lines(section, study["rotation"]["speed_unit"]))
    assert "**Bands cut at the elastic limit:** at 8000 rpm" in text and "no band is left" in text
