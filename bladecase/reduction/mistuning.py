"""Mistuning of a bladed disk: a reduced-order model from the tuned cyclic modes and its forced response.

**Subset of nominal modes** (SNM, Yang & Griffin).  The basis is the tuned disk's modes of one family (or a few) for
every nodal diameter, as travelling waves: for ``k = 0 … N−1`` sector ``j`` moves as ``φ_k e^{ijkα}/√N``
(``α = 2π/N``; ``φ_k`` the sector mode of :func:`~bladecase.fe.cyclic.cyclic_modes`, ``φ_{N−k} = conj(φ_k)``),
so the basis is mass-orthonormal and the tuned stiffness is ``diag(ω_p²)``.  Blade ``j``'s Young's modulus times
``1 + δ_j`` adds ``δ_j K_b`` to its sector (``K_b``: the blade's part of the sector stiffness, not the disk's), and
in the basis

    ``K_r = diag(ω_p²) + B ∘ D``,  ``B_pq = φ_pᴴ K_b φ_q``,  ``D_pq = (1/N) Σ_j δ_j e^{ij(k_q − k_p)α}``

(``D`` is the circulant of the discrete Fourier transform of the deviations).  The **fundamental mistuning model**
(FMM, Feiner & Griffin) is the same with ``B_pq = ω̄²`` on one isolated family whose strain energy is in the blades
(``ω̄²`` the mean of the family's ``ω_p²``): :func:`fmm_model`.

**Forced response** (:func:`forced_response`): engine order ``e`` forces blade ``j`` with ``f e^{2πiej/N}`` (``f``
on the sector's dofs), modal viscous damping ``2ζω_p`` on the tuned modes, the steady state at each frequency of a
sweep; each blade's amplitude is ``|rᵀ u_j|`` (``r``: a response dof or vector of the sector).  The
**amplification factor** (:func:`amplification`) is the largest blade amplitude of the mistuned disk over the sweep
divided by the tuned disk's, each peak refined between its grid neighbours.

>>> sector, kb = lumped_disk(6)
>>> model = mistuning_model(sector, kb, families=[0])
>>> model.diameters.tolist(), model.frequencies.round(4).tolist()
([0, 1, 2, 3, 4, 5], [0.1491, 0.1496, 0.1503, 0.1505, 0.1503, 0.1496])
>>> f, r = model.unit_load(1), 1                     # a unit force and the response on the blade dof
>>> round(amplification(model, np.zeros(6), 1, family_band(model), zeta=0.01, force=f, response=r), 9)
1.0
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.optimize import minimize_scalar

from ..checks import integer, positive, symmetric
from ..fe import CyclicSector, cyclic_modes

__all__ = ["BladeResponse", "MistuningModel", "amplification", "family_band", "fmm_model", "forced_response",
           "lumped_disk", "mistuned_stiffness", "mistuning_model", "peak_response"]


@dataclass(frozen=True, eq=False)
class MistuningModel:
    """A reduced-order mistuning model of a bladed disk (:func:`mistuning_model`, :func:`fmm_model`).

    Attributes
    ----------
    sectors : int
        ``N``, the number of blades.
    lam : (P,) ndarray
        The tuned modes' ``ω_p²`` (rad²/s²).
    diameters : (P,) int ndarray
        Each mode's travelling-wave index ``k_p`` in ``0 … N−1`` (``k`` and ``N − k``: nodal diameter
        ``min(k, N − k)``).
    families : (P,) int ndarray
        Each mode's family (0: the lowest mode of every nodal diameter).
    shapes : (n, P) complex ndarray
        The sector modes ``φ_p`` on the sector's dofs (``φᴴMφ = 1``).
    coupling : (P, P) complex ndarray
        ``B``: ``φ_pᴴ K_b φ_q`` (SNM) or ``ω̄²`` (FMM).
    kind : str
        ``"snm"`` or ``"fmm"``.
    """

    sectors: int
    lam: np.ndarray
    diameters: np.ndarray
    families: np.ndarray
    shapes: np.ndarray
    coupling: np.ndarray
    kind: str

    @property
    def size(self) -> int:
        """``P``: the number of modes of the basis."""
        return self.lam.size

    @property
    def frequencies(self) -> np.ndarray:
        """The tuned modes' frequencies (Hz)."""
        return np.sqrt(self.lam) / (2.0 * math.pi)

    def unit_load(self, dof: int) -> np.ndarray:
        """A unit force on one dof of the sector (a vector on the sector's dofs)."""
        n = self.shapes.shape[0]
        f = np.zeros(n)
        f[integer("dof", dof, 0, n - 1)] = 1.0
        return f


def _family_modes(sector: CyclicSector, families, spectrum=None) -> tuple[list, list, list, list]:
    """The sector modes of each family for every travelling-wave index ``k = 0 … N−1``; a nodal diameter whose
    modes ``spectrum`` (``{k: CyclicModes}`` of this sector) holds, enough of them, is not solved again."""
    fam = sorted({integer("family", f, 0) for f in np.atleast_1d(families).tolist()})
    if not fam:
        raise ValueError("families must list at least one family (0: the lowest mode of every nodal diameter)")
    n = sector.sectors
    known = spectrum or {}
    per_nd = {k: known[k] if k in known and known[k].lam.size > fam[-1] else cyclic_modes(sector, k, fam[-1] + 1)
              for k in range(n // 2 + 1)}
    lam, ks, fs, shapes = [], [], [], []
    for f in fam:
        for k in range(n):
            modes = per_nd[min(k, n - k)]
            if f >= modes.lam.size:
                raise ValueError(f"family {f} does not exist at nodal diameter {min(k, n - k)}: it has "
                                 f"{modes.lam.size} mode(s); valid families: 0 … {modes.lam.size - 1}")
            phi = modes.shapes[:, f]
            lam.append(float(modes.lam[f]))
            ks.append(k)
            fs.append(f)
            shapes.append(phi if k <= n // 2 else np.conj(phi))
    return lam, ks, fs, shapes


def mistuning_model(sector: CyclicSector, blade_stiffness, families=(0,), spectrum=None) -> MistuningModel:
    """The subset-of-nominal-modes model (module docstring) of a tuned cyclic ``sector``.

    Parameters
    ----------
    sector : CyclicSector
        The tuned sector (:func:`~bladecase.fe.cyclic.fe_sector`, or a lumped :class:`CyclicSector`).
    blade_stiffness : (n, n) sparse or dense
        ``K_b``: the blade's part of the sector stiffness (the sector's ``K`` is ``K_disk + K_b``); blade ``j``'s
        deviation ``δ_j`` scales it.
    families : sequence of int
        The mode families of the basis (0: the lowest mode of every nodal diameter); each gives ``N`` modes.
    spectrum : dict or None
        ``{k: CyclicModes}`` already solved for this sector (:func:`~bladecase.fe.cyclic.cyclic_spectrum`): those
        nodal diameters are not solved again.

    >>> sector, kb = lumped_disk(4)
    >>> m = mistuning_model(sector, kb, families=[0, 1])
    >>> m.size, m.families.tolist(), np.allclose(m.coupling, m.coupling.conj().T)
    (8, [0, 0, 0, 0, 1, 1, 1, 1], True)
    """
    if not isinstance(sector, CyclicSector):
        raise ValueError(f"sector must be a CyclicSector (bladecase.fe.fe_sector), got {type(sector).__name__}")
    Kb = sp.csr_array(blade_stiffness, dtype=float)
    if Kb.shape != (sector.n_dofs, sector.n_dofs):
        raise ValueError(f"blade_stiffness must be {sector.n_dofs} × {sector.n_dofs} (the sector's dofs), "
                         f"got {Kb.shape}")
    symmetric("blade_stiffness", Kb)
    lam, ks, fs, shapes = _family_modes(sector, families, spectrum)
    Phi = np.column_stack(shapes)
    B = Phi.conj().T @ (Kb @ Phi)
    return MistuningModel(sector.sectors, np.asarray(lam), np.asarray(ks), np.asarray(fs), Phi,
                          0.5 * (B + B.conj().T), "snm")


def fmm_model(sector: CyclicSector, family: int = 0, spectrum=None) -> MistuningModel:
    """The fundamental mistuning model (Feiner & Griffin) of one isolated ``family``: ``B_pq = ω̄²``.

    Its assumptions: the family is isolated in frequency (no other family near), its strain energy is in the blades,
    and ``δ_j`` is small; then blade ``j``'s alone frequency is ``ω̄ √(1 + δ_j)``.

    >>> sector, kb = lumped_disk(4)
    >>> m = fmm_model(sector)
    >>> m.kind, float(m.coupling[0, 1].real) == float(m.lam.mean())
    ('fmm', True)
    """
    if not isinstance(sector, CyclicSector):
        raise ValueError(f"sector must be a CyclicSector (bladecase.fe.fe_sector), got {type(sector).__name__}")
    lam, ks, fs, shapes = _family_modes(sector, [family], spectrum)
    lam = np.asarray(lam)
    B = np.full((lam.size, lam.size), lam.mean(), dtype=complex)
    return MistuningModel(sector.sectors, lam, np.asarray(ks), np.asarray(fs), np.column_stack(shapes), B, "fmm")


def _deviations(model: MistuningModel, delta) -> np.ndarray:
    try:
        d = np.asarray(delta, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"delta must be {model.sectors} numbers (each blade's stiffness deviation), "
                         f"got {delta!r}") from None
    if d.shape != (model.sectors,) or not np.all(np.isfinite(d)) or np.any(d <= -1.0):
        raise ValueError(f"delta must be {model.sectors} finite deviations > -1 (blade j's Young's modulus × "
                         f"(1 + delta[j])), got shape {d.shape}: {np.array2string(d.ravel()[:6], precision=4)}")
    return d


def mistuned_stiffness(model: MistuningModel, delta) -> np.ndarray:
    """``K_r = diag(ω_p²) + B ∘ D``: the reduced stiffness with blade ``j``'s stiffness × ``(1 + delta[j])``.

    >>> sector, kb = lumped_disk(4)
    >>> m = mistuning_model(sector, kb)
    >>> np.allclose(mistuned_stiffness(m, np.zeros(4)), np.diag(m.lam))
    True
    """
    d = _deviations(model, delta)
    n = model.sectors
    j = np.arange(n)
    dft = np.exp(2j * math.pi * np.outer(np.arange(n), j) / n) @ d / n  # dft[m] = (1/N) Σ_j δ_j e^{ijmα}
    D = dft[(model.diameters[None, :] - model.diameters[:, None]) % n]
    K = model.coupling * D
    K[np.diag_indices_from(K)] += model.lam
    return 0.5 * (K + K.conj().T)


@dataclass(frozen=True)
class BladeResponse:
    """The steady state of every blade over a frequency sweep (:func:`forced_response`).

    Attributes
    ----------
    frequencies : (F,) ndarray
        The sweep (Hz).
    amplitudes : (F, N) ndarray
        Blade ``j``'s amplitude ``|rᵀ u_j|`` at each frequency.
    """

    frequencies: np.ndarray
    amplitudes: np.ndarray

    @property
    def peak(self) -> float:
        """The largest amplitude over blades and frequencies of the sweep."""
        return float(self.amplitudes.max())

    @property
    def blade(self) -> int:
        """The blade that reaches :attr:`peak`."""
        return int(np.unravel_index(np.argmax(self.amplitudes), self.amplitudes.shape)[1])


def _load(model: MistuningModel, order, force, response):
    """``(Fr, E)``: the modal forces of engine order ``order`` and the blades' observation matrix ``(N, P)``."""
    n, dofs = model.sectors, model.shapes.shape[0]
    e = integer("engine order", order, 0)
    vectors = []
    for name, v in (("force", force), ("response", response)):
        if isinstance(v, (int, np.integer)) and not isinstance(v, bool):
            v = model.unit_load(v)
        a = np.asarray(v)
        if a.shape != (dofs,) or not np.all(np.isfinite(a)):
            raise ValueError(f"{name} must be a sector dof (0 … {dofs - 1}) or a finite vector of {dofs} entries, "
                             f"got shape {a.shape}")
        vectors.append(a)
    f, r = vectors
    Fr = math.sqrt(n) * (model.shapes.conj().T @ f) * (model.diameters == e % n)
    wave = np.exp(2j * math.pi * np.outer(np.arange(n), model.diameters) / n) / math.sqrt(n)
    return Fr, wave * (r @ model.shapes)[None, :]


def _zeta(zeta) -> float:
    return positive("zeta", zeta, "> 0 (a modal damping ratio, e.g. 0.003)")


def _amplitudes(K: np.ndarray, rates: np.ndarray, Fr: np.ndarray, E: np.ndarray, hz: np.ndarray) -> np.ndarray:
    """``(F, N)``: every blade's amplitude at each frequency, ``(K + iωC − ω²) q = Fr``."""
    w = 2.0 * math.pi * np.atleast_1d(hz)
    A = K[None, :, :] - (w**2)[:, None, None] * np.eye(K.shape[0])
    A[:, np.arange(K.shape[0]), np.arange(K.shape[0])] += 1j * w[:, None] * rates[None, :]
    q = np.linalg.solve(A, np.broadcast_to(Fr, (w.size, Fr.size))[..., None])[..., 0]
    return np.abs(q @ E.T)


def forced_response(model: MistuningModel, delta, order: int, frequencies, *, zeta: float, force,
                    response) -> BladeResponse:
    """Every blade's steady-state amplitude under engine order ``order`` over ``frequencies`` (Hz).

    ``force``: blade 0's load on the sector's dofs (a dof: a unit force there), blade ``j``'s is it times
    ``e^{2πi·order·j/N}``; ``response``: a sector dof or a vector ``r``, blade ``j``'s amplitude is ``|rᵀu_j|``;
    ``zeta``: the modal damping ratio of the tuned modes (viscous, ``2ζω_p``).

    >>> sector, kb = lumped_disk(6)
    >>> m = mistuning_model(sector, kb)
    >>> tuned = forced_response(m, np.zeros(6), 2, [0.149, 0.1503], zeta=0.01, force=1, response=1)
    >>> bool(np.ptp(tuned.amplitudes, axis=1).max() < 1e-12 * tuned.peak)    # a tuned disk: every blade alike
    True
    """
    hz = np.atleast_1d(np.asarray(frequencies, dtype=float))
    if hz.ndim != 1 or hz.size == 0 or not np.all(np.isfinite(hz)) or np.any(hz <= 0):
        raise ValueError(f"frequencies must be finite frequencies > 0 (Hz), got {frequencies!r}")
    K = mistuned_stiffness(model, delta)
    Fr, E = _load(model, order, force, response)
    rates = 2.0 * _zeta(zeta) * np.sqrt(model.lam)
    return BladeResponse(hz, _amplitudes(K, rates, Fr, E, hz))


def _refined_peak(K, rates, Fr, E, hz: np.ndarray, peaks: int = 3) -> tuple[float, int, float]:
    """``(amplitude, blade, frequency)`` of the largest blade amplitude: the ``peaks`` highest local maxima of the
    grid each refined between its neighbours (bounded Brent)."""
    amp = _amplitudes(K, rates, Fr, E, hz).max(axis=1)
    inner = np.flatnonzero((amp >= np.roll(amp, 1)) & (amp >= np.roll(amp, -1)))
    candidates = inner[np.argsort(amp[inner])[::-1][:peaks]] if inner.size else [int(np.argmax(amp))]
    best = (float(amp.max()), float(hz[int(np.argmax(amp))]))
    for i in candidates:
        lo, hi = hz[max(i - 1, 0)], hz[min(i + 1, hz.size - 1)]
        if hi <= lo:
            continue
        res = minimize_scalar(lambda x: -_amplitudes(K, rates, Fr, E, np.array([x])).max(), bounds=(lo, hi),
                              method="bounded", options={"xatol": 1e-10 * hi})
        if -res.fun > best[0]:
            best = (float(-res.fun), float(res.x))
    blades = _amplitudes(K, rates, Fr, E, np.array([best[1]]))[0]
    return best[0], int(np.argmax(blades)), best[1]


def family_band(model: MistuningModel, margin: float = 0.02, count: int = 801) -> np.ndarray:
    """A sweep (Hz) of ``count`` frequencies over the family's band widened by ``margin`` on each side.

    >>> sector, kb = lumped_disk(6)
    >>> band = family_band(mistuning_model(sector, kb), count=5)
    >>> band.round(4).tolist()
    [0.1461, 0.148, 0.1498, 0.1517, 0.1535]
    """
    f = model.frequencies
    margin = positive("margin", margin)
    return np.linspace(f.min() * (1 - margin), f.max() * (1 + margin), integer("count", count, 3))


def peak_response(model: MistuningModel, delta, order: int, frequencies, *, zeta: float, force,
                  response) -> tuple[float, int, float]:
    """``(amplitude, blade, frequency)``: the largest blade amplitude over the sweep, its peak refined.

    >>> sector, kb = lumped_disk(6)
    >>> a, blade, hz = peak_response(mistuning_model(sector, kb), np.zeros(6), 0, family_band(mistuning_model(
    ...     sector, kb)), zeta=0.01, force=1, response=1)
    >>> blade, round(hz, 5)
    (0, 0.14909)
    """
    hz = np.asarray(frequencies, dtype=float)
    if hz.ndim != 1 or hz.size < 3 or not np.all(np.diff(hz) > 0) or hz[0] <= 0:
        raise ValueError(f"frequencies must be at least 3 increasing frequencies > 0 (Hz), got {frequencies!r}")
    Fr, E = _load(model, order, force, response)
    rates = 2.0 * _zeta(zeta) * np.sqrt(model.lam)
    return _refined_peak(mistuned_stiffness(model, delta), rates, Fr, E, hz)


def amplification(model: MistuningModel, delta, order: int, frequencies, *, zeta: float, force,
                  response) -> float:
    """The amplification factor: the mistuned disk's largest blade amplitude over ``frequencies`` ÷ the tuned
    disk's (both peaks refined; arguments as :func:`forced_response`).

    >>> sector, kb = lumped_disk(6)
    >>> m = mistuning_model(sector, kb)
    >>> delta = np.array([0.02, -0.01, 0.0, 0.015, -0.02, 0.005])
    >>> round(amplification(m, delta, 1, family_band(m), zeta=0.005, force=1, response=1), 3)
    1.216
    """
    kw = {"zeta": zeta, "force": force, "response": response}
    tuned = peak_response(model, np.zeros(model.sectors), order, frequencies, **kw)[0]
    if tuned == 0:
        raise ValueError(f"engine order {order} does not excite the modes of this model at the response (the tuned "
                         "response is zero): choose another force or response dof")
    return peak_response(model, delta, order, frequencies, **kw)[0] / tuned


def lumped_disk(sectors: int, *, disk_mass: float = 5.0, blade_mass: float = 1.0, ground: float = 20.0,
                blade: float = 0.93, coupling: float = 2.0) -> tuple[CyclicSector, sp.csr_array]:
    """``(sector, K_b)``: a lumped bladed disk, two dofs a sector — a disk mass on a ground spring, a blade mass on
    it, neighbouring disk masses coupled — and the blade spring's stiffness (dofs ``[disk, blade, next disk]``).

    >>> sector, kb = lumped_disk(24)
    >>> sector.n_dofs, kb.toarray().tolist()[0]
    (3, [0.93, -0.93, 0.0])
    """
    kd, kb, kc = (positive(n, v) for n, v in (("ground", ground), ("blade", blade), ("coupling", coupling)))
    md, mb = positive("disk_mass", disk_mass), positive("blade_mass", blade_mass)
    K = np.array([[kd + kb + kc, -kb, -kc], [-kb, kb, 0.0], [-kc, 0.0, kc]])
    Kb = kb * np.array([[1.0, -1.0, 0.0], [-1.0, 1.0, 0.0], [0.0, 0.0, 0.0]])
    sector = CyclicSector(sp.csr_array(K), sp.csr_array(np.diag([md, mb, 0.0])), sectors, left=[0], right=[2])
    return sector, sp.csr_array(Kb)
