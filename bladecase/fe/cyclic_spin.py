"""A spinning tuned bladed disk from one sector: the centrifugal state with the cyclic faces tied.

The centrifugal load of a tuned disk is the same on every sector: its static state is a nodal-diameter-0 state of
the whole disk, so the sector's static solve needs its faces tied by the ``k = 0`` constraint (``u_right =
R_α u_left``); a sector spun alone (:func:`~bladecase.fe.rotation.spin` on its model) has free faces and is not
that state.  :func:`cyclic_spin` solves the linear prestress of :mod:`~bladecase.fe.rotation` on the sector under
that constraint — ``T₀ᵀ(K − Ω² M⊥)T₀ q = Ω² T₀ᵀ f₁``, ``u₀ = T₀ q`` — and gives the sector whose stiffness is
``K(Ω) = K + K_σ(u₀) − Ω² M⊥`` (stress stiffening and spin softening, Coriolis coupling left out as in
:func:`~bladecase.fe.rotation.spin`): :func:`~bladecase.fe.cyclic.cyclic_modes` of it are the modes of every nodal
diameter at that speed, the Campbell diagram of each nodal diameter over speeds (:func:`cyclic_campbell`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp

from ..linalg import spd_factor, symmetric_factor
from .centrifugal import _operators, to_rad_s
from .cyclic import CyclicSector, cyclic_basis, cyclic_modes, nodal_diameters
from .model import FEModel

__all__ = ["CyclicSpin", "cyclic_campbell", "cyclic_spin"]


@dataclass(frozen=True, eq=False)
class CyclicSpin:
    """A sector about its centrifugal state (:func:`cyclic_spin`).

    Attributes
    ----------
    speed : float
        Ω (rad/s).
    sector : CyclicSector
        The sector with ``K(Ω)`` (its faces and ``M`` unchanged).
    displacement : ndarray
        The static centrifugal displacement ``u₀`` on the sector's free dofs (m), both faces included.
    """

    speed: float
    sector: CyclicSector
    displacement: np.ndarray


def cyclic_spin(model: FEModel, sector: CyclicSector, speed: float, *, softening: bool = True,
                stiffening: bool = True) -> CyclicSpin:
    """The sector ``sector`` of ``model`` (:func:`~bladecase.fe.cyclic.fe_sector`) linearised about the disk's
    centrifugal state at ``speed`` (rad/s) about the sector's axis (module docstring).

    Raises
    ------
    ValueError
        ``sector`` not made from ``model``, a bad speed, or a speed at which ``K(Ω)`` is not positive definite.
    """
    if not isinstance(model, FEModel) or sector.axis is None or sector.n_dofs != model.n_dofs:
        raise ValueError("cyclic_spin needs the FE model and its sector from fe_sector(model, ...)")
    omega = to_rad_s(speed)
    if omega == 0.0:
        return CyclicSpin(0.0, sector, np.zeros(model.n_dofs))
    ops = _operators(model, sector.axis)
    w2 = omega * omega
    T, _ = cyclic_basis(sector, 0)
    A = sp.csr_array(model.K - w2 * ops.M_perp) if softening else model.K
    A0 = sp.csr_array(T.T @ A @ T)
    A0 = sp.csr_array(0.5 * (A0 + A0.T))
    try:
        solver = spd_factor(A0, "K - Ω² M⊥ (nodal diameter 0)")
    except ValueError:
        solver = symmetric_factor(A0, "K - Ω² M⊥ (nodal diameter 0)",
                                  hint=f"{omega:.6g} rad/s is a critical speed of the disk's spin softening")
    u0 = T @ solver.solve(T.T @ (w2 * ops.f1))
    K = model.K
    if stiffening:
        K = K + ops.stress_stiffness(u0)
    if softening:
        K = K - w2 * ops.M_perp
    K = sp.csr_array(0.5 * (K + K.T))
    return CyclicSpin(omega, replace(sector, K=K), u0)


def cyclic_campbell(model: FEModel, sector: CyclicSector, speeds, count: int = 4,
                    diameters=None) -> dict[int, np.ndarray]:
    """The Campbell diagram of every nodal diameter: ``{k: (len(speeds), count) frequencies (Hz)}``, each speed's
    frequencies of diameter ``k`` ascending (not followed by mode shape).

    >>> import numpy as np
    >>> from skfem import MeshHex
    >>> from bladecase.fe import Mesh, assemble
    >>> from bladecase.fe.cyclic import fe_sector
    >>> from bladecase.fe.rotation import RotationAxis
    >>> t = MeshHex.init_tensor(np.linspace(-0.005, 0.005, 2), np.linspace(0.1, 0.3, 5), np.linspace(-0.2, 0.2, 3))
    >>> r, a = t.p[1], t.p[2]                    # a 4-sector annulus, 0.1 to 0.3 m, about x
    >>> pts = np.c_[t.p[0], -r * np.sin(a * np.pi / 4 / 0.2), r * np.cos(a * np.pi / 4 / 0.2)]
    >>> mesh = Mesh(pts, {"hexahedron": t.t.T}, dim=3, groups={"hub": np.flatnonzero(r == 0.1)})
    >>> model = assemble(mesh, "steel", order=1, clamp="hub")
    >>> f = cyclic_campbell(model, fe_sector(model, 4, RotationAxis((0, 0, 0), (1, 0, 0))), [0.0, 500.0], 1)
    >>> bool(f[0][1, 0] > f[0][0, 0])            # the axial (umbrella) mode stiffens with speed
    True
    """
    ks = nodal_diameters(sector.sectors) if diameters is None else list(diameters)
    out = {int(k): np.empty((len(speeds), count)) for k in ks}
    for i, w in enumerate(speeds):
        spun = cyclic_spin(model, sector, w).sector
        for k in ks:
            out[int(k)][i] = cyclic_modes(spun, k, count).frequencies
    return out
