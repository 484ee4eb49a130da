"""The forced response of a bladed disk with every blade its own massless contact: the steady rub of each blade
under a harmonic load (e.g. an engine order on a mistuned disk), by the exact event-driven simulator.

A harmonic load ``Re(F̂ e^{iΩt})`` on the interior and ``Re(r e^{iΩt})`` at the contacts (their residual static
response to the load) is split off exactly: with ``x = x_p + z``, ``x_p = Re(X̂ e^{iΩt})`` the linear steady state
(``(S − Ω²M + iΩC) X̂ = F̂``, ``C`` the modal damping of the open-phase modes),

    ``M z'' + C z' + S z + Wλ = 0``,   ``s = [g − Re(Y e^{iΩt})] − Wᵀz + Hλ ≥ 0``,   ``Y = WᵀX̂ + r``,

the unforced disk against a clearance that moves harmonically: the flight of
:class:`~bladecase.nsm.massless.nodes.NodalFlight` with a rub of complex amplitudes ``−Y`` at ``Ω``, flown from
the linear steady state (``z = 0``) by the exact event-driven simulator until it settles. The contact
forces are those of the forced problem; the contacts' displacements are ``Re(Y e^{iΩt}) + Wᵀz − H_sλ``.

>>> from bladecase.nsm.damping import Damping
>>> s = NodalSystem(np.eye(2), np.array([[1.1, -0.1], [-0.1, 1.1]]), np.eye(2), np.eye(2), gap=[0.1, 0.1],
...                 casing=[5.0, 5.0])
>>> out = forced_contacts(s, np.array([0.05, 0.05j]), np.zeros(2), 1.0, 0.05, periods=20, window=4)
>>> out.settled, bool(out.peak_force.min() > 0)          # both blades rub, the second a quarter period later
(True, True)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from ..damping import Damping
from .nodal_system import NodalSystem, Rub
from .nodes import NodalFlight, simulate_nodes

__all__ = ["ForcedContacts", "forced_contacts", "linear_contacts"]

#: Instants of the last period at which each contact's force is sampled before its peak is refined.
SAMPLES = 400


@dataclass(frozen=True, eq=False)
class _Moving(Rub):
    """Clearances ``g + Re(D e^{iνt})`` with any complex amplitude per contact (a :class:`Rub` seen through its
    ``nu`` and ``D``)."""

    amplitudes: tuple = ()
    frequency: float = 1.0

    @property
    def nu(self) -> float:
        return float(self.frequency)

    @property
    def D(self) -> np.ndarray:
        return np.asarray(self.amplitudes, dtype=complex)


def linear_contacts(system: NodalSystem, load, residual, omega: float, zeta: float) -> np.ndarray:
    """``Y``: the contacts' complex displacement amplitudes of the linear steady state (every contact open) under
    ``Re(load e^{iΩt})`` (modal damping ratio ``zeta`` on the open-phase modes), ``residual`` added.

    >>> s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), np.eye(1), gap=[1.0])
    >>> complex(linear_contacts(s, [1.0], [0.0], 0.5, 0.0)[0])           # 1/(1 − 0.25)
    (1.3333333333333333+0j)
    """
    w, phi = system.modes
    rates = Damping(zeta=float(zeta)).rates(w)
    q = (phi.T @ np.asarray(load, dtype=complex)) / (w**2 - omega**2 + 2j * omega * rates)
    return system.W.T @ (phi @ q) + np.asarray(residual, dtype=complex)


@dataclass(frozen=True)
class ForcedContacts:
    """The settled forced response with contacts (:func:`forced_contacts`): per contact its ``peak_force`` (N, each
    peak refined), ``contact_fraction`` (of the period) and ``peak_t`` (its instant within the last period, s);
    ``settled`` (the peaks of the last two windows agree to ``rtol``), ``change`` (their relative change),
    ``periods_run``, ``switches``."""

    peak_force: np.ndarray
    contact_fraction: np.ndarray
    peak_t: np.ndarray
    settled: bool
    change: float
    periods_run: int
    switches: int


def _peaks(tr, T: float, samples: int) -> tuple[np.ndarray, np.ndarray]:
    """Each contact's largest force over the last period of the trajectory ``tr`` and its instant: the largest of
    ``samples`` instants refined between its neighbours (bounded Brent)."""
    t0 = tr.t_end - T
    t = t0 + T * np.arange(samples + 1) / samples
    lam = tr.forces(t)
    peak, when = lam.max(axis=1), t[np.argmax(lam, axis=1)]
    for c in np.flatnonzero(peak > 0):
        i = int(np.argmax(lam[c]))
        lo, hi = t[max(i - 1, 0)], t[min(i + 1, t.size - 1)]
        res = minimize_scalar(lambda s, c=c: -tr.forces(np.array([s]))[c, 0], bounds=(lo, hi), method="bounded",
                              options={"xatol": 1e-12 * T})
        if -res.fun > peak[c]:
            peak[c], when[c] = -res.fun, res.x
    return peak, when - t0


def forced_contacts(system: NodalSystem, load, residual, omega: float, zeta: float, *, periods: int = 40,
                    window: int = 10, max_periods: int | None = None, rtol: float = 1e-8,
                    samples: int = SAMPLES) -> ForcedContacts:
    """The settled forced response with contacts (module docstring), flown from the linear steady state for
    ``periods`` periods of ``2π/Ω``, then ``window`` at a time until each contact's peak force over the last period
    changes by less than ``rtol`` (relative to the largest) from one window to the next, or ``max_periods``
    (default ``10 × periods``) have run.

    ``load``: the modal load amplitude ``F̂`` (``(n,)`` complex); ``residual``: the contacts' residual static
    response ``r`` (``(m,)`` complex); ``omega``: ``Ω`` (rad/s); ``zeta``: the modal damping ratio (> 0: a steady
    state to settle to)."""
    if not (np.isfinite(omega) and omega > 0):
        raise ValueError(f"omega must be the forcing's angular frequency > 0 (rad/s), got {omega!r}")
    if not (np.isfinite(zeta) and zeta > 0):
        raise ValueError(f"zeta must be a modal damping ratio > 0 (a steady state to settle to), got {zeta!r}")
    Y = linear_contacts(system, load, residual, omega, zeta)
    damping = Damping(zeta=float(zeta))
    moving = _Moving(1, 0.0, float(omega), tuple(np.zeros(system.m)), tuple(-Y), float(omega))
    flight = NodalFlight(system, damping, moving)
    T = 2 * np.pi / float(omega)
    cap = 10 * int(periods) if max_periods is None else int(max_periods)
    x, v = np.zeros(system.n), np.zeros(system.n)
    run, done, switches, before, change = int(periods), 0, 0, None, np.inf
    while True:  # whole periods of Ω: each segment may restart the clock at 0
        tr = simulate_nodes(system, x, v, run * T, flight=flight)
        switches += int(tr.switch_times.size)
        done += run
        x, v = tr.x_end, tr.v_end
        peak, when = _peaks(tr, T, samples)
        if before is not None:
            change = float(np.abs(peak - before).max() / max(peak.max(), 1e-300))
        if change <= rtol or done >= cap:
            break
        before, run = peak, int(window)
    fraction = tr.contact_time(tr.t_end - T, tr.t_end) / T
    return ForcedContacts(peak, fraction, when, bool(change <= rtol), change, done, switches)
