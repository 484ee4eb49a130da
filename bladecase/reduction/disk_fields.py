"""A state of the reduced bladed disk (:func:`~bladecase.reduction.disk.disk_model`) on every dof of every sector:
the displacement field of the whole annulus, contacts pressed included, without assembling it.

The reduced disk's coordinates are its interior modal coordinates ``x`` (the standing waves ``ψ_a`` of the cyclic
modes) and its contact forces ``λ`` (``N·m``, blade-major; the casing pushes each contact back along its normal).
The field of the annulus is

    ``u = Σ_a ψ_a x_a − Σ_c χ_c λ_c``,   ``χ_c = K⁻¹f_c − Σ_a ψ_a W_{ac}/ω_a²``,

``χ_c`` the residual static field of a unit outward force ``f_c`` on contact ``c`` (its static field with the part of
the kept modes removed: the mode-acceleration correction whose contact values are the model's ``H_s``). A unit force
on contact ``i`` of blade ``l`` is the sum of its cyclic harmonics ``(1/N) Σ_k e^{i(j−l)kα}`` on the sectors ``j``;
each harmonic's answer is the sector's cyclic static response ``X_k`` (:attr:`~bladecase.reduction.disk.Diameter
.static`, the factorisation of nodal diameter ``k`` already used for ``G_k``), so the static part of sector ``j`` is
``(1/N) Σ_k c_k Re(e^{ijkα} X_k Λ_k)``, ``Λ_k = Σ_l e^{−ilkα} λ_l`` (``c_k = 1`` for ``k = 0, N/2``, else 2: the
harmonics ``k`` and ``N − k`` together). Restricted to the contacts it gives back the model's own contact
displacements ``Wᵀx − H_sλ`` exactly (:func:`sector_fields`).

>>> import scipy.sparse as sp
>>> from bladecase.fe.cyclic import CyclicSector
>>> from bladecase.reduction.disk import disk_model
>>> K = np.array([[4.7, -1.0, 0.0, -0.7], [-1.0, 3.0, -2.0, 0.0], [0.0, -2.0, 2.0, 0.0], [-0.7, 0.0, 0.0, 0.7]])
>>> ring = CyclicSector(sp.csr_array(K), sp.csr_array(np.diag([2.0, 0.5, 0.0, 0.0])), 6, left=[0], right=[3])
>>> disk = disk_model(ring, [[0.0], [0.0], [1.0], [0.0]], 0.1, count=1)
>>> x, lam = np.linspace(0.1, 0.2, disk.system.n), np.r_[1.0, np.zeros(5)]       # blade 0 pressed by 1 N
>>> u = sector_fields(disk, x, lam)                                              # (sectors, dofs, 1)
>>> tips = u[:, 2, 0]                                                            # each blade's tip dof
>>> bool(np.allclose(tips, disk.system.W.T @ x - disk.system.flexibility @ lam, rtol=0, atol=1e-13))
True
"""

from __future__ import annotations

import numpy as np

from .disk import DiskModel, _scale

__all__ = ["contact_displacements", "sector_fields"]


def _columns(a, rows: int, name: str) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    a = a.reshape(-1, 1) if a.ndim == 1 else a
    if a.ndim != 2 or a.shape[0] != rows or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be a finite ({rows},) or ({rows}, frames) array, got shape {a.shape}")
    return a


def sector_fields(disk: DiskModel, x, forces) -> np.ndarray:
    """``(N, n_dofs, F)``: every sector's displacements, each in its own frame (sector ``j`` is sector 0 turned by
    ``jα``: :func:`~bladecase.fe.cyclic_waves.rotate_field` turns it into the global frame), for the reduced
    states ``x`` (``(n,)`` or ``(n, F)``) and contact forces ``forces`` (``(N·m,)`` or ``(N·m, F)``, blade-major,
    ``≥ 0`` pushing the contacts back; zeros: every contact open) — module docstring. Velocities: pass ``v`` and
    ``λ'``.

    Raises ``ValueError`` for shapes that do not fit the model, or a model whose nodal diameters lack their static
    responses (built before they were kept)."""
    s, N, m = disk.system, disk.sectors, disk.per_blade
    x = _columns(x, s.n, "x")
    lam = _columns(forces, N * m, "forces")
    if x.shape[1] != lam.shape[1]:
        raise ValueError(f"x and forces must have the same number of frames, got {x.shape[1]} and {lam.shape[1]}")
    if any(d.static is None for d in disk.diameters.values()):
        raise ValueError("the disk model's nodal diameters carry no static responses: rebuild it with disk_model")
    alpha, j = disk.alpha, np.arange(N)
    xe = x + (s.W @ lam) / np.diag(s.S)[:, None]  # the kept modes' part of the static fields moved onto x
    out = np.zeros((N, disk.contact.shape[0], x.shape[1]))
    for a, (k, i, wave) in enumerate(disk.labels):
        if wave == 1:
            continue
        phase = np.exp(1j * j * k * alpha)[:, None, None]
        c = xe[a].astype(complex)
        if 2 * k % N:
            c = c - 1j * xe[disk.index(k, i, 1)]  # Re(z c) = Re z·x_cos + Im z·x_sin
        phi = disk.diameters[k].shapes[:, i] * _scale(k, N)
        out += (phase * (phi[:, None] * c[None, :])[None]).real
    L = lam.reshape(N, m, -1)
    for k, d in disk.diameters.items():
        Lk = np.einsum("l,lif->if", np.exp(-1j * j * k * alpha), L)  # (m, F)
        Xl = d.static @ Lk  # (n_dofs, F)
        ck = 1.0 if 2 * k % N == 0 else 2.0
        out -= ck / N * (np.exp(1j * j * k * alpha)[:, None, None] * Xl[None]).real
    return out


def contact_displacements(disk: DiskModel, fields: np.ndarray) -> np.ndarray:
    """``(N·m, F)``: each blade's contact displacements (blade-major) read on the sectors' fields of
    :func:`sector_fields` through the sector's contact map — for a state of the model, ``Wᵀx − H_sλ``.

    >>> import scipy.sparse as sp
    >>> from bladecase.fe.cyclic import CyclicSector
    >>> from bladecase.reduction.disk import disk_model
    >>> s = CyclicSector(sp.csr_array([[3.0, -1.0, -1.0], [-1.0, 1.0, 0.0], [-1.0, 0.0, 1.0]]),
    ...                  sp.csr_array(np.diag([1.0, 0.0, 0.0])), 4, left=[0], right=[2])
    >>> d = disk_model(s, [[0.0], [1.0], [0.0]], 0.1, 1)
    >>> contact_displacements(d, sector_fields(d, np.zeros(4), [2.0, 0, 0, 0]))[:, 0].round(12).tolist()
    [-2.0, 0.0, 0.0, 0.0]
    """
    fields = np.asarray(fields, dtype=float)
    if fields.ndim != 3 or fields.shape[:2] != (disk.sectors, disk.contact.shape[0]):
        raise ValueError(f"fields must be ({disk.sectors}, {disk.contact.shape[0]}, frames), got {fields.shape}")
    return np.einsum("dc,jdf->jcf", disk.contact, fields).reshape(disk.sectors * disk.per_blade, -1)

