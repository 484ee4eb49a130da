"""The centrifugal prestress at the nodes (bladecase.fe.stress) against CalculiX and a closed form, and the
centrifugal state in every VTK file of a study at speed (mesh.vtu, the .pvd frames)."""

from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree
from skfem import MeshTet

from bladecase.fe import Mesh, assemble
from bladecase.fe.calculix import calculix_deck
from bladecase.fe.rotation import RotationAxis, spin
from bladecase.fe.stress import fe_node_points, nodal_stress, von_mises
from bladecase.post.grid import fe_grid, nodal_field, node_values

CCX = shutil.which("ccx")
needs_ccx = pytest.mark.skipif(CCX is None, reason="CalculiX (ccx) is not installed (apt-get install calculix-ccx)")

HUB, TIP = 0.1, 0.2          # m: a 10 mm × 10 mm steel bar from radius 0.1 to 0.2 m, centred on the plane z = 0
AXIS = RotationAxis((0, 0, 0), (0, 0, 1))
OMEGA = 3000.0               # rad/s: 1.2 GPa at the root (an elastic check, not a design)


@pytest.fixture(scope="module")
def bar():
    """P2 on 8 × 2 × 2 boxes of 6 tetrahedra (425 nodes), clamped at the hub, consistent mass (CalculiX's)."""
    m = MeshTet.init_tensor(np.linspace(HUB, TIP, 9), *2 * [np.linspace(-0.005, 0.005, 3)])
    mesh = Mesh(m.p.T, {"tetra": m.t.T}, dim=3, groups={"root": np.flatnonzero(m.p[0] == HUB)})
    return assemble(mesh, "steel", order=2, mass="consistent")


def _von_mises_on_grid(model, u, kind: str) -> np.ndarray:
    return node_values(model, von_mises(nodal_stress(model, u, kind)), fe_node_points(model))


def _frd(path: Path) -> dict[str, np.ndarray]:
    """The node coordinates (``COORD``) and the nodal blocks (``DISP``, ``STRESS``) of a CalculiX ``.frd``."""
    out, name, rows = {}, None, []
    for line in path.read_text().splitlines():
        if line.startswith("    2C"):
            name, rows = "COORD", []
        elif line.startswith(" -4"):
            name, rows = line.split()[1], []
        elif line.startswith(" -1") and name is not None:
            rows.append([float(line[13 + 12 * k: 25 + 12 * k]) for k in range((len(line) - 13) // 12)])
        elif line.startswith(" -3") and name is not None:
            out[name], name = np.array(rows), None
    return out


def _calculix_static(model, folder: Path, nlgeom: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """CalculiX's static state under ``CENTRIF`` (``*NODE FILE`` U, ``*EL FILE`` S: nodal values, extrapolated from
    the integration points and averaged): node coordinates, displacements, von Mises stress."""
    deck = calculix_deck(model, 1, speed=OMEGA, axis=AXIS, nlgeom=nlgeom)
    load = next(line for line in deck.splitlines() if "CENTRIF" in line)
    deck = deck[: deck.index("*STEP")] + ("*STEP, NLGEOM\n" if nlgeom else "*STEP\n") + \
        f"*STATIC\n*DLOAD\n{load}\n*NODE FILE\nU\n*EL FILE\nS\n*END STEP\n"
    (folder / "bar.inp").write_text(deck)
    subprocess.run([CCX, "bar"], cwd=folder, capture_output=True, timeout=120, check=True,
                   env={"OMP_NUM_THREADS": "1", "PATH": str(Path(CCX).parent)})
    frd = _frd(folder / "bar.frd")
    S = frd["STRESS"][:, :6]
    sigma = np.zeros((len(S), 3, 3))
    for k, (i, j) in enumerate([(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0)]):
        sigma[:, i, j] = sigma[:, j, i] = S[:, k]
    return frd["COORD"], frd["DISP"][:, :3], von_mises(sigma)


@needs_ccx
@pytest.mark.parametrize("nlgeom", [False, True])
def test_von_mises_against_calculix(bar, tmp_path, nlgeom):
    """Node for node (425 nodes, corners and midside), CalculiX's nodal von Mises stress and ours.

    Linear (CalculiX's linear ``*STATIC``: no spin softening, so ours without it): measured 4.2e-5 of the largest
    value (1.16 GPa) — the ``.frd``'s 5 digits and its solver (the displacements agree to 2e-5); for a straight
    C3D10 its extrapolation of the 4 integration points' stresses is the element's exact linear stress field, so
    the recovery itself adds nothing. ``NLGEOM`` against our nonlinear state's Cauchy stress: measured 4.8e-4 (the
    displacements agree to 1.2e-3: CalculiX's own convergence), where the small-strain stress of the same
    displacement is 9.3e-3 off — CalculiX prints the true stress."""
    X, U, vm_ccx = _calculix_static(bar, tmp_path, nlgeom)
    if nlgeom:
        state, kind = spin(bar, OMEGA, AXIS, static="nonlinear"), "cauchy"
    else:
        state, kind = spin(bar, OMEGA, AXIS, softening=False, static="linear"), "linear"
    dist, near = cKDTree(fe_grid(bar).points).query(X)
    assert dist.max() < 1e-12 and np.unique(near).size == len(X) == len(fe_grid(bar).points)
    u = nodal_field(bar, state.displacement)[near]
    assert np.abs(u - U).max() < (2e-3 if nlgeom else 1e-4) * np.abs(U).max()
    vm = _von_mises_on_grid(bar, state.displacement, kind)[near]
    top = vm_ccx.max()
    assert top == pytest.approx(1.16e9, rel=0.01)
    assert np.abs(vm - vm_ccx).max() < (1e-3 if nlgeom else 2e-4) * top
    if nlgeom:  # the small-strain stress of the same state is far off CalculiX's
        small = _von_mises_on_grid(bar, state.displacement, "linear")[near]
        assert np.abs(small - vm_ccx).max() > 10 * np.abs(vm - vm_ccx).max()


def test_a_uniform_rotating_bar(bar):
    """σ(r) = ρΩ²(R² − r²)/2 along a bar clamped at its hub (no bending: centred on the axis's plane). Away from
    the clamp's restrained Poisson contraction and the free end (where σ → 0), r in [0.13, 0.17] m: measured
    0.24 % (linear state), 0.55 % (nonlinear, Cauchy: the bar stretches 0.5 %, so its mass moves out)."""
    grid = fe_grid(bar)
    r = np.hypot(grid.points[:, 0], grid.points[:, 1])
    exact = bar.material.rho * OMEGA**2 * (TIP**2 - r**2) / 2
    middle = (r > 0.13) & (r < 0.17)
    linear = spin(bar, OMEGA, AXIS, softening=False, static="linear")
    vm = _von_mises_on_grid(bar, linear.displacement, "linear")
    np.testing.assert_allclose(vm[middle], exact[middle], rtol=4e-3)
    state = spin(bar, OMEGA, AXIS, static="nonlinear")
    vm = _von_mises_on_grid(bar, state.displacement, "cauchy")
    np.testing.assert_allclose(vm[middle], exact[middle], rtol=8e-3)


def test_bad_input_is_named(bar):
    with pytest.raises(ValueError, match="kind must be one of 'linear', 'cauchy', got 'pk2'"):
        nodal_stress(bar, np.zeros(bar.n_dofs), "pk2")
    with pytest.raises(ValueError, match=rf"u_free must be {bar.n_dofs} finite numbers"):
        nodal_stress(bar, np.zeros(3))


# ----------------------------------------------------------------------------- a study at speed


@pytest.fixture(scope="module")
def plate_at_speed(tmp_path_factory):
    """The committed 2-D plate (P2, plane stress) on a 0.3 m hub at 8000 rpm, its nonlinear centrifugal state, one
    orbit animated as VTK frames."""
    from _studies import PLATE, ROOT

    from bladecase.study import run
    from bladecase.study.schema import loads

    text = PLATE.replace("size = 10", "size = 4").replace("order = 1", "order = 2") + """
[rotation]
speed = 8000
static = "nonlinear"
axis = {origin = [0, -0.3, 0], direction = [0, 0, 1]}
[output]
formats = ["vtu"]
reference = false
animate = 1
frames = 4
"""
    out = tmp_path_factory.mktemp("plate") / "out"
    return run(loads(text, base=ROOT), out, progress=False), out


def test_every_vtk_file_of_a_study_at_speed_carries_the_centrifugal_state(plate_at_speed):
    import meshio
    from _studies import PLATE, ROOT

    from bladecase.study.schema import loads
    from bladecase.study.stages import build_contact, build_mesh, build_model

    res, out = plate_at_speed
    mesh_vtu = meshio.read(out / "mesh.vtu")
    frames = sorted((out / "vtk").glob("*/*.vtu"))
    assert len(frames) == 4 and len(list((out / "vtk").glob("*.pvd"))) == 1
    frame = meshio.read(frames[0])
    names = {"centrifugal_displacement", "prestress_von_mises_cauchy"}   # a nonlinear state: Cauchy
    assert names <= set(mesh_vtu.point_data) and names <= set(frame.point_data)
    assert np.array_equal(meshio.read(frames[-1]).point_data["prestress_von_mises_cauchy"],
                          frame.point_data["prestress_von_mises_cauchy"])             # constant over the frames
    # the displacement is the rotation stage's: at the contact node, radial (+y), the summary's closure
    study = loads(PLATE.replace("order = 1", "order = 2"), base=ROOT)
    contact = build_contact(study, build_model(study, build_mesh(study)))
    closure = mesh_vtu.point_data["centrifugal_displacement"][contact.node, 1]
    assert closure == pytest.approx(res.summary["rotation"]["closure_m"], rel=1e-6)
    # mesh.vtu and the frames agree where their points meet (every mesh node is a grid point here)
    dist, near = cKDTree(frame.points).query(mesh_vtu.points)
    assert dist.max() < 1e-12
    for name in names:
        np.testing.assert_allclose(mesh_vtu.point_data[name], frame.point_data[name][near], rtol=1e-12, atol=0)
    # a strip turning in its own plane (plane stress): σ_yy ≈ ρΩ²(R² − r²)/2 (r from the axis, R the tip's radius)
    # over its middle third: measured 0.36 %
    vm = frame.point_data["prestress_von_mises_cauchy"]
    r = frame.points[:, 1] + 0.3
    R = r.max()
    omega = 8000 * 2 * math.pi / 60
    exact = res.summary["model"]["material"]["rho"] * omega**2 * (R**2 - r**2) / 2
    middle = (r > 0.3 + 0.3 * (R - 0.3)) & (r < 0.3 + 0.7 * (R - 0.3))
    np.testing.assert_allclose(vm[middle], exact[middle], rtol=1e-2)
