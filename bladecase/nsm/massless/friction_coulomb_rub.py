"""The rub of a turning blade with stick–slip friction (:mod:`~bladecase.nsm.massless.friction_coulomb`): the energy
balance of a stick–slip trajectory (:func:`coulomb_energy`) and the rub response at one speed
(:func:`coulomb_rub_response`), with each node's share of its contact time spent sticking.

**The energy balance** over ``[t0, t1]``: ``E(t1) − E(t0) = W_casing + W_friction − D`` with

    E = ½x'ᵀMx' + ½xᵀSx − fᵀx + ½λᵀHλ − λᵀC_nt τ + ½τᵀC_tt τ,
    W_casing = −∫ λᵀg' dt,   W_friction = ∫ τᵀz' dt,   D = ∫ x'ᵀCx' dt

(``f`` a constant load; ``z'`` the nodes' tangential velocities: a sticking node moves with the casing, ``z' = V``, so
friction there feeds the vibration the casing's work ``τV``). With every node sliding along ``+`` it is the balance of
the rotation model (:mod:`~bladecase.nsm.massless.friction_energy`). The integrals are Gauss–Legendre quadratures on
each phase's pieces (one period of that phase's fastest term), at two orders: their difference is the stated error.

>>> import numpy as np
>>> from bladecase.nsm import Damping
>>> from bladecase.nsm.massless.nodes import NodalSystem
>>> from bladecase.nsm.massless.friction import Friction
>>> s = NodalSystem(np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2), np.diag([0.5, 0.5]),
...                 gap=[1.0, 1.0], casing=[4.0, 4.0])
>>> f = Friction(0.3, T=np.array([[0.3, 0.1], [-0.1, 0.4]]), C_tt=np.diag([0.2, 0.2]), radius=[0.5, 0.5],
...              model="coulomb")
>>> r = coulomb_rub_response(s, f, 0.4, 3, 1.2, [0.0, 0.3], Damping(zeta=0.05), revolutions=4, window=2)
>>> bool(r.friction["relative_residual"] < 1e-9), bool(0 < max(r.friction["stick_share"]) < 1)
(True, True)
"""

from __future__ import annotations

import numpy as np

from .friction import Friction
from .friction_coulomb import CoulombFlight, CoulombTrajectory
from .friction_energy import FrictionEnergy
from .nodes import NodalSystem, Rub
from .rub import SAMPLES_PER_PERIOD, SETTLED_RTOL, RubResponse, _change, _checked, _loaded_area

__all__ = ["CoulombEnergy", "coulomb_energy", "coulomb_rub_response", "stick_share"]

#: Gauss–Legendre orders of the two quadratures (their difference: the stated error).
ORDERS = (10, 20)

#: Quadrature pieces per period of a phase's fastest term (20 points a period: far beyond round-off for its
#: exponentials; the two orders' difference says so).
PIECES_PER_PERIOD = 1


#: The energy balance of a stick–slip run: the same terms as the rotation model's (casing input, friction, damping,
#: stored energy, residual, the two quadratures' difference).
CoulombEnergy = FrictionEnergy


def _stored(tr: CoulombTrajectory, t) -> np.ndarray:
    fl = tr.flight
    x, v, lam, tau, _, _ = tr.sample(t)
    s = fl.system
    return (0.5 * (v * (s.M @ v)).sum(0) + 0.5 * (x * (s.S @ x)).sum(0) - fl.load @ x
            + 0.5 * (lam * (fl.H @ lam)).sum(0) - (lam * (fl.C_nt @ tau)).sum(0) + 0.5 * (tau * (fl.C_tt @ tau)).sum(0))


def _powers(tr: CoulombTrajectory, t: np.ndarray) -> np.ndarray:
    fl = tr.flight
    _, v, lam, tau, _, zd = tr.sample(t)
    gdot = fl.rho_rate(t)[: fl.m]
    damp = (v * ((fl.system.M @ fl.phi @ fl.Cq @ fl.phi.T @ fl.system.M) @ v)).sum(0) if fl.Cq is not None else 0 * t
    return np.vstack([-(lam * gdot).sum(0), (tau * zd).sum(0), damp])


def coulomb_energy(tr: CoulombTrajectory, t0: float, t1: float) -> CoulombEnergy:
    """The energy balance of ``tr`` over ``[t0, t1]`` (module docstring)."""
    if not (0 <= t0 < t1 <= tr.t_end * (1 + 1e-12)):
        raise ValueError(f"[t0, t1] = [{t0!r}, {t1!r}] must lie in the trajectory's [0, {tr.t_end!r}] with t0 < t1")
    fl = tr.flight
    inside = (tr.starts > t0) & (tr.starts < t1)
    cuts = np.r_[t0, tr.starts[inside], t1]
    first = max(int(np.searchsorted(tr.starts, t0, side="right")) - 1, 0)
    held = np.r_[first, np.flatnonzero(inside)]  # the phase holding each piece
    period = {}
    for i in held:
        key = tr.codes[i].tobytes()
        if key not in period:  # each phase's own fastest term: its pieces that period long
            fastest = max(float(np.abs(fl.phase(tr.codes[i]).lam).max()), fl.nu, 1e-300)
            period[key] = 2 * np.pi / (PIECES_PER_PERIOD * fastest)
    pieces = [np.linspace(a, b, max(1, int(np.ceil((b - a) / period[tr.codes[i].tobytes()]))) + 1)
              for a, b, i in zip(cuts[:-1], cuts[1:], held)]
    edges = np.unique(np.concatenate(pieces))
    mid, half = 0.5 * (edges[1:] + edges[:-1]), 0.5 * np.diff(edges)
    out = []
    for order in ORDERS:
        g, w = np.polynomial.legendre.leggauss(order)
        t = (mid[:, None] + half[:, None] * g).ravel()
        out.append(_powers(tr, t) @ (half[:, None] * w).ravel())
    casing, fric, damp = out[1]
    E = _stored(tr, [t0, t1])
    change = float(E[1] - E[0])
    residual = change - (casing + fric - damp)
    scale = max(abs(casing), abs(fric), abs(damp), abs(change), float(np.abs(E).max()), np.finfo(float).tiny)
    return CoulombEnergy(float(t0), float(t1), float(casing), float(fric), float(damp), change, float(residual),
                         float(residual / scale), float(np.abs(out[1] - out[0]).max()))


def stick_share(tr: CoulombTrajectory, t0: float, t1: float) -> np.ndarray:
    """Each node's share of its contact time in ``[t0, t1]`` spent sticking (0 for a node that never touches)."""
    contact = tr.contact_time(t0, t1)
    return np.where(contact > 0, tr.stick_time(t0, t1) / np.where(contact > 0, contact, 1.0), 0.0)


def _peaks(tr: CoulombTrajectory, t0: float, t1: float, samples: int) -> tuple[np.ndarray, ...]:
    s = tr.system
    t = np.unique(np.r_[np.linspace(t0, t1, samples), tr.starts[(tr.starts >= t0) & (tr.starts <= t1)]])
    x, _, lam, _, _, zd = tr.sample(t)
    u = s.W.T @ x - s.flexibility @ lam
    return (u.max(axis=1), lam.max(axis=1), (lam / s.casing[:, None]).max(axis=1),
            lam[:, int(np.argmax(lam.sum(axis=0)))], np.abs(zd).max(axis=1))


def coulomb_rub_response(system: NodalSystem, friction: Friction, speed: float, lobes: int, amplitude: float, angles,
                         damping=None, revolutions: int = 40, window: int = 10, areas=None,
                         max_switches: int = 2_000_000, sliding=None) -> RubResponse:
    """The rub response with stick–slip friction at ``speed`` (rad/s) from rest over ``revolutions`` turns, read on
    the last ``window`` (settled when its peaks match the window's before within 2 %; the run does not go on), as
    :func:`~bladecase.nsm.massless.rub.rub_response`. Each node slides past the casing at ``ΩR_j`` (the friction's
    radii; ``sliding``: other speeds, m/s). Its ``friction`` figures: the energy balance of the last revolution and
    the worst relative residual over the window (:func:`coulomb_energy`), each node's share of its contact time
    spent sticking over the window (``stick_share``) and its largest tangential vibration velocity over ``ΩR``."""
    _, speed = _checked(revolutions, window, revolutions, speed)
    if friction.radius is None and sliding is None:
        raise ValueError("the stick–slip rub needs each node's radius (Friction.radius) or its sliding speed")
    rub = Rub(lobes, amplitude, speed, angles)
    fl = CoulombFlight(system, friction, damping, rub, sliding)
    turn = 2 * np.pi / speed
    tr = fl.simulate(np.zeros(system.n), np.zeros(system.n), revolutions * turn, max_switches=max_switches)
    if not tr.complete:
        raise ValueError(f"the stick–slip rub at {speed:.6g} rad/s needed more than {max_switches} phases in "
                         f"{revolutions} revolutions")
    end = tr.t_end
    omega = system.modes[0]
    per_turn = max(SAMPLES_PER_PERIOD * lobes, int(np.ceil(SAMPLES_PER_PERIOD * omega[0] / speed)) * 4)
    now = _peaks(tr, end - window * turn, end, window * per_turn + 1)
    before = _peaks(tr, end - 2 * window * turn, end - window * turn, window * per_turn + 1)
    change = _change(now[:4], before[:4], system.gap)
    settled = change <= SETTLED_RTOL
    t0 = end - window * turn
    fraction = tr.contact_time(t0, end) / (window * turn)
    loaded = None if areas is None else _loaded_area(tr, np.asarray(areas, dtype=float), t0, end)
    revs = [coulomb_energy(tr, end - (k + 1) * turn, end - k * turn) for k in range(window)]
    last = revs[0]
    share = stick_share(tr, t0, end)
    figures = {"mu": float(friction.mu), "model": "coulomb", "casing_j": last.casing, "friction_j": last.friction,
               "damping_j": last.damping, "stored_change_j": last.stored_change, "residual_j": last.residual,
               "relative_residual": max(abs(e.relative) for e in revs), "quadrature_error_j": last.quadrature_error,
               "stick_share": share.tolist(), "stick_share_max": float(share.max()),
               "sliding_node_ratio": (now[4] / np.maximum(fl.V, np.finfo(float).tiny)).tolist()}
    figures["sliding_ratio"] = float(max(figures["sliding_node_ratio"]))
    return RubResponse(speed, int(lobes), float(amplitude), int(revolutions), int(window), system.nodes, now[0],
                       now[1], fraction, now[2], int(tr.switch_times.size), settled, change, float(now[3].sum()),
                       now[3], loaded, "settled" if settled else "transient", 1 if settled else None,
                       int(revolutions), float(window), int(revolutions), {}, figures)
