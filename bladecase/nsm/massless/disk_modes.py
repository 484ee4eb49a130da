"""Travelling-wave nonsmooth modes of a tuned bladed disk: periodic orbits with a rotating-wave symmetry, found by
shooting over a fraction of the period, then checked on the whole disk without the symmetry.

A tuned disk's model (:class:`NodalSystem` of ``N`` blades, e.g. :func:`bladecase.reduction.disk.disk_model`)
commutes with the blade shift ``P`` (``(Pu)_j = u_{j+s}``: the same matrices after renumbering the blades). A
wave of ``k`` nodal diameters travelling round the disk moves blade ``j`` as blade 0 ``jk/N`` of a period later,
``u_{j+1}(t) = u_j(t − kT/N)``; with ``g = gcd(k, N)``, ``N' = N/g`` and ``sk ≡ −g (mod N)``,

    ``u_{j+s}(t) = u_j(t − skT/N) = u_j(t + T/N')``,   i.e.   ``z(T/N') = P z(0)``

for the whole state ``z = (x, v)``. Because the flow commutes with ``P`` (``Φ_t(Pz) = PΦ_t(z)``) and
``P^{N'} = I``, a state with ``Φ_{T/N'}(z) = Pz`` is periodic, ``Φ_T(z) = P^{N'}z = z``: the shooting residual
over ``T/N'`` (:func:`rotating_orbit`) costs ``1/N'`` of a period's flight, and its solutions are exactly the
periodic orbits with that symmetry. The equations, as for :mod:`~bladecase.nsm.massless.nodal_modes`: ``Φ_τ(z₀) −
Pz₀ = 0`` (``τ = T/N'``, exact flow and exact Jacobian, ``∂/∂T`` the vector field over ``N'``), a phase condition
(the velocity of one coordinate zero at ``t = 0``) and the period or the energy fixed; Gauss–Newton.

The check is independent of the symmetry (:func:`return_error`): the state flown over whole periods by the exact
event-driven simulator in the full model must come back; and the stability is the full model's (``N·n`` states,
no symmetry assumed): the Floquet multipliers of the one-period monodromy (:func:`full_orbit`).

>>> from bladecase.reduction.disk import disk_model
>>> import scipy.sparse as sp
>>> from bladecase.fe.cyclic import CyclicSector
>>> K = np.array([[4.7, -1.0, 0.0, -0.7], [-1.0, 3.0, -2.0, 0.0], [0.0, -2.0, 2.0, 0.0], [-0.7, 0.0, 0.0, 0.7]])
>>> ring = CyclicSector(sp.csr_array(K), sp.csr_array(np.diag([2.0, 0.5, 0.0, 0.0])), 6, left=[0], right=[3])
>>> disk = disk_model(ring, [[0.0], [0.0], [1.0], [0.0]], 0.1, count=2)
>>> P, n1 = disk.rotating(1)                        # one nodal diameter, forward
>>> x0, v0, w = disk.travelling_wave(1)
>>> fam = rotating_family(disk.system, P, n1, x0, v0, 2 * np.pi / w, growth=[1.05, 1.3, 1.6])
>>> o = fam[-1]
>>> err = return_error(disk.system, o.x0, o.v0, o.T, periods=3)
>>> bool(o.T < fam[0].T), bool(err < 1e-9)          # stiffened by the rub; back after 3 periods
(True, True)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .nodal_modes import _Problem
from .nodal_orbit import NodalOrbit, _Flow, _Shooter
from .nodes import NodalSystem, simulate_nodes

__all__ = ["RotatingOrbit", "full_orbit", "return_error", "rotating_family", "rotating_orbit"]


@dataclass(frozen=True, eq=False)
class RotatingOrbit:
    """A periodic orbit with a rotating-wave symmetry ``z(T/N') = P z(0)`` (:func:`rotating_orbit`).

    ``x0, v0``: the state at ``t = 0`` (the system's coordinates); ``T``: period (s); ``shift``: ``P``;
    ``fraction``: ``N'``; ``energy``; ``residual``: ``‖Φ_{T/N'}(z₀) − Pz₀‖/‖z₀‖`` (energy norm); ``contacts``:
    the contact phases of ``[0, T/N')`` (start times and closed sets)."""

    system: NodalSystem
    T: float
    x0: np.ndarray
    v0: np.ndarray
    shift: np.ndarray
    fraction: int
    energy: float
    residual: float
    starts: np.ndarray
    active: np.ndarray

    @property
    def frequency(self) -> float:
        """``1/T`` (Hz)."""
        return 1.0 / self.T

    @property
    def touching(self) -> bool:
        """Whether any contact closes."""
        return bool(self.active.any())


class _Rotating(_Problem):
    """The shooting equations over ``T/N'`` against the shifted start, in the scaled unknowns of ``_Problem``."""

    def __init__(self, sh: _Shooter, Pq: np.ndarray, fraction: int, row: np.ndarray, Y: float, T_ref: float):
        super().__init__(sh, 0, Y, T_ref)
        self.Pq, self.fraction, self.row = Pq, int(fraction), row

    def evaluate(self, u: np.ndarray):
        q, p, T = self.unpack(u)
        if not T > 0:
            raise ValueError(f"non-positive period {T!r}")
        f = self.sh.flow(q, p, T / self.fraction)
        D, n = self.D, self.n
        r = np.r_[D * np.r_[f.qT - self.Pq @ q, f.pT - self.Pq @ p] / self.Y, self.row @ u[n:2 * n]]
        return f, r, self.jacobian(f)

    def jacobian(self, f: _Flow) -> np.ndarray:
        n, D = self.n, self.D
        fq, fp = self.sh.field(f.qT, f.pT)
        J = np.zeros((2 * n + 1, 2 * n + 1))
        P2 = np.kron(np.eye(2), self.Pq)
        J[:2 * n, :2 * n] = (D[:, None] * (f.J - P2)) / D[None, :]
        J[:2 * n, -1] = D * np.r_[fq, fp] * self.T_ref / self.Y / self.fraction
        J[-1, n:2 * n] = self.row
        return J


def _setup(system: NodalSystem, shift, fraction: int, x0, v0):
    if not isinstance(system, NodalSystem):
        raise ValueError(f"system must be a NodalSystem, got {type(system).__name__}")
    P = np.asarray(shift, dtype=float)
    if P.shape != (system.n, system.n):
        raise ValueError(f"shift must be the {system.n} × {system.n} blade shift P, got shape {P.shape}")
    if isinstance(fraction, bool) or int(fraction) != fraction or fraction < 1:
        raise ValueError(f"fraction must be an integer N' >= 1 (z(T/N') = P z(0)), got {fraction!r}")
    sh = _Shooter(system)
    phi = system.modes[1]
    Pq = phi.T @ system.M @ P @ phi
    x0, v0 = np.asarray(x0, dtype=float), np.asarray(v0, dtype=float)
    q0, p0 = phi.T @ system.M @ x0, phi.T @ system.M @ v0
    return sh, Pq, q0, p0


def rotating_orbit(system: NodalSystem, shift, fraction: int, guess, *, energy: float | None = None,
                   T: float | None = None, phase: int | None = None) -> RotatingOrbit:
    """The periodic orbit with ``z(T/N') = P z(0)`` near ``guess = (x₀, v₀, T₀)`` (the system's coordinates) at
    the given ``energy`` or period ``T`` (exactly one), by Gauss–Newton on the shooting equations over ``T/N'``
    (module docstring), the phase fixed by ``v₀[phase] = 0`` (default: the guess's largest displacement).

    Raises ``ValueError`` when Newton does not converge (the period and the residual are named).

    Two blades (unit masses on unit springs, coupled by 0.1, massless tips on unit springs at a clearance 0.1):
    the wave of nodal diameter 1 (blade 1 half a period after blade 0), ``x(T/2) = P x(0)``, ``P`` the swap:

    >>> s = NodalSystem(np.eye(2), np.array([[1.1, -0.1], [-0.1, 1.1]]), np.eye(2), np.eye(2),
    ...                 gap=[0.1, 0.1])
    >>> P = np.array([[0.0, 1.0], [1.0, 0.0]])
    >>> w = np.sqrt(1.2)                                  # the opposed linear mode (1, −1)
    >>> o = rotating_orbit(s, P, 2, (0.12 * np.array([1.0, -1.0]), np.zeros(2), 2 * np.pi / w), T=0.97 * 2 * np.pi / w)
    >>> bool(o.touching), bool(return_error(s, o.x0, o.v0, o.T, periods=5) < 1e-10)
    (True, True)
    """
    if (T is None) == (energy is None):
        raise ValueError("rotating_orbit: give exactly one of T and energy")
    x0, v0, T0 = guess
    sh, Pq, q0, p0 = _setup(system, shift, fraction, x0, v0)
    phi = system.modes[1]
    phase = int(np.argmax(np.abs(x0))) if phase is None else int(phase)
    row = phi[phase]  # v[phase] = φ[phase]·p
    Y = float(np.sqrt(np.sum((sh.omega * q0) ** 2) + p0 @ p0))
    if not (np.isfinite(Y) and Y > 0):
        raise ValueError("the guess is the equilibrium (or not finite): no orbit to correct")
    prob = _Rotating(sh, Pq, fraction, row / np.linalg.norm(row), Y, float(T0))
    if T is not None:
        u0 = prob.pack(q0, p0, float(T))
        erow = np.zeros(u0.size)
        erow[-1] = 1.0

        def extra(u):
            return u[-1] - float(T) / prob.T_ref, erow
    else:
        E = float(energy)
        if not (np.isfinite(E) and E > 0):
            raise ValueError(f"energy must be finite and > 0, got {energy!r}")
        u0 = prob.pack(q0, p0, float(T0))

        def extra(u):
            value, r = prob.energy_row(u)
            return (value - E) / E, r / E
    u, f, res, _ = prob.newton(u0, extra)
    q, p, Tn = prob.unpack(u)
    return RotatingOrbit(system, Tn, phi @ q, phi @ p, np.asarray(shift, float), int(fraction),
                         sh.energy(q, p), float(res), f.starts, f.active)


def rotating_family(system: NodalSystem, shift, fraction: int, x0, v0, T0: float, growth=(1.05, 1.2, 1.4),
                    phase: int | None = None) -> list[RotatingOrbit]:
    """Orbits with the rotating-wave symmetry at the energies ``growth[i] × E₀`` (``growth[0] > 1``: at grazing
    the flow is tangent to a switching surface), ``E₀`` that of the linear wave ``(x₀, v₀)`` scaled until its
    first contact grazes (``x₀``, ``v₀``: e.g.
    :meth:`~bladecase.reduction.disk.DiskModel.travelling_wave`; ``T₀ = 2π/ω``); each orbit starts from the
    previous one. The family stops at the first energy where Newton fails (the orbits found so far are returned;
    none: the error is raised)."""
    x0, v0 = np.asarray(x0, dtype=float), np.asarray(v0, dtype=float)
    w = 2 * np.pi / float(T0)
    t = np.linspace(0.0, T0, 721)
    y = system.W.T @ (np.outer(x0, np.cos(w * t)) + np.outer(v0 / w, np.sin(w * t)))
    scale = float(np.min(system.gap / np.max(y, axis=1).clip(1e-300)))
    x, v, T = scale * x0, scale * v0, float(T0)
    E0 = 0.5 * v @ system.M @ v + 0.5 * x @ system.S @ x
    out: list[RotatingOrbit] = []
    for g in growth:
        if not out:  # the linear wave scaled to the energy: a first guess
            x, v = x * np.sqrt(float(g)), v * np.sqrt(float(g))
        try:
            o = rotating_orbit(system, shift, fraction, (x, v, T), energy=float(g) * E0, phase=phase)
        except ValueError:
            if not out:
                raise
            break
        out.append(o)
        x, v, T = o.x0, o.v0, o.T
    return out


def return_error(system: NodalSystem, x0, v0, T: float, periods: int = 1) -> float:
    """``‖z(pT) − z(0)‖/‖z(0)‖`` in the energy norm ``(S^{1/2}x, M^{1/2}v)``: the state flown ``periods`` whole
    periods by the exact event-driven simulator (:func:`simulate_nodes`) in the full model, no symmetry used.

    >>> s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), np.eye(1), gap=[1.0])
    >>> return_error(s, [0.5], [0.0], 2 * np.pi) < 1e-14                  # a free linear flight
    True
    """
    x0, v0 = np.asarray(x0, dtype=float), np.asarray(v0, dtype=float)
    tr = simulate_nodes(system, x0, v0, float(periods) * float(T))
    w, phi = system.modes
    M = system.M
    dq = w * (phi.T @ M @ (tr.x_end - x0))
    dp = phi.T @ M @ (tr.v_end - v0)
    size = np.sqrt(np.sum((w * (phi.T @ M @ x0)) ** 2) + np.sum((phi.T @ M @ v0) ** 2))
    return float(np.sqrt(dq @ dq + dp @ dp) / size)


def full_orbit(system: NodalSystem, x0, v0, T: float, phase: int = 0) -> NodalOrbit:
    """The :class:`NodalOrbit` of the state ``(x₀, v₀)`` over one whole period ``T`` of the full model (no
    symmetry): its exact flow, closing residual and monodromy, hence its Floquet multipliers
    (:attr:`NodalOrbit.multipliers`, :meth:`NodalOrbit.stable`). ``phase``: the open-phase mode it records.

    >>> s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), np.eye(1), gap=[1.0])
    >>> o = full_orbit(s, [0.5], [0.0], 2 * np.pi)
    >>> bool(o.residual < 1e-14), o.stable()
    (True, True)
    """
    sh = _Shooter(system)
    phi = system.modes[1]
    M = system.M
    q0 = phi.T @ M @ np.asarray(x0, dtype=float)
    p0 = phi.T @ M @ np.asarray(v0, dtype=float)
    return NodalOrbit._of(sh, sh.flow(q0, p0, float(T)), int(phase))

