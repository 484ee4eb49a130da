"""``nodal_family(stop_when=...)``: the family stops at the first orbit the caller's limit refuses, that orbit kept
and nothing beyond it computed; the orbits before are the unlimited family's own."""

from __future__ import annotations

import numpy as np

from bladecase.nsm.massless import NodalSystem, nodal_family


def _system() -> NodalSystem:
    K = np.array([[18.0, -8.0, 0.0, 0.0, 0.0], [-8.0, 34.0, -6.0, -20.0, 0.0], [0.0, -6.0, 21.0, 0.0, -15.0],
                  [0.0, -20.0, 0.0, 25.0, -5.0], [0.0, 0.0, -15.0, -5.0, 20.0]])
    i, c = [0, 1, 2], [3, 4]
    Kcc, Kci = K[np.ix_(c, c)], K[np.ix_(c, i)]
    return NodalSystem(np.diag([2.0, 1.5, 0.7]), K[np.ix_(i, i)] - Kci.T @ np.linalg.solve(Kcc, Kci),
                       -Kci.T @ np.linalg.inv(Kcc), np.linalg.inv(Kcc), gap=[0.2, 0.3])


def test_the_family_stops_at_the_callers_limit():
    s = _system()
    whole = nodal_family(s, 0, freq_ratio=1.15)
    limit = 0.5 * (whole.orbits[1].energy + whole.orbits[-1].energy)
    seen = []

    def beyond(orbit):
        seen.append(orbit.energy)
        return f"energy {orbit.energy:.4g} past {limit:.4g}" if orbit.energy > limit else None

    cut = nodal_family(s, 0, freq_ratio=1.15, stop_when=beyond)
    k = next(i for i, o in enumerate(whole.orbits) if o.energy > limit)
    assert cut.end["kind"] == "limit" and cut.stop.startswith("energy ") and len(cut.orbits) == k + 1
    assert cut.orbits[-1].energy > limit >= cut.orbits[-2].energy
    assert max(seen) == cut.orbits[-1].energy  # nothing beyond the first orbit past the limit was computed
    for a, b in zip(cut.orbits, whole.orbits):
        assert a.T == b.T and a.energy == b.energy  # the same steps up to there
