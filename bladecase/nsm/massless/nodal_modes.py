"""Nonsmooth modes of the massless contact model with one contact per node (:class:`NodalSystem`, theory §8).

A nonsmooth mode is a family of periodic orbits of the undamped system with constant clearances, grown from a
linear (open-phase) mode at grazing and followed in the period ``T``. With ``m`` contacts the one-contact closed
forms (:mod:`~bladecase.nsm.massless.orbits`, :mod:`~bladecase.nsm.massless.phases`) do not carry over: here the
orbits are found by SHOOTING the exact flow.

**Unknowns and equations.** The state at ``t = 0`` in the open-phase modal coordinates, ``z₀ = (q₀, p₀)``
(``q = ΦᵀMx``), and the period ``T``. The equations are

- periodicity ``Φ_T(z₀) − z₀ = 0`` (``2n`` equations), ``Φ_T`` the flow of :func:`simulate_nodes` (closed-form
  phases, every switch the certified first root of the ``m`` switching signals);
- the phase condition ``p₀[k] = 0``: ``t = 0`` is a turning point of the dominant open-phase mode ``k`` (the
  mode the family grows from); at grazing, the one AWAY from the contact that grazes first, inside an open flight
  (for the first bending mode of a blade it stays the excursion away from the casing along the family);
- one more: the period fixed, the energy fixed (:func:`nodal_orbit`), or the pseudo-arclength condition
  (:func:`nodal_family`).

Without damping the energy is a first integral, so the periodicity equations are dependent (``∇Eᵀ(Φ_T(z) − z)``
vanishes to second order): the ``2n + 2`` equations in ``2n + 1`` unknowns are consistent and solved by
Gauss–Newton (least squares), which converges quadratically on a zero-residual problem with full column rank.

**Exact sensitivities.** ``∂Φ_T/∂z₀`` is the product of the phases' state-transition matrices: with the phase's
modes ``K_A = Ω² + W_A G_A W_Aᵀ = Ψ ω² Ψᵀ`` (``M = I`` in modal coordinates),
``[[Ψ cos(ωτ) Ψᵀ, Ψ sin(ωτ)/ω Ψᵀ], [−Ψ ω sin(ωτ) Ψᵀ, Ψ cos(ωτ) Ψᵀ]]`` about the phase's equilibrium, and the
saltation matrices are the identity (the vector field is continuous: ``λ = 0`` at every switch). The derivative
with respect to ``T`` is the vector field at ``Φ_T(z₀)``. The phase's modes are computed here from ``K_A``
(independently of the simulator's own), so the Jacobian also checks the flow.

**Single shooting** over the whole period (not multiple shooting over the phase sequence): every phase is an
undamped linear flight, a rotation in its own energy coordinates, so no phase — however long — amplifies a
perturbation exponentially (a long contact phase is as harmless as a short one); the one-period Jacobian is as
well conditioned as the monodromy of the orbit itself. Multiple shooting pays where phases are unstable or
damped; here it would only add ``2n`` unknowns per segment and make the phase sequence part of the unknowns,
which the exact flow already decides. Measured: Newton converges in 3–8 iterations to closing residuals of
``1e-16`` to ``1e-13`` on the 2-contact chain and the 26-node blade.

**Admissibility.** Every fixed point of the exact flow is an admissible orbit: the flow enforces the
complementarity at every instant (``λ`` solves the complementarity problem at the start and after every switch,
each phase ends at the FIRST root of any of its ``m`` signals). That search is certified: every interval of the
grid is either proved free of roots for each signal by the bound on its second derivative, or bisected until a
root is isolated and refined to machine precision (Brent) — no switch is missed, except a tangency closer than
about ``1e-14`` of the signal's magnitude, which may be reported either way. What is checked per orbit is the
closing residual ``‖Φ_T(z₀) − z₀‖/‖z₀‖`` (energy norm), stored as :attr:`NodalOrbit.residual`.

**Families.** :func:`grazing_orbit`: the linear mode ``k`` scaled until the FIRST node touches
(``max_j max_t (y_j − d_j) = 0``). :func:`nodal_family` continues from it through changes of the phase sequence:
a node that starts or stops touching is just another phase sequence of the same exact flow (which is ``C¹``
there, so Newton does not notice), and every orbit records its own (:attr:`NodalOrbit.sequence`,
:attr:`NodalOrbit.touching`). Two ways along: steps in the energy (the default), or pseudo-arclength in
``(z₀, T)`` scaled by the grazing orbit's energy amplitude and period.

**Internal resonances.** Where the family's frequency meets ``ω_j/N`` for a higher open-phase mode ``j``, the
family turns into that mode along a "tongue"; an orbit whose mode holds less than :data:`BACKBONE_SHARE` of the
modal energy is in one (:attr:`NodalFamily.tongues`). By default the family stops there and says where and why
(:attr:`NodalFamily.end`, the backbone's trend below it: :func:`backbone_trend`); with ``through_resonances=True``
the tongue is crossed. The steps along the family, the tongues and their crossing:
:mod:`~bladecase.nsm.massless.nodal_resonance`.

**Floquet.** The monodromy is the one-period Jacobian. Its two trivial multipliers (time shift, energy direction
of the family: a Jordan block at 1 that a plain eigensolver splits by ``~√ε``) are split off exactly in the
basis ``[f̂, U, ê]`` (``f`` the vector field, ``e = ∇E``, as :mod:`bladecase.nsm.floquet` does); the ``2n − 2``
others are the eigenvalues of the middle block. Stable when they all have ``|μ| <= 1 + tol``.

Three masses in a chain from a wall, two massless contact points hanging off masses 2 and 3 (coupled to each
other), condensed; the contacts at clearances 0.2 and 0.3:

>>> import numpy as np
>>> K = np.array([[18.0, -8.0, 0.0, 0.0, 0.0], [-8.0, 34.0, -6.0, -20.0, 0.0], [0.0, -6.0, 21.0, 0.0, -15.0],
...               [0.0, -20.0, 0.0, 25.0, -5.0], [0.0, 0.0, -15.0, -5.0, 20.0]])
>>> i, c = [0, 1, 2], [3, 4]
>>> Kcc, Kci = K[np.ix_(c, c)], K[np.ix_(c, i)]
>>> s = NodalSystem(np.diag([2.0, 1.5, 0.7]), K[np.ix_(i, i)] - Kci.T @ np.linalg.solve(Kcc, Kci),
...                 -Kci.T @ np.linalg.inv(Kcc), np.linalg.inv(Kcc), gap=[0.2, 0.3])
>>> fam = nodal_family(s, mode=0, freq_ratio=1.15)
>>> [o.touching.tolist() for o in (fam.orbits[0], fam.orbits[1], fam.orbits[-1])]  # grazing, one node, both
[[False, False], [True, False], [True, True]]
>>> bool(fam.frequency[-1] / fam.frequency[0] >= 1.15), bool(np.all(np.diff(fam.energy) > 0))
(True, True)
>>> o = fam.orbits[-1]
>>> bool(o.residual < 1e-12), bool(np.abs(o.multipliers[:2] - 1).max() < 1e-12), o.stable()
(True, True, True)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .nodal_orbit import FLOQUET_TOL, MAX_PHASES, NodalOrbit, _Flow, _Shooter, flow_map
from .nodal_resonance import BACKBONE_SHARE, RESONANCE_SHARE, TONGUE_POINTS, _Run, backbone_trend, resonance_ratio
from .nodes import NodalSystem

__all__ = ["BACKBONE_SHARE", "FAMILY_RTOL", "FLOQUET_TOL", "MAX_PHASES", "METHODS", "RESONANCE_SHARE", "TONGUE_POINTS",
           "NodalFamily", "NodalOrbit", "backbone_trend", "flow_map", "grazing_orbit", "nodal_family", "nodal_orbit",
           "resonance_ratio", "transfer_state"]

#: Largest closing residual ``‖Φ_T(z₀) − z₀‖/‖z₀‖`` (energy norm) accepted for an orbit.
FAMILY_RTOL = 1e-10

#: Newton stops once the closing residual is below this (or stops decreasing).
NEWTON_TARGET = 1e-13

#: Most Gauss–Newton iterations per orbit.
NEWTON_MAXITER = 12


# ----------------------------------------------------------------------------- Newton


class _Problem:
    """The shooting equations in scaled unknowns ``u = (Ωq₀/Y, p₀/Y, T/T_ref)``: residual and Jacobian of
    ``[Φ_T(z₀) − z₀ (energy coordinates, /Y); p₀[k]/Y]``."""

    def __init__(self, sh: _Shooter, mode: int, Y: float, T_ref: float):
        self.sh, self.mode, self.Y, self.T_ref = sh, mode, float(Y), float(T_ref)
        self.n = sh.n
        self.D = np.r_[sh.omega, np.ones(sh.n)]

    def pack(self, q, p, T) -> np.ndarray:
        return np.r_[self.sh.omega * q / self.Y, np.asarray(p) / self.Y, T / self.T_ref]

    def unpack(self, u) -> tuple[np.ndarray, np.ndarray, float]:
        n = self.n
        return u[:n] * self.Y / self.sh.omega, u[n:2 * n] * self.Y, float(u[-1] * self.T_ref)

    def evaluate(self, u: np.ndarray) -> tuple[_Flow, np.ndarray, np.ndarray]:
        q, p, T = self.unpack(u)
        if not T > 0:
            raise ValueError(f"non-positive period {T!r}")
        f = self.sh.flow(q, p, T)
        D, n = self.D, self.n
        r = np.r_[D * np.r_[f.qT - f.q0, f.pT - f.p0] / self.Y, u[n + self.mode]]
        return f, r, self.jacobian(f)

    def jacobian(self, f: _Flow) -> np.ndarray:
        """The shooting Jacobian at the ``u`` whose flow ``f`` is already computed."""
        n, D = self.n, self.D
        fq, fp = self.sh.field(f.qT, f.pT)
        J = np.zeros((2 * n + 1, 2 * n + 1))
        J[:2 * n, :2 * n] = (D[:, None] * f.J) / D[None, :] - np.eye(2 * n)
        J[:2 * n, -1] = D * np.r_[fq, fp] * self.T_ref / self.Y
        J[-1, n + self.mode] = 1.0
        return J

    def closing(self, r: np.ndarray, u: np.ndarray) -> float:
        """Relative closing residual from the scaled residual."""
        return float(np.linalg.norm(r[:-1]) / max(np.linalg.norm(u[:-1]), 1e-300))

    def energy_row(self, u: np.ndarray) -> tuple[float, np.ndarray]:
        """``E(u)`` and ``∂E/∂u``."""
        q, p, _ = self.unpack(u)
        gq, gp = self.sh.energy_gradient(q, p)
        return self.sh.energy(q, p), np.r_[gq / self.sh.omega * self.Y, gp * self.Y, 0.0]

    def tangent(self, J: np.ndarray, previous: np.ndarray) -> np.ndarray:
        """The null vector of the ``(2n + 1)``-square Jacobian (rank ``2n``), oriented along ``previous``."""
        t = np.linalg.svd(J)[2][-1]
        return t if t @ previous >= 0 else -t

    def newton(self, u: np.ndarray, extra, maxiter: int = NEWTON_MAXITER) -> tuple[np.ndarray, _Flow, float, int]:
        """Gauss–Newton on the shooting equations plus ``extra(u) -> (value, row)``; returns ``(u, flow, closing
        residual, iterations)``.

        A step longer than a quarter of ``‖u‖`` is shortened to it (an iterate far from the orbit chatters and
        costs); Newton gives up after two growing residuals in a row. Raises ``ValueError`` (naming the period and
        the residual) if it does not reach :data:`FAMILY_RTOL`.
        """
        best = None
        history: list[float] = []
        T_last = self.unpack(u)[2]
        reason = ""
        for it in range(maxiter + 1):
            T_last = self.unpack(u)[2]
            try:
                f, r, J = self.evaluate(u)
            except ValueError as exc:  # a chattering or grazing iterate
                reason = f" ({exc})"
                break
            value, row = extra(u)
            R = np.r_[r, value]
            res = max(self.closing(r, u), abs(r[-1]), abs(value))
            if best is None or res < best[2]:
                best = (u.copy(), f, res, it)
            if res <= NEWTON_TARGET or (res <= FAMILY_RTOL and history and res > 0.5 * history[-1]):
                break
            if len(history) >= 2 and res > history[-1] > history[-2]:
                break
            history.append(res)
            step = np.linalg.lstsq(np.vstack([J, row]), -R, rcond=None)[0]
            cap = 0.25 * max(float(np.linalg.norm(u)), 1.0)
            size = float(np.linalg.norm(step))
            u = u + (step if size <= cap else step * (cap / size))
            if not np.all(np.isfinite(u)):
                break
        if best is None or not best[2] <= FAMILY_RTOL:
            T = best[1].T if best is not None else T_last
            res = best[2] if best is not None else float("nan")
            raise ValueError(f"Newton did not converge at T = {T:.12g} s: closing residual {res:.3g} (relative, needs "
                             f"<= {FAMILY_RTOL:g}){reason}")
        return best


def _check_mode(system: NodalSystem, mode) -> int:
    if isinstance(mode, (bool, np.bool_)) or not isinstance(mode, (int, np.integer)) or not 0 <= mode < system.n:
        raise ValueError(f"mode must be an open-phase mode index (0 = the first), an integer in [0, {system.n}), "
                         f"got {mode!r}")
    return int(mode)


def grazing_orbit(system: NodalSystem, mode: int = 0) -> NodalOrbit:
    """The linear (open-phase) mode ``mode`` (0 = the first) scaled until the FIRST node touches:
    ``max_j max_t (y_j − d_j) = 0``, one open phase, ``t = 0`` at the turning point away from that node.

    Raises ``ValueError`` if the mode does not move any contact node (no contact is ever reached).
    """
    return _grazing(_Shooter(system), _check_mode(system, mode))


def _grazing(sh: _Shooter, mode: int) -> NodalOrbit:
    system = sh.system
    b = sh.Wq[mode]  # y_j = b_j q_mode while open
    if not np.abs(b).max() > 1e-12 * np.abs(sh.Wq).max():
        raise ValueError(f"no contact reached: open-phase mode {mode} does not move the contact nodes "
                         f"(max |Wᵀφ| = {np.abs(b).max():.3g}); no nonsmooth mode grows from it")
    ratio = np.where(np.abs(b) > 0, system.gap / np.where(b == 0, 1.0, np.abs(b)), np.inf)
    j = int(np.argmin(ratio))
    q0 = np.zeros(system.n)
    q0[mode] = -np.sign(b[j]) * ratio[j]  # t = 0 away from node j; it grazes at T/2
    T = 2 * np.pi / sh.omega[mode]
    A = np.zeros((1, system.m), dtype=bool)
    J = sh.transition(np.zeros(1), A, T)
    p0 = np.zeros(system.n)
    f = _Flow(q0, p0, T, np.zeros(1), A, q0[:, None], p0[:, None], q0, p0, J)
    return NodalOrbit._of(sh, f, mode)


def nodal_orbit(system: NodalSystem, guess, *, T: float | None = None, energy: float | None = None,
                mode: int | None = None) -> NodalOrbit:
    """The periodic orbit near ``guess`` (a :class:`NodalOrbit`, or ``(q₀, p₀, T)`` in modal coordinates) with
    the period ``T`` or the ``energy`` fixed (exactly one), by Gauss–Newton on the shooting equations (module
    docstring) with the phase condition ``p₀[mode] = 0`` (default: the guess's mode, else 0).

    Raises ``ValueError`` when Newton does not converge (the period and the closing residual are named).

    The bilinear oscillator (``k₁ = 1`` open, ``k₁ + k₂ = 2`` closed, clearance 1) at energy 2: ``4π/3`` open,
    ``√2 arccos(0.5/√1.75)`` closed:

    >>> s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), np.eye(1), gap=[1.0])
    >>> o = nodal_orbit(s, ([-2.0], [0.0], 2 * np.pi), energy=2.0)
    >>> bool(abs(o.T - (4 * np.pi / 3 + np.sqrt(2) * np.arccos(0.5 / np.sqrt(1.75)))) < 1e-12)
    True
    """
    if (T is None) == (energy is None):
        raise ValueError("nodal_orbit: give exactly one of T and energy")
    if isinstance(guess, NodalOrbit):
        q0, p0, T0 = guess.q0, guess.p0, guess.T
        mode = guess.mode if mode is None else mode
        sh = guess._shooter if guess.system is system else _Shooter(system)
    else:
        try:
            q0, p0, T0 = (np.asarray(guess[0], float).reshape(-1), np.asarray(guess[1], float).reshape(-1),
                          float(guess[2]))
        except (TypeError, ValueError, IndexError):
            raise ValueError("the guess must be a NodalOrbit or (q0, p0, T)") from None
        sh = _Shooter(system)
    return _solve(sh, q0, p0, T0, _check_mode(system, 0 if mode is None else mode), T, energy)


def _solve(sh: _Shooter, q0, p0, T0: float, mode: int, T: float | None, energy: float | None) -> NodalOrbit:
    n = sh.n
    if q0.shape != (n,) or p0.shape != (n,):
        raise ValueError(f"the guess must hold q0 and p0 of {n} modal coordinates")
    if not (np.isfinite(T0) and T0 > 0):
        raise ValueError(f"the guess's period must be finite and > 0, got {T0!r}")
    Y = float(np.sqrt(np.sum((sh.omega * q0) ** 2) + p0 @ p0))
    if not (np.isfinite(Y) and Y > 0):
        raise ValueError("the guess is the equilibrium (or not finite): no orbit to correct")
    prob = _Problem(sh, mode, Y, T0)
    if T is not None:
        T = float(T)
        if not (np.isfinite(T) and T > 0):
            raise ValueError(f"T must be finite and > 0, got {T!r}")
        u0 = prob.pack(q0, p0, T)
        row = np.zeros(u0.size)
        row[-1] = 1.0

        def extra(u):
            return u[-1] - T / prob.T_ref, row
    else:
        E = float(energy)
        if not (np.isfinite(E) and E > 0):
            raise ValueError(f"energy must be finite and > 0, got {energy!r}")
        u0 = prob.pack(q0, p0, T0)

        def extra(u):
            value, row = prob.energy_row(u)
            return (value - E) / E, row / E
    _, f, _, _ = prob.newton(u0, extra)
    return NodalOrbit._of(sh, f, mode)


# ----------------------------------------------------------------------------- families


@dataclass(frozen=True, eq=False)
class NodalFamily:
    """A nonsmooth mode of a :class:`NodalSystem`: its orbits from grazing (``orbits[0]``, the scaled linear mode)
    along the family, the internal-resonance tongues met on the way, and why the continuation stopped.

    Attributes
    ----------
    system : NodalSystem
    mode : int
        The open-phase mode the family grows from.
    orbits : list of NodalOrbit
        In the order followed; an orbit reached by a crossing (:attr:`landings`) is not connected to the one before.
    stop : str
        Why the family stops, in words.
    tongues : tuple of dict
        The runs of orbits whose mode holds less than ``backbone_share`` of the modal energy at ``t = 0`` (the
        family inside an internal-resonance tongue), in order. Each: ``start``, ``stop`` (``orbits[start:stop + 1]``),
        ``mode`` (the open-phase mode ``j`` that takes over, 0 = the first) and ``mode_frequency_hz``, ``ratio``
        (``"p:q"``: mode ``j``'s frequency over the orbit's, nearest with ``q <= 4``) and ``ratio_value``,
        ``frequency_hz`` and ``least_share`` (at the run's orbit of least share), ``energy_range_j``, and ``left``:
        ``"continued"`` (the continuation came back to the backbone), ``"crossed"`` (a step in the period found the
        backbone beyond it: from ``from_frequency_hz``, the tongue's extreme, to ``to_frequency_hz`` and
        ``to_energy_j``, ``landing`` the index of that orbit), ``"end"`` (the
        family ends in it) or ``"open"`` (the family stopped inside it for another reason).
    end : dict or None
        Why the family ends, structured: ``kind`` (``"internal_resonance"``, ``"frequency_ratio"``, ``"energy_max"``,
        ``"limit"`` (``stop_when``), ``"max_points"``, ``"step"``), ``frequency_hz`` and ``energy_j`` where it
        ends, ``trend`` (the backbone's last stretch: :func:`backbone_trend`); for an internal resonance also
        ``mode``, ``mode_frequency_hz``, ``ratio``, ``ratio_value``, ``share`` (the family's mode's share there),
        ``crossing`` (why it was not crossed) and ``mesh_dependent`` (True: where a resonance with a high mode
        falls moves with the mesh).
    backbone_share : float
        The share of the modal energy that puts an orbit on the backbone (:attr:`on_backbone`).
    """

    system: NodalSystem
    mode: int
    orbits: list
    stop: str
    tongues: tuple = ()
    end: dict | None = None
    backbone_share: float = BACKBONE_SHARE

    @property
    def T(self) -> np.ndarray:
        return np.array([o.T for o in self.orbits])

    @property
    def frequency(self) -> np.ndarray:
        return 1.0 / self.T

    @property
    def energy(self) -> np.ndarray:
        return np.array([o.energy for o in self.orbits])

    @property
    def linear_frequency(self) -> float:
        """The open-phase mode's frequency (Hz): the grazing orbit's."""
        return self.orbits[0].frequency

    @property
    def shares(self) -> np.ndarray:
        """The family's mode's share of the modal energy at ``t = 0``, per orbit."""
        return np.array([o.modal_energy_share[self.mode] for o in self.orbits])

    @property
    def on_backbone(self) -> np.ndarray:
        """``(len(orbits),)`` bool: the orbit is on the backbone, in no tongue (:attr:`tongues`)."""
        flag = np.ones(len(self.orbits), dtype=bool)
        for t in self.tongues:
            flag[t["start"]:t["stop"] + 1] = False
        return flag

    @property
    def landings(self) -> list[int]:
        """Indices of the orbits reached by crossing a tongue (each starts a new stretch of the backbone)."""
        return [t["landing"] for t in self.tongues if t["left"] == "crossed"]

    @property
    def touching(self) -> np.ndarray:
        """``(len(orbits), m)`` bool: which nodes touch on each orbit."""
        return np.array([o.touching for o in self.orbits])

    @property
    def changes(self) -> list[int]:
        """Indices ``i`` where the set of touching nodes differs from orbit ``i − 1``'s."""
        t = self.touching
        return [i for i in range(1, len(self.orbits)) if not np.array_equal(t[i], t[i - 1])]

    def at_period(self, T: float, backbone: bool = False) -> list[NodalOrbit]:
        """The orbits of period ``T`` on the family (one per crossing), each by Newton from its neighbours'
        interpolation; ``backbone``: between orbits on the backbone only."""
        return self._at(T, np.array(self.T), "T", backbone)

    def at_energy(self, energy: float, backbone: bool = False) -> list[NodalOrbit]:
        """The orbits of the given energy on the family (one per crossing); ``backbone``: on the backbone only."""
        return self._at(energy, self.energy, "energy", backbone)

    def _at(self, value: float, along: np.ndarray, key: str, backbone: bool) -> list[NodalOrbit]:
        out = []
        jumps, on = set(self.landings), self.on_backbone
        for i in range(len(self.orbits) - 1):
            lo, hi = sorted((along[i], along[i + 1]))
            if not (lo <= value <= hi) or hi == lo or i + 1 in jumps or (backbone and not on[i:i + 2].all()):
                continue
            s = (value - along[i]) / (along[i + 1] - along[i])
            a, b = self.orbits[i], self.orbits[i + 1]
            target = {"T": None, "energy": None, key: value}
            out.append(_solve(a._shooter, (1 - s) * a.q0 + s * b.q0, (1 - s) * a.p0 + s * b.p0,
                              (1 - s) * a.T + s * b.T, self.mode, target["T"], target["energy"]))
        return out

    def to_dict(self) -> dict:
        return {"mode": self.mode, "stop": self.stop, "end": self.end, "tongues": [dict(t) for t in self.tongues],
                "backbone_share": self.backbone_share, "on_backbone": self.on_backbone.tolist(),
                "nodes": list(self.system.nodes), "orbits": [o.to_dict() for o in self.orbits]}

    def __repr__(self) -> str:
        f = self.frequency
        crossed = sum(t["left"] == "crossed" for t in self.tongues)
        return (f"NodalFamily(mode {self.mode}, {len(self.orbits)} orbits, f {f[0]:.6g} → {f[-1]:.6g} Hz, "
                f"E up to {self.energy.max():.4g} J, {len(self.changes)} change(s) of the touching nodes, "
                f"{len(self.tongues)} tongue(s), {crossed} crossed; stopped: {self.stop})")


METHODS = ("energy", "arclength")

#: Default steps ``(ds, ds_max, ds_min)`` per method: ``Δln E`` (energy) or scaled arclength.
STEPS = {"energy": (0.05, 0.3, 1e-4), "arclength": (0.02, 0.5, 1e-6)}


def nodal_family(system: NodalSystem, mode: int = 0, *, method: str = "energy", freq_ratio: float | None = None,
                 energy_max: float | None = None, max_points: int = 200, ds: float | None = None,
                 ds_max: float | None = None, ds_min: float | None = None,
                 resonance_share: float = RESONANCE_SHARE, max_phases: int = MAX_PHASES,
                 through_resonances: bool = False, backbone_share: float = BACKBONE_SHARE,
                 stop_when=None) -> NodalFamily:
    """The nonsmooth mode grown from open-phase mode ``mode`` (0 = the first) at grazing (:func:`grazing_orbit`),
    continued through changes of the phase sequence (module docstring).

    Two ways along the family:

    - ``"energy"`` (default): natural-parameter steps in the energy, each orbit solved at its energy by
      Gauss–Newton from the secant predictor (the grazing orbit scaled for the first). Internal resonances of
      the discrete spectrum cut thin tongues across the family (the family turns into a high mode at a period
      ``N`` times that mode's, e.g. 706:1 on the demo blade); a step in energy lands beyond a tongue thinner than
      itself, on the same backbone — the tongue's excursion is not followed (it is a separate stretch of
      orbits of the same family, at an almost constant period).
    - ``"arclength"``: pseudo-arclength in ``(z₀, T)`` scaled by the grazing orbit's energy amplitude ``Y``
      (``√(2E)``) and period: follows the curve faithfully, into such tongues too.

    An orbit whose mode holds less than ``backbone_share`` of the modal energy at ``t = 0`` (``½(ω_j²q_j² + p_j²)``)
    is inside a tongue (:attr:`NodalFamily.tongues`, :attr:`NodalFamily.on_backbone`). Below ``resonance_share``
    the family has turned into the other mode: without ``through_resonances`` it stops there (the stop message
    names the mode that takes over, the ratio of its frequency to the orbit's, says that where this falls depends
    on the mesh, and gives the backbone's trend below it: :func:`backbone_trend`). With ``through_resonances`` the
    tongue is CROSSED (module docstring): orbits at periods beyond it, predicted from the backbone's last stretch,
    until one is on the backbone again with its energy growing along it; the family goes on from there (by
    pseudo-arclength until its energy grows again, then by its own steps). Also crossed with
    ``through_resonances``: a tongue whose orbits exceed ``energy_max`` or run for :data:`TONGUE_POINTS` orbits, or
    where the step collapses. A tongue that cannot be crossed ends the family (``end["kind"] ==
    "internal_resonance"``).

    The family also stops at the first of: ``freq_ratio`` reached, ``energy_max`` reached (by an orbit on the
    backbone, with ``through_resonances``), ``max_points`` orbits, or the step falling below ``ds_min`` (the message
    names the period and the residual). :attr:`NodalFamily.end` says which, structured.

    Parameters
    ----------
    system : NodalSystem
        Undamped, constant clearances.
    mode : int
        The open-phase mode the family grows from (its velocity vanishes at ``t = 0``: the phase condition).
    method : str
        ``"energy"`` or ``"arclength"``.
    freq_ratio : float or None
        Stop once the frequency reaches ``freq_ratio`` times the linear one (or drops below its inverse).
    energy_max : float or None
        Stop once the energy exceeds it (J).
    max_points : int
        Most orbits (the grazing one included).
    ds, ds_max, ds_min : float or None
        First, largest and smallest step: ``Δln E`` for ``"energy"`` (defaults 0.05, 0.3, 1e-4), the scaled
        arclength for ``"arclength"`` (0.02, 0.5, 1e-6). A step whose Newton fails is halved, one that converges
        in at most 3 iterations grows by 1.5.
    resonance_share : float
        See above (0 disables the resonance handling: the family follows a tongue wherever it leads).
    max_phases : int
        Most phases in one period's flow: a Newton iterate that chatters beyond fails (the step is halved).
    through_resonances : bool
        Cross the internal-resonance tongues instead of stopping at the first.
    backbone_share : float
        See above; in ``[resonance_share, 1)``.
    stop_when : callable or None
        ``orbit -> reason or None``: the family stops at the first orbit for which it returns a reason (a string;
        ``end["kind"] == "limit"``), that orbit kept — e.g. a small-displacement limit, so that nothing beyond it
        is computed.

    Returns
    -------
    NodalFamily
        ``orbits[0]`` the grazing orbit; ``stop`` says why the continuation stopped, ``end`` the same structured,
        ``tongues`` the resonances met.

    Raises
    ------
    ValueError
        Bad input, no contact reached (:func:`grazing_orbit`), or not a single orbit beyond grazing.
    """
    mode = _check_mode(system, mode)
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    for name, value, low in (("max_points", max_points, 2), ("max_phases", max_phases, 1)):
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < low:
            raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")
    if freq_ratio is not None and not (np.isfinite(freq_ratio) and freq_ratio > 1):
        raise ValueError(f"freq_ratio must be a finite number > 1, got {freq_ratio!r}")
    if energy_max is not None and not (np.isfinite(energy_max) and energy_max > 0):
        raise ValueError(f"energy_max must be a finite number > 0, got {energy_max!r}")
    if not (np.isfinite(resonance_share) and 0 <= resonance_share < 1):
        raise ValueError(f"resonance_share must be in [0, 1), got {resonance_share!r}")
    if not (np.isfinite(backbone_share) and resonance_share <= backbone_share < 1):
        raise ValueError(f"backbone_share must be in [resonance_share, 1) = [{resonance_share:g}, 1), got "
                         f"{backbone_share!r}")
    d0, d1, d2 = STEPS[method]
    steps = (d0 if ds is None else ds), (d1 if ds_max is None else ds_max), (d2 if ds_min is None else ds_min)
    if not 0 < steps[2] <= steps[0] <= steps[1]:
        raise ValueError(f"steps must satisfy 0 < ds_min <= ds <= ds_max, got {steps[2]!r}, {steps[0]!r}, "
                         f"{steps[1]!r}")
    sh = _Shooter(system, max_phases)
    g = _grazing(sh, mode)
    run = _Run(_Problem(sh, mode, np.sqrt(2 * g.energy), g.T), g, method, steps,
               {"freq_ratio": freq_ratio, "energy_max": energy_max, "resonance": resonance_share,
                "backbone": backbone_share, "through": bool(through_resonances), "stop_when": stop_when})
    run.follow(max_points)
    if len(run.orbits) < 2:
        raise ValueError(f"no orbit beyond grazing on the family of mode {mode} (T = {run.orbits[0].T:.12g} s): "
                         f"{run.stop}")
    return NodalFamily(system, mode, run.orbits, run.stop, run.tongues(), run.end, backbone_share)


# ----------------------------------------------------------------------------- richer models


def transfer_state(source, target, x, v) -> tuple[np.ndarray, np.ndarray]:
    """A state of the reduced model ``source`` carried into the reduced model ``target`` (both
    :class:`~bladecase.reduction.nodes.NodalReducedModel` of the same FE model and contact).

    The free-dof displacement ``V_s x + C λ(x)`` and velocity ``V_s v + C λ'(x, v)`` (``C`` the closed shapes,
    ``λ' = G_A W_Aᵀ v`` on the closed set) are projected M-orthogonally onto ``target``'s basis:
    ``x_t = M_t⁻¹ V_tᵀ M u`` (the redistributed lumped mass, zero on the contact dofs).
    """
    s = source.system
    x, v = np.asarray(x, float), np.asarray(v, float)
    lam = s.forces(x)
    u = source.basis @ x + source.closed_shapes @ lam
    A = lam > 0
    rate = np.zeros(s.m)
    if A.any():
        idx = np.flatnonzero(A)
        rate[idx] = np.linalg.solve(s.H[np.ix_(idx, idx)], s.W[:, idx].T @ v)
    du = source.basis @ v + source.closed_shapes @ rate
    Vt = target.basis
    Mt = target.system.M
    mass = target.masses
    return np.linalg.solve(Mt, Vt.T @ (mass * u)), np.linalg.solve(Mt, Vt.T @ (mass * du))
