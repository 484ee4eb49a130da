"""The geometrically nonlinear static state: large rotations, small strains (total Lagrangian, St-Venant–Kirchhoff).

The equivalent of CalculiX's ``*STEP, NLGEOM`` / ``*STATIC`` (then ``*FREQUENCY`` with ``PERTURBATION``) and of
ANSYS's ``NLGEOM,ON`` static solve before a prestressed modal analysis, for a linear elastic material.

With the displacement ``u`` of the reference (undeformed) configuration ``X``: the deformation gradient
``F = I + ∇u``, the Green strain ``E = ½(FᵀF − I)``, the second Piola–Kirchhoff stress ``S = λ tr(E) I + 2μ E``
(the linear elastic law on Green's strain: St-Venant–Kirchhoff, right for small strains and large rotations) and
the internal forces ``r(u) = ∫ F S : ∇v``.  The body spinning at ``Ω`` about the axis through ``o`` along ``a``
(``P⊥ = I − a aᵀ``) carries the centrifugal load of its *deformed* position, a follower load,
``f(u) = Ω² ∫ ρ P⊥ (X + u − o)·v = Ω² (f₁ + M⊥ u)`` (``M⊥`` and ``f₁`` of :mod:`~bladecase.fe.rotation`: the mass's
own integration, consistent or lumped), plus an optional dead load ``p``.  The static state solves

    ``R(u) = r(u) − Ω² (f₁ + M⊥ u) − p = 0``

by Newton's method with the consistent tangent ``∂R/∂u = K_T(u) − Ω² M⊥``, where ``K_T(u) = ∫ (Fᵀ∇δu)ˢ : C :
(Fᵀ∇v)ˢ + S : ∇δuᵀ∇v`` holds the material stiffness, the initial-displacement (large-rotation) stiffness (the
``F`` inside the first term) and the initial-stress (geometric) stiffness (the second term), and ``−Ω² M⊥`` is the
load stiffness of the follower load (spin softening).  The load is stepped (``Ω²`` and ``p`` together, by a load
factor ``t`` from 0 to 1, in one step unless it fails), each step's Newton iteration starting from the path
extrapolated from the last two states, its first step shortened to the minimum of the energy along it (exact: the
energy is a quartic), else with full steps; a step that does not converge either way is halved, and a step below
:data:`MIN_STEP` raises ``ValueError`` with the speed (load) reached and the residual.  The vibration about the
state then uses ``K_T(u) − Ω² M⊥`` (:func:`bladecase.fe.rotation.spin` with ``static="nonlinear"``).

Assembly: the weak forms are those of :func:`svk_forms` (scikit-fem ``@LinearForm``/``@BilinearForm`` with the
current displacement as a ``w`` field); they are integrated by one batched product over all cells on the model's
own scikit-fem basis (its curved isoparametric cells, its quadrature), as :func:`~bladecase.fe.assemble` and
:mod:`~bladecase.fe.rotation` do, and scattered into a sparsity pattern computed once (the tests check both give
the same vectors and matrices).  At ``u = 0`` the tangent is the model's ``K`` to round-off.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..linalg import Factor, spd_factor  # noqa: F401  (spd_factor: the docstring's example)
from .centrifugal import RotationAxis, _operators, to_rad_s
from .krylov import ReusedFactor
from .model import FEModel

__all__ = ["MIN_STEP", "NonlinearState", "StVenantKirchhoff", "nonlinear_state", "svk_forms"]

#: The smallest load step (fraction of the full ``Ω²`` and load) before the solve gives up.
MIN_STEP = 1e-3
#: Newton iterations per attempt at a load step (two attempts: with and without the first step's line search).  A
#: slender body's full load often takes 15 to 20 (a thin swept strip spun until its linear state bends it by half its
#: length: 15 in one step; with 10 a step, 169 iterations in 15 steps).
MAX_ITER = 20
#: A load step that converged in this many iterations or fewer is followed by one twice as long.
FAST = 5
#: A Newton correction below this fraction of the state (max norms) ends the iteration (see :func:`nonlinear_state`).
UTOL = 1e-10
#: Above this relative residual the first Newton step of a load step is shortened to the energy's minimum along it.
LINE_SEARCH = 1e-3
#: A Newton step solved by the preconditioned conjugate gradients is solved to a relative residual of the Newton
#: residual (relative; looser for the last step, :func:`_forcing`), at most this
#: (:class:`~bladecase.fe.krylov.ReusedFactor`).
KRYLOV_RTOL = 1e-2


class StVenantKirchhoff:
    """Internal forces ``r(u)`` and tangent ``K_T(u)`` of a model's St-Venant–Kirchhoff body (module docstring) on
    its free dofs, from its own scikit-fem basis (``model`` linear elastic, its ``λ``, ``μ``; a 2-D model's plane
    stress or strain and thickness as :func:`~bladecase.fe.assemble` has them)."""

    def __init__(self, model: FEModel, basis=None):
        from .assembly import _basis, _index_type

        if basis is None:
            basis = _basis(model.mesh, np.asarray(model.mesh.points, dtype=float), model.dim, model.order)[0]
        dim = model.dim
        if dim * basis.N != model.dofs.n_total:
            raise ValueError(f"the model's dof numbering ({model.dofs.n_total} dofs) is not its mesh's "
                             f"({dim * basis.N}): rebuild the model from its mesh")
        self.basis, self.dim, self.free, self.n = basis, dim, model.dofs.fe_index, model.n_dofs
        self.depth = model.thickness if dim == 2 else 1.0
        self.lam, self.mu = model.material.lame(model.plane if dim == 2 else None)
        nel, nb = basis.nelems, basis.Nbfun
        index = np.full(dim * basis.N, -1, dtype=np.int64)
        index[self.free] = np.arange(self.n)
        full = (dim * basis.element_dofs.T[:, :, None] + np.arange(dim)).reshape(nel, nb * dim)
        self.local = index[full]  # (cells, local dofs): free dof or -1
        # the sparsity pattern on the free dofs, once: each kept local entry's slot in the CSR data
        rows = np.broadcast_to(self.local[:, :, None], (nel, nb * dim, nb * dim)).ravel()
        cols = np.broadcast_to(self.local[:, None, :], (nel, nb * dim, nb * dim)).ravel()
        self.keep = (rows >= 0) & (cols >= 0)
        key = rows[self.keep] * self.n + cols[self.keep]
        unique, self.slot = np.unique(key, return_inverse=True)
        itype = _index_type(max(unique.size, self.n + 1))
        self.indices = (unique % self.n).astype(itype)
        self.indptr = np.r_[0, np.cumsum(np.bincount(unique // self.n, minlength=self.n))].astype(itype)
        self.nnz = unique.size

    def _cells(self, u_free: np.ndarray) -> np.ndarray:
        u = np.zeros(self.dim * self.basis.N)
        u[self.free] = u_free
        return u.reshape(-1, self.dim)[self.basis.element_dofs.T]  # (e, a, i)

    def _kinematics(self, U: np.ndarray, cells: slice):
        """``(G, F, S)`` at the quadrature points of a batch of cells: basis gradients ``(e, a, k, q)``, the
        deformation gradient and the 2nd Piola–Kirchhoff stress ``(e, i, k, q)``."""
        from .assembly import _gradients

        G = _gradients(self.basis, cells)
        H = np.einsum("eai,eakq->eikq", U[cells], G)  # ∇u
        E = 0.5 * (H + H.transpose(0, 2, 1, 3) + np.einsum("eikq,eilq->eklq", H, H))  # not ½(FᵀF − I): no cancellation
        F = H
        for i in range(self.dim):
            F[:, i, i, :] += 1.0
        S = 2.0 * self.mu * E
        trace = np.einsum("eiiq->eq", E)
        for i in range(self.dim):
            S[:, i, i, :] += self.lam * trace
        return G, F, S

    def forces(self, u_free: np.ndarray) -> np.ndarray:
        """``r(u) = ∫ F S : ∇v`` on the free dofs."""
        from .assembly import CHUNK_CELLS

        U = self._cells(u_free)
        nel, nb = self.basis.nelems, self.basis.Nbfun
        out = np.empty((nel, nb, self.dim))
        for start in range(0, nel, CHUNK_CELLS):
            cells = slice(start, min(start + CHUNK_CELLS, nel))
            G, F, S = self._kinematics(U, cells)
            P = np.einsum("eilq,elkq->eikq", F, S)
            out[cells] = np.einsum("eikq,eakq,eq->eai", P, G, self.basis.dx[cells], optimize=True)
        return self._scatter(out.reshape(nel, -1))

    def _scatter(self, local: np.ndarray) -> np.ndarray:
        kept = self.local >= 0
        return np.bincount(self.local[kept], weights=local[kept] * self.depth, minlength=self.n)

    def tangent(self, u_free: np.ndarray, forces: bool = False):
        """``K_T(u)`` (CSR, free dofs, symmetric); with ``forces``, ``(K_T(u), r(u))`` from one pass."""
        from .assembly import CHUNK_CELLS

        U = self._cells(u_free)
        dim, nel, nb = self.dim, self.basis.nelems, self.basis.Nbfun
        nloc = nb * dim
        data = np.empty((nel, nloc, nloc))
        r = np.empty((nel, nloc)) if forces else None
        for start in range(0, nel, CHUNK_CELLS):
            cells = slice(start, min(start + CHUNK_CELLS, nel))
            G, F, S = self._kinematics(U, cells)
            dx = self.basis.dx[cells]
            ne, nq = dx.shape
            D = np.einsum("eikq,eakq->eaiq", F, G)  # (F ∇φ_a)_i: the variation of E is sym(Fᵀ ∇(φ_a e_i))
            A = np.matmul((D * dx[:, None, None, :]).reshape(ne, nloc, nq),
                          D.reshape(ne, nloc, nq).transpose(0, 2, 1)).reshape(ne, nb, dim, nb, dim)
            Ke = self.lam * A + self.mu * A.transpose(0, 1, 4, 3, 2)  # λ D_ai D_bj + μ D_aj D_bi
            GG = np.einsum("eakq,ebkq,eq->eabq", G, G, dx, optimize=True)
            FF = np.einsum("eikq,ejkq->eqij", F, F)
            Ke += self.mu * np.matmul(GG.reshape(ne, nb * nb, nq), FF.reshape(ne, nq, dim * dim)) \
                .reshape(ne, nb, nb, dim, dim).transpose(0, 1, 3, 2, 4)  # μ (FFᵀ)_ij ∇φ_a·∇φ_b
            geometric = np.einsum("eklq,eakq,eblq,eq->eab", S, G, G, dx, optimize=True)  # S : ∇φ_a ⊗ ∇φ_b
            for i in range(dim):
                Ke[:, :, i, :, i] += geometric
            Ke = Ke.reshape(ne, nloc, nloc)
            data[cells] = 0.5 * (Ke + Ke.transpose(0, 2, 1))
            if forces:
                P = np.einsum("eilq,elkq->eikq", F, S)
                r[cells] = np.einsum("eikq,eakq,eq->eai", P, G, dx, optimize=True).reshape(ne, nloc)
        values = np.bincount(self.slot, weights=data.ravel()[self.keep], minlength=self.nnz) * self.depth
        K = sp.csr_array((values, self.indices, self.indptr), shape=(self.n, self.n))
        return (K, self._scatter(r)) if forces else K


def svk_forms(lam: float, mu: float):
    """``(residual, tangent)``: the internal forces and the tangent stiffness of a St-Venant–Kirchhoff body as
    scikit-fem forms on an ``ElementVector`` basis, the current displacement passed as the field ``u``
    (``residual.assemble(basis, u=basis.interpolate(x))``, ``tangent.assemble(basis, u=...)``) — the weak forms
    :class:`StVenantKirchhoff` integrates in one batched product (module docstring).

    >>> import numpy as np
    >>> from skfem import Basis, ElementTetP1, ElementVector, MeshTet
    >>> from skfem.models.elasticity import linear_elasticity
    >>> basis = Basis(MeshTet(), ElementVector(ElementTetP1()))
    >>> residual, tangent = svk_forms(1.0, 0.5)
    >>> zero = basis.interpolate(np.zeros(basis.N))
    >>> K0 = tangent.assemble(basis, u=zero)     # at rest: linear elasticity
    >>> bool(abs(K0 - linear_elasticity(1.0, 0.5).assemble(basis)).max() < 1e-12)
    True
    """
    from skfem import BilinearForm, LinearForm
    from skfem.helpers import ddot, grad, mul, trace, transpose

    def state(w):
        H = grad(w["u"])
        dim = H.shape[0]
        eye = np.zeros_like(H)
        for i in range(dim):
            eye[i, i] = 1.0
        F = eye + H
        E = 0.5 * (mul(transpose(F), F) - eye)
        return eye, F, lam * trace(E) * eye + 2.0 * mu * E

    @LinearForm
    def residual(v, w):
        _, F, S = state(w)
        return ddot(mul(F, S), grad(v))

    @BilinearForm
    def tangent(du, v, w):
        eye, F, S = state(w)
        dE = 0.5 * (mul(transpose(F), grad(du)) + mul(transpose(grad(du)), F))
        dS = lam * trace(dE) * eye + 2.0 * mu * dE
        return ddot(mul(grad(du), S) + mul(F, dS), grad(v))

    return residual, tangent


@dataclass(frozen=True, eq=False)
class NonlinearState:
    """A converged geometrically nonlinear static state (module docstring).

    Attributes
    ----------
    displacement : ndarray
        ``u`` on the free dofs.
    tangent : scipy.sparse.csr_array
        ``K_T(u) − Ω² M⊥`` at the state (free dofs, symmetric): the stiffness of the vibration about it.
    iterations : int
        Newton iterations, all load steps and retries together.
    steps : int
        Load steps tried (those cut in half and a warm start's attempt included).
    residual : float
        ``‖R(u)‖ / ‖Ω² (f₁ + M⊥ u) + p‖`` at the state.
    factorisations : int
        Tangents factorised (one per Newton iteration with ``krylov=False``).
    krylov_iterations : int
        Solves with a factorisation made by the preconditioned conjugate gradients.
    preconditioner : Factor or None
        The last factorisation used (made here, or the one given): pass it on as ``preconditioner=`` to the state
        at a nearby speed.
    warm : bool
        Whether the state was reached from ``previous`` states (else from rest, by load steps).
    """

    displacement: np.ndarray
    tangent: sp.csr_array
    iterations: int
    steps: int
    residual: float
    factorisations: int = 0
    krylov_iterations: int = 0
    preconditioner: Factor | None = None
    warm: bool = False


class _Problem:
    """``R(u, t) = r(u) − t (Ω² (f₁ + M⊥ u) + p)`` and its Jacobian ``K_T(u) − t Ω² M⊥`` at load factor ``t``."""

    def __init__(self, body: StVenantKirchhoff, ops, w2: float, load: np.ndarray):
        self.body, self.ops, self.w2, self.load = body, ops, w2, load

    def external(self, u: np.ndarray, t: float) -> np.ndarray:
        f = t * self.load
        if self.ops is not None:
            f = f + (t * self.w2) * (self.ops.f1 + self.ops.M_perp @ u)
        return f

    def residual(self, u: np.ndarray, t: float) -> tuple[np.ndarray, float]:
        """``(R, ‖R‖ / ‖f‖)`` (internal forces only, no tangent)."""
        f = self.external(u, t)
        R = self.body.forces(u) - f
        return R, float(np.linalg.norm(R)) / max(float(np.linalg.norm(f)), 1e-300)

    def linearised(self, u: np.ndarray, t: float) -> tuple[sp.csr_array, np.ndarray, float]:
        """``(∂R/∂u, R, ‖R‖ / ‖f‖)`` from one pass over the cells."""
        K, r = self.body.tangent(u, forces=True)
        f = self.external(u, t)
        R = r - f
        if self.ops is not None:
            K = sp.csr_array(K - (t * self.w2) * self.ops.M_perp)
        return K, R, float(np.linalg.norm(R)) / max(float(np.linalg.norm(f)), 1e-300)


def nonlinear_state(model: FEModel, speed: float = 0.0, axis: RotationAxis | None = None, *,
                     load: np.ndarray | None = None, rtol: float = 1e-9, steps: int = 1,
                     max_iter: int = MAX_ITER, previous: Sequence[tuple[float, np.ndarray]] = (),
                     preconditioner: Factor | None = None, krylov: bool = True) -> NonlinearState:
    """The geometrically nonlinear static state of ``model`` under its centrifugal load at ``speed`` (rad/s) about
    ``axis`` and a dead ``load`` (free dofs, N), by Newton's method with load stepping (module docstring).

    Parameters
    ----------
    model : FEModel
        The model at rest (linear elastic material, metres).
    speed : float
        Rotation speed, rad/s (0: no centrifugal load).
    axis : RotationAxis
        The rotation axis (required with a speed).
    load : ndarray or None
        A dead load on the free dofs (its direction does not follow the deformation).
    rtol : float
        Converged when ``‖R(u)‖ <= rtol ‖Ω² (f₁ + M⊥ u) + p‖`` (Euclidean norms on the free dofs), or when a Newton
        correction is below :data:`UTOL` of the state and the residual below ``√rtol`` (the residual's round-off
        floor: on a slender body internal forces much larger than the load cancel at each node).
    steps : int
        Load steps to start with (equal in ``Ω²`` and ``p``). Each step: Newton's iteration from the last state
        extrapolated along the path, its first step shortened to the energy's minimum along it
        (:func:`_line_search`); failing that in ``max_iter`` iterations, plain Newton from the same start; failing
        both, the step is halved.  A step that converges in :data:`FAST` iterations or fewer is followed by one
        twice as long.
    previous : sequence of (speed, displacement)
        Converged states of the same model, axis and dead load at other speeds (rad/s; e.g. a sweep's speeds before
        this one): the iteration starts at the full load from their extrapolation, linear in ``Ω²`` through the two
        nearest in ``Ω²`` (one: scaled by ``Ω²`` without a dead load, else as it is); if it does not converge, from
        rest by load steps as without.
    preconditioner : Factor
        A factorisation of a nearby tangent (e.g. the previous speed's ``K(Ω)``, :attr:`SpinState.factor
        <bladecase.fe.rotation.SpinState.factor>`, or :attr:`NonlinearState.preconditioner`) to precondition the
        Newton steps' conjugate gradients from the start.
    krylov : bool
        Solve the Newton steps by the conjugate gradients preconditioned with the last factorisation, factorising
        a tangent only when they are slow (module docstring); ``False``: factorise every tangent.

    Raises
    ------
    ValueError
        No load; a step below :data:`MIN_STEP` of the full load does not converge (the message gives the speed and
        the load fraction reached and the last residual); ``previous`` without a speed, or not (speed, displacement)
        pairs of this model.

    Examples
    --------
    A steel cantilever 1 m × 20 mm × 20 mm under a tip load ``P`` with ``PL²/EI = 1``: the elastica's tip deflection
    is ``0.3017 L`` where the linear solution says ``L/3``, and the tip moves ``0.0566 L`` towards the root:

    >>> import numpy as np
    >>> from skfem import MeshTet
    >>> from bladecase.fe import Mesh, assemble
    >>> t = MeshTet.init_tensor(np.linspace(0, 1, 21), *2 * [np.linspace(-0.01, 0.01, 3)])
    >>> mesh = Mesh(t.p.T.copy(), {"tetra": t.t.T.copy()}, dim=3, groups={"root": np.flatnonzero(t.p[0] == 0)})
    >>> beam = assemble(mesh, "steel", order=2)
    >>> tip = (beam.dofs.coords[:, 0] == 1.0) & (beam.dofs.direction == 2)
    >>> P = beam.material.E * 0.02**4 / 12                  # PL²/EI = 1
    >>> load = np.where(tip, P / tip.sum(), 0.0)
    >>> state = nonlinear_state(beam, load=load)
    >>> linear = spd_factor(beam.K).solve(load)[tip].mean()
    >>> round(float(linear), 4), round(float(state.displacement[tip].mean()), 4)   # this mesh: 0.8 % stiff
    (0.3306, 0.2994)
    """
    omega = to_rad_s(speed)
    rpm = omega * 60 / (2 * math.pi)
    ops = None
    if omega > 0:
        if not isinstance(axis, RotationAxis):
            raise ValueError(f"a speed needs axis=RotationAxis(origin, direction), got {axis!r}")
        ops = _operators(model, axis)
    p = np.zeros(model.n_dofs) if load is None else np.asarray(load, dtype=float).ravel()
    if p.shape != (model.n_dofs,) or not np.all(np.isfinite(p)):
        raise ValueError(f"load must be {model.n_dofs} finite numbers (one per free dof), got shape {p.shape}")
    if ops is None and not p.any():
        raise ValueError("nonlinear_state needs a load: a speed (with its axis) or a nonzero dead load")
    problem = _Problem(_body(model, ops), ops, omega * omega, p)

    def reached(t):
        return (f"{omega * math.sqrt(t):.6g} rad/s ({rpm * math.sqrt(t):.6g} rpm) of {omega:.6g} rad/s, "
                if ops is not None else "") + f"load factor {t:.4g}"

    solver = ReusedFactor(preconditioner, krylov=krylov)
    start = _warm_start(previous, omega, model.n_dofs, bool(p.any()))

    def done(u, tangent, res, iterations, taken, warm):
        return NonlinearState(u, sp.csr_array(0.5 * (tangent + tangent.T)), iterations, taken, res,
                              solver.factorisations, solver.iterations, solver.factor, warm)

    iterations = taken = 0
    if start is not None:  # the full load from the other speeds' states; failing that, from rest
        trial, iterations, tangent, res = _attempt(problem, start, 1.0, rtol, max_iter, solver)
        taken = 1
        if tangent is not None:
            return done(trial, tangent, res, iterations, taken, True)
    u = np.zeros(model.n_dofs)
    t, dt = 0.0, 1.0 / max(int(steps), 1)
    last = None  # the last state and its load factor: the next step starts from their extrapolation
    while True:
        target = min(1.0, t + dt)
        start = u if last is None else u + (u - last[0]) * ((target - t) / (t - last[1]))
        taken += 1
        trial, k, tangent, res = _attempt(problem, start, target, rtol, max_iter, solver)
        iterations += k
        if tangent is not None:
            last, u, t = (u, t), trial, target
            if t >= 1.0:
                return done(u, tangent, res, iterations, taken, False)
            dt = 2.0 * dt if k <= FAST else dt
            continue
        dt *= 0.5
        if dt < MIN_STEP:
            raise ValueError(f"the geometrically nonlinear static state did not converge: reached {reached(t)}; "
                             f"the step to {reached(target)} failed (relative residual {res:.3g} after {k} Newton "
                             f"iterations, steps down to {MIN_STEP:g} of the load): the load may pass a limit "
                             "(buckling, or spin softening beating the stiffness); check the speed, the axis and "
                             "the mesh's length unit, or use static = 'second-order'")


def _warm_start(previous, omega: float, n: int, dead: bool) -> np.ndarray | None:
    """The start at the full load from ``previous`` (speed, displacement) states (:func:`nonlinear_state`), ``None``
    without."""
    states = list(previous) if previous is not None else []
    if not states:
        return None
    if omega <= 0:
        raise ValueError("previous states start a spinning body's state: give a speed (and its axis), or no previous")
    known = []
    for i, state in enumerate(states):
        try:
            w, u = state
        except (TypeError, ValueError):
            raise ValueError(f"previous[{i}] must be a (speed in rad/s, displacement) pair, got {state!r}") from None
        w, u = to_rad_s(w), np.asarray(u, dtype=float).ravel()
        if w <= 0 or u.shape != (n,) or not np.all(np.isfinite(u)):
            raise ValueError(f"previous[{i}] must be a speed > 0 (rad/s) and {n} finite displacements (one per free "
                             f"dof of this model), got speed {w!r} and shape {u.shape}")
        known.append((w * w, u))
    known.sort(key=lambda s: abs(s[0] - omega * omega))
    (x1, u1), w2 = known[0], omega * omega
    for x2, u2 in known[1:]:
        if x2 != x1:  # linear in Ω² through the nearest two
            return u1 + (u2 - u1) * ((w2 - x1) / (x2 - x1))
    return u1 if dead else u1 * (w2 / x1)


def _attempt(problem: _Problem, start: np.ndarray, t: float, rtol: float, max_iter: int, solver: ReusedFactor):
    """One load step to ``t`` from ``start``: Newton with the first step's line search, then without if that
    shortened it and failed: ``(u, iterations, tangent or None, residual)``."""
    iterations = 0
    for search in (True, False):
        trial, k, tangent, res, shortened = _newton(problem, start, t, rtol, max_iter, search, solver)
        iterations += k
        if tangent is not None or not shortened:
            break
    return trial, iterations, tangent, res


def _newton(problem: _Problem, u: np.ndarray, t: float, rtol: float, max_iter: int, search: bool,
            solver: ReusedFactor):
    """Newton's iteration at load factor ``t`` from ``u``: ``(u, iterations, tangent, residual, shortened)``, the
    tangent at the converged ``u`` (``None``: not converged in ``max_iter`` iterations), ``shortened`` whether the
    line search shortened the first step (else an attempt without it would repeat this one)."""
    still = shortened = False
    for k in range(max_iter + 1):
        A, R, res = problem.linearised(u, t)
        if not np.isfinite(res):
            return u, k, None, res, shortened
        if res <= rtol or (still and res <= math.sqrt(rtol)):
            return u, k, A, res, shortened
        if k == max_iter:
            break
        try:
            step = solver.solve(A, R, _forcing(res, rtol), "K_T − Ω² M⊥")
        except ValueError:  # singular: a limit or bifurcation point on the path (the step is cut)
            return u, k + 1, None, res, shortened
        if search and k == 0 and res > LINE_SEARCH:
            alpha = _line_search(problem, u, step, float(step @ R), t)
            step, shortened = step * alpha, alpha != 1.0
        u = u - step
        still = float(np.abs(step).max()) <= UTOL * max(float(np.abs(u).max()), 1e-300)
    return u, max_iter, None, res, shortened


def _forcing(res: float, rtol: float) -> float:
    """The relative residual to solve a Newton step to by the conjugate gradients at the relative residual ``res``:
    ``res`` (the quadratic convergence), or looser when the step's own error, ``η res``, can be a tenth of ``rtol``
    and its quadratic term is below it; at most :data:`KRYLOV_RTOL`."""
    return max(min(KRYLOV_RTOL, max(res, 0.1 * rtol / res)), 1e-13)


def _line_search(problem: _Problem, u: np.ndarray, step: np.ndarray, g0: float, t: float) -> float:
    """The length ``α`` of the Newton step ``u − α step`` that minimises the total potential energy along it.

    The problem is conservative (a hyperelastic body; the centrifugal load of a symmetric ``M⊥`` and a dead load
    derive from potentials), and St-Venant–Kirchhoff's energy is a polynomial of degree 4 in ``u``: along the step
    the energy's slope ``g(α) = step · R(u − α step)`` is a cubic with ``g(0) = g0`` and, the tangent being exact,
    ``g'(0) = −g0``; ``g(1)`` and ``g(½)`` fix it, and ``α`` is its first positive root (within [1/64, 4]).  The
    full step is kept when ``|g(1)| <= ½ g0``, or when ``g0 <= 0`` (an indefinite tangent: no descent direction).
    From the unloaded state the linear step of a spinning blade overshoots several times (its tangent lacks the
    stress stiffening of the load it applies): the demo blade at 10 000 rpm converges in 10 iterations with this,
    in 17 to 35 without."""
    def slope(alpha):
        return float(step @ problem.residual(u - alpha * step, t)[0])

    if g0 <= 0:
        return 1.0
    g1 = slope(1.0)
    if abs(g1) <= 0.5 * g0:
        return 1.0
    gh = slope(0.5)
    c2 = 8.0 * gh - 4.0 * g0 - g1
    c3 = g1 - c2
    roots = np.roots([c3, c2, -g0, g0])
    real = roots[(np.abs(roots.imag) <= 1e-9 * np.abs(roots).max()) & (roots.real > 0)].real
    return float(np.clip(real.min(), 1 / 64, 4.0)) if real.size else (1.0 if g1 > 0 else 0.5)


_BODIES: dict[int, tuple[FEModel, StVenantKirchhoff]] = {}


def _body(model: FEModel, ops=None) -> StVenantKirchhoff:
    """The model's :class:`StVenantKirchhoff`, kept for the last few models (a speed sweep reuses it)."""
    hit = _BODIES.get(id(model))
    if hit is not None and hit[0] is model:
        return hit[1]
    body = StVenantKirchhoff(model, None if ops is None else ops.basis)
    if len(_BODIES) >= 4:
        _BODIES.pop(next(iter(_BODIES)))
    _BODIES[id(model)] = (model, body)
    return body
