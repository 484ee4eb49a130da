"""``bladecase.fe.calculix``: the model as a CalculiX deck, run by ``ccx``, its frequencies equal to bladecase's.

The runs need ``ccx`` (Debian: calculix-ccx) and are skipped without it; the deck's contents and the errors are
checked everywhere."""

from __future__ import annotations

import math
import shutil

import numpy as np
import pytest
from skfem import MeshTet, MeshTri

from bladecase.fe import Mesh, assemble
from bladecase.fe.abaqus import read_abaqus
from bladecase.fe.calculix import calculix_deck, calculix_frequencies, run_calculix, write_calculix
from bladecase.fe.rotation import RotationAxis, spin
from bladecase.linalg import lowest_modes

needs_ccx = pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX (ccx) is not installed")


def _bar():
    t = MeshTet.init_tensor(np.linspace(0.1, 0.3, 13), np.linspace(0, 0.02, 3), np.linspace(0, 0.006, 2))
    return Mesh(t.p.T, {"tetra": t.t.T}, dim=3, groups={"root": np.flatnonzero(np.isclose(t.p[0], 0.1))})


@pytest.fixture(scope="module")
def bar():
    mesh = _bar()
    return mesh, assemble(mesh, "steel", order=1)


def _ours(model, count=4):
    return np.sqrt(lowest_modes(model.K, model.M, count)[0]) / (2 * math.pi)


def test_the_deck_reads_back_as_the_same_mesh_and_clamp(bar, tmp_path):
    mesh, model = bar
    path = write_calculix(model, tmp_path / "bar.inp", 6, unit="mm")
    back = read_abaqus(str(path))
    assert np.allclose(back.points, mesh.points * 1e3, rtol=1e-12, atol=0)
    # the same tetrahedra, some turned over (CalculiX wants a positive volume: every one has it in the deck)
    assert np.array_equal(np.sort(back.cells[0].data, axis=1), np.sort(mesh.cells["tetra"], axis=1))
    p = back.points[back.cells[0].data]
    assert np.all(np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]) > 0)
    assert sorted(back.point_sets["boundary_fixed"].tolist()) == sorted(model.clamped.tolist())
    text = path.read_text()
    assert f"{model.material.E * 1e-6:.12g}, {model.material.nu:.12g}" in text  # MPa
    assert f"{model.material.rho * 1e-12:.12g}" in text and "*FREQUENCY\n6\n" in text


def test_bad_input_is_refused(bar, tmp_path):
    mesh, model = bar
    from skfem import MeshHex
    from skfem.io.meshio import to_meshio

    h = to_meshio(MeshHex.init_tensor(np.linspace(0, 0.1, 5), np.linspace(0, 0.01, 2), np.linspace(0, 0.01, 2)))
    block = Mesh(h.points, {"hexahedron": h.cells_dict["hexahedron"]}, dim=3,
                 groups={"root": np.flatnonzero(h.points[:, 0] == 0)})
    with pytest.raises(ValueError, match="order 2 elements on a mesh of hexahedron cells"):
        calculix_deck(assemble(block, "steel", order=2))
    with pytest.raises(ValueError, match="unit must be one of 'm', 'mm', got 'inch'"):
        calculix_deck(model, unit="inch")
    with pytest.raises(ValueError, match="count must be an integer >= 1"):
        calculix_deck(model, 0)
    with pytest.raises(ValueError, match="a speed needs axis=RotationAxis"):
        calculix_deck(model, speed=100.0)
    with pytest.raises(ValueError, match=r"an \.inp file"):
        write_calculix(model, tmp_path / "bar.txt")
    with pytest.raises(ValueError, match="no eigenvalue output"):
        (tmp_path / "x.dat").write_text("nothing\n")
        calculix_frequencies(tmp_path / "x.dat")


@pytest.fixture(scope="module")
def beam():
    """The 20-node hexahedral strip of test_calculix.py (the same element and Gauss rule in both codes)."""
    from test_calculix import _hex20_beam

    return assemble(_hex20_beam(), "steel", order=2)


@needs_ccx
@pytest.mark.parametrize("unit", ["m", "mm"])
def test_frequencies_equal_calculix_at_rest(beam, tmp_path, unit):
    """C3D20, in SI and in millimetres: equal to the 7 digits CalculiX prints."""
    theirs = run_calculix(beam, tmp_path, 4, unit=unit)
    assert theirs == pytest.approx(_ours(beam), rel=2e-7)


@needs_ccx
def test_linear_tetrahedra_in_calculix(bar, tmp_path):
    """C3D4 (the bar's tetrahedra, some turned over for CalculiX): its mass is integrated differently there —
    measured 0.58 % on these coarse cells —, the stiffness the same; the deck runs and the frequencies follow."""
    _, model = bar
    theirs = run_calculix(model, tmp_path, 4)
    assert theirs == pytest.approx(_ours(model), rel=1e-2)


@needs_ccx
def test_a_plane_model_in_calculix(tmp_path):
    """Plane stress and plane strain triangles (CPS3 / CPE3, turned counter-clockwise) with their thickness:
    CalculiX expands plane elements into a layer of 3-D wedges, not the same element — measured 1.3 % apart at
    most on this coarse plate; the deck runs and the frequencies follow."""
    t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5))
    mesh = Mesh(np.c_[t.p.T, np.zeros(t.p.shape[1])], {"triangle": t.t.T}, dim=2,
                groups={"root": np.flatnonzero(t.p[0] == 0)})
    for plane in ("stress", "strain"):
        model = assemble(mesh, "steel", order=1, thickness=0.002, plane=plane)
        theirs = run_calculix(model, tmp_path, 4, name=f"plate_{plane}")
        assert theirs == pytest.approx(_ours(model), rel=2e-2), plane


@needs_ccx
@pytest.mark.parametrize("unit", ["m", "mm"])
def test_spinning_frequencies_follow_calculix(beam, tmp_path, unit):
    """The C3D20 strip spinning at 6000 rpm about z through the origin (radial from 0.1 m): f1 rises by a factor
    2.5, and agrees with CalculiX's perturbation step to the spin softening its linear static step leaves out
    (measured 4e-4)."""
    omega = 6000 * 2 * math.pi / 60
    axis = RotationAxis((0, 0, 0), (0, 0, 1))
    state = spin(beam, omega, axis, static="linear")
    ours = np.sqrt(lowest_modes(state.model.K, state.model.M, 4, factor=state.factor)[0]) / (2 * math.pi)
    theirs = run_calculix(beam, tmp_path, 4, speed=omega, axis=axis, unit=unit)
    assert theirs[0] / _ours(beam)[0] > 2.0
    assert ours == pytest.approx(theirs, rel=1e-3)


def test_p2_on_linear_tetrahedra_is_written_as_straight_c3d10(bar):
    """bladecase's P2 field on linear tetrahedra is the C3D10 field with every midside node at its edge's middle:
    the deck has one new node per edge, at the middle."""
    mesh, _ = bar
    model = assemble(mesh, "steel", order=2)
    deck = calculix_deck(model, 4)
    assert "*ELEMENT, TYPE=C3D10, ELSET=EALL" in deck
    cells = mesh.cells["tetra"]
    edges = {tuple(sorted((c[a], c[b]))) for c in cells for a, b in ((0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3))}
    nodes = deck.split("*NODE\n")[1].split("\n*")[0].splitlines()
    assert len(nodes) == len(mesh.points) + len(edges)
    # the clamp holds the midside nodes of the root face's edges too
    root = set(mesh.groups["root"].tolist())
    held = deck.split("*NSET, NSET=CLAMPED\n")[1].split("\n*")[0].replace("\n", ",").split(",")
    assert len(held) == len(root) + sum(a in root and b in root for a, b in edges)


@needs_ccx
def test_the_assemble_command_writes_a_deck_calculix_agrees_with(tmp_path, capsys):
    """``bladecase assemble --calculix``: the demo blade with a consistent mass (P2 on gmsh's tetrahedra, written
    as C3D10), in millimetres: CalculiX's frequencies within 5e-5 of bladecase's (the integration rule; measured
    3e-6 … 1.6e-5); a deck that is not .inp is refused with exit code 2 before anything is written."""
    import subprocess

    from bladecase.cli import main
    from bladecase.study.demo import demo_text

    text = demo_text().replace('mass = "lumped"', 'mass = "consistent"').replace('model = "massless"', "")
    text = text.replace("casing_stiffness = 1e6", "").replace('method = "massless"', 'method = "lanczos-si"')
    (tmp_path / "s.toml").write_text(text)
    assert main(["assemble", str(tmp_path / "s.toml"), "-o", str(tmp_path / "m.npz"), "--calculix",
                 str(tmp_path / "blade.txt")]) == 2
    assert not (tmp_path / "m.npz").exists()
    assert main(["assemble", str(tmp_path / "s.toml"), "-o", str(tmp_path / "m.npz"), "--calculix",
                 str(tmp_path / "blade.inp"), "--calculix-unit", "mm"]) == 0
    out = capsys.readouterr().out
    ours = np.array([float(x) for x in out.split("linear frequencies (Hz): ")[1].splitlines()[0].split(", ")])
    subprocess.run([shutil.which("ccx"), "blade"], cwd=tmp_path, capture_output=True, check=True, timeout=600)
    theirs = calculix_frequencies(tmp_path / "blade.dat", ours.size)
    assert theirs == pytest.approx(ours, rel=5e-5)
