"""The parametric C3D10 sector against CalculiX's cyclic-symmetry run with the same integration rule.

CalculiX integrates the quadratic tetrahedron (C3D10) with four points (a degree-2 rule) for stiffness and mass;
bladecase, by default, with scikit-fem's degree-4 rule.  With its tetrahedra assembled on CalculiX's rule, the
two codes solve the same discrete sector, and every nodal diameter's frequencies must agree to 1e-5 relative: the
cyclic constraint (the rotated face pairs, the complex phase per nodal diameter) is then the only thing compared.
Skipped without ``ccx``."""

from __future__ import annotations

import os
import subprocess

import numpy as np
import pytest
from test_cyclic_calculix import CCX, cyclic_deck, read_cyclic_dat

from bladecase.fe import assemble, assembly
from bladecase.fe.cyclic import cyclic_spectrum, fe_sector

pytestmark = pytest.mark.skipif(CCX is None, reason="CalculiX (ccx) is not installed (apt-get install calculix-ccx)")


@pytest.fixture
def calculix_rule(monkeypatch):
    """The tetrahedra's quadrature as CalculiX's C3D10: degree 2 (four points), stiffness and mass alike."""
    basis = assembly.CellBasis

    def with_rule(*a, **k):
        if "quadrature" not in k:
            k.setdefault("intorder", 2)
        return basis(*a, **k)

    monkeypatch.setattr(assembly, "CellBasis", with_rule)


def test_parametric_sector_matches_calculix_with_its_element_rule(tmp_path, calculix_rule):
    from bladecase.fe.sector import SectorGeometry, sector_mesh
    from bladecase.fe.shapes import BladeGeometry

    blade = BladeGeometry(span=0.15, root_chord=0.04, thickness=0.006)
    g = SectorGeometry(sectors=12, hub_radius=0.15, rim_radius=0.25, disk_thickness=0.04, blade=blade)
    mesh = sector_mesh(g, size=0.04, order=2)
    model = assemble(mesh, "steel", order=2, clamp="hub")
    count = 2
    ours = cyclic_spectrum(fe_sector(model, 12, g.axis, left="left", right="right"), count)
    deck = cyclic_deck(model, 12, mesh.group("left"), mesh.group("right"), 2 * count)
    deck = deck.replace("0, 0, 0, 1, 0, 0", f"0, 0, {-g.rim_radius!r}, 1, 0, {-g.rim_radius!r}")
    (tmp_path / "cyc.inp").write_text(deck)
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1")
    subprocess.run([CCX, "cyc"], cwd=tmp_path, capture_output=True, check=True, timeout=300, env=env)
    theirs = read_cyclic_dat((tmp_path / "cyc.dat").read_text())
    offset = np.array([ours[k].frequencies / theirs[k] - 1 for k in sorted(ours)])  # (diameters, families)
    print("largest relative difference", np.abs(offset).max())
    assert sorted(theirs) == sorted(ours) and np.abs(offset).max() < 1e-5, offset
