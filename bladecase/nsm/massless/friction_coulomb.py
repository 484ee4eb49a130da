"""Coulomb friction with stick and slip at the contact nodes (``model = "coulomb"``): :class:`CoulombFlight`,
:func:`simulate_coulomb`.

**The model.** The casing's surface under node ``j`` moves along the node's tangent at the sliding speed ``V_j``
(``ΩR_j`` for a blade turning inside its casing; ``0`` for a casing at rest). The node, massless, moves along its
tangent by ``z_j = T_jᵀx − (C_ntᵀλ)_j + (C_tt τ)_j`` (:mod:`~bladecase.nsm.massless.friction`: the same couplings
and compliances as the rotation model), so the casing slides past it at ``v_j = V_j − z'_j``. In contact
(``λ_j > 0``) the node either

- **slides**: ``τ_j = σ_j μλ_j`` with ``σ_j = sign(v_j)``, the friction along the casing's relative motion, as long
  as ``σ_j v_j >= 0``; or
- **sticks**: ``z'_j = V_j`` (it moves with the casing), with ``|τ_j| <= μλ_j``.

Each combination (open, sliding either way, sticking, per node) is a LINEAR phase, non-symmetric, flown in closed
form (:class:`~bladecase.nsm.massless.friction_coulomb_phase.CoulombPhase`: the sticking nodes' ramp ``V_j t`` is a
forcing linear in time). A phase ends at the first root of its switching signals (the certified search of the model
without friction, the ramp's linear term added):

- an open node's clearance reaches 0: it closes, sliding along the sign of ``v_j`` (sticking when ``v_j = 0``);
- a closed node's ``λ_j`` reaches 0: it opens;
- a sliding node's ``σ_j v_j`` reaches 0: it sticks, its tangential position held on the casing from there — or, if
  the stick force would leave the friction cone at once, its sliding reverses;
- a sticking node's ``μλ_j ∓ τ_j`` reaches 0 (the stick force reaches ``±μλ_j``): it slides that way.

The choice at a switch is checked: the new phase's signals must start admissible (on or above 0, those on their
surface leaving it), else the next candidate is taken (for a closing node: sliding along ``v_j``, sticking, sliding
the other way). The nodes' own tangential compliance ``C_tt`` must be positive: with it, ``x``, ``x'``, ``λ`` and ``τ``
are continuous at every switch, and a sliding node whose relative velocity reaches 0 always sticks first (the stick
force starts on the cone with the slip's rate, and moves inside it), so a reversal passes through a stick phase in
which ``τ_j`` crosses from ``+μλ_j`` to ``−μλ_j``. That stick phase's cone signal starts with zero value and zero
slope: it is let leave its surface over a first short flight (checked at sixteen points), then searched as the others.

Coupled nodes often reach their switches together: a blade tip's nodes all turn round at about the same instant.
The node that switches first changes its neighbours' force rates through the compliances, and a neighbour whose
signal sits on its surface may have to change too (above). When that, node by node, finds no admissible next state,
the nodes on the friction cone (all sliding nodes, and the sticking ones whose force is on it) are decided together
by the rate-level complementarity problem of their stick and slip, as the closed contacts of the model without
friction are. The new phase's signals are computed afresh, through
solves that lose a few digits: a signal the switch leaves on its surface (to :data:`ADMISSIBLE_RTOL`) and leaving it
may start just below it by round-off; it is put on it, so the next flight does not take that round-off for a
switch. A signal that only touches its surface and turns back (flat there and curving up, such as a stuck node's
force touching the cone once a period) keeps the phase when no next state of its node starts admissible.

With ``V_j`` large enough that ``v_j`` never reaches 0 every contact slides along ``+`` and the phases are those of
the rotation model (:class:`~bladecase.nsm.massless.friction.FrictionFlight`): the same orbit.

>>> import numpy as np
>>> from bladecase.nsm.massless.nodes import NodalSystem
>>> from bladecase.nsm.massless.friction import Friction
>>> # a normal dof pressed on its contact by a constant load; a tangential dof on its node's spring (1/C_tt = 20)
>>> s = NodalSystem(np.eye(2), np.diag([4.0, 1.0]), np.array([[1.0], [0.0]]), [[0.02]], gap=[0.1])
>>> f = Friction(0.5, T=[[0.0], [1.0]], C_tt=[[0.05]], model="coulomb")
>>> tr = simulate_coulomb(s, f, [0.148148, 0.0], [0.0, 0.0], 4.0, sliding=[0.3], load=[3.0, 0.0], codes=[3])
>>> tr.switch_times.round(4).tolist()        # stuck on the belt, slides, sticks again, ...
[0.2486, 0.3622, 1.5456, 1.7965, 2.9325, 3.3403]
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .friction import Friction, lemke
from .friction_coulomb_phase import OPEN, SLIP_NEG, SLIP_POS, STICK, CoulombPhase, RampSignals
from .nodal_switches import first_switch, leave_flat
from .nodes import MAX_SWITCHES, SURFACE_RTOL, NodalSystem, Rub, Sampled, casing_gap, flight_terms, lcp

__all__ = ["CODES", "CoulombFlight", "CoulombTrajectory", "simulate_coulomb"]

#: A node's codes in :attr:`CoulombTrajectory.codes`, by name.
CODES = {"open": OPEN, "slip+": SLIP_POS, "slip-": SLIP_NEG, "stick": STICK}

#: Relative size (to the signal's rate terms) below which a signal starting on its surface has a zero slope.
FLAT_RTOL = 1e-7

#: Relative size (to the signal's terms) within which a signal starting a phase counts as on its surface when the
#: phase is checked at a switch: the coupled compliances' solves lose a few digits there.
ADMISSIBLE_RTOL = 1e-6

#: The same for the nodes the rate-level problem decided together (:meth:`CoulombFlight._on_cone`): their margins
#: come out of solves after several nodes changed at once, a few more digits lost (1.7e-6 measured on the demo
#: blade's tip; such a margin, rising, is admissible).
DECIDED_RTOL = 1e-5

#: Points at which a second-order start is checked positive over its first flight.
LEAVE_POINTS = 16


class CoulombFlight:
    """The phases of a :class:`NodalSystem` with stick–slip :class:`~bladecase.nsm.massless.friction.Friction`
    (module docstring): damping (:class:`~bladecase.nsm.damping.Damping` of the open-phase modes), an out-of-round
    casing (:class:`Rub`), the sliding speeds ``sliding`` (m/s per node; default ``ΩR_j`` from the rub's speed and
    the friction's radii, else 0: a casing at rest) and a constant ``load`` on the interior (N, ``(n,)``)."""

    def __init__(self, system: NodalSystem, friction: Friction, damping=None, rub: Rub | None = None,
                 sliding=None, load=None):
        if not isinstance(system, NodalSystem):
            raise ValueError(f"system must be a NodalSystem, got {type(system).__name__}")
        if not isinstance(friction, Friction):
            raise ValueError(f"friction must be a Friction, got {type(friction).__name__}")
        friction.check(system)
        self.system, self.friction, self.mu = system, friction, float(friction.mu)
        self.m, self.n = system.m, system.n
        self.omega, self.phi = system.modes
        self.Wq, self.Tq = self.phi.T @ system.W, self.phi.T @ friction.T
        self.H, self.C_nt, self.C_tt = system.H, friction.C_nt, friction.C_tt
        if not np.all(np.diag(self.C_tt) > 0):
            bad = [system.nodes[k] for k in np.flatnonzero(~(np.diag(self.C_tt) > 0))]
            raise ValueError(f"the stick–slip model needs each contact node's own tangential compliance C_tt > 0 "
                             f"(m/N); it is not at nodes {bad}: a massless node held rigidly along its tangent "
                             "cannot stick without an impact law")
        self.Cq, self.nu, self.D = flight_terms(self.omega, damping, rub, self.m)
        self.R = None if self.D is None else np.r_[self.D, np.zeros(self.m)]
        if sliding is None:
            sliding = rub.speed * friction.radius if rub is not None and friction.radius is not None else 0.0
        V = np.broadcast_to(np.asarray(sliding, dtype=float), (self.m,)).copy()
        if not np.all(np.isfinite(V)):
            raise ValueError(f"the sliding speeds must be finite (m/s, one per node), got {V.tolist()}")
        self.V = V
        self.rho1 = np.r_[np.zeros(self.m), V]
        f = np.zeros(self.n) if load is None else np.asarray(load, dtype=float).reshape(-1)
        if f.shape != (self.n,) or not np.all(np.isfinite(f)):
            raise ValueError(f"load must be a finite vector of the {self.n} interior dofs, got shape {f.shape}")
        self.load, self.fq = f, self.phi.T @ f
        self._phases: dict[bytes, CoulombPhase] = {}

    def phase(self, codes: np.ndarray) -> CoulombPhase:
        """The phase of the node codes ``codes`` (cached)."""
        codes = np.asarray(codes, dtype=np.int8)
        key = codes.tobytes()
        ph = self._phases.get(key)
        if ph is None:
            ph = self._phases[key] = CoulombPhase(self, codes)
        return ph

    def gap(self, t) -> np.ndarray:
        """The clearances at the times ``t``: ``(m,)`` or ``(m, k)``."""
        return casing_gap(self.system.gap, self.D, self.nu, t)

    def rho_rate(self, t) -> np.ndarray:
        """``ρ'(t) = (g'(t), V)``: ``(2m, k)``."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        g = np.zeros((self.m, t.size)) if self.D is None else np.multiply.outer(1j * self.nu * self.D,
                                                                                 np.exp(1j * self.nu * t)).real
        return np.vstack([g, np.repeat(self.V[:, None], t.size, 1)])

    def encode(self, x, v) -> tuple[np.ndarray, np.ndarray]:
        M = self.system.M
        return self.phi.T @ (M @ x), self.phi.T @ (M @ v)

    # ------------------------------------------------------------------ switches

    def _violations(self, codes, anchors, q, p, t, decided=None) -> tuple[CoulombPhase, list[int]]:
        """The phase ``codes`` started at ``(q, p, t)`` and its signals that start inadmissible, the most negative
        first: below 0, or on their surface and not leaving it (falling, or flat and not curving up). ``decided``:
        nodes whose state the rate-level problem chose (:meth:`_on_cone`): their signals above 0 — beyond
        :data:`~bladecase.nsm.massless.nodes.SURFACE_RTOL` of their size, not by round-off — may fall (a slide at a
        small rate ends in the flight)."""
        ph = self.phase(codes)
        amp = ph.amplitudes(q, p, t, anchors)
        sig = ph.signals(self, amp, t, anchors, 0.0)
        f0, d0 = (v[0] for v in sig.values(0.0))
        scale = np.maximum(sig.magnitude, np.finfo(float).tiny)
        rate = np.abs(sig.C) @ np.abs(sig.lam) + np.abs(sig.E) * sig.nu + np.abs(sig.slope)
        on = np.abs(f0) <= ADMISSIBLE_RTOL * scale
        flat = on & (np.abs(d0) <= FLAT_RTOL * np.maximum(rate, np.finfo(float).tiny))
        if decided is not None:
            rows = decided[[node for node, _ in ph.meta]]
            on = (on | (rows & (np.abs(f0) <= DECIDED_RTOL * scale))) & ~(rows & (f0 > SURFACE_RTOL * scale))
        bad = (~on & (f0 < 0)) | (on & ~flat & (d0 < 0)) | (flat & (sig.second() <= 0))
        order = np.argsort(np.where(on, 0.0, f0 / scale), kind="stable")
        return ph, [int(k) for k in order if bad[k]]

    def _start(self, codes, anchors, q, p, t) -> bool:
        """Whether the phase ``codes`` starts admissible at ``(q, p, t)`` (:meth:`_violations`)."""
        return not self._violations(codes, anchors, q, p, t)[1]

    def _anchor(self, ph: CoulombPhase, j: int, q, t: float, anchors) -> float:
        """``z_j(t) − V_j t``: the anchor of node ``j`` sticking from ``t`` (its tangential position continuous)."""
        z = ph.Zq[j] @ q + ph.Zr[j] @ ph.rho(self, t, anchors)
        return float(z - self.V[j] * t)

    def _options(self, ph: CoulombPhase, j: int, kind: str, codes, p, t: float) -> tuple:
        """The next states of node ``j`` when its signal ``kind`` of the phase ``ph`` reaches 0, in order."""
        if kind == "gap":
            rel = self.V[j] - (ph.Zq[j] @ p + ph.Zr[j] @ self.rho_rate(t)[:, 0])
            s = SLIP_POS if rel >= 0 else SLIP_NEG
            return (s, STICK, SLIP_POS + SLIP_NEG - s)
        if kind == "force":
            return (OPEN,)
        if kind == "slip":
            return (STICK, SLIP_POS + SLIP_NEG - codes[j])  # stick, or the sliding reverses
        return (SLIP_POS if kind == "cone+" else SLIP_NEG,)

    def _switch(self, ph: CoulombPhase, k: int, codes, anchors, q, p, t):
        """The codes and anchors after the signal ``k`` of the phase ``ph`` reached 0 (module docstring). The
        massless nodes are coupled through their compliances: one node's change can make another's signal start
        inadmissible (a sliding node's relative velocity jumps with its neighbour's force rate); that node then
        changes too, as its own signal says, until the new phase starts admissible."""
        j, kind = ph.meta[k]
        order = self._options(ph, j, kind, codes, p, t)

        def put(node, c, new, anc):
            new, anc = new.copy(), anc.copy()
            new[node] = c
            if c == STICK:
                anc[node] = self._anchor(ph, node, q, t, anchors)
            return new, anc

        for c in order:
            new, anc = put(j, c, codes, anchors)
            for _ in range(2 * self.m + 2):
                cand, bad = self._violations(new, anc, q, p, t)
                if not bad:
                    return new, anc
                i, kind_i = cand.meta[bad[0]]
                if i == j:  # the switching node itself: its next option
                    break
                new, anc = put(i, self._options(cand, i, kind_i, new, p, t)[0], new, anc)
        if self._grazes(ph, k, q, p, t, anchors) and not self._violations(codes, anchors, q, p, t)[1]:
            return codes, anchors  # the signal touched its surface and turns back: the phase goes on
        if kind not in ("gap", "force"):  # the nodes on the cone decided together, at the rate level
            new, anc, decided = self._on_cone(ph, j, kind, codes, anchors, q, p, t)
            for _ in range(2 * self.m + 2):
                cand, bad = self._violations(new, anc, q, p, t, decided)
                if not bad:
                    return new, anc
                i, kind_i = cand.meta[bad[0]]
                new, anc = put(i, self._options(cand, i, kind_i, new, p, t)[0], new, anc)
        raise ValueError(f"at t = {t:.12g} s contact node {self.system.nodes[j]} ({kind} signal at 0) has no "
                         f"admissible next state (tried {[_NAMES[c] for c in order]}): a grazing or degenerate switch")

    def _on_cone(self, ph: CoulombPhase, j: int, kind: str, codes, anchors, q, p, t: float):
        """The codes and anchors of the nodes on the friction cone at a switch (every sliding node, and every
        sticking one whose force is on the cone, to :data:`ADMISSIBLE_RTOL`, with the switching node ``j``), and
        those nodes (a mask), decided together by the rate-level complementarity problem of their stick and slip:
        with them all stuck, the rates ``m`` of their margins to the cone ``μλ_i − s_iτ_i`` (``s_i`` the side they
        are on); sliding at the rates ``w >= 0`` (each anchor moving by ``−s_i w_i``) adds ``A w``; ``w >= 0``,
        ``m + A w >= 0``, complementary (:func:`~bladecase.nsm.massless.friction.lemke`). A node with ``w_i > 0``
        slides, the others stick."""
        amp = ph.amplitudes(q, p, t, anchors)
        f0 = ph.signals(self, amp, t, anchors, 0.0).values(0.0)[0][0]
        scale = _start_scale(ph.signals(self, amp, t, anchors, 0.0))
        side = np.zeros(self.m)
        side[codes == SLIP_POS], side[codes == SLIP_NEG] = 1.0, -1.0
        for i, (node, kd) in enumerate(ph.meta):
            if codes[node] == STICK and kd in ("cone+", "cone-") and abs(f0[i]) <= ADMISSIBLE_RTOL * scale[i]:
                side[node] = 1.0 if kd == "cone+" else -1.0
        side[j] = {"cone+": 1.0, "cone-": -1.0}.get(kind, side[j])
        D = np.flatnonzero(side != 0)
        stuck, anc = codes.copy(), anchors.copy()
        for i in D:
            if codes[i] != STICK:
                anc[i] = self._anchor(ph, i, q, t, anchors)
        stuck[D] = STICK
        st = self.phase(stuck)
        sig = st.signals(self, st.amplitudes(q, p, t, anc), t, anc, 0.0)
        d0 = sig.values(0.0)[1][0]
        row = {(node, kd): i for i, (node, kd) in enumerate(st.meta)}
        margin = np.array([d0[row[(i, "cone+" if side[i] > 0 else "cone-")]] for i in D])
        G = (self.mu * st.El[D] - side[D][:, None] * st.Pt[D]) @ st.Ur[:, self.m + D]  # margins per anchor
        w = lemke(margin, -G * side[D][None, :])
        new = stuck.copy()
        slide = D[w > 0]
        new[slide] = np.where(side[slide] > 0, SLIP_POS, SLIP_NEG)
        return new, anc, side != 0

    def _grazes(self, ph: CoulombPhase, k: int, q, p, t: float, anchors) -> bool:
        """Whether the signal ``k`` of the phase ``ph`` touches its surface at ``t`` and turns back: flat there
        (its slope round-off, :data:`FLAT_RTOL` of its rate terms) and curving up."""
        sig = ph.signals(self, ph.amplitudes(q, p, t, anchors), t, anchors, 0.0)
        d0 = sig.values(0.0)[1][0, k]
        rate = np.abs(sig.C[k]) @ np.abs(sig.lam) + np.abs(sig.E[k]) * sig.nu + np.abs(sig.slope[k])
        return bool(abs(d0) <= FLAT_RTOL * max(rate, np.finfo(float).tiny) and sig.second()[k] > 0)

    def initial(self, q, p, t: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """The codes and anchors of a state: the closed nodes from the normal complementarity problem, each sliding
        along its relative velocity (sticking, its tangential force 0, where that velocity is 0)."""
        lam = lcp(self.gap(t) - self.Wq.T @ q, self.H)
        rel = self.V - self.Tq.T @ p
        tol = SURFACE_RTOL * np.maximum(np.abs(self.V), np.abs(self.Tq.T @ p))
        codes = np.where(lam > 0, np.where(rel > tol, SLIP_POS, np.where(rel < -tol, SLIP_NEG, STICK)),
                         OPEN).astype(np.int8)
        return codes, self._stick_anchors(codes, q, t)

    def _stick_anchors(self, codes, q, t: float) -> np.ndarray:
        """Anchors that give the sticking nodes no tangential force at ``(q, t)``."""
        anchors = np.zeros(self.m)
        S = np.flatnonzero(codes == STICK)
        if S.size:
            ph = self.phase(codes)
            tau = ph.forces(self, q[:, None], t, anchors)[1][S, 0]
            Mt = (ph.Pt @ ph.Ur[:, self.m:])[np.ix_(S, S)]
            anchors[S] = np.linalg.solve(Mt, -tau)
        return anchors

    # ------------------------------------------------------------------ flight

    def simulate(self, x0, v0, t_end: float, codes=None, max_switches: int = MAX_SWITCHES) -> CoulombTrajectory:
        """:func:`simulate_coulomb` with this flight."""
        x, v = np.asarray(x0, float).reshape(-1), np.asarray(v0, float).reshape(-1)
        if x.size != self.n or v.size != self.n or not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
            raise ValueError(f"x0 and v0 must be finite with {self.n} interior dofs, got {x.size} and {v.size}")
        t_end = float(t_end)
        if not (np.isfinite(t_end) and t_end > 0):
            raise ValueError(f"t_end must be finite and > 0, got {t_end!r}")
        q, p = self.encode(x, v)
        t = 0.0
        if codes is None:
            codes, anchors = self.initial(q, p)
        else:
            codes = np.asarray(codes, dtype=np.int8).reshape(-1)
            if codes.shape != (self.m,) or not np.all(np.isin(codes, list(CODES.values()))):
                raise ValueError(f"codes must give each of the {self.m} nodes one of {CODES}, got {codes.tolist()}")
            anchors = self._stick_anchors(codes, q, t)
        if not self._start(codes, anchors, q, p, t):
            raise ValueError(f"the initial state is not admissible with the node codes {codes.tolist()} (a force "
                             "or a clearance negative, or a sliding against its relative velocity)")
        starts, cl, al, qs, ps, amps = [], [], [], [], [], []
        while len(starts) <= max_switches:
            ph = self.phase(codes)
            amp = ph.amplitudes(q, p, t, anchors)
            starts.append(t), cl.append(codes), al.append(anchors), qs.append(q), ps.append(p), amps.append(amp)
            horizon = t_end - t
            if horizon <= 0:
                break
            hit, cut = self._fly(ph, amp, t, anchors, horizon, q, p)
            if hit is None:
                q, p = ph.advance(amp, t, cut, anchors)
                t = t + cut if cut < horizon else t_end
                if t >= t_end:
                    break
                continue  # a flat start left its surface: the same phase flown on, a new segment
            tau, k = hit
            q, p = ph.advance(amp, t, tau, anchors)
            t += tau
            codes, anchors = self._switch(ph, k, codes, anchors, q, p, t)
        return CoulombTrajectory(self, np.array(starts), np.array(cl), np.array(al), np.array(qs).T,
                                 np.array(ps).T, np.array(amps), t, bool(t >= t_end))

    def _fly(self, ph: CoulombPhase, amp, t: float, anchors, horizon: float, q, p):
        """The first switch of a flight (``(τ, signal)``, or ``None``) and the span searched."""
        sig = ph.signals(self, amp, t, anchors, horizon)
        f0, d0 = (v[0] for v in sig.values(0.0))
        rate = np.abs(sig.C) @ np.abs(sig.lam) + np.abs(sig.E) * sig.nu + np.abs(sig.slope)
        flat_rate = np.abs(d0) <= FLAT_RTOL * np.maximum(rate, np.finfo(float).tiny)
        # a signal the switch left on its surface (to :meth:`_violations`' tolerance), below it by round-off and
        # leaving it, is put on it: its start is the switch's, not a crossing of its own
        near = (f0 < 0) & (np.abs(f0) <= ADMISSIBLE_RTOL * _start_scale(sig)) & ((d0 > 0) | flat_rate)
        if near.any():
            sig = _lifted(sig, np.where(near, -f0, 0.0))
            f0 = np.where(near, 0.0, f0)
        scale = np.maximum(sig.magnitude, np.finfo(float).tiny)
        on = (np.abs(f0) <= SURFACE_RTOL * scale) | near
        flat = on & flat_rate
        span = horizon
        if flat.any():
            band = ADMISSIBLE_RTOL * _start_scale(sig)
            for k in np.flatnonzero(flat):
                tau = leave_flat(sig.row(k), horizon, sig.step, band[k], LEAVE_POINTS)
                if tau is None:
                    raise ValueError("grazing switch: a sticking node's friction force does not leave the cone's "
                                     "surface")
                span = min(span, tau)
            keep = ~flat
            sig = RampSignals(sig.lam, sig.C * keep[:, None], sig.E * keep, sig.nu, np.where(keep, sig.const, 1.0),
                              sig.lam2, sig.slope * keep, np.where(keep, sig.base, 1.0), span)
            on = on & keep
        # a signal with no oscillating part: its ramp's root in closed form (the certified search skips it)
        still = (np.abs(sig.C).sum(axis=1) == 0) & (np.abs(sig.E) == 0) & (sig.slope < 0)
        ramp = None
        if still.any():
            roots = np.where(still, np.maximum(sig.base, 0.0) / np.where(still, -sig.slope, 1.0), np.inf)
            k = int(np.argmin(roots))
            if roots[k] <= span:
                span, ramp = float(roots[k]), (float(roots[k]), k)
        hit = first_switch(sig, span, on) if span > 0 else None
        return (hit if hit is not None else ramp), span


_NAMES = {v: k for k, v in CODES.items()}


def _start_scale(sig: RampSignals) -> np.ndarray:
    """The signals' sizes at a phase's start (the ramp's growth over the flight left out), as
    :meth:`CoulombFlight._violations` measures them."""
    return np.maximum(np.abs(sig.C).sum(axis=1) + np.abs(sig.E) + np.abs(sig.base), np.finfo(float).tiny)


def _lifted(sig: RampSignals, shift: np.ndarray) -> RampSignals:
    """``sig`` with each signal raised by ``shift`` (its constant part)."""
    return RampSignals(sig.lam, sig.C, sig.E, sig.nu, sig.const + shift, sig.lam2, sig.slope, sig.base + shift,
                       sig.horizon)


@dataclass(frozen=True, eq=False)
class CoulombTrajectory(Sampled):
    """Result of :func:`simulate_coulomb`: the start of every phase (time, node codes, sticking anchors, modal state,
    amplitudes); a flight cut where a flat start left its surface starts a new phase with the same codes."""

    flight: CoulombFlight
    starts: np.ndarray
    codes: np.ndarray
    anchors: np.ndarray
    q: np.ndarray
    p: np.ndarray
    amplitudes: np.ndarray
    t_end: float
    complete: bool

    @property
    def system(self) -> NodalSystem:
        return self.flight.system

    @property
    def active(self) -> np.ndarray:
        """The closed contacts of each phase."""
        return self.codes > OPEN

    @property
    def switch_times(self) -> np.ndarray:
        """The times where some node changes its code."""
        change = np.any(self.codes[1:] != self.codes[:-1], axis=1)
        return self.starts[1:][change]

    def _each(self, t):
        t = np.atleast_1d(np.asarray(t, dtype=float))
        k = np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0, self.starts.size - 1)
        order = np.argsort(k, kind="stable")
        bounds = np.searchsorted(k[order], np.arange(self.starts.size + 1))
        for i in np.flatnonzero(np.diff(bounds)):
            yield i, order[bounds[i]:bounds[i + 1]], t

    def sample(self, t) -> tuple[np.ndarray, ...]:
        """Interior ``(x, v)`` (``(n, k)``), the normal and tangential forces ``λ``, ``τ`` and the nodes' tangential
        displacements and velocities ``z``, ``z'`` (``(m, k)``) at the times ``t``, in closed form."""
        fl = self.flight
        t = np.atleast_1d(np.asarray(t, dtype=float))
        n, m = fl.n, fl.m
        Q, P = np.empty((n, t.size)), np.empty((n, t.size))
        lam, tau, z, zd = (np.zeros((m, t.size)) for _ in range(4))
        for i, sel, _ in self._each(t):
            ph = fl.phase(self.codes[i])
            an = self.anchors[i]
            Q[:, sel], P[:, sel] = ph.advance(self.amplitudes[i], self.starts[i], t[sel] - self.starts[i], an)
            rho = ph.rho(fl, t[sel], an)
            lam[:, sel], tau[:, sel] = ph.forces(fl, Q[:, sel], t[sel], an)
            z[:, sel] = ph.Zq @ Q[:, sel] + ph.Zr @ rho
            zd[:, sel] = ph.Zq @ P[:, sel] + ph.Zr @ fl.rho_rate(t[sel])
        return fl.phi @ Q, fl.phi @ P, lam, tau, z, zd

    def _time(self, mask: np.ndarray, t0: float, t1: float | None) -> np.ndarray:
        t1 = self.t_end if t1 is None else t1
        ends = np.r_[self.starts[1:], self.t_end]
        span = np.clip(np.minimum(ends, t1) - np.maximum(self.starts, t0), 0.0, None)
        return span @ mask

    def contact_time(self, t0: float = 0.0, t1: float | None = None) -> np.ndarray:
        """Time each node spends closed in ``[t0, t1]`` (s)."""
        return self._time(self.codes > OPEN, t0, t1)

    def stick_time(self, t0: float = 0.0, t1: float | None = None) -> np.ndarray:
        """Time each node spends sticking in ``[t0, t1]`` (s)."""
        return self._time(self.codes == STICK, t0, t1)


def simulate_coulomb(system: NodalSystem, friction: Friction, x0, v0, t_end: float, damping=None,
                     rub: Rub | None = None, sliding=None, load=None, codes=None,
                     max_switches: int = MAX_SWITCHES) -> CoulombTrajectory:
    """Exact event-driven simulation with stick–slip friction (module docstring) from ``(x0, v0)`` at ``t = 0``:
    ``sliding``, the casing's sliding speed under each node (m/s; default ``ΩR_j`` from ``rub`` and the friction's
    radii, else 0); ``load``, a constant force on the interior; ``codes``, each node's state at the start (default:
    from the state, :meth:`CoulombFlight.initial`). A run that hits ``max_switches`` phases stops with
    ``complete = False``.

    >>> s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), [[0.05]], gap=[1.0])
    >>> f = Friction(0.2, T=[[0.5]], C_tt=[[0.1]], model="coulomb")
    >>> tr = simulate_coulomb(s, f, [2.0], [0.0], 10.0, sliding=[100.0])   # fast: it slides all along
    >>> bool(tr.complete), float(tr.stick_time()[0])
    (True, 0.0)
    """
    return CoulombFlight(system, friction, damping, rub, sliding, load).simulate(x0, v0, t_end, codes, max_switches)
