"""An independent FE code on the same mesh: CalculiX (``ccx``) computes the natural frequencies of a 20-node
hexahedral steel beam at rest and spinning (``*STATIC`` with ``CENTRIF``, then ``*FREQUENCY`` with
``PERTURBATION``); bladecase's must agree.  Skipped where ``ccx`` is not installed (Debian: calculix-ccx)."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from bladecase.fe import Mesh, assemble
from bladecase.fe.calculix import run_calculix
from bladecase.fe.rotation import RotationAxis, spin
from bladecase.linalg import lowest_modes

CCX = shutil.which("ccx")
pytestmark = pytest.mark.skipif(CCX is None, reason="CalculiX (ccx) is not installed (apt-get install calculix-ccx)")

L, B, H = 0.3, 0.03, 0.006  # a 300 mm steel strip, 30 mm wide (y), 6 mm thick (z), radial along x
E, NU, RHO = 2.1e11, 0.3, 7850.0
HUB = 0.1  # the strip's root at x = 0.1 m from the axis (z), spun in the x-y plane
EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]


def _hex20_beam(nx: int = 12, ny: int = 2, nz: int = 1) -> Mesh:
    """A structured 20-node hexahedral beam (VTK node order = Abaqus C3D20 order)."""
    xs, ys, zs = (np.linspace(a, b, 2 * n + 1) for a, b, n in ((HUB, HUB + L, nx), (-B / 2, B / 2, ny),
                                                             (-H / 2, H / 2, nz)))
    grid = np.stack(np.meshgrid(xs, ys, zs, indexing="ij"), axis=-1)
    index = -np.ones(grid.shape[:3], dtype=np.int64)
    cells = []
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                c = [(2 * i, 2 * j, 2 * k), (2 * i + 2, 2 * j, 2 * k), (2 * i + 2, 2 * j + 2, 2 * k),
                     (2 * i, 2 * j + 2, 2 * k)]
                c += [(a, b, cz + 2) for a, b, cz in c]
                mids = [tuple((np.array(c[p]) + np.array(c[q])) // 2) for p, q in EDGES]
                cells.append(c + mids)
    used = sorted({n for cell in cells for n in cell})
    for m, ijk in enumerate(used):
        index[ijk] = m
    points = np.array([grid[ijk] for ijk in used])
    t = np.array([[index[n] for n in cell] for cell in cells])
    root = np.flatnonzero(np.isclose(points[:, 0], HUB))
    return Mesh(points, {"hexahedron20": t}, dim=3, groups={"root": root})


def _ccx_frequencies(model, folder: Path, rpm: float, count: int = 4) -> np.ndarray:
    """CalculiX's ``count`` lowest frequencies of ``model`` (its deck by :mod:`bladecase.fe.calculix`), spun about z
    through the origin at ``rpm`` (a linear ``*STATIC`` step with ``CENTRIF``, then a ``PERTURBATION`` step)."""
    spin_ = {"speed": rpm * 2 * math.pi / 60, "axis": RotationAxis((0, 0, 0), (0, 0, 1))} if rpm else {}
    return run_calculix(model, folder, count, name="beam", **spin_)


@pytest.fixture(scope="module")
def beam():
    mesh = _hex20_beam()
    return mesh, assemble(mesh, _material(), order=2, mass="consistent")


def _material():
    from bladecase.fe import Material

    return Material(E, NU, RHO, "steel (CalculiX deck)")


@pytest.mark.parametrize("rpm", [0.0, 3000.0, 6000.0])
def test_frequencies_agree_with_calculix(beam, tmp_path, rpm):
    mesh, model = beam
    state = spin(model, rpm * 2 * math.pi / 60, RotationAxis((0, 0, 0), (0, 0, 1)), static="linear")
    ours = np.sqrt(lowest_modes(state.model.K, state.model.M, 4, factor=state.factor)[0]) / (2 * math.pi)
    theirs = _ccx_frequencies(model, tmp_path, rpm)
    # the same mesh and element (20-node hexahedra, 27-point Gauss rule): at rest equal to 1e-7; spinning, they
    # differ by the static states (CalculiX's linear static step has no spin softening): measured 4e-5 at 3000 rpm,
    # 4e-4 at 6000 rpm (f1 2.5 times the one at rest), 1.5e-3 at 12000 rpm, growing as Ω²
    assert ours == pytest.approx(theirs, rel=1e-6 if rpm == 0 else 1e-3), (ours, theirs)
    if rpm:
        rest = _ccx_frequencies(model, tmp_path, 0.0)
        assert (theirs[0] / rest[0] - 1) > 0.02  # the speed matters: the check is not at rest in disguise


# ----------------------------------------------------------------------------- the demo blade (tetra10) at speed

def test_demo_blade_at_speed_against_calculix(tmp_path):
    """The demo blade (leaned 30 mm: its centrifugal load bends it) on a 0.25 m hub about x, consistent mass:
    at rest equal; at 5000 and 10000 rpm the second-order static state against CalculiX with NLGEOM (large
    deformations in the static step): f1 within 0.1 %, f2 within 1 %; f3, f4 2-4 % apart (measured 2.6/-2.0 % and
    3.9/-1.5 %): the geometry update of large deflections, which a stress-stiffened state does not make."""
    from bladecase.study.demo import demo_study
    from bladecase.study.stages import build_mesh

    mesh = build_mesh(demo_study())
    model = assemble(mesh, "Ti-6Al-4V", order=2, mass="consistent", clamp="root")  # P2 on tetra: straight C3D10
    axis = RotationAxis((0, 0, -0.25), (1, 0, 0))
    rest = np.sqrt(lowest_modes(model.K, model.M, 4)[0]) / (2 * math.pi)
    assert rest == pytest.approx(run_calculix(model, tmp_path, 4, name="blade"), rel=1e-5)
    for rpm in (5000, 10000):
        state = spin(model, rpm * 2 * math.pi / 60, axis, static="second-order")
        ours = np.sqrt(lowest_modes(state.model.K, state.model.M, 4, factor=state.factor)[0]) / (2 * math.pi)
        theirs = run_calculix(model, tmp_path, 4, name="blade", speed=rpm * 2 * math.pi / 60, axis=axis,
                              nlgeom=True)
        assert ours[0] == pytest.approx(theirs[0], rel=2e-3), rpm
        assert ours[1] == pytest.approx(theirs[1], rel=1.2e-2), rpm
        assert ours[2:] == pytest.approx(theirs[2:], rel=5e-2), rpm
        assert ours[0] / rest[0] > 1.2  # at speed: f1 23 % and 74 % above the one at rest
