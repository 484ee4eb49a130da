"""Fixes from a review: massless branches' ``orbit_at`` and ``table``, the 2-D rotation axis, the comparison grid's
main model, ``load_mesh``'s docstring, issue numbers in user-facing text, the package version."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import bladecase as bc
from bladecase.nsm import Branch, backbone, chain
from bladecase.nsm.massless.model import simulate_massless
from bladecase.nsm.massless.phases import PhasedOrbit

# -- 1. Branch.orbit_at on the massless model's branches ------------------------------------------------------------


@pytest.fixture(scope="module")
def phased(bar10_massless_mode):
    """The 10-element bar's first massless mode over (3.2, 4.1): one contact phase from grazing, two after the
    pattern changes near T = 3.2695, then a fold in T (measured: 17 one-phase points, then 97 two-phase ones);
    conftest's ``massless_mode(bar(10, 0.5, contact="massless"), (3.2, 4.1))``."""
    return bar10_massless_mode


def _returns(orbit) -> float:
    """Relative return error of one period of the exact event-driven simulation from mid-open (not a switch)."""
    t0 = orbit.mid_open_time
    x0, v0 = (z[:, 0] for z in orbit.state(np.array([t0])))
    traj = simulate_massless(orbit.system, x0, v0, orbit.T)
    closings = sum(p == "closed" for p in traj.phases)
    assert closings == orbit.k
    sv = float(np.abs(orbit.state(np.linspace(0, orbit.T, 16))[1]).max())
    return max(np.abs(traj.x_end - x0).max() / np.abs(x0).max(), np.abs(traj.v_end - v0).max() / sv)


def test_orbit_at_on_a_phased_massless_mode(phased):
    """Between two points of the same phase pattern: the exact orbit at T, between its neighbours, periodic."""
    assert all(isinstance(o, PhasedOrbit) for o in phased.orbits)
    o1, o2 = phased.orbits[10], phased.orbits[11]
    T = 0.5 * (o1.T + o2.T)
    (orbit,) = phased.orbit_at(T)
    assert isinstance(orbit, PhasedOrbit) and orbit.k == 1 and orbit.admissible
    assert orbit.T == pytest.approx(T, rel=1e-13)
    assert min(o1.energy, o2.energy) < orbit.energy < max(o1.energy, o2.energy)
    assert _returns(orbit) < 1e-8


def test_orbit_at_across_a_change_of_phase_pattern(phased):
    """Between the last one-phase point and the first two-phase one: the admissible continuation (two phases)."""
    sizes = [o.durations.size for o in phased.orbits]
    i = sizes.index(3) - 1
    o1, o2 = phased.orbits[i], phased.orbits[i + 1]
    assert (o1.k, o2.k) == (1, 2)
    T = 0.5 * (o1.T + o2.T)
    found = [o for o in phased.orbit_at(T) if abs(o.energy - o1.energy) < 0.01 * o1.energy]
    (orbit,) = found
    assert orbit.admissible and orbit.k == 2 and orbit.T == pytest.approx(T, rel=1e-13)
    assert min(o1.energy, o2.energy) < orbit.energy < max(o1.energy, o2.energy)
    assert _returns(orbit) < 1e-8


def test_orbit_at_every_crossing_once(phased):
    """The mode folds back in T: T = 3.3 is crossed by the one-phase and the two-phase stretches; a period on a
    computed point gives that orbit once; outside the range nothing; a bad period is refused by name."""
    at = phased.orbit_at(3.3)
    assert sorted(o.k for o in at) == [1, 2] and all(o.admissible for o in at)
    point = phased.orbits[5]
    (orbit,) = phased.orbit_at(point.T)
    assert orbit.energy == pytest.approx(point.energy, rel=1e-9)
    assert phased.orbit_at(5.0) == [] and phased.orbit_at(1.0) == []
    for bad in (-1.0, 0.0, float("nan"), "3.5", None):
        with pytest.raises(ValueError, match=r"period T must be a finite number > 0, got"):
            phased.orbit_at(bad)


def test_orbit_at_after_a_round_trip_and_on_one_phase_branches(phased):
    """The same after ``to_dict``/``from_dict``, and the one-phase branches of ``nonsmooth_mode`` still work."""
    back = Branch.from_dict(phased.system, phased.to_dict())
    T = 0.5 * (phased.orbits[10].T + phased.orbits[11].T)
    (a,), (b,) = back.orbit_at(T), phased.orbit_at(T)
    assert a.energy == pytest.approx(b.energy, rel=1e-12)
    (one,) = bc.nonsmooth_mode(phased.system, 1, (3.8, 4.1))
    orbits = [o for o in one.orbit_at(3.95) if o.admissible]
    assert len(orbits) == 1 and orbits[0].T == 3.95


def test_newton_orbit_at_on_a_scanned_period_once():
    """A period on a scanned point was returned twice (by the pairs on both sides): once now."""
    branch = backbone(chain(2, k=1.0, m=0.5, gap=1.0), np.linspace(4.0, 12.0, 9))
    (orbit,) = branch.orbit_at(5.0)
    assert orbit.T == 5.0 and orbit.energy == pytest.approx(branch.energy[1], rel=1e-12)


# -- 2. Branch.table speaks of contact phases for the massless model ------------------------------------------------


def test_massless_table_speaks_of_contact_phases(phased):
    table = phased.table(points=True)
    assert "impact" not in table and "ipp" not in table
    assert table.startswith("nonsmooth mode (massless contact), 114 orbits (curve)")
    assert "1 to 2 contact phases per period" in table.splitlines()[0]
    assert "contact closes at" in table and "∫λ dt per phase" in table
    assert "admissible intervals of T:" in table
    (one,) = bc.nonsmooth_mode(phased.system, 1, (3.8, 4.1))
    assert "1 contact phase per period" in one.table() and "impact" not in one.table()
    newton = backbone(chain(2, k=1.0, m=0.5, gap=1.0), np.linspace(4.0, 12.0, 9)).table()
    assert newton.startswith("1-ipp family") and "1 impact(s) per period" in newton


# -- 3. a 2-D model's rotation axis: off-plane parts refused, not dropped --------------------------------------------


@pytest.fixture(scope="module")
def strip2d():
    """A 2-D strip radial along +y from r = 0.2 to 0.3 m in the plane z = 0."""
    from skfem import MeshTri

    from bladecase.fe import Mesh, assemble

    t = MeshTri.init_tensor(np.linspace(-0.01, 0.01, 3), np.linspace(0.2, 0.3, 11))
    p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    mesh = Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 1] == 0.2)})
    return assemble(mesh, "steel", order=1, thickness=0.002)


@pytest.mark.parametrize(("origin", "direction", "match"), [
    ((0, 0, 0.1), (1, 0, 0), r"axis offset out of it: origin z = 0\.1 with a direction in the plane \(1, 0, 0\)"),
    ((0, 0, 0), (1, 0, 1), r"tilted axis: direction \(0\.707107, 0, 0\.707107\)"),
])
def test_a_plane_model_refuses_an_axis_out_of_its_plane(strip2d, origin, direction, match):
    from bladecase.fe.rotation import RotationAxis, coriolis_matrix, spin

    axis = RotationAxis(origin, direction)
    for call in (lambda: spin(strip2d, 1000.0, axis), lambda: coriolis_matrix(strip2d, axis, 1000.0)):
        with pytest.raises(ValueError, match=match) as err:
            call()
        assert "perpendicular to its plane (direction (0, 0, 1), any origin)" in str(err.value)
        assert "in its plane through it (direction (dx, dy, 0) with origin z = 0)" in str(err.value)


def test_a_plane_model_spins_about_the_axes_its_plane_holds(strip2d):
    """Perpendicular to the plane: the origin's z only slides the point along the axis (same state); in the plane
    through it: the radial load in the plane; a 3-D model takes any axis."""
    from bladecase.fe.rotation import RotationAxis, spin

    u0 = spin(strip2d, 1000.0, RotationAxis((0, 0, 0), (0, 0, 1))).displacement
    u1 = spin(strip2d, 1000.0, RotationAxis((0, 0, 0.5), (0, 0, 1))).displacement
    assert np.array_equal(u0, u1) and np.abs(u0).max() > 0
    assert np.abs(spin(strip2d, 1000.0, RotationAxis((0, 0, 0), (1, 0, 0))).displacement).max() > 0
    assert RotationAxis((0, 0, 0.1), (1, 0, 1)).check_plane(3).origin.tolist() == [0.0, 0.0, 0.1]


def test_a_plane_study_refuses_an_offset_rotation_axis(tmp_path):
    from _studies import PLATE, ROOT

    from bladecase.study import run
    from bladecase.study.schema import StudyError, loads

    text = PLATE.replace("size = 10", "size = 4") + """
[rotation]
speed = 8000
axis = {origin = [0, -0.3, 0.05], direction = [1, 0, 0]}
[output]
formats = ["png"]
reference = false
animate = 0
"""
    with pytest.raises(StudyError, match=r"^\[rotation\] axis: a 2-D \(plane\) model .* origin z = 0\.05"):
        run(loads(text, base=ROOT), tmp_path / "out", progress=False)


# -- 4. a comparison grid without its own main model builds only the models it asks for ----------------------------


def test_a_grid_without_size_makes_its_largest_size_the_main_model():
    from _studies import PLATE, ROOT

    from bladecase.study.schema import loads

    text = PLATE.replace('method = "modal"\nsize = 10\n', 'method = "modal"\nsizes = [6, 12]\n')
    r = loads(text, base=ROOT)["reduction"]
    assert r["size"] == 12 and r["compare"] == [{"method": "modal", "size": 6}]  # no modal-20
    models = {(r["method"], r["size"])} | {(x["method"], x["size"]) for x in r["compare"]}
    assert models == {("modal", 6), ("modal", 12)}
    # methods without method: the first of them, with every size of the grid, and nothing else
    text = PLATE.replace('method = "modal"\nsize = 10\n', 'methods = ["craig-bampton", "modal"]\nsizes = [8, 4]\n')
    r = loads(text, base=ROOT)["reduction"]
    assert (r["method"], r["size"]) == ("craig-bampton", 8)
    models = {(r["method"], r["size"])} | {(x["method"], x["size"]) for x in r["compare"]}
    assert models == {(m, n) for m in ("craig-bampton", "modal") for n in (4, 8)} and len(r["compare"]) == 3
    # given: kept (the main model outside the grid, as asked)
    text = PLATE.replace('size = 10\n', 'size = 10\nsizes = [6, 12]\n')
    r = loads(text, base=ROOT)["reduction"]
    assert r["size"] == 10 and [x["size"] for x in r["compare"]] == [6, 12]
    # the massless model's grid no longer trips on the Newton default method
    massless = PLATE.replace('method = "modal"\nsize = 10\n', 'methods = ["massless"]\nsizes = [4, 8]\n').replace(
        "clearance = 1e-4", 'clearance = 1e-4\nmodel = "massless"\nface = "tip"')
    r = loads(massless, base=ROOT)["reduction"]
    assert (r["method"], r["size"], r["compare"]) == ("massless", 8, [{"method": "massless", "size": 4}])


# -- 5. load_mesh's docstring says what it reads --------------------------------------------------------------------


def test_load_mesh_docstring_names_the_bodies_it_reads(tmp_path):
    """Every accepted body cell type is named, nothing says non-simplex cells are refused — and what it names
    reads: a hexahedron, a wedge, a quadrilateral; a pyramid is refused with the accepted types."""
    import meshio

    from bladecase.fe.cells import BODY_TYPES
    from bladecase.fe.mesh import load_mesh

    doc = load_mesh.__doc__
    assert "simplex" not in doc.lower()
    for t in BODY_TYPES[2] + BODY_TYPES[3]:
        assert f"``{t}``" in doc, t
    cube = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1.0]])
    bodies = {"hexahedron": (cube, [0, 1, 2, 3, 4, 5, 6, 7]), "wedge": (cube[[0, 1, 3, 4, 5, 7]], [0, 1, 2, 3, 4, 5]),
              "quad": (cube[:4], [0, 1, 2, 3]), "pyramid": (np.r_[cube[:4], [[0.5, 0.5, 1]]], [0, 1, 2, 3, 4])}
    for name, (points, cell) in bodies.items():
        meshio.write(tmp_path / f"{name}.vtu", meshio.Mesh(points, [(name, np.array([cell]))]))
        if name == "pyramid":
            with pytest.raises(ValueError, match=r"has no volume cells \(tetra, .*wedge18\) nor planar cells"):
                load_mesh(tmp_path / f"{name}.vtu")
        else:
            assert load_mesh(tmp_path / f"{name}.vtu").body_type == name


# -- 6. no issue numbers in the scripts' descriptions and help ------------------------------------------------------

_ROOT = Path(__file__).resolve().parent.parent
#: Benchmarks owned elsewhere (their texts are not this file's business).
_OTHERS = {"bench_search.py", "bench_search_contact.py", "bench_reference.py"}


def test_fig8_help_cites_no_issue():
    from conftest import run_forked  # the script as __main__ in a forked child: no interpreter start

    code, output = run_forked(_ROOT / "examples" / "fig8_sensitivity.py", "--help", cwd=_ROOT / "examples")
    assert code == 0, output
    assert "Fig. 8" in output and "issue" not in output.lower()


@pytest.mark.parametrize("script", sorted(p.name for p in (_ROOT / "benchmarks").glob("*.py")
                                          if p.name not in _OTHERS) + ["../examples/fig8_sensitivity.py"])
def test_scripts_cite_no_issue(script):
    """Docstrings, help and printed text of the scripts: no 'issue 14', '(issue 11)', 'the issue's goal'."""
    import re

    text = (_ROOT / "benchmarks" / script).read_text(encoding="utf-8")
    hits = re.findall(r".{0,30}\b[Ii]ssues?\b(?:'s)?.{0,30}", text)
    assert not hits, hits


# -- 7. one version: pyproject.toml, bladecase.__version__, the CHANGELOG's latest section --------------------------


def test_version_is_the_changelogs_latest():
    import re
    import tomllib

    project = tomllib.loads((_ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    # one place: the package metadata's version is bladecase.__version__ (setuptools' dynamic attr)
    assert "version" not in project["project"] and "version" in project["project"]["dynamic"]
    assert project["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "bladecase.__version__"}
    changelog = (_ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    top = re.search(r"^## \[([^\]]+)\]", changelog, flags=re.M).group(1)
    assert top == bc.__version__ != "0.1.0"
    assert "still says 0.1.0" not in changelog
