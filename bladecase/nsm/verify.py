"""The independent check of a periodic orbit: the event-driven simulator, started from the orbit's
post-impact state, must come back to it after one period with the same number of impacts.

The orbit's equations (:mod:`~bladecase.nsm.newton.modal`) and the simulator (:mod:`~bladecase.nsm.newton.simulation`)
share no code path but the system's matrices, so agreement is evidence that the orbit exists in the
system it was computed for — and only in that system (checking a reduced model's orbit in a richer
model is a separate question).
"""

from __future__ import annotations

import numpy as np

from .newton.orbits import PeriodicOrbit
from .newton.simulation import simulate

#: Relative tolerance of the independent check of an animated orbit: the
#: event-driven simulator started from its post-impact state at ``t = 0`` must
#: come back to that state after one period (with ``k`` impacts).
VERIFY_RTOL = 1e-8


def verify(orbit: PeriodicOrbit) -> dict:
    """Simulate one period from the orbit's post-impact state (:func:`bladecase.simulate`) and compare.

    Returns ``{"return_error": ‖z(T) − z(0)‖/‖z(0)‖ (state (x, v) scaled by
    its component ranges), "impacts": impacts found in (0, T], "ok": bool}``.

    >>> from bladecase import chain, orbit_1ipp
    >>> check = verify(orbit_1ipp(chain(2, k=1.0, m=0.5, gap=1.0), T=6.0))
    >>> check["ok"], check["impacts"], check["return_error"] < 1e-12
    (True, 1, True)
    """
    if getattr(orbit, "contact_model", "newton") == "massless":
        return _verify_massless(orbit)
    T, k = orbit.T, orbit.k
    x0, v0 = orbit.state(np.array([0.0]))
    x0, v0 = x0[:, 0], v0[:, 0]
    flights = np.diff(np.concatenate([[0.0], orbit.impact_times]))
    try:
        traj = simulate(orbit.system, x0, v0, T + 0.5 * flights.min())
    except ValueError as exc:  # e.g. the orbit's state at t = 0 is not at/behind the casing
        return {"return_error": float("inf"), "impacts": 0, "ok": False, "reason": str(exc)}
    hits = np.flatnonzero((traj.impact_times > 0) & (traj.impact_times <= T + 0.25 * flights.min()))
    if hits.size == 0:
        return {"return_error": float("inf"), "impacts": 0, "ok": False}
    last = hits[-1]
    sx, sv = max(np.abs(x0).max(), 1e-300), max(np.abs(v0).max(), 1e-300)
    err = max(np.abs(traj.x[:, last] - x0).max() / sx, np.abs(traj.v[:, last] - v0).max() / sv,
              abs(traj.impact_times[last] - T) / T)
    return {"return_error": float(err), "impacts": int(hits.size), "ok": bool(err <= VERIFY_RTOL and hits.size == k)}


def _verify_massless(orbit) -> dict:
    """The massless model's check: from the orbit's state at mid-contact (an orbit of several contact phases: the
    middle of its first open phase), one period of :func:`~bladecase.nsm.massless.model.simulate_massless` must
    come back with as many closings as the orbit has contact phases."""
    from .massless.model import simulate_massless

    T = orbit.T
    t0 = orbit.beta if hasattr(orbit, "beta") else orbit.mid_open_time  # no switch at t = 0
    x0, v0 = (z[:, 0] for z in orbit.state(np.array([t0])))
    try:
        traj = simulate_massless(orbit.system, x0, v0, T)
    except ValueError as exc:
        return {"return_error": float("inf"), "impacts": 0, "ok": False, "reason": str(exc)}
    sx = max(float(np.abs(x0).max()), 1e-300)
    sv = max(float(np.abs(orbit.state(np.linspace(0, T, 16))[1]).max()), 1e-300)  # v0 may be ~0 at mid-contact
    err = max(np.abs(traj.x_end - x0).max() / sx, np.abs(traj.v_end - v0).max() / sv)
    closings = sum(p == "closed" for p in traj.phases)
    return {"return_error": float(err), "impacts": int(closings),
            "ok": bool(err <= VERIFY_RTOL and closings == getattr(orbit, "k", 1))}
