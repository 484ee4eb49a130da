"""``bladecase.fe.cyclic_spin``: a spinning tuned disk from one sector (the centrifugal state with the faces tied)
equals the whole disk spun by ``bladecase.fe.rotation.spin`` as one mesh, every nodal diameter (measured 2.6e-13 at a
speed that moves the frequencies by up to 7.6 %); a sector spun alone (free faces) does not (1.5e-3 off)."""

from __future__ import annotations

import math

import numpy as np
from _cyclic_util import annulus, frequencies_union, hex_sector

from bladecase.fe import assemble
from bladecase.fe.cyclic import cyclic_spectrum, fe_sector
from bladecase.fe.cyclic_spin import cyclic_campbell, cyclic_spin
from bladecase.fe.rotation import RotationAxis, spin
from bladecase.linalg import lowest_modes

AXIS = RotationAxis((0, 0, 0), (1, 0, 0))


def test_spun_sector_equals_the_spun_disk():
    n, speed = 8, 1500.0  # rad/s: the tips at 390 m/s
    mesh = hex_sector(n)
    model = assemble(mesh, "steel", order=1, clamp="hub")
    sector = fe_sector(model, n, AXIS)
    spun = cyclic_spin(model, sector, speed)
    spectrum = cyclic_spectrum(spun.sector, 4)
    union, complete = frequencies_union(spectrum)
    ring = assemble(annulus(mesh, n), "steel", order=1, clamp="hub")
    state = spin(ring, speed, AXIS)
    f = np.sqrt(lowest_modes(state.model.K, ring.M, 24, factor=state.factor)[0]) / (2 * math.pi)
    below = f[f < complete * (1 - 1e-6)]
    assert below.size >= 16
    assert np.max(np.abs(union[:below.size] - below) / below) < 1e-8
    rest, _ = frequencies_union(cyclic_spectrum(sector, 4))
    assert np.max(np.abs(union[:below.size] / rest[:below.size] - 1)) > 0.01  # the speed matters
    # the sector spun alone, its cut faces free, is another state: its frequencies are off
    alone = cyclic_spectrum(fe_sector(spin(model, speed, AXIS).model, n, AXIS), 4)
    wrong, _ = frequencies_union(alone)
    assert np.max(np.abs(wrong[:below.size] / below - 1)) > 1e-4
    # the static state is the disk's: the same radial growth of the blade tips
    tip = model.mesh.group("tip")
    grow = spun.displacement[model.dof_of(tip, "z")]
    ring_tip = np.flatnonzero(np.isclose(ring.mesh.points[:, 1], 0) & np.isin(
        np.round(ring.mesh.points[:, 2], 12), np.round(model.mesh.points[tip, 2], 12)))
    assert ring_tip.size and np.allclose(
        np.sort(state.displacement[ring.dof_of(ring_tip, "z")]),
        np.sort(grow[np.isclose(model.mesh.points[tip, 1], 0)]), rtol=1e-8)


def test_campbell_per_nodal_diameter_starts_at_rest():
    n = 6
    model = assemble(hex_sector(n, nr=1, nb=2, nt=2, nx=1, band=(0, 2)), "steel", order=1, clamp="hub")
    sector = fe_sector(model, n, AXIS)
    c = cyclic_campbell(model, sector, [0.0, 800.0], count=2, diameters=[0, 2])
    rest = cyclic_spectrum(sector, 2, diameters=[0, 2])
    for k in (0, 2):
        assert c[k].shape == (2, 2)
        assert np.allclose(c[k][0], rest[k].frequencies, rtol=1e-12)
        assert c[k][1, 0] > c[k][0, 0]
