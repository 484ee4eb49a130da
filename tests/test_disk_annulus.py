"""A travelling-wave nonsmooth mode of an FE bladed disk (hexahedral sector, 12 blades, each blade's tip face its
massless contact on a compliant casing) drawn on the annulus: the expanded field against the reduced orbit's own
contact displacements (``Wᵀx − H_sλ``), against the travelling-wave symmetry it was never told (sector ``j`` at ``t``
is sector 0 at ``t − jkT/N`` turned by ``jα``), and the VTK frames' largest penetration against the summary's."""

from __future__ import annotations

import meshio
import numpy as np
import pytest
from _cyclic_util import hex_sector

from bladecase.fe import assemble
from bladecase.fe.cyclic import fe_sector
from bladecase.fe.cyclic_waves import rotate_field
from bladecase.fe.rotation import RotationAxis
from bladecase.nsm.massless.disk_modes import rotating_family
from bladecase.post.disk.annulus_orbit import annulus_frames, write_annulus_orbit
from bladecase.post.vtk import read_time_series
from bladecase.reduction import Contact
from bladecase.reduction.disk import disk_model, massless_sector
from bladecase.reduction.disk_fields import contact_displacements, sector_fields

AXIS = RotationAxis((0, 0, 0), (1, 0, 0))
N, K_ND = 12, 2
OPTIONS = {"formats": ["vtu"], "frames": 10, "scale": "auto", "auto_fraction": 0.1, "fps": 10, "window": [240, 180]}


@pytest.fixture(scope="module")
def case():
    mesh = hex_sector(N, nt=3, band=(1, 2), nr=1, nb=3, nx=1)
    model = assemble(mesh, "steel", order=1, clamp="hub", mass="lumped")
    sector = fe_sector(model, N, AXIS)
    contact = Contact.face(model, "tip", (0.0, 0.0, 1.0), 1e-4, weights="area")
    ms, W, gap = massless_sector(model, sector, contact)
    probe = disk_model(ms, W, gap, count=2)
    kc = 2.0 / float(probe.system.flexibility[0, 0])  # a casing twice as stiff as the blade at its tip
    disk = disk_model(ms, W, gap, count=2, casing=kc, diameters=probe.diameters)
    P, n1 = disk.rotating(K_ND)
    # the mode of K_ND that moves the tip radially (the plate's first bending moves it sideways)
    mode = max(range(2), key=lambda i: np.abs(disk.system.W[disk.index(K_ND, i, 0)]).max())
    x0, v0, w = disk.travelling_wave(K_ND, mode)
    orbit = rotating_family(disk.system, P, n1, x0, v0, 2 * np.pi / w, growth=(1.1, 1.5))[-1]
    assert orbit.touching
    return model, ms, disk, orbit


def test_the_annulus_field_gives_back_the_orbits_contact_displacements(case):
    _, _, disk, orbit = case
    f = annulus_frames(disk, orbit, 7)
    assert (f["forces"] > 0).any()  # some frames press: the residual fields count
    s = disk.system
    y = contact_displacements(disk, sector_fields(disk, f["x"], f["forces"]))
    expected = s.W.T @ f["x"] - s.flexibility @ f["forces"]
    assert np.abs(y - expected).max() <= 1e-10 * np.abs(expected).max()
    pressed = f["forces"] > 0  # pressed: the blade is beyond its clearance by λ/k (the casing gives)
    gap = np.broadcast_to(s.gap[:, None], y.shape)
    assert np.allclose((y - gap)[pressed], (f["forces"] / s.casing[:, None])[pressed], rtol=1e-8, atol=0)


def test_sector_j_repeats_sector_0_later_by_jk_over_n_of_the_period(case):
    _, ms, disk, orbit = case
    T = orbit.T
    tr = annulus_frames(disk, orbit, 4)["trajectory"]
    t = np.array([0.13, 0.41, 0.77]) * T
    x, _, lam = tr.sample(t)
    now = sector_fields(disk, x, lam)
    top = np.abs(now).max()
    for j in (1, 5, 11):
        earlier = np.mod(t - j * K_ND * T / N, T)
        xe, _, le = tr.sample(earlier)
        then = sector_fields(disk, xe, le)[0]
        a = j * ms.alpha  # both in the global frame: sector 0's field turned by jα
        assert np.abs(rotate_field(ms, now[j], a) - rotate_field(ms, then, a)).max() <= 1e-10 * top
        assert np.abs(now[j] - then).max() <= 1e-10 * top


def test_the_vtk_frames_show_the_summarys_largest_penetration(case, tmp_path):
    model, ms, disk, orbit = case
    out = write_annulus_orbit(model, ms, disk, orbit, tmp_path, OPTIONS, stem="annulus_orbit", title="test")
    assert out["pvd"] == "vtk/annulus_orbit.pvd" and out["max_penetration_mm"] > 0
    times, files = read_time_series(tmp_path / out["pvd"])
    assert len(files) == OPTIONS["frames"] and np.all(np.diff(times) > 0)
    deepest = 0.0
    for path in files:
        frame = meshio.read(path)
        deepest = max(deepest, float(np.nanmax(-frame.point_data["normal_gap"])))
        assert frame.points.shape[0] == out["disk_nodes"]
    assert abs(deepest * 1e3 - out["max_penetration_mm"]) <= 1e-6 * out["max_penetration_mm"]
