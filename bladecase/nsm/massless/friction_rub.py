"""The rub of a turning blade with friction at its contact nodes: the exact response over revolutions
(:func:`~bladecase.nsm.massless.friction.friction_flight`), the energy balance of each revolution
(:mod:`~bladecase.nsm.massless.friction_energy`) and the check that the sliding is dominated by the rotation."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .friction_energy import per_revolution
from .nodes import NodalTrajectory, Rub

__all__ = ["FrictionRub", "friction_rub"]


@dataclass(frozen=True, eq=False)
class FrictionRub:
    """:func:`friction_rub`'s answer: the trajectory, the energy balance of each revolution, the sliding check
    (``None`` without the nodes' radii) and the friction work per revolution over the last one (J)."""

    trajectory: NodalTrajectory
    energy: list
    sliding: object
    friction_per_revolution: float

    @property
    def worst_relative(self) -> float:
        """The largest relative residual of the revolutions' energy balances."""
        return max(abs(e.relative) for e in self.energy)


def friction_rub(system, friction, speed: float, lobes: int, amplitude: float, angles, damping=None,
                 revolutions: int = 10) -> FrictionRub:
    """The rub of ``system`` with ``friction`` at ``speed`` (rad/s) inside a casing with ``lobes`` lobes of
    ``amplitude`` (m), from rest over ``revolutions`` turns: its energy balance per revolution and, when the
    friction gives the nodes' radii, whether the sliding is rotation-dominated.

    >>> from bladecase.nsm import Damping
    >>> from bladecase.nsm.massless.nodes import NodalSystem
    >>> from bladecase.nsm.massless.friction import Friction
    >>> s = NodalSystem(np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2), np.diag([0.5, 0.5]),
    ...                 gap=[1.0, 1.0], casing=[4.0, 4.0])
    >>> f = Friction(0.15, T=np.array([[0.3, 0.0], [0.0, 0.3]]), radius=[20.0, 20.0])
    >>> r = friction_rub(s, f, 0.4, 3, 1.2, [0.0, 0.3], Damping(zeta=0.05), revolutions=4)
    >>> bool(r.worst_relative < 1e-10), r.sliding.ok
    (True, True)
    """
    from .friction import friction_flight, sliding_check
    from .nodes import simulate_nodes

    fl = friction_flight(system, friction, damping, Rub(lobes, amplitude, speed, angles))
    turn = 2 * np.pi / speed
    tr = simulate_nodes(system, np.zeros(system.n), np.zeros(system.n), revolutions * turn, flight=fl)
    energy = per_revolution(tr, speed)
    radius = None if friction is None else friction.radius
    sliding = None if radius is None or friction.mu == 0 else sliding_check(tr, speed, (revolutions - 1) * turn)
    return FrictionRub(tr, energy, sliding, energy[-1].friction)
