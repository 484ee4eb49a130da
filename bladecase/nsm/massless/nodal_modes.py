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

**Internal resonances.** Where the family's frequency meets ``ω_j/N`` for a higher open-phase mode ``j`` (a
frequency ratio ``N:1``, or ``p:q``), the family turns into that mode: a "tongue" along which the energy grows at
an almost constant period while mode ``j`` takes the modal energy (measured by each mode's share of
``Σ ½(ω_i²q_i² + p_i²)`` at ``t = 0``). An energy step lands beyond a tongue thinner than itself, on the same
backbone; arclength follows it. Followed, a tongue does not lead back: on the demo blade (8:1 with the third mode,
215.50 Hz) and on the 3-mass chain of the tests (3:1) the arclength family keeps turning into mode ``j`` — 0.5 %
of the modal energy left in the first mode at 25 times the energy where the tongue began — it has become mode
``j``'s subharmonic family, and the first mode's backbone goes on beyond the resonance on a separate branch (the
two modes' branches avoid crossing; no fold leads from one to the other). Where such a resonance falls depends on
the mesh (the high modes move with it: 215.50 Hz, 8:1, on the demo's tip mesh; 215.90 Hz, 4:1 with the second
mode, on a finer one), so a family that stops there stops at a property of the mesh.

An orbit whose mode holds less than ``backbone_share`` (:data:`BACKBONE_SHARE`) of the modal energy is in a tongue
(:attr:`NodalFamily.tongues`, :attr:`NodalFamily.on_backbone`); below :data:`RESONANCE_SHARE` the family has
turned. Then, by default, it stops, and says where and why (:attr:`NodalFamily.end`: the mode, the ratio, the
backbone's trend below it, :func:`backbone_trend`). With ``through_resonances=True`` the tongue is CROSSED: from
the backbone's reference orbit before the tongue (the last one at least :data:`TREND_SHARE` in the mode, else the
cleanest of the stretch), orbits are solved at fixed periods beyond the tongue's frequency, ``f_tongue ±
d·2^(k/2)`` (``d`` the distance in frequency from the last orbit on the backbone to the tongue; as far as the
backbone's span from grazing or :data:`CROSS_SPAN` of the frequency), by Newton from the secant along the
backbone's last two orbits or, failing that, from the reference orbit itself; the first one on the backbone
(share ``>= backbone_share``, energy above the reference's, the same turning point, the energy growing along the
curve in the backbone's direction of frequency) resumes the family — by pseudo-arclength along the tangent there
(a stretch between two resonances can dip in energy), by the family's own steps once its energy grows. That orbit
is not connected to the tongue's by continuation (:attr:`NodalFamily.landings`; :meth:`NodalFamily.at_energy` does
not interpolate across it). A tongue with no backbone orbit beyond it — the motion stays shared between the two
modes, as at the chain's 2:1 resonance when its first mass is doubled — ends the family.

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
from fractions import Fraction

import numpy as np

from ... import log
from .nodal_orbit import FLOQUET_TOL, MAX_PHASES, NodalOrbit, _Flow, _Shooter, flow_map
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

#: A family has turned into another mode (an internal resonance: it stops there, or crosses it) when its mode holds
#: less than this share of the modal energy at t = 0.
RESONANCE_SHARE = 0.5

#: An orbit is on the backbone when its mode holds at least this share of the modal energy at t = 0; a run of orbits
#: below it is a tongue (:attr:`NodalFamily.tongues`).
BACKBONE_SHARE = 0.9

#: The backbone's trend (the crossing's predictor, :func:`backbone_trend`) is read on orbits at least this clean.
TREND_SHARE = 0.98

#: Most orbits followed inside a tongue (still above ``resonance_share``) before crossing it.
TONGUE_POINTS = 12

#: Most periods tried beyond a tongue when crossing it: ``f_tongue ± d·2^(k/2)``, ``k = 0, 1, …`` (module docstring),
#: as far as the backbone's own span from grazing or this share of the frequency, whichever is larger.
CROSS_TRIES = 16
CROSS_SPAN = 0.02


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
        fq, fp = self.sh.field(f.qT, f.pT)
        Jz = (D[:, None] * f.J) / D[None, :] - np.eye(2 * n)
        JT = D * np.r_[fq, fp] * self.T_ref / self.Y
        J = np.zeros((2 * n + 1, 2 * n + 1))
        J[:2 * n, :2 * n], J[:2 * n, -1] = Jz, JT
        J[-1, n + self.mode] = 1.0
        return f, r, J

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


def _newton(prob: _Problem, u: np.ndarray, extra, maxiter: int = NEWTON_MAXITER
            ) -> tuple[np.ndarray, _Flow, float, int]:
    """Gauss–Newton on the shooting equations plus ``extra(u) -> (value, row)``; returns ``(u, flow, closing
    residual, iterations)``.

    A step longer than a quarter of ``‖u‖`` is shortened to it (an iterate far from the orbit chatters and
    costs); Newton gives up after two growing residuals in a row. Raises ``ValueError`` (naming the period and
    the residual) if it does not reach :data:`FAMILY_RTOL`.
    """
    best = None
    history: list[float] = []
    T_last = prob.unpack(u)[2]
    reason = ""
    for it in range(maxiter + 1):
        T_last = prob.unpack(u)[2]
        try:
            f, r, J = prob.evaluate(u)
        except ValueError as exc:  # a chattering or grazing iterate
            reason = f" ({exc})"
            break
        value, row = extra(u)
        R = np.r_[r, value]
        res = max(prob.closing(r, u), abs(r[-1]), abs(value))
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
    _, f, _, _ = _newton(prob, u0, extra)
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
        ``"max_points"``, ``"step"``), ``frequency_hz`` and ``energy_j`` where it ends, ``trend`` (the backbone's
        last stretch: :func:`backbone_trend`); for an internal resonance also ``mode``, ``mode_frequency_hz``,
        ``ratio``, ``ratio_value``, ``share`` (the family's mode's share there), ``crossing`` (why it was not crossed)
        and ``mesh_dependent`` (True: where a resonance with a high mode falls moves with the mesh).
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

#: Steps of the pseudo-arclength stretch that follows a crossing (the family's own steps resume after it).
RESUME_STEPS = (0.02, 0.5, 1e-4)


def nodal_family(system: NodalSystem, mode: int = 0, *, method: str = "energy", freq_ratio: float | None = None,
                 energy_max: float | None = None, max_points: int = 200, ds: float | None = None,
                 ds_max: float | None = None, ds_min: float | None = None,
                 resonance_share: float = RESONANCE_SHARE, max_phases: int = MAX_PHASES,
                 through_resonances: bool = False, backbone_share: float = BACKBONE_SHARE) -> NodalFamily:
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
    run = _Run(_Shooter(system, max_phases), mode, method, steps,
               {"freq_ratio": freq_ratio, "energy_max": energy_max, "resonance": resonance_share,
                "backbone": backbone_share, "through": bool(through_resonances)})
    run.follow(max_points)
    if len(run.orbits) < 2:
        raise ValueError(f"no orbit beyond grazing on the family of mode {mode} (T = {run.orbits[0].T:.12g} s): "
                         f"{run.stop}")
    return NodalFamily(system, mode, run.orbits, run.stop, run.tongues(), run.end, backbone_share)


class _Run:
    """One family being followed (:func:`nodal_family`): the orbits, the stepper's state, the tongues crossed."""

    def __init__(self, sh: _Shooter, mode: int, method: str, steps: tuple, opts: dict):
        g = _grazing(sh, mode)
        self.sh, self.mode, self.method, self.steps, self.opts = sh, mode, method, steps, opts
        self.prob = _Problem(sh, mode, np.sqrt(2 * g.energy), g.T)
        self.state = {"u": [self.prob.pack(g.q0, g.p0, g.T)], "E": [g.energy], "tan": None}
        self.orbits, self.shares = [g], [1.0]
        self.stepping, self.h = method, float(steps[0])
        self.segment = 0            # the first orbit of the current stretch: grazing or the last landing
        self.crossed: dict[int, float] = {}  # landing index -> the tongue's frequency the crossing started from
        self.stop, self.end, self.failure = "", None, ""

    # -- the loop ----------------------------------------------------------------------------------------------

    def _limits(self) -> tuple:
        return self.steps if self.stepping == self.method else RESUME_STEPS

    def follow(self, max_points: int) -> None:
        step = {"energy": _energy_step, "arclength": _arclength_step}
        while len(self.orbits) < max_points:
            try:
                f, its = step[self.stepping](self.prob, self.state, self.h)
            except ValueError as exc:
                if self.h / 2 >= self._limits()[2]:
                    self.h /= 2
                    continue
                if self.shares[-1] < self.opts["backbone"] and self.opts["resonance"] > 0:
                    why = f"the step fell below ds_min = {self._limits()[2]:g} inside it ({exc})"
                    if self.opts["through"] and self._cross():
                        if self._checked(self.orbits[-1]):
                            return
                        continue
                    self._resonance_end(why)
                else:
                    self._finish("step", f"step below ds_min = {self._limits()[2]:g} after {len(self.orbits)} "
                                         f"orbits: {exc}")
                return
            self._add(NodalOrbit._of(self.sh, f, self.mode))
            self.h = min(self.h * (1.5 if its <= 3 else 1.0 if its <= 5 else 0.5), self._limits()[1])
            if self._checked(self.orbits[-1]):
                return
        self._finish("max_points", f"max_points = {max_points} reached")

    def _add(self, orbit: NodalOrbit) -> None:
        self.orbits.append(orbit)
        self.shares.append(float(orbit.modal_energy_share[self.mode]))

    def _checked(self, orbit: NodalOrbit) -> bool:
        """The stop tests on the newest orbit (a crossing happens here); True when the family ends."""
        o = self.opts
        ratio = orbit.frequency / self.orbits[0].frequency
        on = self.shares[-1] >= o["backbone"]
        if o["freq_ratio"] is not None and (ratio >= o["freq_ratio"] or ratio <= 1 / o["freq_ratio"]):
            self._finish("frequency_ratio", f"frequency ratio {ratio:.6g} reached (freq_ratio = {o['freq_ratio']:g})")
            return True
        over = o["energy_max"] is not None and orbit.energy >= o["energy_max"]
        if over and (on or not o["through"] or o["resonance"] == 0):
            self._finish("energy_max", f"energy {orbit.energy:.6g} J reached (energy_max = {o['energy_max']:g})")
            return True
        E = self.state["E"]
        if self.stepping != self.method and on and len(E) >= 2 and np.log(E[-1] / E[-2]) >= self.steps[0] / 4:
            self.stepping, self.h = self.method, float(self.steps[0])  # the energy grows again: the family's steps
        if o["resonance"] == 0 or on:
            return False
        run = len(self.orbits) - self._last_on() - 1
        deep = self.shares[-1] < o["resonance"]
        if not deep and not (o["through"] and (over or run >= TONGUE_POINTS)):
            return False
        why = "" if deep else f"its energy {orbit.energy:.4g} J is past energy_max" if over else f"{run} orbits in it"
        if o["through"] and self._cross():
            return self._checked(self.orbits[-1])
        self._resonance_end(why)
        return True

    def _last_on(self) -> int:
        """Index of the last orbit on the backbone (the stretch's first orbit always is)."""
        return max(i for i in range(self.segment, len(self.orbits)) if self.shares[i] >= self.opts["backbone"])

    # -- crossing a tongue -------------------------------------------------------------------------------------

    def _cross(self) -> bool:
        """Find the backbone beyond the tongue the family is in (module docstring); on success the orbit found is
        appended and the family resumes from it; else :attr:`failure` says why not."""
        orbits, prob = self.orbits, self.prob
        b = self._last_on()
        r = _reference(self.shares, self.segment, b)
        ref = orbits[r]
        d = (ref.frequency - orbits[0].frequency) or (orbits[-1].frequency - orbits[0].frequency)
        s = 1.0 if d >= 0 else -1.0   # the backbone's direction in frequency
        f_tongue = s * max(s * o.frequency for o in orbits[b:])
        d0 = max(s * (f_tongue - orbits[b].frequency), 1e-4 * f_tongue)
        span = max(abs(f_tongue - orbits[0].frequency), CROSS_SPAN * f_tongue, d0)
        pair = [i for i in range(self.segment, r + 1) if self.shares[i] >= self.opts["backbone"]][-2:]
        ua, ub = (prob.pack(orbits[i].q0, orbits[i].p0, orbits[i].T) for i in (pair[0], r))
        fa = orbits[pair[0]].frequency
        tried = 0
        for k in range(CROSS_TRIES):
            jump = d0 * 2 ** (k / 2)
            if jump > span:
                break
            f_t = f_tongue + s * jump
            tried += 1
            secant = ua + (ub - ua) * ((f_t - fa) / (ref.frequency - fa) if ref.frequency != fa else 1.0)
            landed = self._land((secant, ub), f_t, s, ref)
            if landed is None:
                continue
            orbit, u, tan = landed
            self._add(orbit)
            i = len(orbits) - 1
            self.crossed[i] = f_tongue
            self.segment, self.stepping = i, "arclength"
            self.h = float(self.steps[0] if self.method == "arclength" else RESUME_STEPS[0])
            self.state = {"u": [u], "E": [orbit.energy], "tan": tan}
            log.info("nodal family of mode %d: internal resonance near %.6g Hz crossed to the backbone at %.6g Hz "
                     "(%.4g J)", self.mode, f_tongue, orbit.frequency, orbit.energy)
            return True
        hi = f_tongue + s * d0 * 2 ** ((tried - 1) / 2) if tried else f_tongue
        self.failure = (f"no orbit on the backbone (the mode holding >= {self.opts['backbone']:.0%} of the modal "
                        f"energy, the energy growing along it) at {tried} periods beyond it, "
                        f"{min(f_tongue + s * d0, hi):.6g} to {max(f_tongue + s * d0, hi):.6g} Hz")
        return False

    def _land(self, guesses: tuple, f_t: float, s: float, last: NodalOrbit):
        """The orbit at frequency ``f_t`` by Newton from the first of ``guesses`` that converges (the secant along the
        backbone's last stretch, then the state of ``last``, its reference orbit before the tongue) if it is on the
        backbone beyond the tongue: ``(orbit, u, tangent)``, else None."""
        prob, mode = self.prob, self.mode
        T_t = 1.0 / f_t
        row = np.zeros(guesses[0].size)
        row[-1] = 1.0
        for up in guesses:
            up = up.copy()
            up[-1] = T_t / prob.T_ref
            try:
                u, f, _, _ = _newton(prob, up, lambda v: (v[-1] - T_t / prob.T_ref, row))
                break
            except ValueError:
                continue
        else:
            return None
        orbit = NodalOrbit._of(self.sh, f, mode)
        if (orbit.modal_energy_share[mode] < self.opts["backbone"] or orbit.energy <= last.energy
                or np.sign(orbit.q0[mode]) != np.sign(last.q0[mode])):
            return None
        tan = prob.tangent(_jacobian(prob, f, u), np.r_[np.zeros(u.size - 1), -s])
        if abs(tan[-1]) < 1e-9 or prob.energy_row(u)[1] @ tan <= 0:
            return None
        return orbit, u, tan

    # -- the end -----------------------------------------------------------------------------------------------

    def _finish(self, kind: str, stop: str) -> None:
        last = self.orbits[-1]
        self.stop = stop
        self.end = {"kind": kind, "frequency_hz": float(last.frequency), "energy_j": float(last.energy),
                    "trend": backbone_trend(self.orbits, self.shares, self.segment, backbone=self.opts["backbone"])}

    def _resonance_end(self, why: str) -> None:
        b = self._last_on()
        k = b + 1 + int(np.argmin(self.shares[b + 1:]))
        res = _resonance(self.sh, self.orbits[k], self.mode)
        trend = backbone_trend(self.orbits, self.shares, self.segment, upto=b)
        f_end = float(max(o.frequency for o in self.orbits[b:])) if trend is None or trend["df_dlnE_hz"] >= 0 \
            else float(min(o.frequency for o in self.orbits[b:]))
        crossing = ("not crossed (through_resonances=False)" if not self.opts["through"]
                    else f"not crossed: {self.failure}")
        share = self.shares[k]
        self.stop = (f"internal resonance at T = {self.orbits[k].T:.9g} s ({self.orbits[k].frequency:.6g} Hz): "
                     f"open-phase mode {res['mode']} ({res['mode_frequency_hz']:.6g} Hz, {res['ratio_value']:.4f} × "
                     f"the orbit's frequency, {res['ratio']}) holds {res['share']:.0%} of the modal energy, mode "
                     f"{self.mode} {share:.0%}" + (f" ({why})" if why else "") + f"; {crossing}. Where a "
                     "resonance with a high mode falls depends on the mesh, so this end is the mesh's, not the "
                     "blade's" + (f": {_trend_words(trend)}" if trend else ""))
        self.end = {"kind": "internal_resonance", "frequency_hz": f_end, "energy_j": float(self.orbits[-1].energy),
                    **{key: res[key] for key in ("mode", "mode_frequency_hz", "ratio", "ratio_value")},
                    "share": share, "other_share": res["share"], "crossing": crossing, "mesh_dependent": True,
                    "trend": trend}
        log.info("nodal family of mode %d: %s", self.mode, self.stop)

    def tongues(self) -> tuple:
        """The tongues met (:attr:`NodalFamily.tongues`)."""
        out, i, n = [], 1, len(self.orbits)
        while i < n:
            if self.shares[i] >= self.opts["backbone"]:
                i += 1
                continue
            j = i
            while j + 1 < n and self.shares[j + 1] < self.opts["backbone"]:
                j += 1
            k = i + int(np.argmin(self.shares[i:j + 1]))
            rec = {"start": i, "stop": j, **_resonance(self.sh, self.orbits[k], self.mode),
                   "frequency_hz": float(self.orbits[k].frequency), "least_share": float(self.shares[k]),
                   "energy_range_j": [float(min(o.energy for o in self.orbits[i:j + 1])),
                                      float(max(o.energy for o in self.orbits[i:j + 1]))]}
            rec.pop("share")
            if j + 1 in self.crossed:
                land = self.orbits[j + 1]
                rec.update(left="crossed", landing=j + 1, from_frequency_hz=float(self.crossed[j + 1]),
                           to_frequency_hz=float(land.frequency), to_energy_j=float(land.energy))
            elif j + 1 < n:
                rec["left"] = "continued"
            else:
                rec["left"] = "end" if self.end and self.end["kind"] == "internal_resonance" else "open"
            out.append(rec)
            i = j + 1
        return tuple(out)


def _resonance(sh: _Shooter, orbit: NodalOrbit, mode: int) -> dict:
    """The open-phase mode that takes the most modal energy from ``mode`` on ``orbit``, its frequency and the ratio
    of that frequency to the orbit's (``"p:q"``, :func:`resonance_ratio`)."""
    share = orbit.modal_energy_share
    j = int(np.argmax(np.where(np.arange(share.size) == mode, -1.0, share)))
    value = float(sh.omega[j] * orbit.T / (2 * np.pi))
    p, q = resonance_ratio(value)
    return {"mode": j, "mode_frequency_hz": float(sh.omega[j] / (2 * np.pi)), "ratio": f"{p}:{q}",
            "ratio_value": value, "share": float(share[j])}


def resonance_ratio(value: float, q_max: int = 4, rtol: float = 0.02) -> tuple[int, int]:
    """The ratio ``p:q`` of a resonance with frequency ratio ``value`` (a high mode's frequency over the orbit's):
    the smallest ``q <= q_max`` with ``|value − p/q| <= rtol·value`` (the mode's frequency moves with the contact,
    so the measured ratio is not exact), else the nearest fraction with ``q <= q_max``.

    >>> resonance_ratio(7.9924), resonance_ratio(2.9741), resonance_ratio(7.49)
    ((8, 1), (3, 1), (15, 2))
    """
    for q in range(1, q_max + 1):
        p = int(round(value * q))
        if p >= 1 and abs(value - p / q) <= rtol * value:
            return p, q
    best = Fraction(value).limit_denominator(q_max)
    return max(best.numerator, 1), best.denominator


def _reference(shares, lo: int, hi: int) -> int:
    """The backbone's reference orbit before a tongue, in ``[lo, hi]``: the last at least :data:`TREND_SHARE` clean,
    else the one of highest share (the orbits after it already bend into the tongue)."""
    clean = [i for i in range(lo, hi + 1) if shares[i] >= TREND_SHARE]
    return clean[-1] if clean else lo + int(np.argmax(shares[lo:hi + 1]))


def _trend_indices(shares, lo: int, hi: int, backbone: float | None = None) -> list[int]:
    """The orbits that show the backbone's trend up to ``hi``: those of ``[lo, hi]`` at least :data:`TREND_SHARE`
    clean; with ``backbone`` (the last stretch wanted), else those of ``[lo, hi]`` on the backbone; else the clean
    ones of ``[0, hi]`` (before a tongue: the stretch between two resonances bends into both); else those of
    ``[lo, hi]`` up to the reference (:func:`_reference`)."""
    sets = [[i for i in range(lo, hi + 1) if shares[i] >= TREND_SHARE]]
    if backbone is not None:
        sets.append([i for i in range(lo, hi + 1) if shares[i] >= backbone])
    sets.append([i for i in range(hi + 1) if shares[i] >= TREND_SHARE])
    return next((idx for idx in sets if len(idx) >= 2), list(range(lo, _reference(shares, lo, hi) + 1)))


def backbone_trend(orbits, shares, lo: int = 0, upto: int | None = None, count: int = 3,
                   backbone: float | None = None) -> dict | None:
    """The frequency–energy relation of the backbone's last stretch, ``f ≈ f₀ + b·ln(E/E₀)`` fitted (least
    squares) on the last ``count`` orbits up to ``orbits[upto]`` at least :data:`TREND_SHARE` clean (``shares``: the
    family's mode's share of the modal energy) from ``orbits[lo]`` (the current stretch); if it has fewer than
    two, with ``backbone``, its orbits on the backbone (``shares >= backbone``: the family's end), else the clean
    orbits of the whole family (before a tongue); ``(f₀, E₀)`` the last of them: what a reader extrapolates along.

    Returns ``frequency_hz`` (``f₀``), ``energy_j`` (``E₀``), ``df_dlnE_hz`` (``b``), ``hz_per_doubling``
    (``b ln 2``), ``dE_df_j_per_hz`` (``E₀/b`` at ``E₀``), ``frequency_range_hz`` and ``energy_range_j`` of the
    fitted orbits and their number ``orbits``; None with fewer than two.
    """
    upto = len(orbits) - 1 if upto is None else upto
    idx = _trend_indices(shares, lo, upto, backbone)[-count:]
    if len(idx) < 2:
        return None
    f = np.array([orbits[i].frequency for i in idx])
    lnE = np.log([orbits[i].energy for i in idx])
    if np.ptp(lnE) <= 0:
        return None
    b = float(np.polyfit(lnE - lnE[-1], f, 1)[0])
    E0 = float(np.exp(lnE[-1]))
    return {"frequency_hz": float(f[-1]), "energy_j": E0, "df_dlnE_hz": b, "hz_per_doubling": float(b * np.log(2)),
            "dE_df_j_per_hz": E0 / b if b != 0 else float("inf"), "frequency_range_hz": [float(f[0]), float(f[-1])],
            "energy_range_j": [float(np.exp(lnE[0])), E0], "orbits": len(idx)}


def _trend_words(trend: dict) -> str:
    return (f"below it the backbone rises {trend['hz_per_doubling']:.3g} Hz per doubling of the energy "
            f"(f ≈ {trend['frequency_hz']:.6g} Hz + {trend['df_dlnE_hz']:.4g} Hz × ln(E / {trend['energy_j']:.4g} J), "
            f"fitted on {trend['orbits']} orbits from {trend['frequency_range_hz'][0]:.6g} Hz): extrapolate along it")


def _energy_step(prob: _Problem, state: dict, h: float) -> tuple[_Flow, int]:
    """One natural-parameter step ``ln E → ln E + h`` from the secant predictor."""
    us, Es = state["u"], state["E"]
    E = Es[-1] * np.exp(h)
    if len(us) == 1:
        up = us[0].copy()
        up[:-1] *= np.sqrt(E / Es[0])
    else:
        up = us[-1] + (us[-1] - us[-2]) * (h / np.log(Es[-1] / Es[-2]))

    def extra(u):
        value, row = prob.energy_row(u)
        return (value - E) / E, row / E
    u, f, _, its = _newton(prob, up, extra)
    us.append(u)
    Es.append(prob.sh.energy(*prob.unpack(u)[:2]))
    return f, its


def _arclength_step(prob: _Problem, state: dict, h: float) -> tuple[_Flow, int]:
    """One pseudo-arclength step of length ``h`` along the tangent (the amplitude's direction at grazing)."""
    u0 = state["u"][-1]
    tan = state["tan"]
    if tan is None:
        tan = np.r_[u0[:-1] / np.linalg.norm(u0[:-1]), 0.0]  # the amplitude grows; dT/ds = 0 at grazing
    up = u0 + h * tan

    def extra(v):
        return float(tan @ (v - up)), tan
    u, f, _, its = _newton(prob, up, extra)
    if (u - u0) @ tan <= 0:
        raise ValueError(f"the continuation turned back at T = {f.T:.12g} s")
    state["tan"] = prob.tangent(_jacobian(prob, f, u), tan)
    state["u"].append(u)
    state["E"].append(prob.sh.energy(*prob.unpack(u)[:2]))
    return f, its


def _jacobian(prob: _Problem, f: _Flow, u: np.ndarray) -> np.ndarray:
    """The shooting Jacobian at the converged ``u`` (flow ``f`` already computed there)."""
    n, D = prob.n, prob.D
    fq, fp = prob.sh.field(f.qT, f.pT)
    J = np.zeros((2 * n + 1, 2 * n + 1))
    J[:2 * n, :2 * n] = (D[:, None] * f.J) / D[None, :] - np.eye(2 * n)
    J[:2 * n, -1] = D * np.r_[fq, fp] * prob.T_ref / prob.Y
    J[-1, n + prob.mode] = 1.0
    return J


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
