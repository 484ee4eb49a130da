"""The rub response of a whole bladed disk turning inside an out-of-round casing: every blade sees the casing's lobes
at its own angle, and the response is read blade by blade and by nodal diameter.

The disk is the reduced annulus of :func:`~bladecase.reduction.disk.disk_model` (``N`` blades, ``m`` contacts each,
blade-major). Blade ``j`` sits at ``θ_j = 2πj/N`` (its contacts at ``θ_j`` plus their own ``offsets``); turning at
``Ω`` inside a casing of ``L`` lobes of amplitude ``a``, its contact ``i`` sees the clearance
``g − a cos(L(Ωt + θ_j + offset_i))``. The whole disk — ``N·m`` contacts at once — is simulated exactly from rest,
with the settling of the single blade's rub (:func:`~bladecase.nsm.massless.rub.rub_response`: a ``window`` of
revolutions at a time until the window's peaks match the previous window's within 2 %, else characterised as
``transient``, ``quasi-periodic`` or ``irregular``). On the span the figures are read on, per blade:

* ``peak_force`` — its largest contact force (N; each peak refined between the samples by bounded Brent);
* ``penetration`` — the casing's largest penetration at it (m; ``peak_force / k_c``, 0 for a rigid casing);
* ``contact_share`` — the share of the span its (first) contact is closed (exact, from the phases; with several
  contacts, the largest of theirs);

and the **travelling-wave content**: the DFT over the blades of the blade tips' displacements (each blade's mean
over its contacts, its time mean removed), ``U_k(t) = Σ_j u_j(t) e^{−2πijk/N}``, its power summed over the span and
folded onto the nodal diameters ``0 … ⌊N/2⌋`` (``k`` and ``N − k`` together): ``nd_share``, and the dominant
nodal diameter. A tuned disk in a casing of ``L`` lobes is forced by the pattern ``e^{iLθ_j}``: its steady response
repeats blade to blade — blade ``j`` runs ``j/(N f_rot)`` ahead of blade 0, ``u_j(t) = u_0(t + θ_j/Ω)`` — and its
lobe-passing harmonic sits on the nodal diameter ``L mod N``, folded (:func:`expected_diameter`; its ``h``-th
harmonic on ``hL mod N``).

>>> import scipy.sparse as sp
>>> from bladecase.fe.cyclic import CyclicSector
>>> from bladecase.nsm import Damping
>>> from bladecase.reduction.disk import disk_model
>>> K = np.array([[4.7, -1.0, 0.0, -0.7], [-1.0, 3.0, -2.0, 0.0], [0.0, -2.0, 2.0, 0.0], [-0.7, 0.0, 0.0, 0.7]])
>>> ring = CyclicSector(sp.csr_array(K), sp.csr_array(np.diag([2.0, 0.5, 0.0, 0.0])), 6, left=[0], right=[3])
>>> disk = disk_model(ring, [[0.0], [0.0], [1.0], [0.0]], 0.1, count=2)
>>> r = disk_rub(disk, speed=0.2, lobes=2, amplitude=0.12, damping=Damping(zeta=0.3), revolutions=8, window=2)
>>> r.response, r.dominant, expected_diameter(2, 6), bool(np.ptp(r.peak_force) < 1e-6 * r.peak_force.max())
('settled', 2, 2, True)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize_scalar

from .rub import RubResponse, rub_run

__all__ = ["DiskRub", "disk_rub", "disk_rub_sweep", "expected_diameter", "nd_content"]

#: Samples per lobe passing on which the nodal-diameter content and the peaks (before refinement) are read.
SAMPLES_PER_PASSING = 64


def expected_diameter(lobes: int, sectors: int) -> int:
    """The nodal diameter a casing of ``lobes`` lobes forces on a tuned disk of ``sectors`` blades: ``L mod N``,
    folded into ``0 … ⌊N/2⌋`` (aliased: ``L`` and ``N ± L`` force the same pattern).

    >>> [expected_diameter(L, 12) for L in (1, 3, 6, 9, 12, 14, 25)]
    [1, 3, 6, 3, 0, 2, 1]
    """
    k = int(lobes) % int(sectors)
    return min(k, int(sectors) - k)


def nd_content(u) -> np.ndarray:
    """The share of the power of the blades' displacements ``u`` (``(N, samples)``: blade ``j``'s samples in row
    ``j``, equally spaced) on each nodal diameter ``0 … ⌊N/2⌋``: the DFT over the blades, ``k`` and ``N − k``
    folded together, each blade's time mean removed first (the shares sum to 1; all 0 for a still disk).

    >>> j, t = np.arange(8)[:, None], np.linspace(0, 1, 50)[None, :]
    >>> np.round(nd_content(np.cos(2 * np.pi * (t + 3 * j / 8))), 12).tolist()   # a wave of 3 diameters
    [0.0, 0.0, 0.0, 1.0, 0.0]
    """
    u = np.asarray(u, dtype=float)
    if u.ndim != 2 or u.shape[0] < 2:
        raise ValueError(f"u must be an (N, samples) array of N >= 2 blades' displacements, got shape {u.shape}")
    N = u.shape[0]
    power = (np.abs(np.fft.fft(u - u.mean(axis=1, keepdims=True), axis=0)) ** 2).sum(axis=1)
    folded = np.zeros(N // 2 + 1)
    for k in range(N):
        folded[min(k, N - k)] += power[k]
    total = folded.sum()
    return folded / total if total > 0 else folded


@dataclass(frozen=True)
class DiskRub:
    """The disk's rub at one speed (module docstring): per blade ``peak_force`` (N), ``penetration`` (m),
    ``contact_share``; ``nd_share`` (nodal diameters ``0 … ⌊N/2⌋``), ``dominant`` (its largest), ``expected``
    (``L mod N`` folded); ``rub``: the whole disk's :class:`~bladecase.nsm.massless.rub.RubResponse` (per
    contact; its settling, ``response``, revolutions); ``trajectory``: the simulated span (with ``keep``) for
    :meth:`tips`."""

    speed: float
    lobes: int
    amplitude: float
    sectors: int
    per_blade: int
    peak_force: np.ndarray
    penetration: np.ndarray
    contact_share: np.ndarray
    nd_share: np.ndarray
    rub: RubResponse
    trajectory: object = field(default=None, repr=False, compare=False)

    @property
    def dominant(self) -> int:
        """The nodal diameter the response's oscillation concentrates on."""
        return int(np.argmax(self.nd_share))

    @property
    def expected(self) -> int:
        """``L mod N``, folded: the nodal diameter a tuned disk's lobe-passing response sits on."""
        return expected_diameter(self.lobes, self.sectors)

    @property
    def response(self) -> str:
        """``settled``, ``periodic-q``, ``transient``, ``quasi-periodic`` or ``irregular`` (the rub's)."""
        return self.rub.response

    def tips(self, t) -> np.ndarray:
        """``(N, len(t))``: each blade's tip displacement (m, outwards; the mean over its contacts) at the times
        ``t`` (s, the run's clock, within the kept span; needs ``keep=True``)."""
        if self.trajectory is None:
            raise ValueError("the trajectory was not kept: run disk_rub(..., keep=True)")
        return _tips(self.trajectory, np.atleast_1d(np.asarray(t, dtype=float)), self.sectors, self.per_blade)

    def rows(self) -> list[dict]:
        """One row per blade: ``speed_rad_s, blade, peak_force_n, penetration_m, contact_share, dominant_nd,
        response``."""
        return [{"speed_rad_s": self.speed, "blade": j, "peak_force_n": float(self.peak_force[j]),
                 "penetration_m": float(self.penetration[j]), "contact_share": float(self.contact_share[j]),
                 "dominant_nd": self.dominant, "response": self.response} for j in range(self.sectors)]

    def as_dict(self) -> dict:
        """Plain numbers and lists (for JSON)."""
        return {"speed": self.speed, "lobes": self.lobes, "amplitude": self.amplitude, "sectors": self.sectors,
                "peak_force": self.peak_force.tolist(), "penetration": self.penetration.tolist(),
                "contact_share": self.contact_share.tolist(), "nd_share": self.nd_share.tolist(),
                "dominant": self.dominant, "expected": self.expected, "response": self.response,
                "settled": self.rub.settled, "revolutions_run": self.rub.revolutions_run,
                "switches": self.rub.switches}


def _tips(tr, t: np.ndarray, N: int, m: int) -> np.ndarray:
    s = tr.flight.system
    x, _, lam = tr.sample(t)
    u = s.W.T @ x - s.flexibility @ lam
    return u.reshape(N, m, -1).mean(axis=1)


def _peak_forces(tr, t: np.ndarray) -> np.ndarray:
    """Each contact's largest force over the samples ``t`` (sorted), refined between the neighbours of its largest
    sample (bounded Brent)."""
    lam = tr.sample(t)[2]
    peak = lam.max(axis=1)
    span = t[-1] - t[0]
    for c in np.flatnonzero(peak > 0):
        i = int(np.argmax(lam[c]))
        lo, hi = t[max(i - 1, 0)], t[min(i + 1, t.size - 1)]
        res = minimize_scalar(lambda s, c=c: -tr.sample(np.array([s]))[2][c, 0], bounds=(lo, hi), method="bounded",
                              options={"xatol": 1e-13 * span})
        peak[c] = max(peak[c], -res.fun)
    return peak


def disk_rub(disk, speed: float, lobes: int, amplitude: float, damping=None, *, offsets=None,
             revolutions: int = 40, window: int = 10, max_revolutions: int | None = None,
             max_switches: int = 2_000_000, keep: bool = False) -> DiskRub:
    """The rub of the whole ``disk`` (a :class:`~bladecase.reduction.disk.DiskModel`) at ``speed`` (rad/s) in a
    casing of ``lobes`` lobes of ``amplitude`` (m) (module docstring); ``damping``: a
    :class:`~bladecase.nsm.damping.Damping` of the open-phase modes; ``offsets``: the contacts' angles within a blade
    (rad, default 0); ``revolutions``, ``window``, ``max_revolutions``, ``max_switches``: as
    :func:`~bladecase.nsm.massless.rub.rub_response`; ``keep``: keep the trajectory (:meth:`DiskRub.tips`)."""
    N, m = disk.sectors, disk.per_blade
    rub, tr = rub_run(disk.system, speed, lobes, amplitude, disk.angles(offsets), damping, revolutions, window,
                      max_switches, None, max_revolutions)
    passing = 2 * np.pi / (rub.speed * rub.lobes)
    passings = int(round(rub.read_revolutions * rub.lobes))
    t = tr.t_end - passing * passings * (1.0 - np.arange(passings * SAMPLES_PER_PASSING + 1)
                                         / (passings * SAMPLES_PER_PASSING))
    t = np.unique(np.r_[t, tr.starts[(tr.starts >= t[0]) & (tr.starts <= t[-1])]])
    peaks = _peak_forces(tr, t).reshape(N, m)
    force = peaks.max(axis=1)
    pen = (peaks / disk.system.casing.reshape(N, m)).max(axis=1)  # 0 for a rigid casing (k_c = inf)
    share = rub.contact_fraction.reshape(N, m).max(axis=1)
    grid = np.linspace(t[0], t[-1], passings * SAMPLES_PER_PASSING, endpoint=False)
    content = nd_content(_tips(tr, grid, N, m))
    return DiskRub(rub.speed, rub.lobes, rub.amplitude, N, m, force, pen, share, content, rub,
                   tr if keep else None)


def _one(args) -> DiskRub:
    disk, speed, lobes, amplitude, damping, offsets, revolutions, window, cap = args
    return disk_rub(disk, speed, lobes, amplitude, damping, offsets=offsets, revolutions=revolutions, window=window,
                    max_revolutions=cap)


def disk_rub_sweep(disk, speeds, lobes: int, amplitude: float, damping=None, *, offsets=None,
                   revolutions: int = 40, window: int = 10, max_revolutions: int | None = None,
                   executor=None) -> list[DiskRub]:
    """:func:`disk_rub` at every speed of ``speeds`` (rad/s), one task per speed through ``executor`` (anything with
    a ``map`` of a function over a list, e.g. the study's executors; default: in turn).

    >>> import scipy.sparse as sp
    >>> from bladecase.fe.cyclic import CyclicSector
    >>> from bladecase.nsm import Damping
    >>> from bladecase.reduction.disk import disk_model
    >>> K = np.array([[4.7, -1.0, 0.0, -0.7], [-1.0, 3.0, -2.0, 0.0], [0.0, -2.0, 2.0, 0.0], [-0.7, 0, 0, 0.7]])
    >>> ring = CyclicSector(sp.csr_array(K), sp.csr_array(np.diag([2.0, 0.5, 0.0, 0.0])), 4, left=[0], right=[3])
    >>> disk = disk_model(ring, [[0.0], [0.0], [1.0], [0.0]], 0.1, count=2)
    >>> out = disk_rub_sweep(disk, [0.9, 1.1], 1, 0.12, Damping(zeta=0.2), revolutions=4, window=1)
    >>> [(r.response, r.dominant) for r in out]
    [('settled', 1), ('settled', 1)]
    """
    speeds = np.asarray(speeds, dtype=float).reshape(-1)
    if speeds.size == 0 or not np.all(np.isfinite(speeds)) or np.any(speeds <= 0):
        raise ValueError(f"speeds must be finite numbers > 0 (rad/s), got {speeds.tolist()}")
    jobs = [(disk, float(w), lobes, amplitude, damping, offsets, revolutions, window, max_revolutions)
            for w in speeds]
    if executor is None:
        return [_one(job) for job in jobs]
    return list(executor.map(_one, jobs))
