"""The abradable coating yielding during the flight: each contact node's normal contact a Jenkins element,
:class:`CoatingFlight`, :func:`simulate_coating`.

**The law.** Node ``j`` of a :class:`~bladecase.nsm.massless.nodes.NodalSystem` meets the coating's surface
``w_j`` further out than its clearance ``g_j(t)`` says; the coating is a spring ``k_j`` (the system's ``casing``:
the coating's stiffness per area × the node's area) in series with a one-way plastic slider of force
``λ_y,j`` (the yield pressure × the node's area). With ``y_j = (Wᵀx)_j − (H_sλ)_j`` the node's normal
displacement, each node is

- **open**: ``λ_j = 0``, its clearance ``s_j = g_j + w_j − y_j ≥ 0``;
- **elastic**: ``λ_j = k_j(y_j − g_j − w_j)``, ``0 ≤ λ_j ≤ λ_y,j``, its surface ``w_j`` held;
- **plastic**: ``λ_j = λ_y,j`` (a constant load: the node is free of its constraint) and its surface recedes with
  it, ``w_j(t) = y_j − g_j − λ_y,j/k_j``: the coating is removed at the rate ``w_j' = y_j' − g_j' ≥ 0``.

Each combination is a LINEAR phase: the elastic nodes' forces solve ``H_AA λ_A = W_Aᵀx − g_A − w_A −
H_AP λ_y,P``, so ``M x'' + C x' + (S + W_A G_A W_Aᵀ) x = W_A G_A(g_A + w_A + H_AP λ_y,P) − W_P λ_y,P``, flown in
closed form as the phases without yield (:class:`~bladecase.nsm.massless.nodes_phase._Phase`). A phase ends at
the first root of its switching signals (the same certified search): an open node's clearance (it closes,
elastic); an elastic node's ``λ_j`` (it opens) and ``λ_y,j − λ_j`` (it yields, plastic); a plastic node's removal
rate ``w_j'`` (it stops pushing in: elastic again, its surface held where it stopped). The choice at a switch is
checked: the new phase's signals must start admissible (each on or above 0, those on their surface leaving it),
else the node whose signal fails changes too, as that signal says. A node that stops yielding starts elastic with
its force at ``λ_y,j`` and a zero rate (its removal rate reached 0): that signal is let leave its surface over a
first short flight, checked at sixteen points, as the stick–slip model's (``friction_coulomb``).

**Energy.** ``x``, ``x'`` and ``λ`` are continuous at every switch; with a constant clearance and no damping the
energy ``½x'ᵀMx' + ½xᵀSx + ½λᵀHλ`` plus the work of the plastic flow ``Σ_j λ_y,j (w_j − w_j(0))`` is conserved.

**Friction** (:class:`~bladecase.nsm.massless.friction.Friction`, the rotation model): each node in contact is
dragged by ``μλ_j`` along the casing's motion, so the interior is driven by ``W − μT`` and the forces see
``H_μ = H − μC_nt`` (a plastic node: ``μλ_y,j``, constant too). The phases are then not symmetric: flown from their
first-order eigenvectors, a growing one refused; the box problem of a decision is solved by Lemke's method.

**A worn casing** (:class:`~bladecase.nsm.massless.nodes.Profile`): the surface of an open or elastic node is the
profile's depth at its angle, stepping at the cells' edges; a plastic node keeps its own receding surface while it
is deeper than the cell's. At a step the nodes are decided again: the forces solve the box-constrained problem
``0 ≤ λ ≤ λ_y`` (a node pressed beyond its yield then has its excess removed at once, as
:func:`~bladecase.nsm.massless.wear.pass_tip` removes a sample's).

>>> from bladecase.nsm.massless.nodes import NodalSystem
>>> s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), [[0.0]], gap=[1.0], casing=[100.0])
>>> tr = simulate_coating(s, [10.0], [0.0], [10.0], 3.0)      # from 0 at speed 10 into a coating of yield 10
>>> tr.codes[:, 0].tolist()                                   # open, elastic, plastic, elastic, open
[0, 1, 2, 1, 0]
>>> lam = tr.sample(np.linspace(0.0, 3.0, 3001))[2]
>>> float(lam.max()) <= 10.0 * (1 + 1e-12), round(float(tr.removed()[0]), 9)   # x_max − 1 − 10/100
(True, 3.766068747)
>>> round(float(np.sqrt(221.0) - 10.0 - 1.1), 9)      # x_max from the energy: ½x² + ½·100·0.1² + 10(x − 1.1) = 50
3.766068747
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from scipy.optimize import lsq_linear

from .friction import first_order_modes, lemke
from .nodal_switches import _Signals, first_switch, leave_flat
from .nodes import MAX_SWITCHES, NodalSystem, Profile, Rub, Sampled, casing_gap, flight_terms
from .nodes_phase import _Phase

__all__ = ["CODES", "CoatingFlight", "CoatingTrajectory", "simulate_coating"]

#: A node's codes.
OPEN, ELASTIC, PLASTIC = 0, 1, 2
CODES = {"open": OPEN, "elastic": ELASTIC, "plastic": PLASTIC}

#: Relative size (to a signal's terms) within which a signal starting a phase counts as on its surface.
ADMISSIBLE_RTOL = 1e-7

#: Relative size (to the signal's rate terms) below which a signal on its surface has a zero slope.
FLAT_RTOL = 1e-7

#: Relative size (of a cell's angle) within which a node counts as on a cell's edge.
EDGE_RTOL = 1e-9


#: Points at which a flat start is checked positive over its first flight.
LEAVE_POINTS = 16

#: Whether a flight starts from the phase, amplitudes and signals its decision just computed (the same numbers;
#: ``False`` makes them again, as the identity test does).
REUSE = True


class CoatingPhase(_Phase):
    """The phase of the node codes ``codes`` (module docstring) in the open-phase modal coordinates; its surfaces
    ``w`` enter its constants only (:meth:`at_surface`)."""

    def __init__(self, fl: CoatingFlight, codes: np.ndarray):
        m, n = fl.system.m, fl.n
        self.codes = codes
        self._fl = fl
        ia, ip = np.flatnonzero(codes == ELASTIC), np.flatnonzero(codes == PLASTIC)
        self.A, self.idx = codes == ELASTIC, ia
        H, Hs, Wq, Wf = fl.Hc, fl.Hy, fl.Wq, fl.Wf
        sym = fl.friction is None
        Lq_lam, Lg_lam, lam_c = np.zeros((m, n)), np.zeros((m, m)), np.zeros(m)
        lam_c[ip] = fl.yield_force[ip]
        if ia.size:
            try:
                if sym:
                    chol = sla.cho_factor(H[np.ix_(ia, ia)], lower=True, check_finite=False)
                    G = sla.cho_solve(chol, np.eye(ia.size), check_finite=False)
                    G = 0.5 * (G + G.T)
                else:
                    G = np.linalg.inv(H[np.ix_(ia, ia)])
            except np.linalg.LinAlgError:
                raise ValueError("the elastic contacts' flexibility is not positive definite") from None
            Lq_lam[ia] = G @ Wq[:, ia].T
            Lg_lam[np.ix_(ia, ia)] = -G
            lam_c[ia] = -G @ (H[np.ix_(ia, ip)] @ fl.yield_force[ip])
            self.G = G
        # λ = Λq q + Λg (g(t) + w) + λc; the interior: q'' + C q' + Ω² q = −W_f λ (W_f = W − μT with friction)
        self.Lq_lam, self.Lg_lam, self.lam_c = Lq_lam, Lg_lam, lam_c
        K = np.diag(fl.omega**2) + Wf @ Lq_lam
        if sym:
            K = 0.5 * (K + K.T)
            Kf = sla.cho_factor(K, check_finite=False)
            self.eq_w = sla.cho_solve(Kf, -Wf @ Lg_lam, check_finite=False)  # q_eq per unit of g + w
            self.eq_c = sla.cho_solve(Kf, -Wf @ lam_c, check_finite=False)
        else:
            self.eq_w, self.eq_c = np.linalg.solve(K, -Wf @ Lg_lam), np.linalg.solve(K, -Wf @ lam_c)
        self.K = K
        self.nu = fl.nu
        self.X = np.zeros(n, complex)
        Dv = fl.D if fl.D is not None else np.zeros(m, complex)
        if fl.nu > 0 and fl.D is not None and ia.size:
            Z = K - fl.nu**2 * np.eye(n) + (1j * fl.nu * fl.Cq if fl.Cq is not None else 0)
            try:
                self.X = np.linalg.solve(Z, -Wf @ (Lg_lam @ fl.D))
            except np.linalg.LinAlgError:
                raise ValueError(f"the casing's excitation at {fl.nu / 2 / np.pi:.6g} Hz is at an undamped resonance "
                                 "of a contact phase: add damping or change the speed") from None
        if sym:
            self._modes(K, fl.Cq, n)
        else:
            self._grows(K, fl, codes)
            self._modes(K, fl.Cq if fl.Cq is not None else np.zeros((n, n)), n)
        # the switching signals Lq q + Lp q' + Lg (g + w) + Ld g' + c, one or two a node: (node, kind)
        rows, meta = [], []
        zn, zm, eye = np.zeros(n), np.zeros(m), np.eye(m)
        for j in range(m):
            e = eye[j]
            if codes[j] == OPEN:
                rows.append((-Wq[:, j] + H[j] @ Lq_lam, zn, e + H[j] @ Lg_lam, zm, H[j] @ lam_c))
                meta.append((j, "gap"))
            elif codes[j] == ELASTIC:
                rows.append((Lq_lam[j], zn, Lg_lam[j], zm, lam_c[j]))
                meta.append((j, "force"))
                rows.append((-Lq_lam[j], zn, -Lg_lam[j], zm, fl.yield_force[j] - lam_c[j]))
                meta.append((j, "yield"))
            else:
                rows.append((zn, Wq[:, j] - Hs[j] @ Lq_lam, zm, -e - Hs[j] @ Lg_lam, 0.0))
                meta.append((j, "flow"))
        self.Sq, self.Sp, self.Sg, self.Sd = (np.array([r[k] for r in rows]) for k in range(4))
        self.Sc = np.array([r[4] for r in rows])
        self.meta = meta
        self.LVx = self.Sq @ self.Vx + self.Sp @ self.Vv
        nu = self.nu
        self.E0 = (self.Sq @ self.X + 1j * nu * (self.Sp @ self.X) + self.Sg @ Dv + 1j * nu * (self.Sd @ Dv)
                   if nu > 0 else np.zeros(len(rows), complex))
        self.lam2 = np.abs(self.lam) ** 2
        self.w = None

    @staticmethod
    def _grows(K: np.ndarray, fl: CoatingFlight, codes: np.ndarray) -> None:
        """Refuse a phase with friction that grows (its stiffness not symmetric): the search needs decaying terms."""
        n = K.shape[0]
        C = fl.Cq if fl.Cq is not None else np.zeros((n, n))
        nodes = fl.system.nodes
        first_order_modes(K, C, lambda: f"a contact phase with friction (nodes "
                          f"{[nodes[k] for k in np.flatnonzero(codes == 1)]} elastic, "
                          f"{[nodes[k] for k in np.flatnonzero(codes == 2)]} yielding, mu = {fl.friction.mu:g})",
                          vectors=False)

    def at_surface(self, w: np.ndarray) -> CoatingPhase:
        """The phase with the nodes' surfaces ``w`` (m): its equilibrium and its signals' constants."""
        out = object.__new__(CoatingPhase)  # a shallow copy (copy.copy's, without its dispatch)
        out.__dict__.update(self.__dict__)
        fl = self._fl
        u = fl.system.gap + w
        out.w = w
        out.q_eq = self.eq_w @ u + self.eq_c
        out.const = self.Sq @ out.q_eq + self.Sg @ u + self.Sc
        return out

    def forces(self, Q: np.ndarray, t: np.ndarray) -> np.ndarray:
        """``λ`` ``(m, k)`` at the modal displacements ``Q`` ``(n, k)`` and the times ``t``."""
        g = self._fl.gap(t) + self.w[:, None]
        return self.Lq_lam @ Q + self.Lg_lam @ g + self.lam_c[:, None]


def _runs(depth: np.ndarray) -> np.ndarray:
    """For each cell ``c`` of a profile's ``depth`` (``n`` cells round the casing), how many cells further on
    (wrapping round) the first of another depth lies: ``1`` to ``n − 1``, or ``n`` when every cell has its depth.

    >>> _runs(np.array([0.0, 0.0, 1.0, 0.0])).tolist()
    [2, 1, 1, 3]
    """
    n = depth.size
    dd = np.r_[depth, depth]
    change = np.flatnonzero(dd[1:] != dd[:-1]) + 1  # the cells (unwrapped) of another depth than the one before
    if not change.size:
        return np.full(n, n, dtype=np.int64)
    first = change[np.searchsorted(change, np.arange(n), side="right")]  # the first change after each cell
    return (first - np.arange(n)).astype(np.int64)


def _start(ph, a, t: float):
    """The signals of the phase ``ph`` started with the amplitudes ``a`` at ``t``: ``(signals, values, rates,
    scales, on their surface, flat there)``."""
    sig = ph.signals(a, t)
    f0, d0 = (v[0] for v in sig.values(0.0))
    scale = np.maximum(sig.magnitude, np.finfo(float).tiny)
    rate = np.abs(sig.C) @ np.abs(sig.lam) + np.abs(sig.E) * sig.nu
    on = np.abs(f0) <= ADMISSIBLE_RTOL * scale
    flat = on & (np.abs(d0) <= FLAT_RTOL * np.maximum(rate, np.finfo(float).tiny))
    return sig, f0, d0, scale, on, flat


class CoatingFlight:
    """Exact flights of a :class:`~bladecase.nsm.massless.nodes.NodalSystem` whose contacts press a yielding
    coating (module docstring): ``yield_force`` ``λ_y,j`` (N, one a node, each > 0), ``damping`` of the open-phase
    modes, an out-of-round casing (:class:`~bladecase.nsm.massless.nodes.Rub`)."""

    def __init__(self, system: NodalSystem, yield_force, damping=None, rub: Rub | None = None, friction=None):
        if not isinstance(system, NodalSystem):
            raise ValueError(f"system must be a NodalSystem, got {type(system).__name__}")
        if friction is not None:
            friction.check(system)
            if friction.model != "rotation":
                raise ValueError(f"the coating yielding in flight flies the friction model 'rotation', got "
                                 f"{friction.model!r}")
            if friction.mu == 0:
                friction = None
        ly = np.broadcast_to(np.asarray(yield_force, dtype=float), (system.m,)).copy()
        if not np.all(np.isfinite(ly) & (ly > 0)):
            raise ValueError(f"yield_force must be finite and > 0 at every contact node (N), got {ly.tolist()}")
        self.system, self.yield_force = system, ly
        self.omega, self.phi = system.modes
        self.n, self.m = system.n, system.m
        self.Wq = self.phi.T @ system.W
        self.friction = friction
        # with friction (module docstring): the interior is driven by W − μT, the constraints see H − μC_nt
        mu = 0.0 if friction is None else friction.mu
        C_nt = np.zeros((self.m, self.m)) if friction is None else friction.C_nt
        self.Wf = self.Wq if friction is None else self.Wq - mu * (self.phi.T @ friction.T)
        self.Hc, self.Hy = system.H - mu * C_nt, system.flexibility - mu * C_nt
        self.Cq, self.nu, self.D = flight_terms(self.omega, damping, rub, system.m)
        self._phases: dict[bytes, CoatingPhase] = {}
        self._ready = None  # the start settle last found admissible (:meth:`_ready_start`)
        self._runs = (None, None)  # a profile and its runs of equal depths (:func:`_runs`)

    def phase(self, codes: np.ndarray, w: np.ndarray) -> CoatingPhase:
        """The phase of the node codes ``codes`` with the surfaces ``w`` (cached per codes)."""
        codes = np.asarray(codes, dtype=np.int8)
        key = codes.tobytes()
        ph = self._phases.get(key)
        if ph is None:
            ph = self._phases[key] = CoatingPhase(self, codes.copy())
        return ph.at_surface(np.asarray(w, dtype=float))

    def gap(self, t) -> np.ndarray:
        """The clearances without the coating's wear at the times ``t``: ``(m,)`` or ``(m, k)``."""
        return casing_gap(self.system.gap, self.D, self.nu, t)

    def encode(self, x, v) -> tuple[np.ndarray, np.ndarray]:
        M = self.system.M
        return self.phi.T @ (M @ x), self.phi.T @ (M @ v)

    def positions(self, ph: CoatingPhase, Q: np.ndarray, t) -> tuple[np.ndarray, np.ndarray]:
        """The nodes' normal displacements ``y`` and forces ``λ`` ``(m, k)`` in the phase ``ph``."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        Q = Q.reshape(self.n, -1)
        lam = ph.forces(Q, t)
        return self.Wq.T @ Q - self.Hy @ lam, lam

    def plastic_surface(self, ph: CoatingPhase, q: np.ndarray, t: float) -> np.ndarray:
        """Each node's surface if it were plastic now: ``y − g − λ_y/k`` (m)."""
        y = self.positions(ph, q, t)[0][:, 0]
        return y - self.gap(t) - self.yield_force / self.system.casing

    # ------------------------------------------------------------------ decisions

    def _bad(self, ph: CoatingPhase, a, t: float, start=None) -> list[int]:
        """The signals of the phase ``ph`` started with the amplitudes ``a`` at ``t`` that start inadmissible, the
        most negative first: below 0, or on their surface and falling (flat ones must curve up: checked in flight);
        ``start``: their :func:`_start`, if computed."""
        sig, f0, d0, scale, on, flat = _start(ph, a, t) if start is None else start
        bad = (~on & (f0 < 0)) | (on & ~flat & (d0 < 0))
        order = np.argsort(np.where(on, 0.0, f0 / scale), kind="stable")
        return [int(k) for k in order if bad[k]]

    def _change(self, ph: CoatingPhase, k: int, codes, w, q, t: float):
        """The codes and surfaces after the signal ``k`` of ``ph`` reached 0 (its node changes as it says)."""
        j, kind = ph.meta[k]
        codes, w = codes.copy(), w.copy()
        if kind == "gap":
            codes[j] = ELASTIC
        elif kind == "force":
            codes[j] = OPEN
        elif kind == "yield":
            codes[j] = PLASTIC
        else:  # the removal stops: elastic on the surface where it stopped
            w[j] = self.plastic_surface(ph, q, t)[j]
            codes[j] = ELASTIC
        return codes, w

    def settle(self, codes, w, q, p, t: float, first: int | None = None, ph=None):
        """Admissible codes and surfaces at ``(q, p, t)``: from ``codes`` (after the signal ``first`` of ``ph``
        changed its node), each node whose signal starts inadmissible changed as that signal says."""
        if first is not None:
            codes, w = self._change(ph, first, codes, w, q, t)
        seen = set()
        for _ in range(4 * self.m + 4):
            new = self.phase(codes, w)
            a = new.amplitudes(q, p, t)
            start = _start(new, a, t)
            bad = self._bad(new, a, t, start)
            if not bad:  # the flight that follows starts from these (:meth:`_ready_start`)
                self._ready = (codes, w, q, p, t, new, a, start)
                return codes, w
            key = (codes.tobytes(), bad[0])
            if key in seen:
                break
            seen.add(key)
            codes, w = self._change(new, bad[0], codes, w, q, t)
        raise ValueError(f"at t = {t:.12g} s the contact nodes have no admissible state (codes {codes.tolist()}): a "
                         "grazing or degenerate switch")

    def decide(self, q, p, t: float, w) -> tuple[np.ndarray, np.ndarray]:
        """The codes and surfaces of a state against the surfaces ``w``: the forces from the box-constrained problem
        ``0 ≤ λ ≤ λ_y`` (min ``½λᵀHλ − λᵀ(Wᵀx − g − w)``), a node pressed beyond its yield having its excess
        removed at once, then settled at the rate level (:meth:`settle`)."""
        b = self.Wq.T @ q - self.gap(t) - w
        H = self.Hc
        if self.friction is None:
            L = np.linalg.cholesky(H)
            res = lsq_linear(L.T, sla.solve_triangular(L, b, lower=True), bounds=(0.0, self.yield_force),
                             method="bvls", tol=1e-14)
            lam = np.clip(res.x, 0.0, self.yield_force)
        else:  # H_μ is not symmetric: the box as a complementarity problem in (λ, excess) solved by Lemke's method
            m = self.m
            M = np.block([[H, np.eye(m)], [-np.eye(m), np.zeros((m, m))]])
            lam = np.clip(lemke(np.r_[-b, self.yield_force], M)[:m], 0.0, self.yield_force)
        slack = -b + H @ lam
        tol = 1e-9 * self.yield_force
        codes = np.where(lam <= tol, OPEN, np.where(lam >= self.yield_force - tol, PLASTIC, ELASTIC)).astype(np.int8)
        w = w.copy()
        over = (codes == PLASTIC) & (slack < 0)
        w[over] -= slack[over]
        codes[(codes == PLASTIC) & ~over] = ELASTIC  # on its yield, not beyond: the rate decides
        return self.settle(codes, w, q, p, t)

    # ------------------------------------------------------------------ flight

    def _fly(self, ph: CoatingPhase, a, t: float, horizon: float, start=None):
        """The first switch of a flight (``(τ, signal)``, or ``None``) and the span searched (a flat start that
        leaves its surface cuts the flight short); ``start``: the phase's :func:`_start`, if computed."""
        sig, _, _, _, on, flat = _start(ph, a, t) if start is None else start
        span = horizon
        if flat.any():
            leave = []
            for k in np.flatnonzero(flat):
                tau = leave_flat(sig.row(k), horizon, sig.step, ADMISSIBLE_RTOL * max(sig.magnitude[k], 1e-300),
                                 LEAVE_POINTS)
                if tau is None:  # it stays on its surface: a switch now (e.g. a node that stopped yielding
                    return (0.0, int(k)), 0.0  # yields on: its removal rate only grazed zero)
                leave.append(tau)
            span = min(span, min(leave))
            keep = ~flat
            sig = _Signals(sig.lam, sig.C * keep[:, None], sig.E * keep, sig.nu, np.where(keep, sig.const, 1.0),
                           sig.lam2)
            on = on & keep
        return (first_switch(sig, span, on) if span > 0 else None), span

    def simulate(self, x0, v0, t_end: float, w0=None, profile: Profile | None = None,
                 max_switches: int = MAX_SWITCHES) -> CoatingTrajectory:
        """:func:`simulate_coating` with this flight."""
        s = self.system
        x, v = np.asarray(x0, float).reshape(-1), np.asarray(v0, float).reshape(-1)
        if x.size != self.n or v.size != self.n or not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
            raise ValueError(f"x0 and v0 must be finite with {self.n} interior dofs, got {x.size} and {v.size}")
        t_end = float(t_end)
        if not (np.isfinite(t_end) and t_end > 0):
            raise ValueError(f"t_end must be finite and > 0, got {t_end!r}")
        if profile is not None and len(profile.angles) != s.m:
            raise ValueError(f"the profile needs one angle per contact node ({s.m}), got {len(profile.angles)}")
        w = np.zeros(s.m) if w0 is None else np.broadcast_to(np.asarray(w0, dtype=float), (s.m,)).copy()
        if profile is not None:
            w = w + profile.depth[self._cells(profile, 0.0) % profile.depth.size]
        q, p = self.encode(x, v)
        t = 0.0
        before = w
        codes, w = self.decide(q, p, t, w)
        starts, cl, wl, qs, ps, amps, jumps, flown = [], [], [], [], [], [], [], []
        still = 0  # switches in a row at the same instant
        while len(starts) <= max_switches:
            ph, a, start = self._ready_start(codes, w, q, p, t)
            starts.append(t), cl.append(codes), wl.append(w), qs.append(q), ps.append(p), amps.append(a)
            flown.append(ph)
            jumps.append(np.zeros(s.m) if before is None else self._jump(ph, q, t, codes, w, before))
            before = None  # a switch in flight removes nothing at once; a flight cut short neither
            edges = self._edges(profile, t, codes, w) if profile is not None else np.full(s.m, np.inf)
            stop = min(float(edges.min()), t_end)
            hit, span = self._fly(ph, a, t, stop - t, start)
            if hit is None:
                q, p = ph.advance(a, t, span)
                if span < stop - t:
                    t += span
                    continue  # a flat start left its surface: the same phase flown on
                t = stop
                if t >= t_end:
                    break
                codes, w, before = self._step(ph, codes, w, q, p, t, profile, edges <= t)
                continue
            tau, k = hit
            still = still + 1 if tau == 0.0 else 0
            if still > 2 * s.m + 2:  # switching back and forth without moving
                raise ValueError(f"grazing switch at t = {t:.12g} s: a node that stopped yielding does not leave its "
                                 "yield force")
            q, p = ph.advance(a, t, tau)
            t += tau
            codes, w = self.settle(codes, w, q, p, t, first=k, ph=ph)
        return CoatingTrajectory(self, np.array(starts), np.array(cl), np.array(wl), np.array(qs).T,
                                 np.array(ps).T, np.array(amps), t, bool(t >= t_end), np.array(jumps),
                                 tuple(flown) if REUSE else None)

    def _ready_start(self, codes, w, q, p, t: float):
        """The phase of ``codes`` and ``w``, its amplitudes at ``(q, p, t)`` and their :func:`_start`: those
        :meth:`settle` just computed for these very arrays (the same numbers), else made (``start`` ``None``)."""
        r, self._ready = self._ready, None
        if REUSE and r is not None and r[0] is codes and r[1] is w and r[2] is q and r[3] is p and r[4] == t:
            return r[5], r[6], r[7]
        ph = self.phase(codes, w)
        return ph, ph.amplitudes(q, p, t), None

    @staticmethod
    def _cells(profile: Profile, t: float) -> np.ndarray:
        """Each node's cell at ``t`` (unwrapped index), a node on an edge counted in the cell it enters."""
        theta = profile.speed * t + np.asarray(profile.angles)
        return np.floor(theta / profile.step + EDGE_RTOL).astype(np.int64)

    def _edges(self, profile: Profile, t: float, codes, w) -> np.ndarray:
        """Each node's next edge of the profile that changes its phase: the first cell of another depth than its
        surface (open, elastic), the next cell (plastic: its own surface against the cell's)."""
        n = profile.depth.size
        c0 = self._cells(profile, t)
        if self._runs[0] is not profile:
            self._runs = (profile, _runs(profile.depth))
        nxt = (c0 + 1) % n  # each node's next cell: another depth than its surface, or its run's length further
        k = np.where((profile.depth[nxt] != w) | (codes == PLASTIC), 0, self._runs[1][nxt])
        return ((c0 + 1 + k) * profile.step - np.asarray(profile.angles)) / profile.speed

    def _jump(self, ph: CoatingPhase, q, t: float, codes, w, before) -> np.ndarray:
        """The depth each node removed at once at ``t`` (a step of the profile, the start): its decided surface (its
        own receding one if plastic) beyond the surface it had (``before``)."""
        plastic = codes == PLASTIC
        after = np.where(plastic, self.plastic_surface(ph, q, t), w) if plastic.any() else w
        return np.maximum(after - before, 0.0)

    def _step(self, ph: CoatingPhase, codes, w, q, p, t: float, profile: Profile, crossing: np.ndarray):
        """The codes and surfaces after the nodes ``crossing`` entered a new cell of the profile at ``t``: an open or
        elastic node on the new cell's depth, a plastic one on its own surface while it is the deeper (a node
        pressed beyond its yield removes the excess at once), and the surfaces the nodes had before deciding."""
        depth = profile.depth[self._cells(profile, t) % profile.depth.size]
        plastic = codes == PLASTIC
        own = self.plastic_surface(ph, q, t) if plastic.any() else w  # read where plastic only
        new = np.where(crossing, np.where(plastic, np.maximum(own, depth), depth), np.where(plastic, own, w))
        if np.any(crossing & plastic & (depth > own)):
            return (*self.decide(q, p, t, new), new)
        try:
            return (*self.settle(codes, np.where(plastic, w, new), q, p, t), new)
        except ValueError:
            return (*self.decide(q, p, t, new), new)


@dataclass(frozen=True, eq=False)
class CoatingTrajectory(Sampled):
    """Result of :func:`simulate_coating`: the start of every phase (time, node codes, surfaces, modal state,
    amplitudes, and the depth each node removed at once there: ``jumps``, ``(phases, m)``)."""

    flight: CoatingFlight
    starts: np.ndarray
    codes: np.ndarray
    surfaces: np.ndarray
    q: np.ndarray
    p: np.ndarray
    amplitudes: np.ndarray
    t_end: float
    complete: bool
    jumps: np.ndarray = None  # type: ignore[assignment]
    flown: tuple | None = None  # the phase flown from each start (its surfaces set), kept to sample the flight

    def _phase(self, i: int) -> CoatingPhase:
        """The phase flown from the start ``i`` (the one kept, else made again: the same numbers)."""
        if self.flown is not None:
            return self.flown[i]
        return self.flight.phase(self.codes[i], self.surfaces[i])

    @property
    def switch_times(self) -> np.ndarray:
        """Times of the switches (the phases' starts after the first)."""
        return self.starts[1:]

    def sample(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Interior ``(x, v)`` ``(n, k)``, the contact forces ``λ`` and the nodes' normal displacements ``y``
        ``(m, k)`` at the times ``t``, in closed form from the phase holding each."""
        fl = self.flight
        t = np.atleast_1d(np.asarray(t, dtype=float))
        k = np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0, self.starts.size - 1)
        Q, P = np.empty((fl.n, t.size)), np.empty((fl.n, t.size))
        lam, y = np.zeros((fl.m, t.size)), np.zeros((fl.m, t.size))
        for i in np.unique(k):
            sel = np.flatnonzero(k == i)
            ph = self._phase(i)
            Q[:, sel], P[:, sel] = ph.advance(self.amplitudes[i], self.starts[i], t[sel] - self.starts[i])
            y[:, sel], lam[:, sel] = fl.positions(ph, Q[:, sel], t[sel])
        return fl.phi @ Q, fl.phi @ P, lam, y

    def removed(self) -> np.ndarray:
        """Each node's depth removed over the flight (m): the sum of its plastic phases' recession and of what it
        removed at once (pressed beyond its yield where the profile steps)."""
        fl = self.flight
        out = self.jumps.sum(axis=0) if self.jumps is not None else np.zeros(fl.m)
        ends = np.r_[self.starts[1:], self.t_end]
        for i in np.flatnonzero((self.codes == PLASTIC).any(axis=1)):
            ph = self._phase(i)
            q1 = ph.advance(self.amplitudes[i], self.starts[i], ends[i] - self.starts[i])[0]
            rec = fl.plastic_surface(ph, q1, ends[i]) - fl.plastic_surface(ph, self.q[:, i], self.starts[i])
            out += np.where(self.codes[i] == PLASTIC, rec, 0.0)
        return out


def simulate_coating(system: NodalSystem, yield_force, x0, v0, t_end: float, damping=None, rub: Rub | None = None,
                     w0=None, profile: Profile | None = None, max_switches: int = MAX_SWITCHES,
                     friction=None) -> CoatingTrajectory:
    """Exact event-driven simulation of ``system`` pressing a coating that yields at the node forces
    ``yield_force`` (N; module docstring) from ``(x0, v0)`` at ``t = 0``: ``w0`` the nodes' surfaces at the start
    (m, default 0), ``profile`` a worn casing's depths round it (added to them), ``damping`` and ``rub`` as
    :func:`~bladecase.nsm.massless.nodes.simulate_nodes`', ``friction`` a
    :class:`~bladecase.nsm.massless.friction.Friction` of the rotation model (module docstring). A run that hits
    ``max_switches`` stops with ``complete = False``.

    >>> s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), [[0.0]], gap=[1.0], casing=[100.0])
    >>> tr = simulate_coating(s, [1e9], [0.0], [10.0], 3.0)    # a yield never reached: the elastic flight
    >>> bool(tr.complete), float(tr.removed()[0])
    (True, 0.0)
    """
    return CoatingFlight(system, yield_force, damping, rub, friction).simulate(x0, v0, t_end, w0, profile,
                                                                               max_switches)
