"""A mistuned bladed disk against the casing: the reduced disk of :func:`~bladecase.reduction.disk.disk_model` (every
blade its own massless contact) with each blade's stiffness scaled, and its engine-order load.

**Mistuning.** Blade ``j``'s stiffness times ``1 + δ_j`` adds ``δ_j K_b`` to sector ``j`` (``K_b``: the blade's
part of the sector stiffness, :func:`~bladecase.reduction.mistuning_fe.blade_stiffness`). In the disk's
coordinates (its standing waves ``ψ_a``, sector ``j``'s part ``Ψ_j``) the open-phase stiffness becomes

    ``S(δ) = diag(ω²) + Σ_j δ_j B_j``,   ``B_j = Ψ_jᵀ K_b Ψ_j``   (:func:`blade_coupling`, :func:`mistuned_disk`).

The contacts' residual flexibility ``H_s`` is the tuned one: exact when the blade's stiffness that mistuning scales
does not touch the contact's own (the massless tip's spring to its blade) and every mode is kept; otherwise its
error is of the order of ``δ`` times the residual part, small beside the modes' part for small deviations.

**Engine-order load** (:func:`engine_order_load`): blade ``j`` loaded by ``Re(f e^{2πiej/N} e^{iΩt})`` (``f`` on the
sector's dofs: the same pattern as :func:`~bladecase.reduction.mistuning.forced_response`) is a single harmonic
``k = e mod N``: its modal load ``F̂_a = Σ_j ψ_a(j)ᵀ f e^{2πiej/N}`` and the contacts' residual static response
``r_l = e^{ilkα} X_kᴴ f − (Wᵀ S₀⁻¹ F̂)_l`` (reciprocity with the contacts' static fields ``X_k``; the part of the
kept modes removed).

>>> import scipy.sparse as sp
>>> from bladecase.fe.cyclic import CyclicSector
>>> from bladecase.reduction.disk import disk_model
>>> K = np.array([[4.7, -1.0, 0.0, -0.7], [-1.0, 3.0, -2.0, 0.0], [0.0, -2.0, 2.0, 0.0], [-0.7, 0.0, 0.0, 0.7]])
>>> ring = CyclicSector(sp.csr_array(K), sp.csr_array(np.diag([2.0, 0.5, 0.0, 0.0])), 4, left=[0], right=[3])
>>> disk = disk_model(ring, [[0.0], [0.0], [1.0], [0.0]], 0.1, count=2)
>>> Kb = np.zeros((4, 4)); Kb[:2, :2] = [[1.0, -1.0], [-1.0, 1.0]]      # the disk-blade spring
>>> B = blade_coupling(disk, Kb)
>>> s = mistuned_disk(disk, B, [0.0, 0.0, 0.0, 0.0])
>>> bool(np.allclose(s.S, disk.system.S))
True
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

from ..nsm.massless.nodes import NodalSystem
from .disk import DiskModel, _scale

__all__ = ["blade_coupling", "engine_order_load", "mistuned_disk", "sector_waves"]


def sector_waves(disk: DiskModel, j: int) -> np.ndarray:
    """``Ψ_j`` (``n_dofs × n``): every coordinate's wave on sector ``j``, in its own frame."""
    N = disk.sectors
    out = np.empty((disk.contact.shape[0], disk.labels.shape[0]))
    for a, (k, i, wave) in enumerate(disk.labels):
        z = disk.diameters[k].shapes[:, i] * np.exp(1j * j * k * disk.alpha) * _scale(k, N)
        out[:, a] = z.imag if wave else z.real
    return out


def blade_coupling(disk: DiskModel, blade_stiffness) -> np.ndarray:
    """``(N, n, n)``: ``B_j = Ψ_jᵀ K_b Ψ_j`` for every blade (module docstring), computed once for all samples."""
    Kb = sp.csr_array(blade_stiffness, dtype=float)
    dofs = disk.contact.shape[0]
    if Kb.shape != (dofs, dofs):
        raise ValueError(f"blade_stiffness must be {dofs} × {dofs} (the sector's dofs), got {Kb.shape}")
    out = []
    for j in range(disk.sectors):
        P = sector_waves(disk, j)
        B = P.T @ (Kb @ P)
        out.append(0.5 * (B + B.T))
    return np.array(out)


def mistuned_disk(disk: DiskModel, coupling: np.ndarray, delta, gap=None) -> NodalSystem:
    """The disk's :class:`NodalSystem` with blade ``j``'s stiffness × ``(1 + delta[j])`` (module docstring);
    ``gap``: each contact's clearance (``(N·m,)``, blade-major; default the disk's)."""
    d = np.asarray(delta, dtype=float)
    if d.shape != (disk.sectors,) or not np.all(np.isfinite(d)) or np.any(d <= -1):
        raise ValueError(f"delta must be {disk.sectors} finite deviations > -1 (blade j's stiffness × (1 + delta[j]))"
                         f", got shape {d.shape}")
    s = disk.system
    return NodalSystem(s.M, s.S + np.einsum("j,jab->ab", d, coupling), s.W, s.flexibility,
                       s.gap if gap is None else gap,
                       None if not np.isfinite(s.casing).any() else s.casing, nodes=s.nodes)


def engine_order_load(disk: DiskModel, force, order: int) -> tuple[np.ndarray, np.ndarray]:
    """``(F̂, r)``: the modal load (``(n,)`` complex) of engine order ``order`` with blade 0's load ``force`` on the
    sector's dofs, and the contacts' residual static response to it (``(N·m,)`` complex, blade-major) — module
    docstring."""
    f = np.asarray(force, dtype=float)
    N = disk.sectors
    if f.shape != (disk.contact.shape[0],) or not np.all(np.isfinite(f)):
        raise ValueError(f"force must be a finite vector on the sector's {disk.contact.shape[0]} dofs, got {f.shape}")
    phase = np.exp(2j * math.pi * int(order) * np.arange(N) / N)
    F = sum(phase[j] * (sector_waves(disk, j).T @ f) for j in range(N))
    k = int(order) % N
    d = disk.diameters[min(k, N - k)]
    X = d.static if k <= N // 2 else np.conj(d.static)
    blade0 = X.conj().T @ f  # (m,): blade 0's contacts under the pattern
    static = (np.exp(1j * np.arange(N) * k * disk.alpha)[:, None] * blade0[None, :]).ravel()
    lam = np.diag(disk.system.S)
    return F, static - disk.system.W.T @ (F / lam)
