"""The rotating frame of a spinning model: the axis (:class:`RotationAxis`), speeds in rad/s (:func:`to_rad_s`) and
the centrifugal operators of a model about an axis at unit speed — ``M⊥``, ``f₁`` and the stress stiffness of a
displacement — which the linearised state (:mod:`~bladecase.fe.rotation`) and the geometrically nonlinear one
(:mod:`~bladecase.fe.nonlinear_static`) both use."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..checks import finite
from .model import FEModel

#: Rotation-speed units and their factor to rad/s.
SPEED_UNITS = {"rad/s": 1.0, "rpm": 2.0 * math.pi / 60.0, "hz": 2.0 * math.pi}


def to_rad_s(value: float, unit: str = "rad/s") -> float:
    """A rotation speed in ``unit`` (``"rad/s"``, ``"rpm"``, ``"hz"``) in rad/s.

    >>> round(to_rad_s(17188.7, "rpm"), 1)   # NASA Rotor 37's design speed
    1800.0
    """
    key = unit.lower() if isinstance(unit, str) else unit
    if key not in SPEED_UNITS:
        raise ValueError(f"speed unit must be one of {', '.join(map(repr, SPEED_UNITS))}, got {unit!r}")
    x = finite("speed", value)
    if x < 0:
        raise ValueError(f"speed must be >= 0, got {value!r}")
    return x * SPEED_UNITS[key]


@dataclass(frozen=True)
class RotationAxis:
    """The rotation axis: a point ``origin`` and a ``direction`` (normalised here); 2 numbers are ``(x, y)``, the
    ``z`` component 0.

    A 2-D (plane) model lies in the plane ``z = 0`` and moves in it only: it can spin about an axis only if the
    centrifugal load stays in its plane, i.e. about an axis perpendicular to the plane (direction ``(0, 0, ±1)``,
    the blade turning in its own plane; the origin's ``z`` does not matter: it only slides the point along the
    axis) or an axis in the plane (direction ``(dx, dy, 0)``) through it (origin ``z = 0``: the plane holds the
    axis, like a meridional section).  Any other axis, tilted or offset out of the plane, would load the model
    out of its plane, which it cannot carry: :meth:`check_plane` refuses it (``ValueError`` naming the axis and
    the valid ones) instead of dropping the out-of-plane part; :func:`spin` and :func:`coriolis_matrix` call it.

    >>> RotationAxis((0, 0, 0), (0, 0, 2)).direction.tolist()
    [0.0, 0.0, 1.0]
    >>> RotationAxis((0, 0, 0.1), (1, 0, 0)).check_plane(2)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: a 2-D (plane) model lies in the plane z = 0 and cannot spin about an axis offset out of it: ...
    >>> RotationAxis((0, 0, 0.1), (0, 0, 1)).check_plane(2).origin.tolist()   # perpendicular: any origin
    [0.0, 0.0, 0.1]
    """

    origin: np.ndarray = (0.0, 0.0, 0.0)
    direction: np.ndarray = (0.0, 0.0, 1.0)

    def __post_init__(self):
        o = np.asarray(self.origin, dtype=float).ravel()
        d = np.asarray(self.direction, dtype=float).ravel()
        if o.size == 2:
            o = np.r_[o, 0.0]
        if d.size == 2:
            d = np.r_[d, 0.0]
        if o.size != 3 or not np.all(np.isfinite(o)):
            raise ValueError(f"rotation axis origin must be 2 or 3 finite numbers, got {self.origin!r}")
        norm = float(np.linalg.norm(d)) if d.size == 3 and np.all(np.isfinite(d)) else 0.0
        if norm == 0.0:
            raise ValueError(f"rotation axis direction must be 2 or 3 finite numbers, not all zero, got "
                             f"{self.direction!r}")
        object.__setattr__(self, "origin", o)
        object.__setattr__(self, "direction", d / norm)

    def check_plane(self, dim: int, scale: float = 1.0) -> RotationAxis:
        """This axis if a model of dimension ``dim`` can spin about it, else ``ValueError`` (see the class): a 3-D
        model about any axis; a 2-D (plane) model, lying in ``z = 0``, about an axis perpendicular to its plane
        (any origin) or in its plane through it (origin ``z = 0``, to ``1e-12 scale``; ``scale``: the model's
        size, m).  A tilted axis or one offset out of the plane would put part of the centrifugal load out of the
        plane, where a plane model has no displacement to carry it."""
        if dim != 2:
            return self
        d, o = self.direction, self.origin
        normal = max(abs(d[0]), abs(d[1])) <= 1e-12
        in_plane = abs(d[2]) <= 1e-12
        valid = ("a 2-D model spins about an axis perpendicular to its plane (direction (0, 0, 1), any origin) or "
                 "about an axis in its plane through it (direction (dx, dy, 0) with origin z = 0)")
        direction = f"({', '.join(f'{x:.6g}' for x in d)})"
        if not (normal or in_plane):
            raise ValueError(f"a 2-D (plane) model lies in the plane z = 0 and cannot spin about a tilted axis: "
                             f"direction {direction} (normalised) is neither perpendicular to the plane nor in "
                             f"it, and would load the model out of its plane; {valid}")
        if in_plane and abs(o[2]) > 1e-12 * max(float(scale), float(np.abs(o).max()), 1e-300):
            raise ValueError(f"a 2-D (plane) model lies in the plane z = 0 and cannot spin about an axis offset out "
                             f"of it: origin z = {o[2]:.6g} with a direction in the plane {direction} puts its "
                             f"centrifugal load out of the plane; {valid}")
        return self

    def projector(self, dim: int) -> np.ndarray:
        """``P⊥ = I − a aᵀ`` on the model's ``dim`` displacement components."""
        return (np.eye(3) - np.outer(self.direction, self.direction))[:dim, :dim]

    def radius(self, x: np.ndarray) -> np.ndarray:
        """Distance of the points ``x`` (n, 3) from the axis."""
        r = np.asarray(x, dtype=float) - self.origin
        return np.linalg.norm(r - np.outer(r @ self.direction, self.direction), axis=1)


class _Operators:
    """What a model needs at every speed: the basis, ``M⊥``, ``f₁`` (Ω = 1) and the stress integration."""

    def __init__(self, model: FEModel, axis: RotationAxis):
        from .assembly import _basis, _scalar_mass

        mesh = model.mesh
        points = np.asarray(mesh.points, dtype=float)
        basis, _, _ = _basis(mesh, points, model.dim, model.order)
        dim = model.dim
        if dim * basis.N != model.dofs.n_total:
            raise ValueError(f"the model's dof numbering ({model.dofs.n_total} dofs) is not its mesh's "
                             f"({dim * basis.N}): rebuild the model from its mesh")
        axis.check_plane(dim, float(np.abs(points).max(initial=0.0)))
        self.basis, self.dim, self.free = basis, dim, model.dofs.fe_index
        self.depth = model.thickness if dim == 2 else 1.0
        self.lam, self.mu = model.material.lame(model.plane if dim == 2 else None)
        Ms = _scalar_mass(basis, model.mass, model.order)
        Ms = sp.diags_array(Ms) if not sp.issparse(Ms) else Ms
        Ms = sp.csr_array(Ms) * (model.material.rho * self.depth)
        self.Ms = Ms  # ρ ∫ φ_a φ_b (scalar, all dofs): M⊥, f₁ and the Coriolis matrix are made from it
        P = axis.projector(dim)
        positions = np.zeros((basis.N, 3))
        positions[:, :dim] = basis.doflocs.T
        r_perp = ((positions - axis.origin) @ (np.eye(3) - np.outer(axis.direction, axis.direction)))[:, :dim]
        f1 = (Ms @ r_perp).ravel()  # ∫ ρ P⊥(x − o)·v, numbered dim·s + c
        m_perp = sp.csr_array(sp.kron(Ms, P, format="csr"))
        self.f1 = f1[self.free]
        self.M_perp = sp.csr_array(m_perp[self.free][:, self.free])

    def stress_stiffness(self, u_free: np.ndarray) -> sp.csr_array:
        """``K_σ`` (free dofs) of the stress of the displacement ``u_free``."""
        from .assembly import CHUNK_CELLS, _gradients, _index_type

        basis, dim = self.basis, self.dim
        u = np.zeros(dim * basis.N)
        u[self.free] = u_free
        U = u.reshape(-1, dim)[basis.element_dofs.T]  # (e, a, i)
        nel, nb = basis.nelems, basis.Nbfun
        data = np.empty((nel, nb, nb))
        for start in range(0, nel, CHUNK_CELLS):
            cells = slice(start, min(start + CHUNK_CELLS, nel))
            G = _gradients(basis, cells)  # (e, a, k, q)
            grad = np.einsum("eakq,eai->eikq", G, U[cells])
            eps = 0.5 * (grad + grad.transpose(0, 2, 1, 3))
            sigma = 2.0 * self.mu * eps
            trace = np.einsum("eiiq->eq", eps)
            for i in range(dim):
                sigma[:, i, i, :] += self.lam * trace
            data[cells] = np.einsum("eklq,eakq,eblq,eq->eab", sigma, G, G, basis.dx[cells], optimize=True)
        data = 0.5 * (data + data.transpose(0, 2, 1)) * self.depth
        n = basis.N
        ed = basis.element_dofs.T.astype(_index_type(n))
        rows = np.broadcast_to(ed[:, :, None], data.shape).ravel()
        cols = np.broadcast_to(ed[:, None, :], data.shape).ravel()
        Ks = sp.csr_array(sp.coo_array((data.ravel(), (rows, cols)), shape=(n, n)))
        full = sp.csr_array(sp.kron(Ks, sp.eye_array(dim), format="csr"))
        return sp.csr_array(full[self.free][:, self.free])


_CACHE: dict[tuple, tuple[FEModel, _Operators]] = {}


def _operators(model: FEModel, axis: RotationAxis) -> _Operators:
    """The operators of ``model`` about ``axis``, kept for the last few models (one per speed sweep)."""
    key = (id(model), *axis.origin.tolist(), *axis.direction.tolist())
    hit = _CACHE.get(key)
    if hit is not None and hit[0] is model:
        return hit[1]
    ops = _Operators(model, axis)
    if len(_CACHE) >= 4:
        _CACHE.pop(next(iter(_CACHE)))
    _CACHE[key] = (model, ops)
    return ops
