"""The massless contact model with several unilateral contacts: every contact node its own constraint.

A structure whose contact dofs carry no inertia (theory §8), touched at ``m`` contact nodes, each with its own
normal and clearance. The interior dofs ``x`` (``n``) obey

    M x'' + C x' + S x + W λ = 0,        λ ≥ 0,   s = g(t) − Wᵀx + H λ ≥ 0,   λᵀs = 0,

- ``S``: the open-phase stiffness (contact dofs free, statically condensed); ``Wᵀx`` the contact nodes' normal
  displacements while every contact is open;
- ``H = H_s + diag(1/k_j)``: the contact nodes' own flexibility ``H_s = W_cᵀK_cc⁻¹W_c`` (the interior held;
  symmetric positive definite when the nodes' normals are independent) plus the casing's compliance at each
  node (``k_j = inf``: rigid);
- ``λ_j``: the casing's force on node ``j``; ``s_j``: what is left of its clearance ``g_j(t)`` (node ``j`` sits at
  ``y_j − (H_sλ)_j`` and the casing has yielded by ``λ_j/k_j``);
- ``g(t) = g₀ + Re(D e^{iνt})``: the clearances, constant or seen by a blade turning inside an out-of-round
  casing (:class:`Rub`).

For ``H`` symmetric positive definite the complementarity problem has ONE solution for every ``x``, continuous
and piecewise linear in ``x``: there is no impact and no impact law. With the set ``A`` of closed contacts,
``λ_A = G_A(W_Aᵀx − g_A)``, ``G_A = H_AA⁻¹``, so each phase is LINEAR,

    M x'' + C x' + (S + W_A G_A W_Aᵀ) x = W_A G_A g_A(t),

flown in closed form (modes of the phase, or the state-space eigenvectors when damped, plus the harmonic
particular solution). A phase ends at the FIRST root of any of its ``m`` switching signals — ``λ_j`` for a
closed contact, ``s_j`` for an open one, each a linear function of the state and of ``g(t)`` — found by a
certified search over all of them at once (no switch is missed). At a switch the new set comes from the
complementarity problem at the rate level (which contacts gain force, which start to open): simultaneous
switches are taken as they come. ``x``, ``x'`` and ``λ`` are continuous at every switch: with a constant gap and
no damping, the energy ``½x'ᵀMx' + ½xᵀSx + ½λᵀHλ`` is conserved, and the saltation matrices are the identity.

With ``m = 1`` this is :class:`~bladecase.nsm.massless.model.MasslessSystem` (``k_c = 1/H``). The system and its
complementarity problem live in :mod:`~bladecase.nsm.massless.nodal_system`, the search for a phase's first
switch in :mod:`~bladecase.nsm.massless.nodal_switches`.

>>> import numpy as np
>>> s = NodalSystem(np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2), np.diag([0.5, 0.5]),
...                 gap=[1.0, 1.0])
>>> tr = simulate_nodes(s, [2.0, 0.0], [0.0, 0.0], 20.0)
>>> tr.active[0].tolist(), tr.switch_times.size > 4
([True, False], True)
>>> abs(s.energy(tr.x_end, tr.v_end) - s.energy([2.0, 0.0], [0.0, 0.0])) < 1e-12
True
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np

from . import nodes_phase
from .nodal_switches import first_switch
from .nodal_system import NODES_DENSE_LIMIT, NodalSystem, Profile, Rub, lcp
from .nodes_phase import EIGVEC_COND_LIMIT, _Phase, phase_signals  # noqa: F401  (friction builds on them)

__all__ = ["NODES_DENSE_LIMIT", "NodalFlight", "NodalSystem", "NodalTrajectory", "Profile", "Rub", "lcp",
           "simulate_nodes"]

#: Default ``max_switches`` of :func:`simulate_nodes`.
MAX_SWITCHES = 1_000_000

#: Relative size below which a switching signal counts as ON its surface at a switch.
SURFACE_RTOL = 1e-9


def casing_gap(d: np.ndarray, D: np.ndarray | None, nu: float, t) -> np.ndarray:
    """The clearances ``d + Re(D e^{iνt})`` of an out-of-round casing seen at speed (``D`` ``None``: a round one,
    ``d``) at the times ``t``: ``(m,)`` for a scalar ``t``, else ``(m, k)``."""
    if D is None:
        return d if np.ndim(t) == 0 else np.repeat(d[:, None], np.size(t), 1)
    if np.ndim(t) == 0:
        return d + (D * np.exp(1j * nu * t)).real
    return d[:, None] + np.multiply.outer(D, np.exp(1j * nu * np.atleast_1d(t))).real


def flight_terms(omega: np.ndarray, damping, rub: Rub | None, m: int):
    """``(Cq, nu, D)`` of a flight: the modal damping matrix of the open-phase modes ``omega`` (``None``: undamped),
    and the out-of-round casing's frequency and clearance amplitudes (``0, None``: round); checks one angle per
    contact node."""
    Cq = None
    if damping is not None and (damping.alpha or damping.beta or np.any(np.asarray(damping.zeta or 0) > 0)):
        Cq = np.diag(2 * damping.rates(omega))
    if rub is None:
        return Cq, 0.0, None
    if len(rub.angles) != m:
        raise ValueError(f"the rub needs one angle per contact node ({m}), got {len(rub.angles)}")
    return Cq, rub.nu, rub.D


class NodalFlight:
    """Exact flights of a :class:`NodalSystem`: its phases (cached per set of closed contacts), optional
    damping (:class:`~bladecase.nsm.damping.Damping` of the open-phase modes) and an out-of-round casing
    (:class:`Rub`), and a general clearance profile round the casing (:class:`Profile`: :meth:`set_profile`)."""

    def __init__(self, system: NodalSystem, damping=None, rub: Rub | None = None, profile: Profile | None = None):
        if not isinstance(system, NodalSystem):
            raise ValueError(f"system must be a NodalSystem, got {type(system).__name__}")
        self.system = system
        self.omega, self.phi = system.modes
        self.n = system.n
        self.Wq = self.phi.T @ system.W
        self.Cq, self.nu, self.D = flight_terms(self.omega, damping, rub, system.m)
        self._phases: OrderedDict[bytes, _Phase] = OrderedDict()  # the least recently used first
        self.profile = None
        if profile is not None:
            self.set_profile(profile, 0.0, 0.0)

    def set_profile(self, profile: Profile | None, t0: float, t1: float) -> None:
        """Fly the clearances widened by ``profile`` over ``[t0, t1]``: its steps there are cut into the flights
        (:meth:`next_break`); ``None``: no profile. The phases' modes are kept; a trajectory flown before with
        another profile must not be sampled after."""
        if profile is not None and len(profile.angles) != self.system.m:
            raise ValueError(f"the profile needs one angle per contact node ({self.system.m}), got "
                             f"{len(profile.angles)}")
        self.profile = profile
        self._shifted: dict = {}
        if profile is None:
            return
        b = profile.breaks(t0, t1)
        edges = np.r_[t0, b, max(t1, t0)]
        self.breaks = b
        self.pieces = profile.offset(0.5 * (edges[1:] + edges[:-1]))  # (m, len(b) + 1): each piece's offset

    def _piece(self, t) -> np.ndarray:
        return np.searchsorted(self.breaks, t, side="right")

    def next_break(self, t: float) -> float:
        """The first step of the profile after ``t`` (``inf``: none)."""
        if self.profile is None:
            return np.inf
        i = int(self._piece(t))
        return float(self.breaks[i]) if i < self.breaks.size else np.inf

    def phase(self, A: np.ndarray, t: float | None = None) -> _Phase:
        """The phase of the closed contacts ``A``; with a profile, as it is in the piece holding the time ``t``."""
        key = np.packbits(A).tobytes()
        ph = self._phases.get(key)
        if ph is None:
            ph = self._phases[key] = self._new_phase(A.copy())
            if len(self._phases) > nodes_phase.PHASE_CACHE:  # made again if needed: the same numbers bit for bit
                self._phases.popitem(last=False)
        else:
            self._phases.move_to_end(key)
        if self.profile is None or t is None:
            return ph
        i = int(self._piece(t))
        out = self._shifted.get((key, i))
        if out is None:
            if len(self._shifted) >= nodes_phase.PHASE_CACHE:  # made again if needed, as the phases
                self._shifted.clear()
            out = self._shifted[(key, i)] = ph.shifted(self.pieces[:, i])
        return out

    def _new_phase(self, A: np.ndarray) -> _Phase:
        return _Phase(self, A)

    def gap(self, t) -> np.ndarray:
        """The clearances at the times ``t``: ``(m,)`` or ``(m, k)``."""
        if self.profile is not None:
            return self._base_gap(t) + self.pieces[:, self._piece(t)]
        return self._base_gap(t)

    def _base_gap(self, t) -> np.ndarray:
        return casing_gap(self.system.gap, self.D, self.nu, t)

    def gap_rate(self, t: float) -> np.ndarray:
        if self.D is None:
            return np.zeros(self.system.m)
        return (1j * self.nu * self.D * np.exp(1j * self.nu * t)).real

    def encode(self, x, v) -> tuple[np.ndarray, np.ndarray]:
        M = self.system.M
        return self.phi.T @ (M @ x), self.phi.T @ (M @ v)

    def decode(self, q, p) -> tuple[np.ndarray, np.ndarray]:
        return self.phi @ q, self.phi @ p

    def active_set(self, q, p, t: float, on: np.ndarray | None = None) -> np.ndarray:
        """The closed contacts from the state: the complementarity problem, at the rate level where a contact is
        on its surface (both its force and its remaining clearance zero). ``on``: contacts known to be on their
        surfaces (a switch just found them there, each to its own signal's tolerance): decided at the rate level
        whatever their force's round-off."""
        return self.closed_set(self.system.H, q, p, t, on, lambda r, H: lcp(r, 0.5 * (H + H.T)), lcp)

    def closed_set(self, H: np.ndarray, q, p, t: float, on: np.ndarray | None, rate_solver, solver) -> np.ndarray:
        """:meth:`active_set` with the contacts' flexibility ``H`` (non-symmetric with friction) and the
        complementarity solvers of the position level (``solver``) and of the rate level (``rate_solver``)."""
        g = self.gap(t)
        y = self.Wq.T @ q
        lam = solver(g - y, H)
        slack = g - y + H @ lam
        tol_s = SURFACE_RTOL * max(float(np.abs(g).max()), float(np.abs(y).max()))
        A = lam > tol_s / float(np.abs(H).max())
        Dset = ~A & (slack <= tol_s)
        if on is not None:
            A, Dset = A & ~on, Dset | on
        if not Dset.any():
            return A
        B, Dn = np.flatnonzero(A), np.flatnonzero(Dset)
        u = self.gap_rate(t) - self.Wq.T @ p
        if B.size:
            X = np.linalg.solve(H[np.ix_(B, B)], np.column_stack([u[B], H[np.ix_(B, Dn)]]))
            qD = u[Dn] - H[np.ix_(Dn, B)] @ X[:, 0]
            HD = H[np.ix_(Dn, Dn)] - H[np.ix_(Dn, B)] @ X[:, 1:]
        else:
            qD, HD = u[Dn], H[np.ix_(Dn, Dn)]
        A[Dn] = rate_solver(qD, HD) > 0
        return A


class Sampled:
    """What a trajectory with ``sample(t)`` (interior ``x``, ``v`` first) and ``t_end`` gives alike: the interior
    state at any times and at its end."""

    def state(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Interior ``(x, v)`` at the times ``t`` (``(n, k)``), in closed form from the phase holding each."""
        x, v, *_ = self.sample(t)
        return x, v

    @property
    def x_end(self) -> np.ndarray:
        return self.state(self.t_end)[0][:, 0]

    @property
    def v_end(self) -> np.ndarray:
        return self.state(self.t_end)[1][:, 0]


@dataclass(frozen=True, eq=False)
class NodalTrajectory(Sampled):
    """Result of :func:`simulate_nodes`: the start of every phase (time, set of closed contacts, modal state)."""

    flight: NodalFlight
    starts: np.ndarray
    active: np.ndarray
    q: np.ndarray
    p: np.ndarray
    t_end: float
    complete: bool
    amplitudes: np.ndarray = field(default=None, repr=False)  # type: ignore[assignment]

    @property
    def system(self) -> NodalSystem:
        return self.flight.system

    @property
    def switch_times(self) -> np.ndarray:
        """Times of the switches (the phases' starts after the first)."""
        return self.starts[1:]

    def sample(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Interior ``(x, v)`` and the contact forces ``λ`` (``(m, k)``) at the times ``t``, in closed form from the
        phase holding each (its forces from its own linear law: no complementarity problem to solve)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        k = np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0, self.starts.size - 1)
        fl = self.flight
        Q, P = np.empty((fl.n, t.size)), np.empty((fl.n, t.size))
        lam = np.zeros((self.system.m, t.size))
        order = np.argsort(k, kind="stable")
        bounds = np.searchsorted(k[order], np.arange(self.starts.size + 1))
        for i in np.flatnonzero(np.diff(bounds)):
            sel = order[bounds[i]:bounds[i + 1]]
            ph = fl.phase(self.active[i], self.starts[i])
            a = self.amplitudes[i] if self.amplitudes is not None else ph.amplitudes(self.q[:, i], self.p[:, i],
                                                                                      self.starts[i])
            Q[:, sel], P[:, sel] = ph.advance(a, self.starts[i], t[sel] - self.starts[i])
            if ph.idx.size:
                lam[np.ix_(ph.idx, sel)] = np.maximum(ph.closed_forces(Q[:, sel], t[sel], fl.gap), 0.0)
        x, v = fl.decode(Q, P)
        return x, v, lam

    def forces(self, t) -> np.ndarray:
        """Contact forces ``(m, k)`` at the times ``t``."""
        return self.sample(t)[2]

    def contact_time(self, t0: float = 0.0, t1: float | None = None) -> np.ndarray:
        """Time each contact spends closed in ``[t0, t1]`` (s)."""
        t1 = self.t_end if t1 is None else t1
        ends = np.r_[self.starts[1:], self.t_end]
        span = np.clip(np.minimum(ends, t1) - np.maximum(self.starts, t0), 0.0, None)
        return span @ self.active


def simulate_nodes(system: NodalSystem, x0, v0, t_end: float, damping=None, rub: Rub | None = None,
                   max_switches: int = MAX_SWITCHES, flight: NodalFlight | None = None,
                   profile: Profile | None = None) -> NodalTrajectory:
    """Exact event-driven simulation of the massless model with ``m`` contacts from ``(x0, v0)`` at ``t = 0``.

    Each phase is flown in closed form; each switch is the first root of any of the phase's ``m`` switching
    signals (certified); the set of closed contacts after a switch solves the complementarity problem (module
    docstring). ``damping``: :class:`~bladecase.nsm.damping.Damping` of the open-phase modes; ``rub``: the
    clearances of an out-of-round casing seen at speed (:class:`Rub`); ``profile``: a general clearance profile
    round the casing (:class:`Profile`), whose steps cut the flights (the set of closed contacts after a step
    solves the complementarity problem; each step is a phase start of the trajectory). A run that hits
    ``max_switches`` stops with ``complete = False``.
    """
    fl = flight if flight is not None else NodalFlight(system, damping, rub)
    x, v = np.asarray(x0, float).reshape(-1), np.asarray(v0, float).reshape(-1)
    if x.size != system.n or v.size != system.n or not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
        raise ValueError(f"x0 and v0 must be finite with {system.n} interior dofs, got {x.size} and {v.size}")
    t_end = float(t_end)
    if not (np.isfinite(t_end) and t_end > 0):
        raise ValueError(f"t_end must be finite and > 0, got {t_end!r}")
    if isinstance(max_switches, bool) or int(max_switches) < 1:
        raise ValueError(f"max_switches must be an integer >= 1, got {max_switches!r}")
    if profile is not None:
        fl.set_profile(profile, 0.0, t_end)
    q, p = fl.encode(x, v)
    t = 0.0
    A = fl.active_set(q, p, t)
    on = np.zeros(system.m, dtype=bool)
    toggled = False  # the last switch changed one contact's status without the complementarity problem
    starts, actives, qs, ps, amps = [0.0], [A], [q], [p], []
    while len(starts) <= max_switches:
        ph = fl.phase(A, t)
        a = ph.amplitudes(q, p, t)
        signals = ph.signals(a, t)
        if toggled:
            toggled = False
            f0, d0 = signals.values(0.0)
            if np.any(on & (d0[0] <= 0)):  # the toggled contact does not leave its surface in the new phase (its
                # neighbours' forces, through the blade, turned it back): the rate-level complementarity decides
                A_lcp = fl.active_set(q, p, t, on)
                if not np.array_equal(A_lcp, A):
                    A = A_lcp
                    actives[-1] = A
                    continue
        amps.append(a)
        step = fl.next_break(t)
        hit = first_switch(signals, (t_end if step >= t_end else step) - t, on)
        if hit is None and step < t_end:  # the profile steps: the closed contacts from the new clearances
            q, p = ph.advance(a, t, step - t)
            t = step
            sig = fl.phase(A, t).signals_at(q, fl.gap(t))  # the same contacts, strictly, at the new clearances?
            if not np.all(sig > SURFACE_RTOL * max(float(np.abs(sig).max()), np.finfo(float).tiny)):
                A = fl.active_set(q, p, t)
            on = np.zeros(system.m, dtype=bool)
            starts.append(t)
            actives.append(A)
            qs.append(q)
            ps.append(p)
            continue
        if hit is None:
            t = t_end
            break
        tau, j = hit
        q, p = ph.advance(a, t, tau)
        t += tau
        on = np.abs(signals.values(tau)[0][0]) <= SURFACE_RTOL * np.maximum(signals.magnitude, np.finfo(float).tiny)
        on[j] = True
        if on.sum() == 1:  # one contact switches: it changes status (the next flight checks it leaves its surface)
            A = A.copy()
            A[j] = not A[j]
            toggled = True
        else:  # several on their surfaces at once: the rate-level complementarity problem decides
            A_new = fl.active_set(q, p, t, on)
            if np.array_equal(A_new, A):
                A_new = A.copy()
                A_new[j] = not A[j]
            A = A_new
        starts.append(t)
        actives.append(A)
        qs.append(q)
        ps.append(p)
    if len(amps) < len(starts):
        amps.append(fl.phase(A, starts[-1]).amplitudes(q, p, starts[-1]))
    return NodalTrajectory(fl, np.array(starts), np.array(actives), np.array(qs).T, np.array(ps).T, t,
                           bool(t >= t_end), np.array(amps))
