"""Which blade of a mistuned disk rubs first, and how soon: each blade's tip excursion under an engine order against
its own clearance.

The forced response of :mod:`bladecase.reduction.mistuning` is linear in the forcing amplitude ``F``: blade ``j``'s
tip excursion along the casing normal peaks (over the frequency sweep, its own peak refined) at ``a_j F``
(:func:`blade_peaks`, ``a_j`` per unit force). As ``F`` rises from zero — a rising forcing, or a speed run through
a resonance whose forcing grows — blade ``j`` first reaches its clearance ``c_j`` at ``F_j = c_j/a_j``; the blade
that rubs first is the one of the smallest ``F_j`` (:func:`first_rub`), and its margins are

* ``level``: ``F_first`` — the forcing at which the disk first rubs (N; per unit of the given force);
* ``tuned_ratio``: ``F_first`` over the tuned disk's (every blade alike, uniform clearance: ``c/a_tuned``) — below
  1, mistuning brings the first rub earlier (for a uniform clearance, the inverse of the amplification factor);
* ``lead``: ``F_second/F_first − 1`` — how much more forcing the next blade needs: a small lead, the first blade is
  first by chance.

A clearance per blade (an out-of-round casing seen at each blade's angle, a worn or offset casing) changes who
rubs first: the blade of the largest ``a_j/c_j``, not of the largest ``a_j``. :func:`blade_clearances` reads each
blade's clearance off a casing of revolution (:class:`~bladecase.reduction.casing.Casing`), offset or out-of-round.

>>> from bladecase.reduction.mistuning import family_band, lumped_disk, mistuning_model
>>> sector, kb = lumped_disk(6)
>>> m = mistuning_model(sector, kb)
>>> delta = np.array([0.02, -0.01, 0.0, 0.015, -0.02, 0.005])
>>> r = sample_rub(delta, model=m, order=1, frequencies=family_band(m), zeta=0.005, force=1, response=1,
...                clearance=1e-3)
>>> r["blade"], round(r["tuned_ratio"], 3), bool(r["lead"] > 0)       # uniform clearance: 1/amplification
(1, 0.822, True)
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize_scalar

from ..checks import integer
from ..fe.cyclic import rotation_matrix
from .casing import Casing
from .mistuning import MistuningModel, _amplitudes, _load, _zeta, mistuned_stiffness

__all__ = ["blade_clearances", "blade_peaks", "first_rub", "sample_rub"]

#: Local maxima of each blade's amplitude on the sweep refined (bounded Brent between the grid neighbours).
PEAKS_PER_BLADE = 2


def blade_peaks(model: MistuningModel, delta, order: int, frequencies, *, zeta: float, force, response
                ) -> tuple[np.ndarray, np.ndarray]:
    """``(a, hz)``: each blade's largest amplitude ``|rᵀu_j|`` over the sweep ``frequencies`` (Hz) and where, each
    blade's own peak refined (arguments as :func:`~bladecase.reduction.mistuning.forced_response`).

    >>> from bladecase.reduction.mistuning import family_band, lumped_disk, mistuning_model
    >>> sector, kb = lumped_disk(4)
    >>> m = mistuning_model(sector, kb)
    >>> a, hz = blade_peaks(m, np.zeros(4), 1, family_band(m), zeta=0.01, force=1, response=1)
    >>> bool(np.ptp(a) < 1e-9 * a.max())                  # a tuned disk: every blade alike
    True
    """
    hz = np.asarray(frequencies, dtype=float)
    if hz.ndim != 1 or hz.size < 3 or not np.all(np.diff(hz) > 0) or hz[0] <= 0:
        raise ValueError(f"frequencies must be at least 3 increasing frequencies > 0 (Hz), got {frequencies!r}")
    K = mistuned_stiffness(model, delta)
    Fr, E = _load(model, order, force, response)
    rates = 2.0 * _zeta(zeta) * np.sqrt(model.lam)
    grid = _amplitudes(K, rates, Fr, E, hz)  # (F, N)
    n = model.sectors
    peaks, where = grid.max(axis=0), hz[np.argmax(grid, axis=0)]
    for j in range(n):
        col = grid[:, j]
        inner = np.flatnonzero((col >= np.roll(col, 1)) & (col >= np.roll(col, -1)))
        for i in inner[np.argsort(col[inner])[::-1][:PEAKS_PER_BLADE]]:
            lo, hi = hz[max(i - 1, 0)], hz[min(i + 1, hz.size - 1)]
            res = minimize_scalar(lambda x, j=j: -_amplitudes(K, rates, Fr, E[j:j + 1], np.array([x]))[0, 0],
                                  bounds=(lo, hi), method="bounded", options={"xatol": 1e-10 * hi})
            if -res.fun > peaks[j]:
                peaks[j], where[j] = -res.fun, res.x
    return peaks, where


def first_rub(peaks, clearance) -> dict:
    """The blade that reaches its clearance first as the forcing rises (module docstring), from each blade's peak
    excursion per unit force ``peaks`` and its ``clearance`` (m; one value: every blade's): ``{"blade", "level",
    "lead", "levels"}``.

    >>> first_rub([1.0, 2.0, 1.5], [1.0, 1.0, 2.0])      # blade 1 needs a force 0.5, blade 0 1.0, blade 2 1.33
    {'blade': 1, 'level': 0.5, 'lead': 1.0, 'levels': [1.0, 0.5, 1.3333333333333333]}
    """
    a = np.asarray(peaks, dtype=float)
    c = np.broadcast_to(np.asarray(clearance, dtype=float), a.shape)
    if a.ndim != 1 or a.size < 1 or not np.all(np.isfinite(a)) or np.any(a < 0):
        raise ValueError(f"peaks must be each blade's peak excursion per unit force (finite, >= 0), got {peaks!r}")
    if not (np.all(np.isfinite(c)) and np.all(c > 0)):
        raise ValueError(f"clearance must be > 0 (m), one value or one per blade, got {clearance!r}")
    levels = np.divide(c, a, out=np.full(a.shape, np.inf), where=a > 0)
    order = np.argsort(levels, kind="stable")
    first = int(order[0])
    lead = float(levels[order[1]] / levels[first] - 1.0) if a.size > 1 else float("inf")
    return {"blade": first, "level": float(levels[first]), "lead": lead, "levels": levels.tolist()}


def sample_rub(delta, *, model: MistuningModel, order: int, frequencies, zeta: float, force, response,
               clearance, tuned_level: float | None = None) -> dict:
    """One sample's task (a module-level function for any executor): who rubs first (:func:`first_rub`) with the
    blades' peaks (:func:`blade_peaks`), and ``tuned_ratio``, the first-rub forcing over the tuned disk's with the
    same clearances (``tuned_level``: that of the tuned disk, computed when not given): ``{"blade", "level",
    "lead", "tuned_ratio", "peaks", "frequencies_hz"}``."""
    a, hz = blade_peaks(model, delta, order, frequencies, zeta=zeta, force=force, response=response)
    if tuned_level is None:
        tuned, _ = blade_peaks(model, np.zeros(model.sectors), order, frequencies, zeta=zeta, force=force,
                               response=response)
        tuned_level = first_rub(tuned, clearance)["level"]
    out = first_rub(a, clearance)
    out["tuned_ratio"] = out["level"] / float(tuned_level)
    out.update(peaks=a.tolist(), frequencies_hz=hz.tolist())
    return out


def blade_clearances(tip, sectors: int, axis, casing: Casing, lobes: int | None = None,
                     amplitude: float = 0.0) -> np.ndarray:
    """Each blade's tip clearance (m) to ``casing`` with the disk at rest. Blade ``j``'s tip is blade 0's ``tip`` (a
    point, m) turned by ``jα`` (``α = 2π/N``, right-handed) about the disk's ``axis`` (a
    :class:`~bladecase.fe.rotation.RotationAxis`); its clearance is measured along its radius about the casing's own
    axis, ``R(s_j) − r_j`` (the casing's radius at the tip's axial station less the tip's radius: what its radial
    excursion must cover). An out-of-round casing of ``lobes`` lobes reaches ``amplitude`` further in where blade
    0's tip is: ``c_j = R(s_j) − r_j − amplitude·cos(lobes·φ_j)``, ``φ_j`` blade ``j``'s angle about the casing's
    axis from blade 0's tip — the clearance the rub response sees at ``t = 0``. A casing offset from the disk's axis
    gives every blade its own clearance too.

    >>> from bladecase.fe.rotation import RotationAxis
    >>> axis = RotationAxis((0, 0, 0), (1, 0, 0))
    >>> c = blade_clearances([0, 0, 0.25], 4, axis, Casing(axis, radius=0.2502), lobes=2, amplitude=1e-4)
    >>> (c * 1e6).round(6).tolist()      # µm: 200 less a lobe at blades 0 and 2, plus a trough at 1 and 3
    [100.0, 300.0, 100.0, 300.0]

    Raises ``ValueError`` when a blade's tip touches or crosses the casing, naming the blade.
    """
    n = integer("sectors", sectors, 1)
    p0 = np.asarray(tip, dtype=float).reshape(3)
    o, d = np.asarray(axis.origin, dtype=float), np.asarray(axis.direction, dtype=float)
    points = np.array([o + rotation_matrix(d, 2 * np.pi * j / n) @ (p0 - o) for j in range(n)])
    a, x = casing.axis.direction, points - casing.axis.origin
    s = x @ a
    radial = x - np.outer(s, a)
    r = np.linalg.norm(radial, axis=1)
    if np.any(r <= 0):
        raise ValueError(f"blade 0's tip {p0.tolist()} turned about the disk's axis meets the casing's axis: it has no "
                         "radial direction to the casing")
    R, _ = casing.profile(s)
    c = R - r
    if lobes is not None and amplitude:
        e = radial / r[:, None]
        phi = np.arctan2(np.cross(e[0], e) @ a, e @ e[0])
        c = c - float(amplitude) * np.cos(int(lobes) * phi)
    if np.any(c <= 0):
        j = int(np.argmin(c))
        raise ValueError(f"blade {j}'s tip (radius {r[j]:.6g} m about the casing's axis) touches or crosses the casing "
                         f"at rest: clearance {c[j]:.4g} m (every blade's must be > 0: a larger casing radius, or a "
                         "smaller out-of-round amplitude)")
    return c
