"""A blade spinning about an axis: the centrifugal static state, stress stiffening and spin softening.

At a rotation speed ``Ω`` (rad/s) about an axis through ``o`` along the unit vector ``a``, a material
point at ``x`` feels the centrifugal body force ``ρ Ω² P⊥ (x + u − o)``, with ``P⊥ = I − a aᵀ`` the
projection on the plane of rotation.  Linearised about the static centrifugal state ``u₀``:

* **static state**: ``(K − Ω² M⊥) u₀ = Ω² f₁``, with ``M⊥ = ∫ ρ (P⊥ u)·v`` (the mass matrix's own
  integration: consistent, or lumped as the model's mass is) and ``f₁ = ∫ ρ P⊥ (x − o)·v``;
* **stress (geometric) stiffness** ``K_σ = ∫ σ₀ : (∇u)ᵀ ∇v`` from the stress ``σ₀ = C ε(u₀)``;
* **spin softening** ``−Ω² M⊥``;
* the vibration about ``u₀`` is then governed by ``K(Ω) = K + K_σ − Ω² M⊥`` and ``M``: every later stage
  (reduction, nonsmooth modes, forcing) takes :attr:`SpinState.model`, an :class:`FEModel` whose ``K``
  is ``K(Ω)``.  Coriolis coupling (``2Ω G``, skew) is left out of ``K(Ω)``: it is small for modes whose
  motion is mostly parallel to the axis or radial (a blade's flap and torsion); it is not a stiffness.

This is the linear prestress of ANSYS (``PSTRES``, ``SPIN SOFTENING``).  It reproduces the Southwell coefficients
of a rotating cantilever (flapwise ``1.1933 + 1.5709 R/L`` for the first mode; chordwise 1 less).  CalculiX's
linear ``*STATIC`` step with ``CENTRIF`` then ``*FREQUENCY`` with ``PERTURBATION`` differs in two terms (measured
in ``benchmarks/bench_nlgeom.py``, docs/rotation.md): its static step has no load stiffness (``K u₀ = Ω² f₁``) and
its perturbation stiffness holds the material stiffness with the static state's deformation gradient.

``static="nonlinear"`` (:mod:`~bladecase.fe.nonlinear_static`) solves the geometrically nonlinear state instead
(large rotations, the follower load ``Ω² (f₁ + M⊥ u)``) and vibrates about it with its full tangent
``K_T(u₀) − Ω² M⊥``: CalculiX's ``NLGEOM`` static step and ``PERTURBATION`` frequencies, ANSYS's large-deflection
prestressed modal analysis.

A sweep of speeds passes each speed's state on to the next (:func:`spin`'s ``previous``): the nonlinear state
starts from the earlier speeds' states and its Newton steps, as the solves of ``"auto"``'s and ``"second-order"``'s
states, are preconditioned by the nearest speed's factorisation of ``K(Ω)`` (:mod:`~bladecase.fe.krylov`); the
states are the same to the solvers' tolerances.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp

from ..linalg import SPDFactor, spd_factor
from .centrifugal import SPEED_UNITS, RotationAxis, _Operators, _operators, to_rad_s  # noqa: F401
from .krylov import ReusedFactor
from .model import FEModel

__all__ = ["RotationAxis", "SpinState", "coriolis_matrix", "second_order_state", "spin", "spun_state", "to_rad_s"]

#: The static centrifugal states :func:`spin` solves for (see its ``static``).
STATIC_STATES = ("linear", "second-order", "nonlinear", "auto")


@dataclass(frozen=True, eq=False)
class SpinState:
    """A model linearised about its static centrifugal state at one speed (see the module).

    Attributes
    ----------
    speed : float
        Rotation speed (rad/s).
    axis : RotationAxis
    model : FEModel
        The model with ``K`` replaced by ``K(Ω) = K + K_σ − Ω² M⊥`` (``K_T(u₀) − Ω² M⊥`` about a nonlinear state;
        ``M`` unchanged).
    displacement : ndarray
        The static centrifugal displacement ``u₀`` on the free dofs (m).
    softening, stiffening : bool
        Whether ``−Ω² M⊥`` and ``K_σ`` are in ``K(Ω)``.
    """

    speed: float
    axis: RotationAxis
    model: FEModel
    displacement: np.ndarray
    softening: bool = True
    stiffening: bool = True
    #: The factorisation of ``model.K`` (``K(Ω)``), made once here: pass it on as ``factor=``.
    factor: SPDFactor | None = None
    #: The static state solved: ``"linear"``, ``"second-order"`` or ``"nonlinear"`` (see :func:`spin`).
    static: str = "linear"
    #: Iterations of the second-order state, Newton iterations of the nonlinear one (0: linear).
    iterations: int = 0
    #: With ``static`` "auto"/"second-order": how much one second-order step moved the linear state (relative, max
    #: norm; what ``"auto"`` decides on).
    second_order_change: float | None = None
    #: The nonlinear state's load steps (0 for the others).
    load_steps: int = 0
    #: Factorisations made for this state (the static solves' and ``K(Ω)``'s).
    factorisations: int = 0
    #: Solves with a factorisation made by the preconditioned conjugate gradients (:mod:`~bladecase.fe.krylov`).
    krylov_iterations: int = 0

    def nodal_displacement(self) -> np.ndarray:
        """``u₀`` at every mesh node ``(n_nodes, 3)`` (zero at clamped nodes)."""
        from .model import node_operator

        dim = self.model.dim
        u = (node_operator(self.model) @ self.displacement).reshape(-1, dim)
        return np.c_[u, np.zeros((u.shape[0], 3 - dim))]


def spin(model: FEModel, speed: float, axis: RotationAxis | None = None, *, softening: bool = True,
         stiffening: bool = True, factor: SPDFactor | None = None, static: str = "linear",
         previous: Sequence[SpinState] = ()) -> SpinState:
    """The model linearised about its static centrifugal state at ``speed`` (rad/s) about ``axis``.

    Parameters
    ----------
    model : FEModel
        The model at rest (``K``, ``M`` of its mesh, in metres).
    speed : float
        Rotation speed, rad/s (:func:`to_rad_s` converts rpm).
    axis : RotationAxis
        Default: the z axis through the origin.
    softening, stiffening : bool
        Include spin softening ``−Ω² M⊥`` and the stress stiffness ``K_σ`` (both by default).
    factor : SPDFactor
        ``K``'s factorisation, reused when ``softening`` is off (the static solve is then with ``K``).
    static : {"linear", "second-order", "nonlinear", "auto"}
        The static centrifugal state: ``"linear"``, ``(K − Ω² M⊥) u₀ = Ω² f₁`` (the linear prestress of ANSYS;
        ``K(Ω) = K + K_σ(u₀) − Ω² M⊥``); ``"second-order"``, the fixed point of ``(K + K_σ(u) − Ω² M⊥) u =
        Ω² f₁`` — the tension the load creates also resists the bending it causes on a leaned, swept or twisted
        blade; ``"nonlinear"``, the geometrically nonlinear state (large rotations, the follower centrifugal load:
        :func:`~bladecase.fe.nonlinear_static.nonlinear_state`) with ``K(Ω) = K_T(u₀) − Ω² M⊥``, its full tangent
        — CalculiX's ``NLGEOM`` static step and ``PERTURBATION`` frequencies (on the demo blade leaned 30 mm at
        10 000 rpm: within 0.01 % of them for f1–f4, where the second-order state is 3.9 % off f3); ``"auto"``, the
        linear state unless one second-order step moves it by more than 1 %, then the nonlinear state. Both
        ``softening`` and ``stiffening`` are needed by ``"nonlinear"`` (``"second-order"`` and ``"auto"`` stay linear
        without).
    previous : sequence of SpinState
        This model's states about the same axis at other speeds (a sweep's speeds before this one): the nonlinear
        state starts from their nonlinear states (:func:`~bladecase.fe.nonlinear_static.nonlinear_state`'s
        ``previous``), and the nearest one's factorisation of ``K(Ω)`` preconditions the conjugate gradients of the
        static solves (:class:`~bladecase.fe.krylov.ReusedFactor`): the same state to the solvers' tolerance, with
        fewer factorisations (:attr:`SpinState.factorisations`).

    Raises
    ------
    ValueError
        An axis a 2-D (plane) model cannot spin about (tilted, or in the plane but offset out of it: see
        :class:`RotationAxis`); a speed that is negative or not finite; a speed at which ``K − Ω² M⊥`` is no
        longer positive definite (the blade diverges under spin softening: the message gives the speed); a
        nonlinear state that does not converge (the message gives the speed reached and the residual); ``previous``
        not states of this model about this axis.

    Examples
    --------
    A 1 m steel beam of 20 mm square section along x, spun about z: its first flapwise frequency (motion along
    the axis) at λ = Ω √(ρAL⁴/EI) = 2 is 4.1373 / 3.5160 = 1.177 times the one at rest (Hodges & Rutkowski;
    1.175 on this coarse 20-cell beam, 1.176 on 40 cells):

    >>> import numpy as np
    >>> from skfem import MeshTet
    >>> from bladecase.fe import Mesh, assemble
    >>> from bladecase.linalg import lowest_modes
    >>> m = MeshTet.init_tensor(np.linspace(0, 1, 21), *2 * [np.linspace(-0.01, 0.01, 3)])
    >>> mesh = Mesh(m.p.T.copy(), {"tetra": m.t.T.copy()}, dim=3, groups={"root": np.flatnonzero(m.p[0] == 0)})
    >>> beam = assemble(mesh, "steel")
    >>> speed = 2 * np.sqrt(beam.material.E * 0.02**2 / 12 / beam.material.rho)   # λ = 2 (rad/s)
    >>> state = spin(beam, speed, RotationAxis((0, 0, 0), (0, 0, 1)))
    >>> rest = lowest_modes(beam.K, beam.M, 2)[0]
    >>> spun = lowest_modes(state.model.K, state.model.M, 2, factor=state.factor)[0]
    >>> round(float(np.sqrt(spun[1] / rest[1])), 3)
    1.175
    """
    if not isinstance(model, FEModel):
        raise ValueError(f"model must be a bladecase FEModel, got {type(model).__name__}")
    omega = to_rad_s(speed)
    if static not in STATIC_STATES:
        raise ValueError(f"static must be one of {', '.join(map(repr, STATIC_STATES))}, got {static!r}")
    axis = axis if axis is not None else RotationAxis()
    if not isinstance(axis, RotationAxis):
        raise ValueError(f"axis must be a RotationAxis, got {type(axis).__name__}")
    if omega == 0.0:
        return SpinState(0.0, axis, model, np.zeros(model.n_dofs), softening, stiffening, factor)
    if static == "nonlinear" and not (softening and stiffening):
        raise ValueError("static = 'nonlinear' solves the large-deflection state with its follower centrifugal load: "
                         "its tangent holds the stress stiffness and the spin softening, so softening and stiffening "
                         "must both be on (or use static = 'linear')")
    near = _nearest(previous, model, axis, omega)
    ops = _operators(model, axis)
    w2 = omega * omega
    rpm = omega * 60 / (2 * math.pi)
    iterations, change, steps, used, K = 0, None, 0, "linear", None
    nearest = next((s.factor for s in near if s.factor is not None), None)
    solver = ReusedFactor(nearest)
    made = krylov = 0
    if static != "nonlinear":
        if not softening and factor is None:
            factor, made = spd_factor(model.K, "K"), 1
        # "auto" decides on the probe's states solved to PROBE_RTOL, the state kept solved again to LINEAR_RTOL
        probe = PROBE_RTOL if static == "auto" and stiffening and softening and nearest is not None else LINEAR_RTOL
        u0 = _linear_state(model, ops, w2, softening, factor, omega, solver, probe)
    if static in ("second-order", "auto") and stiffening and softening:
        change, step = _second_order_step(model, ops, w2, u0, solver, probe)
        # "auto": when the state moves with its own stress stiffness, its rotations matter too
        used = static if static == "second-order" else AUTO_STATE if change > AUTO_RTOL else "linear"
        if used == "linear" and probe != LINEAR_RTOL:
            u0 = _linear_state(model, ops, w2, softening, factor, omega, solver, LINEAR_RTOL)
        if used == "second-order":
            u0, iterations = _second_order(model, ops, w2, step, omega, change, solver)
    made, krylov = made + solver.factorisations, solver.iterations
    if used == "nonlinear" or static == "nonlinear":
        from .nonlinear_static import nonlinear_state

        state = nonlinear_state(model, omega, axis, preconditioner=nearest if nearest is not None else solver.factor,
                                previous=[(s.speed, s.displacement) for s in near if s.static == "nonlinear"])
        u0, K, iterations, steps, used = state.displacement, state.tangent, state.iterations, state.steps, "nonlinear"
        made, krylov = made + state.factorisations, krylov + state.krylov_iterations
    if K is None:
        K = model.K
        if stiffening:
            K = K + ops.stress_stiffness(u0)
        if softening:
            K = K - w2 * ops.M_perp
        K = sp.csr_array(0.5 * (K + K.T))
    try:
        tangent = spd_factor(K, "K(Ω)")
    except ValueError:
        raise ValueError(f"at {omega:.6g} rad/s ({rpm:.6g} rpm) the blade is unstable: its stiffness about the "
                         "centrifugal state, K + K_σ − Ω² M⊥, is not positive definite (spin softening beats the "
                         "stiffening); check the speed, the rotation axis and the mesh's length unit") from None
    out = SpinState(omega, axis, replace(model, K=K), u0, softening, stiffening, tangent, used, iterations, change,
                    steps, made + 1, krylov)
    _SPUN[out.model] = (omega, axis, u0, used)
    return out


#: The state each model :func:`spin` returned was linearised about, weakly keyed by that model: :func:`spun_state`.
_SPUN: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def spun_state(model: FEModel) -> tuple[float, RotationAxis, np.ndarray, str] | None:
    """``(speed, axis, displacement, static)`` of the centrifugal state a model :func:`spin` returned is linearised
    about (``displacement`` on its free dofs, ``static`` the state solved: ``"linear"``, ``"second-order"`` or
    ``"nonlinear"``); ``None`` for a model at rest or not from :func:`spin` in this process (what the results
    draw the prestress of a study at speed from, without solving it again).

    >>> from bladecase.fe import Mesh, assemble
    >>> from skfem import MeshTet
    >>> m = MeshTet.init_tensor(np.linspace(0, 0.1, 4), *2 * [np.linspace(0, 0.01, 2)])
    >>> rest = assemble(Mesh(m.p.T, {"tetra": m.t.T}, dim=3, groups={"root": np.flatnonzero(m.p[0] == 0)}), "steel")
    >>> state = spin(rest, 1000.0, RotationAxis((0, 0, 0), (0, 0, 1)))
    >>> spun_state(rest) is None, spun_state(state.model)[3], spun_state(state.model)[2] is state.displacement
    (True, 'linear', True)
    """
    return _SPUN.get(model)


#: Relative residual to which a static state's linear solve is taken when the conjugate gradients solve it
#: (:class:`~bladecase.fe.krylov.ReusedFactor`; a factorisation solves it to round-off).
LINEAR_RTOL = 1e-11
#: ``static = "auto"`` with ``previous`` states: the relative residual of the conjugate gradients of the linear and
#: the second-order step it decides on (the change, compared with :data:`AUTO_RTOL`, to about this); the linear
#: state, when kept, is solved again to :data:`LINEAR_RTOL`.
PROBE_RTOL = 1e-6


def _linear_state(model: FEModel, ops: _Operators, w2: float, softening: bool, factor, omega: float,
                  solver: ReusedFactor, rtol: float = LINEAR_RTOL) -> np.ndarray:
    """``(K − Ω² M⊥) u₀ = Ω² f₁`` (``K u₀ = Ω² f₁`` without ``softening``, with ``factor``, ``K``'s)."""
    if not softening:
        return factor.solve(w2 * ops.f1)
    A = sp.csr_array(model.K - w2 * ops.M_perp)
    try:  # definite below the first mode's speed; past it (slender blades) indefinite but regular
        return solver.solve(A, w2 * ops.f1, rtol, "K - Ω² M⊥")
    except ValueError:
        rpm = omega * 60 / (2 * math.pi)
        raise ValueError(f"at {omega:.6g} rad/s ({rpm:.6g} rpm) K − Ω² M⊥ is singular: the speed is a "
                         "critical speed of the blade's spin softening; choose another speed") from None


def _nearest(previous, model: FEModel, axis: RotationAxis, omega: float) -> list[SpinState]:
    """``previous`` (:func:`spin`) checked, the nearest speed first."""
    states = list(previous) if previous is not None else []
    for i, s in enumerate(states):
        if not isinstance(s, SpinState) or s.model.n_dofs != model.n_dofs:
            raise ValueError(f"previous[{i}] must be a SpinState of this model ({model.n_dofs} free dofs) from "
                             f"spin, got {type(s).__name__}")
        if not (np.allclose(s.axis.origin, axis.origin) and np.allclose(s.axis.direction, axis.direction)):
            raise ValueError(f"previous[{i}] spins about another axis ({s.axis}) than this state ({axis}): "
                             "pass states about the same axis")
    return sorted((s for s in states if s.speed > 0), key=lambda s: abs(s.speed - omega))


#: ``static = "auto"``: the linear state is kept when one step of the second-order iteration moves it by less than
#: this (relative, max norm); else :data:`AUTO_STATE` is solved.
AUTO_RTOL = 1e-2
#: The state ``static = "auto"`` solves past :data:`AUTO_RTOL`: the geometrically nonlinear one (CalculiX's NLGEOM
#: to 1e-4 on the demo blade where the second-order state is 1 to 4 % off f2–f4; docs/rotation.md).
AUTO_STATE = "nonlinear"


def _second_order_step(model: FEModel, ops: _Operators, w2: float, u: np.ndarray, solver: ReusedFactor,
                       rtol: float = LINEAR_RTOL) -> tuple[float, np.ndarray]:
    """One step of the second-order iteration from ``u``: ``(relative change (max norm), new state)``."""
    A = sp.csr_array(model.K + ops.stress_stiffness(u) - w2 * ops.M_perp)
    new = solver.solve(A, w2 * ops.f1, rtol, "K + K_σ − Ω² M⊥")
    return float(np.abs(new - u).max()) / max(float(np.abs(new).max()), 1e-300), new


def _second_order(model: FEModel, ops: _Operators, w2: float, u: np.ndarray, omega: float, change: float,
                  solver: ReusedFactor, rtol: float = 1e-6, max_iter: int = 30) -> tuple[np.ndarray, int]:
    """The fixed point of ``(K + K_σ(u) − Ω² M⊥) u = Ω² f₁`` from its first step ``u`` (which moved the linear state
    by ``change``): ``(u, iterations)``."""
    for k in range(1, max_iter + 1):
        if change <= rtol:
            return u, k
        change, u = _second_order_step(model, ops, w2, u, solver)
    raise ValueError(f"the second-order centrifugal state did not converge in {max_iter} iterations at {omega:.6g} "
                     f"rad/s (last relative change {change:.2e}): use static = 'linear' or 'nonlinear'")


def coriolis_matrix(model: FEModel, axis: RotationAxis, speed: float) -> sp.csr_array:
    """The Coriolis (gyroscopic) matrix ``G = 2Ω ∫ ρ (a × u̇)·v`` on the free dofs (skew-symmetric): the vibration
    about the centrifugal state is ``M ü + G u̇ + K(Ω) u = 0``.  Left out of :func:`spin`'s ``K(Ω)``; measure its
    effect with it (a quadratic eigenproblem, e.g. on a modal basis)."""
    omega = to_rad_s(speed)
    ops = _operators(model, axis)
    a = axis.direction
    skew = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])[: ops.dim, : ops.dim]
    G = sp.csr_array(sp.kron(ops.Ms, 2.0 * omega * skew, format="csr"))
    return sp.csr_array(G[ops.free][:, ops.free])


def second_order_state(model: FEModel, speed: float, axis: RotationAxis | None = None) -> tuple[SpinState, int]:
    """``spin(model, speed, axis, static="second-order")`` and its iteration count."""
    state = spin(model, speed, axis, static="second-order")
    return state, state.iterations
