"""The whole bladed disk against the casing: a reduced massless-contact model of the annulus built from one
sector's cyclic modes (:func:`disk_model`), without assembling the annulus.

A tuned disk of ``N`` sectors, each blade with ``m`` contacts (one face-mean contact, or every node of its tip),
is, in the massless contact model of theory §8, a structure whose contact dofs carry no inertia. Its every
blade's contacts are their own unilateral constraints: ``N·m`` contacts, a
:class:`~bladecase.nsm.massless.nodes.NodalSystem`, so that the exact simulator, the shooting and Floquet apply
unchanged.

**The basis.** The massless structure (the sector's lumped masses with those of its contact dofs moved to their
neighbours, :func:`massless_sector`) is cyclic: its modes of nodal diameter ``k`` are the sector's modes under
``u_right = e^{ikα} R_α u_left`` (:mod:`bladecase.fe.cyclic`). A complex sector mode ``φ`` (``φᴴMφ = 1``) gives
the annulus' standing waves, sector ``j`` in its own frame

    ``c_j = s Re(φ e^{ijkα})``,   ``s_j = s Im(φ e^{ijkα})``,   ``s = √(2/N)`` (``s = √(1/N)``, one wave, for
    ``k = 0`` and ``k = N/2``),

mass-orthonormal on the annulus (``Σ_j e^{2ijkα} = 0`` for ``2k ≢ 0 mod N``) and eigenvectors of it. The reduced
model keeps these waves for every nodal diameter (``count`` modes each, those below ``cutoff`` Hz): interior
coordinates ``x``, ``M = I``, ``S = diag(ω²)``, and each blade's contact displacements ``W[:, j·m + i]`` (the
sector's contact map on each wave's sector ``j``).

**The contacts' flexibility.** The modes miss the static flexibility of the contact dofs themselves (massless,
infinitely fast) and of the modes left out; it is added as a residual (mode-acceleration) flexibility,
``H_s = C − Wᵀ S⁻¹ W``, with ``C`` the annulus' static compliance between all the blades' contacts. ``C`` is a block
circulant: a force pattern ``F e^{ilkα}`` on the blades ``l`` answers ``G_k F e^{ijkα}``, ``G_k = Wᵀ T_k (T_kᴴ K
T_k)⁻¹ T_kᴴ W`` (the cyclic problem of ``k``, ``G_{N−k} = conj G_k``), so ``C_{j−l} = (1/N) Σ_k G_k e^{i(j−l)kα}``.
Every nodal diameter is one sparse factorisation of its cyclic stiffness, used for both its modes and its ``G_k``.

**Blade shift.** Moving the pattern by ``s`` blades, ``(Px)_j = x_{j+s}``, turns each (cos, sin) pair of nodal
diameter ``k`` by ``θ = skα``: ``(a, b) → (a cos θ + b sin θ, −a sin θ + b cos θ)`` (:meth:`DiskModel.shift`). It
commutes with the model (``S``, ``M``, and ``Wᵀ P = P_blades Wᵀ``, ``H_s`` circulant) — the symmetry the
travelling waves of :mod:`bladecase.nsm.massless.disk_modes` are searched with.

>>> import scipy.sparse as sp
>>> from bladecase.fe.cyclic import CyclicSector
>>> K = np.array([[3.0 + 1.0 + 0.7, -1.0, 0.0, -0.7], [-1.0, 1.0 + 2.0, -2.0, 0.0], [0.0, -2.0, 2.0, 0.0],
...               [-0.7, 0.0, 0.0, 0.7]])          # disk, blade, massless tip, next disk
>>> ring = CyclicSector(sp.csr_array(K), sp.csr_array(np.diag([2.0, 0.5, 0.0, 0.0])), 6, left=[0], right=[3])
>>> disk = disk_model(ring, [[0.0], [0.0], [1.0], [0.0]], 0.1, count=2)
>>> disk.system, disk.labels[:3].tolist()           # 2 modes of each diameter; k = 1, 2: cos and sin
(NodalSystem(n=12, m=6 contacts, gap 0.1–0.1 m, rigid), [[0, 0, 0], [1, 0, 0], [1, 0, 1]])
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from scipy.sparse.linalg import LinearOperator, eigsh

from ..checks import integer
from ..fe import FEModel
from ..fe.cyclic import CyclicSector, _complex_modes, _real_form, nodal_diameters
from ..linalg import spd_factor
from ..nsm.massless.nodes import NodalSystem
from .contact import Contact
from .massless import massless_masses

__all__ = ["DiskModel", "Diameter", "diameter", "disk_model", "massless_sector", "sector_system"]

#: Real forms up to this size are solved densely (a lumped or tiny sector); larger ones by shift-invert Lanczos.
DISK_DENSE = 400


@dataclass(frozen=True, eq=False)
class Diameter:
    """One nodal diameter of the massless sector: ``lam`` (ω², ascending), ``shapes`` (complex sector modes,
    ``φᴴMφ = 1``), ``G`` (``m × m`` complex: the contacts' static compliance under the cyclic constraint of ``k``),
    ``seconds`` (factorisation, modes and compliance); ``static`` (``n_dofs × m`` complex: the sector's static
    response ``X_k`` to each contact's unit force under the cyclic constraint of ``k``, ``G_k = WᵀX_k``; the
    contacts' fields on the mesh, :mod:`bladecase.reduction.disk_fields`)."""

    k: int
    lam: np.ndarray
    shapes: np.ndarray
    G: np.ndarray
    seconds: float
    static: np.ndarray | None = field(default=None, repr=False)


def _check_contact(sector: CyclicSector, W, gap) -> tuple[np.ndarray, np.ndarray]:
    W = np.asarray(W.toarray() if hasattr(W, "toarray") else W, dtype=float)
    W = W.reshape(-1, 1) if W.ndim == 1 else W
    if W.ndim != 2 or W.shape[0] != sector.n_dofs or W.shape[1] == 0 or not np.all(np.isfinite(W)):
        raise ValueError(f"the contact map must be a finite ({sector.n_dofs}, m) array (one column per contact of a "
                         f"blade, on the sector's dofs), got shape {W.shape}")
    faces = np.r_[sector.left, sector.right]
    if np.any(W[faces]):
        raise ValueError("a contact moves a dof of a cyclic face: a blade's contact must lie inside its sector")
    c = np.flatnonzero(np.any(W != 0, axis=1))
    mass = np.asarray(sp.csr_array(sector.M)[c][:, c].toarray())
    if np.any(mass):
        raise ValueError("the sector's contact dofs carry mass: the massless model needs them massless (an FE "
                         "sector: massless_sector(model, sector, contact))")
    gap = np.broadcast_to(np.asarray(gap, dtype=float), (W.shape[1],)).copy()
    return W, gap


def _massless_eigs(Kk, Mk, count: int, factor) -> tuple[np.ndarray, np.ndarray]:
    """The lowest ``count`` eigenpairs of ``K_k φ = ω² M_k φ`` with ``M_k`` singular on the massless dofs: dense
    on the massive dofs with the massless ones condensed (small), else shift-invert Lanczos with the factor."""
    size = Kk.shape[0]
    zero = np.asarray(Mk.diagonal()) == 0
    if size <= DISK_DENSE:
        K, M = Kk.toarray(), Mk.toarray()
        a, z = np.flatnonzero(~zero), np.flatnonzero(zero)
        X = np.linalg.solve(K[np.ix_(z, z)], K[np.ix_(z, a)]) if z.size else np.zeros((0, a.size))
        S = K[np.ix_(a, a)] - K[np.ix_(a, z)] @ X
        lam, va = sla.eigh(0.5 * (S + S.T), M[np.ix_(a, a)], subset_by_index=[0, min(count, a.size) - 1])
        V = np.zeros((size, lam.size))
        V[a], V[z] = va, -X @ va
        return lam, V
    wanted = min(count, size - int(zero.sum()) - 2)
    op = LinearOperator(Kk.shape, matvec=factor.solve, dtype=float)
    v0 = np.random.default_rng(0).standard_normal(size)  # a fixed start: the same modes on every run
    lam, V = eigsh(Kk, k=wanted, M=Mk, sigma=0.0, OPinv=op, which="LM", v0=v0)
    order = np.argsort(lam)
    lam, V = lam[order], V[:, order]
    V = V / np.sqrt(np.einsum("ij,ij->j", V, Mk @ V))
    return lam, V


def diameter(sector: CyclicSector, W, k: int, count: int) -> Diameter:
    """The massless sector's ``count`` lowest modes of nodal diameter ``k`` and its contacts' compliance ``G_k``
    (module docstring), from one factorisation of the cyclic stiffness of ``k``.

    >>> import scipy.sparse as sp
    >>> from bladecase.fe.cyclic import CyclicSector
    >>> s = CyclicSector(sp.csr_array([[3.0, -1.0, -1.0], [-1.0, 1.0, 0.0], [-1.0, 0.0, 1.0]]),
    ...                  sp.csr_array(np.diag([1.0, 0.0, 0.0])), 4, left=[0], right=[2])
    >>> d = diameter(s, [[0.0], [1.0], [0.0]], 0, 1)      # ground spring 1, massless tip on a unit spring
    >>> round(float(d.lam[0]), 12), np.round(d.G.real, 12).tolist()
    (1.0, [[2.0]])
    """
    start = time.perf_counter()
    W = np.asarray(W, dtype=float)
    Kk, Mk, Tr, Ti, real = _real_form(sector, k)
    factor = spd_factor(Kk, f"K of nodal diameter {k}", hint="is the sector clamped (e.g. at its hub)?")
    wanted = count if real else 2 * count + 4
    lam, V = _massless_eigs(Kk, Mk, wanted, factor)
    lam, shapes = _complex_modes(sector, Tr, Ti, lam, V, real, count)
    mk = Tr.shape[1]
    R = np.vstack([Tr.T @ W, -(Ti.T @ W)]) if not real else Tr.T @ W
    X = factor.solve(R)
    X = X.reshape(R.shape)
    if real:
        G = (R.T @ X).astype(complex)
        static = (Tr @ X).astype(complex)
    else:
        br, bi, xr, xi = R[:mk], R[mk:], X[:mk], X[mk:]
        G = R.T @ X + 1j * (br.T @ xi - bi.T @ xr)
        static = (Tr @ xr - Ti @ xi) + 1j * (Ti @ xr + Tr @ xi)  # T z, T = T_r + iT_i, z = x_r + ix_i
    return Diameter(k, lam, shapes, 0.5 * (G + G.conj().T), time.perf_counter() - start, static)


@dataclass(frozen=True, eq=False)
class DiskModel:
    """The reduced annulus (:func:`disk_model`): ``system`` (``N·m`` contacts, blade-major: contact ``j·m + i`` is
    contact ``i`` of blade ``j``); ``labels`` (``n × 3``: each coordinate's nodal diameter, mode index and wave,
    0 cosine, 1 sine); ``diameters`` (``{k: Diameter}``); ``sectors``; ``per_blade`` (``m``); ``contact`` (the
    sector's contact map, ``(n_dofs, m)``); ``compliance`` (``C``, the annulus' static compliance between all the
    contacts); ``seconds``."""

    system: NodalSystem
    labels: np.ndarray
    diameters: dict
    sectors: int
    per_blade: int
    contact: np.ndarray = field(repr=False)
    compliance: np.ndarray = field(repr=False)
    seconds: float = 0.0

    @property
    def alpha(self) -> float:
        """The sector angle ``2π/N`` (rad)."""
        return 2.0 * math.pi / self.sectors

    def index(self, k: int, mode: int = 0, wave: int = 0) -> int:
        """The reduced coordinate of the ``wave`` (0 cosine, 1 sine) of ``mode`` of nodal diameter ``k``."""
        hit = np.flatnonzero((self.labels == (k, mode, wave)).all(axis=1))
        if hit.size != 1:
            raise ValueError(f"the model keeps no wave {wave} of mode {mode} of nodal diameter {k}")
        return int(hit[0])

    def shift(self, s: int) -> np.ndarray:
        """``P``: the reduced coordinates of the pattern moved by ``s`` blades, ``(Pu)_j = u_{j+s}`` (module
        docstring), an ``n × n`` rotation of each (cos, sin) pair."""
        n = self.labels.shape[0]
        P = np.zeros((n, n))
        for a, (k, i, wave) in enumerate(self.labels):
            theta = int(s) * k * self.alpha
            if wave == 1:
                continue
            if 2 * k % self.sectors == 0:  # k = 0 or N/2: one wave, ±1
                P[a, a] = round(math.cos(theta))
                continue
            b = self.index(k, i, 1)
            c, si = math.cos(theta), math.sin(theta)
            P[a, a], P[a, b], P[b, a], P[b, b] = c, si, -si, c
        return P

    def rotating(self, k: int) -> tuple[np.ndarray, int]:
        """``(P, N')`` of a wave of ``k`` nodal diameters (``0 < k < N``; ``k > N/2``: the backward wave of ``N − k``)
        travelling round the disk: blade ``j`` repeats blade 0's motion ``jk/N`` of a period later, so
        ``x(t + T/N') = P x(t)``, ``N' = N/gcd(k, N)``, ``P`` the shift by ``s`` blades, ``sk ≡ −gcd(k, N) mod N``."""
        N = self.sectors
        k = integer("k", k, 1, N - 1, note=f" (a travelling wave on a disk of {N} blades)")
        g = math.gcd(k, N)
        n1 = N // g
        s = (-pow(k // g, -1, n1)) % n1 if n1 > 1 else 0
        return self.shift(s), n1

    def travelling_wave(self, k: int, mode: int = 0) -> tuple[np.ndarray, np.ndarray, float]:
        """``(x₀, v₀, ω)`` of the linear wave of ``mode`` of nodal diameter ``k`` (``0 < k < N``) travelling as
        :meth:`rotating` says, at unit amplitude: ``x(t) = c cos ωt + s sin ωt`` for ``k < N/2``, ``c cos ωt −
        s sin ωt`` for ``k > N/2`` (the backward wave of ``N − k``)."""
        kk = min(k, self.sectors - k)
        if 2 * kk == self.sectors:
            raise ValueError(f"nodal diameter {kk} of a disk of {self.sectors} blades is a standing wave only")
        a, b = self.index(kk, mode, 0), self.index(kk, mode, 1)
        omega = float(np.sqrt(self.system.S[a, a]))
        x0, v0 = np.zeros(self.labels.shape[0]), np.zeros(self.labels.shape[0])
        x0[a] = 1.0
        v0[b] = omega if k < self.sectors / 2 else -omega
        return x0, v0, omega

    def angles(self, offsets=None) -> np.ndarray:
        """Each contact's angle about the engine axis (rad), blade-major: ``jα + offsets[i]`` for contact ``i`` of
        blade ``j`` (``offsets``: the contacts' own angles within blade 0, default 0) — the ``angles`` of
        :func:`~bladecase.nsm.massless.rub.rub_response` for the disk in an out-of-round casing (each blade sees the
        lobes at its own angle).

        >>> import scipy.sparse as sp
        >>> from bladecase.fe.cyclic import CyclicSector
        >>> s = CyclicSector(sp.csr_array([[3.0, -1.0, -1.0], [-1.0, 1.0, 0.0], [-1.0, 0.0, 1.0]]),
        ...                  sp.csr_array(np.diag([1.0, 0.0, 0.0])), 4, left=[0], right=[2])
        >>> np.degrees(disk_model(s, [[0.0], [1.0], [0.0]], 0.1, 1).angles()).round(9).tolist()
        [0.0, 90.0, 180.0, 270.0]
        """
        off = np.zeros(self.per_blade) if offsets is None else np.broadcast_to(
            np.asarray(offsets, dtype=float), (self.per_blade,))
        return (np.arange(self.sectors)[:, None] * self.alpha + off[None, :]).ravel()

    def blade_displacements(self, x) -> np.ndarray:
        """``(N, n_dofs)``: every sector's displacements in its own frame for the reduced state ``x`` (every contact
        open; the contact dofs follow statically)."""
        x = np.asarray(x, dtype=float)
        N = self.sectors
        out = np.zeros((N, self.contact.shape[0]))
        j = np.arange(N)
        for a, (k, i, wave) in enumerate(self.labels):
            phi = self.diameters[k].shapes[:, i]
            z = np.exp(1j * j * k * self.alpha)[:, None] * phi[None, :] * _scale(k, N)
            out += x[a] * (z.imag if wave else z.real)
        return out


def _scale(k: int, N: int) -> float:
    return math.sqrt((1.0 if 2 * k % N == 0 else 2.0) / N)


def disk_model(sector: CyclicSector, contact, gap, count: int = 4, *, cutoff: float | None = None,
               casing=None, diameters=None) -> DiskModel:
    """The reduced massless-contact model of the whole disk from one massless ``sector`` (module docstring).

    Parameters
    ----------
    sector : CyclicSector
        The massless sector: its contact dofs carry no mass (an FE sector: :func:`massless_sector`).
    contact : (n_dofs, m) array_like
        Each contact of a blade as a column on the sector's dofs (``Wᵀu``: its normal displacement).
    gap : float or (m,) array_like
        Each contact's clearance (m), the same on every blade.
    count : int
        Modes kept per nodal diameter.
    cutoff : float or None
        Keep only the modes below this frequency (Hz): with ``count`` large enough, a complete set below it.
    casing : None, float or (m,) array_like
        The casing's stiffness at each contact of a blade (N/m; ``None``: rigid).
    diameters : dict or None
        ``{k: Diameter}`` already computed (:func:`diameter`), reused.

    A lumped disk of 5 blades (disk, blade, massless tip per sector), every mode kept: the residual flexibility is
    the tips' own springs (1/2 each, uncoupled):

    >>> import scipy.sparse as sp
    >>> from bladecase.fe.cyclic import CyclicSector
    >>> K = np.array([[4.7, -1.0, 0.0, -0.7], [-1.0, 3.0, -2.0, 0.0], [0.0, -2.0, 2.0, 0.0], [-0.7, 0.0, 0.0, 0.7]])
    >>> ring = CyclicSector(sp.csr_array(K), sp.csr_array(np.diag([2.0, 0.5, 0.0, 0.0])), 5, left=[0], right=[3])
    >>> disk = disk_model(ring, [[0.0], [0.0], [1.0], [0.0]], 0.1, count=2)
    >>> disk.system.n, bool(np.allclose(disk.system.flexibility, np.eye(5) / 2.0))
    (10, True)
    """
    start = time.perf_counter()
    W, gap = _check_contact(sector, contact, gap)
    count = integer("count", count, 1)
    N, m = sector.sectors, W.shape[1]
    ds = dict(diameters or {})
    for k in nodal_diameters(N):
        if k not in ds:
            ds[k] = diameter(sector, W, k, count)
    alpha = 2.0 * math.pi / N
    j = np.arange(N)
    labels, lam, rows = [], [], []
    for k in nodal_diameters(N):
        d = ds[k]
        for i, l2 in enumerate(d.lam):
            if cutoff is not None and math.sqrt(l2) / (2 * math.pi) >= cutoff:
                continue
            a = W.T @ d.shapes[:, i]  # (m,) complex: blade 0's contacts
            z = (np.exp(1j * j * k * alpha)[:, None] * a[None, :]).ravel() * _scale(k, N)  # blade-major
            for wave in (0, 1) if 2 * k % N else (0,):
                labels.append((k, i, wave))
                lam.append(l2)
                rows.append(z.imag if wave else z.real)
    order = np.argsort(lam, kind="stable")
    labels, lam, Wr = np.array(labels)[order], np.array(lam)[order], np.array(rows)[order]
    C = _circulant(ds, N, m)
    Hs = C - Wr.T @ (Wr / lam[:, None])
    k_c = None if casing is None else np.tile(np.broadcast_to(np.asarray(casing, dtype=float), (m,)), N)
    system = NodalSystem(np.eye(lam.size), np.diag(lam), Wr, Hs, np.tile(gap, N), k_c,
                         nodes=tuple(range(N * m)))
    return DiskModel(system, labels, ds, N, m, W, C, time.perf_counter() - start)


def _circulant(ds: dict, N: int, m: int) -> np.ndarray:
    """``C``: block ``(j, l)`` is ``C_{(j−l) mod N} = (1/N) Σ_k G_k e^{i(j−l)kα}``, ``k`` over ``0 … N−1``."""
    alpha = 2.0 * math.pi / N
    blocks = []
    for d in range(N):
        acc = np.zeros((m, m))
        for k, dk in ds.items():
            term = dk.G * np.exp(1j * d * k * alpha)
            acc += (term.real if 2 * k % N == 0 else 2.0 * term.real)
        blocks.append(acc / N)
    C = np.zeros((N * m, N * m))
    for j in range(N):
        for lb in range(N):
            C[j * m:(j + 1) * m, lb * m:(lb + 1) * m] = blocks[(j - lb) % N]
    return 0.5 * (C + C.T)


def sector_system(sector: CyclicSector, contact, gap, k: int, count: int = 4, casing=None) -> NodalSystem:
    """The massless model of ONE blade moving as a standing wave of nodal diameter ``k = 0`` (all blades in phase)
    or ``k = N/2`` (alternate blades in opposition): the sector's modes of ``k``, its contacts' compliance ``G_k``
    with the modes' part removed — a :class:`NodalSystem` of ``m`` contacts that lives in the sector alone.

    >>> import scipy.sparse as sp
    >>> from bladecase.fe.cyclic import CyclicSector
    >>> s = CyclicSector(sp.csr_array([[3.0, -1.0, -1.0], [-1.0, 1.0, 0.0], [-1.0, 0.0, 1.0]]),
    ...                  sp.csr_array(np.diag([1.0, 0.0, 0.0])), 4, left=[0], right=[2])
    >>> sector_system(s, [[0.0], [1.0], [0.0]], 0.1, 0, 1).flexibility.round(12).tolist()   # the tip spring
    [[1.0]]
    """
    W, gap = _check_contact(sector, contact, gap)
    N = sector.sectors
    k = integer("k", k, 0, N // 2)
    if 2 * k % N:
        raise ValueError(f"nodal diameter {k} of a disk of {N} blades is not a standing wave of one blade "
                         f"(valid: 0{f' or {N // 2}' if N % 2 == 0 else ''})")
    d = diameter(sector, W, k, integer("count", count, 1))
    w = (W.T @ d.shapes).real.T  # (c, m)
    Hs = d.G.real - w.T @ (w / d.lam[:, None])
    return NodalSystem(np.eye(d.lam.size), np.diag(d.lam), w, Hs, gap, casing)


def massless_sector(model: FEModel, sector: CyclicSector, contact: Contact,
                    nodes: bool = False) -> tuple[CyclicSector, np.ndarray, np.ndarray]:
    """``(massless sector, contact map, gap)`` of an FE sector and a blade's ``contact`` (a face or a node): the
    lumped masses with those of the contact dofs moved to their neighbours
    (:func:`~bladecase.reduction.massless.massless_masses`), and the contact map — one face-mean column
    (``nodes=False``) or one column per node of the face (``nodes=True``).

    Raises ``ValueError`` for a consistent mass model or a contact on a cyclic face.
    """
    if nodes:
        W = sp.csr_array(contact.node_normal_map(model)).T.toarray()
        gap, _ = contact.node_clearances(model)
    else:
        W = np.asarray(contact.w(model), dtype=float).reshape(-1, 1)
        gap = np.array([contact.gap])
    c = np.flatnonzero(np.any(W != 0, axis=1))
    masses = massless_masses(model, c)
    out = CyclicSector(sector.K, sp.diags_array(masses).tocsr(), sector.sectors, sector.left, sector.right,
                       sector.link, sector.triples, sector.axis, sector.pairs)
    _check_contact(out, W, gap)
    return out, W, np.asarray(gap, dtype=float)
