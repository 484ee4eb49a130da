"""The massless contact model (theory §8): contact dofs without inertia, Signorini without an impact law.

With the contact dofs ``c`` (where ``w ≠ 0``) massless, static condensation of ``c`` leaves the interior dofs
``i`` with a unilateral spring:

    M x'' + S x + k_c ŵ max(0, ŵᵀx - d) = 0,

- ``S = K_ii - K_ic K_cc⁻¹ K_ci``: the open-phase stiffness (contact dofs free, statically condensed);
- ``ŵ = -K_ic K_cc⁻¹ w_c``: while open, the contact displacement is ``wᵀx_full = ŵᵀx``;
- ``k_c = 1 / (w_cᵀ K_cc⁻¹ w_c)``: the static stiffness of the contact dofs alone — in series with the casing's
  stiffness ``k_casing`` when the casing is compliant (:func:`series_stiffness`; ``inf``: a rigid casing).

A compliant casing (a spring ``k_casing`` between the contact and the rigid casing at ``d``, the casing's local
flexibility and its abradable coating) changes nothing else: with ``λ = k_casing (w_cᵀx_c - d)`` in the closed
phase, ``λ = k (ŵᵀx - d)`` with ``k = k_c k_casing / (k_c + k_casing)``, both switches are still at ``ŵᵀx = d``,
and the contact dofs sit ``λ / k_casing`` beyond ``d`` (the casing yields). The same model with a rigid casing is
the limit ``k_casing → ∞``. A casing stiffness well below ``k_c`` keeps the closed phase's dynamics in the low modes
that every model of the blade resolves: the nonsmooth modes then converge under refinement
(docs/massless.md, "A compliant casing").

Open phase: ``y = ŵᵀx <= d``, ``λ = 0``. Closed phase: ``w_cᵀx_c = d`` held by the multiplier
``λ = k_c (y - d) >= 0``. Both switches happen at ``y = d`` (closing when ``y`` reaches ``d`` from below, opening
when ``λ`` reaches 0), the vector field is continuous, energy ``½vᵀMv + ½xᵀSx + ½k_c max(0, y - d)²`` (= the full
model's ``½vᵀMv + ½xᵀKx``) is conserved, and the saltation matrices are the identity.

Each phase is an exact modal flight (:class:`Phase`); switches are the FIRST root of the phase's contact signal,
a trigonometric sum, found with the certified search of :mod:`bladecase.nsm.signals`.

>>> import numpy as np
>>> s = condense(np.diag([1.0, 0.0]), np.array([[4.0, -3.0], [-3.0, 3.0]]), np.array([0.0, 1.0]), gap=1.0)
>>> s.S, s.w, s.kc      # mass on k₁ = 1 to the wall, k₂ = 3 to a massless contact point: bilinear oscillator
(array([[1.]]), array([1.]), 3.0)
>>> traj = simulate_massless(s, [-2.0], [0.0], t_end=10.0)
>>> traj.phases[:2], round(abs(s.energy(traj.x_end, traj.v_end) - 2.0), 12)
(('closed', 'open'), 0.0)
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.linalg as sla

from ..signals import TrigSum, first_upcrossing
from ..system import INACTIVE_RTOL, Spectrum

#: Largest interior size handled (dense eigenproblems of both phases).
MASSLESS_DENSE_LIMIT = 4000


@dataclass(frozen=True, eq=False)
class Phase:
    """Exact flight of one contact phase, ``M x'' + K_p x = f_p``: M-normalised modes, equilibrium ``x_eq``.

    ``b = Φᵀŵ`` and ``y_eq = ŵᵀx_eq`` give the contact signal ``y(τ) = ŵᵀx(τ)`` as a trigonometric sum.
    """

    omega: np.ndarray
    phi: np.ndarray
    x_eq: np.ndarray
    b: np.ndarray
    y_eq: float
    M: np.ndarray = None  # type: ignore[assignment]

    def modal(self, x, v) -> tuple[np.ndarray, np.ndarray]:
        """Modal displacement and velocity ``(Φᵀ M (x - x_eq), Φᵀ M v)``."""
        return self.phi.T @ (self.M @ (x - self.x_eq)), self.phi.T @ (self.M @ v)

    def advance(self, x, v, tau: float) -> tuple[np.ndarray, np.ndarray]:
        """State after a flight of duration ``tau`` in this phase (closed form)."""
        return self.flight(x, v)(tau)

    def flight(self, x, v):
        """``tau -> advance(x, v, tau)``: the flight from one state, its modal coordinates computed once (the same
        numbers as :meth:`advance` at every ``tau``, for the many instants of one orbit's phase)."""
        q, p = self.modal(x, v)
        omega, phi, x_eq = self.omega, self.phi, self.x_eq

        def at(tau: float) -> tuple[np.ndarray, np.ndarray]:
            c, s = np.cos(omega * tau), np.sin(omega * tau)
            return x_eq + phi @ (c * q + s * p / omega), phi @ (-omega * s * q + c * p)

        return at

    def contact(self, x, v) -> TrigSum:
        """``y(τ) = ŵᵀx(τ)`` during this phase from the state ``(x, v)``."""
        q, p = self.modal(x, v)
        return TrigSum(self.b * q, self.b * p / self.omega, self.omega, self.y_eq)


def _phase(M: np.ndarray, K: np.ndarray, f: np.ndarray, w: np.ndarray, name: str) -> Phase:
    lam, phi = sla.eigh(K, M)
    if lam.min() <= 0:
        raise ValueError(f"the {name}-phase stiffness is not positive definite (lowest eigenvalue {lam.min():.3g})")
    x_eq = np.linalg.solve(K, f)
    return Phase(np.sqrt(lam), phi, x_eq, phi.T @ w, float(w @ x_eq), M)


@dataclass(frozen=True, eq=False)
class MasslessSystem:
    """Interior dynamics of a structure whose contact dofs carry no inertia (see the module docstring).

    Attributes
    ----------
    M, S : (n, n) ndarray
        Interior mass (SPD) and open-phase stiffness (SPD).
    w : (n,) ndarray
        ``ŵ``: the contact displacement is ``ŵᵀx`` while open.
    kc : float
        Stiffness of the unilateral spring: ``1 / (w_cᵀ K_cc⁻¹ w_c)``, in series with ``casing``
        (:func:`series_stiffness`).
    gap : float
        Clearance ``d > 0``.
    expand : (n_full, n) ndarray or None
        Open-phase displacement of every dof of the full model from the interior ones (``None``: not kept).
    casing : float
        The casing's stiffness already included in ``kc`` (``inf``: rigid casing, the default). Kept as a record:
        the closed phase's contact displacement is ``d + λ / casing``.
    """

    M: np.ndarray
    S: np.ndarray
    w: np.ndarray
    kc: float
    gap: float
    expand: np.ndarray | None = None
    casing: float = float("inf")

    contact_model = "massless"

    def __post_init__(self) -> None:
        n = self.M.shape[0]
        if n > MASSLESS_DENSE_LIMIT:
            raise ValueError(f"massless model of {n} interior dofs: at most {MASSLESS_DENSE_LIMIT} (dense phases); "
                             "reduce the model first")
        if not (np.isfinite(self.gap) and self.gap > 0):
            raise ValueError(f"gap must be finite and > 0, got {self.gap!r}")
        if not (np.isfinite(self.kc) and self.kc > 0):
            raise ValueError(f"contact stiffness kc must be finite and > 0, got {self.kc!r}")
        if not (self.casing > 0 and not np.isnan(self.casing)):
            raise ValueError(f"casing stiffness must be > 0 (inf: a rigid casing), got {self.casing!r}")

    @property
    def n(self) -> int:
        """Interior dofs."""
        return self.M.shape[0]

    @cached_property
    def open(self) -> Phase:
        """Open phase: ``M x'' + S x = 0``."""
        return _phase(self.M, self.S, np.zeros(self.n), self.w, "open")

    @cached_property
    def closed(self) -> Phase:
        """Closed phase: ``M x'' + (S + k_c ŵŵᵀ) x = k_c d ŵ``."""
        return _phase(self.M, self.S + self.kc * np.outer(self.w, self.w), self.kc * self.gap * self.w, self.w,
                      "closed")

    @cached_property
    def spectrum(self) -> Spectrum:
        """The open-phase modes (contact free): the linear modes from which the nonsmooth modes grow."""
        o = self.open
        return Spectrum(o.omega, o.phi, o.b, np.abs(o.b) > INACTIVE_RTOL * np.abs(o.b).max())

    @cached_property
    def transfer(self) -> np.ndarray:
        """``P = Φ_cᵀ M Φ_o`` (orthogonal): closed-phase modal coordinates of the open-phase modes."""
        return self.closed.phi.T @ self.M @ self.open.phi

    @property
    def kc_structure(self) -> float:
        """The contact dofs' own stiffness ``1 / (w_cᵀ K_cc⁻¹ w_c)``, without the casing (``kc`` when it is rigid)."""
        return self.kc if np.isinf(self.casing) else 1.0 / (1.0 / self.kc - 1.0 / self.casing)

    def energy(self, x, v) -> float:
        """Total energy (kinetic + strain, the contact dofs' strain included)."""
        x, v = np.asarray(x, float), np.asarray(v, float)
        y = float(self.w @ x)
        return float(0.5 * v @ self.M @ v + 0.5 * x @ self.S @ x + 0.5 * self.kc * max(0.0, y - self.gap) ** 2)

    def multiplier(self, x) -> float:
        """Contact force ``λ = k_c max(0, ŵᵀx - d)``."""
        return self.kc * max(0.0, float(self.w @ np.asarray(x, float)) - self.gap)

    def __repr__(self) -> str:
        casing = "" if np.isinf(self.casing) else f", casing={self.casing:.4g}"
        return f"MasslessSystem(n={self.n}, gap={self.gap:g}, kc={self.kc:.4g}{casing})"


def series_stiffness(kc: float, casing: float) -> float:
    """Stiffness of the contact dofs (``kc``) in series with the casing (``casing``; ``inf``: rigid).

    >>> series_stiffness(3.0, float("inf")), series_stiffness(3.0, 6.0)
    (3.0, 2.0)
    """
    casing = float(casing)
    if not (casing > 0 and not np.isnan(casing)):
        raise ValueError(f"casing stiffness must be > 0 N/m (inf: a rigid casing), got {casing!r}")
    return float(kc) if np.isinf(casing) else float(kc) * casing / (float(kc) + casing)


class BoundOrbit:
    """What the massless orbit records share: they pickle without their system (``system`` and cached values
    dropped; :meth:`bind` re-attaches one)."""

    def __getstate__(self) -> dict:
        import dataclasses

        state = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        state["system"] = None
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)

    def _bound(self) -> MasslessSystem:
        if self.system is None:
            raise ValueError("this orbit is not bound to a system (it was unpickled): call orbit.bind(system)")
        return self.system

    def bind(self, system: MasslessSystem):
        """This orbit attached to ``system`` (a copy)."""
        import dataclasses

        if not isinstance(system, MasslessSystem):
            raise ValueError(f"bind needs a MasslessSystem, got {type(system).__name__}")
        return dataclasses.replace(self, system=system)


def condense(M, K, w, gap: float, casing: float = float("inf")) -> MasslessSystem:
    """The massless model of a full system ``(M, K, w, d)`` whose mass is zero on the contact dofs.

    ``casing``: the casing's stiffness (N/m; ``inf``, the default: rigid), in series with the contact dofs'.

    ``M`` must have zero rows and columns on the contact dofs ``c = {j : w_j ≠ 0}`` (move their mass to the
    neighbours first, e.g. with :func:`redistribute_mass`); ``K`` must be SPD. Dense arrays (a reduced model or
    a bar); the full model's displacement is kept as ``expand``.
    """
    M = np.asarray(M.toarray() if hasattr(M, "toarray") else M, float)
    K = np.asarray(K.toarray() if hasattr(K, "toarray") else K, float)
    w = np.asarray(w, float).reshape(-1)
    n = w.size
    if M.shape != (n, n) or K.shape != (n, n):
        raise ValueError(f"M and K must be {n}×{n} like w, got {M.shape} and {K.shape}")
    c = np.flatnonzero(w)
    i = np.setdiff1d(np.arange(n), c)
    if c.size == 0:
        raise ValueError("w is zero: no contact dof")
    heavy = np.abs(M[c]).max()
    if heavy > 0:
        raise ValueError(f"the contact dofs {c.tolist()} carry mass (max |M| on their rows {heavy:.3g}); "
                         "a massless model needs zero rows and columns there — redistribute their mass first")
    Kcc, Kci = K[np.ix_(c, c)], K[np.ix_(c, i)]
    X = np.linalg.solve(Kcc, np.column_stack([Kci, w[c]]))
    S = K[np.ix_(i, i)] - Kci.T @ X[:, :-1]
    expand = np.zeros((n, i.size))
    expand[i, np.arange(i.size)] = 1.0
    expand[c] = -X[:, :-1]
    kc = series_stiffness(1.0 / float(w[c] @ X[:, -1]), casing)
    return MasslessSystem(M[np.ix_(i, i)], 0.5 * (S + S.T), -Kci.T @ X[:, -1], kc, float(gap), expand, float(casing))


def redistribute_mass(masses: np.ndarray, coords: np.ndarray, contact: int, neighbours: np.ndarray) -> np.ndarray:
    """Lumped masses with the ``contact`` node's mass moved to ``neighbours``, total mass and centre of mass kept.

    The smallest change ``δ`` (weighted by the neighbours' own masses, ``Σ δ_j²/m_j`` minimal) with
    ``Σ δ = m_c`` and ``Σ δ_j x_j = m_c x_c``. Raises ValueError if a mass would become non-positive.

    >>> redistribute_mass(np.array([1.0, 1.0, 0.5]), np.array([[1.0], [2.0], [3.0]]), 2, np.array([0, 1]))
    array([0.5, 2. , 0. ])
    """
    masses = np.asarray(masses, float).copy()
    coords = np.asarray(coords, float).reshape(masses.size, -1)
    mc, xc = masses[contact], coords[contact]
    X = np.column_stack([np.ones(neighbours.size), coords[neighbours] - xc])  # constraints: Σδ = mc, Σδ(x-xc) = 0
    Wt = masses[neighbours]
    G = (X * Wt[:, None]).T @ X
    rhs = np.zeros(X.shape[1])
    rhs[0] = mc
    mu = np.linalg.lstsq(G, rhs, rcond=None)[0]
    delta = Wt * (X @ mu)
    if np.abs(X.T @ delta - rhs).max() > 1e-10 * mc:
        raise ValueError(f"the neighbours {neighbours.tolist()} of node {contact} cannot keep both the total mass and "
                         "the centre of mass (too few, or aligned); give more neighbours")
    new = masses[neighbours] + delta
    if np.any(new <= 0):
        raise ValueError(f"moving the mass {mc:.3g} of node {contact} to its neighbours {neighbours.tolist()} "
                         "would make a mass non-positive; give more neighbours")
    masses[neighbours] = new
    masses[contact] = 0.0
    return masses


# ----------------------------------------------------------------------------- event-driven simulation

@dataclass(frozen=True, eq=False)
class MasslessTrajectory:
    """Result of :func:`simulate_massless`: switch times, the phase entered at each, states at the switches."""

    switch_times: np.ndarray
    phases: tuple[str, ...]
    x: np.ndarray
    v: np.ndarray
    x_end: np.ndarray
    v_end: np.ndarray
    t_end: float
    complete: bool


def _leave_surface(f: TrigSum, horizon: float) -> float:
    """A time ``τ > 0`` with ``f(τ) < 0`` for a signal that starts on its switching surface moving away."""
    f0, d0 = (float(a) for a in f(0.0))
    scale = max(f.magnitude, abs(f.const), 1e-300)
    if f0 < -1e-12 * scale:
        return 0.0
    if d0 >= 0:
        raise ValueError("grazing switch: the contact signal does not leave the switching surface "
                         f"(value {f0:.3g}, slope {d0:.3g})")
    tau = min(-d0 / max(f.curvature_bound, 1e-300), horizon)  # f <= f0 + d0 τ + B₂τ²/2 < 0 on (0, τ]
    while float(f(tau)[0]) >= 0 and tau > 1e-300:
        tau /= 2
    return tau


def simulate_massless(system: MasslessSystem, x0, v0, t_end: float, max_switches: int = 100_000
                      ) -> MasslessTrajectory:
    """Exact event-driven simulation of the massless model from ``(x0, v0)`` at ``t = 0`` to ``t_end``.

    Each phase is flown in closed form; the next switch is the FIRST root of ``y - d`` (open) or ``d - y``
    (closed) — certified: no contact phase is missed. A run that hits ``max_switches`` stops with
    ``complete = False``.
    """
    x, v = np.asarray(x0, float).reshape(-1), np.asarray(v0, float).reshape(-1)
    if x.size != system.n or v.size != system.n:
        raise ValueError(f"x0 and v0 must have {system.n} interior dofs, got {x.size} and {v.size}")
    if not (np.isfinite(t_end) and t_end > 0):
        raise ValueError(f"t_end must be finite and > 0, got {t_end!r}")
    if isinstance(max_switches, bool) or int(max_switches) < 1:
        raise ValueError(f"max_switches must be an integer >= 1, got {max_switches!r}")
    d = system.gap
    y0, dy0 = float(system.w @ x), float(system.w @ v)
    on_surface = abs(y0 - d) <= 1e-12 * max(d, abs(y0))
    closed = dy0 > 0 if on_surface else y0 > d  # on the surface: the motion decides
    t, times, phases, xs, vs = 0.0, [], [], [], []
    while len(times) < max_switches:
        ph = system.closed if closed else system.open
        y = ph.contact(x, v)
        sign = -1.0 if closed else 1.0
        f = TrigSum(sign * y.alpha, sign * y.beta, y.omega, sign * (y.const - d))
        start = _leave_surface(f, t_end - t)
        tau = first_upcrossing(f, start, t_end - t)
        if tau is None:
            x, v = ph.advance(x, v, t_end - t)
            t = t_end
            break
        x, v = ph.advance(x, v, tau)
        t += tau
        closed = not closed
        times.append(t)
        phases.append("closed" if closed else "open")
        xs.append(x)
        vs.append(v)
    complete = t >= t_end
    shape = (system.n, len(xs))
    return MasslessTrajectory(np.array(times), tuple(phases), np.array(xs).T.reshape(shape),
                              np.array(vs).T.reshape(shape), x, v, t, complete)
