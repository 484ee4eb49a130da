"""Mistuning statistics: random blade deviations, the amplification factor of each sample through an executor,
its distribution and Whitehead's bound ``½(1 + √N)``; the worst mistuning pattern by optimisation.

The samples are drawn in the caller (``numpy.random.default_rng(seed)``, normal with standard deviation ``std``),
so a ``seed`` gives the same deviations whatever runs them; each sample's task is a module-level function of its
deviations with the model and the forcing shared (sent once per worker), so a serial loop, local processes and a
Dask cluster give the same numbers bit for bit.

>>> from bladecase.reduction.mistuning import lumped_disk, mistuning_model
>>> sector, kb = lumped_disk(6)
>>> stats = mistuning_statistics(mistuning_model(sector, kb), 1, std=0.02, samples=20, seed=1, zeta=0.005,
...                              force=1, response=1)
>>> stats.factors.shape, round(stats.bound, 4), bool(stats.factors.max() <= stats.bound)
((20,), 1.7247, True)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

from ..checks import integer, positive
from .mistuning import MistuningModel, _load, family_band, peak_response

__all__ = ["MistuningStatistics", "mistuning_statistics", "random_mistuning", "sample_peak", "whitehead_bound",
           "worst_mistuning"]

#: The percentiles :meth:`MistuningStatistics.summary` reports.
PERCENTILES = (5, 50, 95, 99)


def whitehead_bound(sectors: int) -> float:
    """Whitehead's bound ``½(1 + √N)``: no mistuning of a disk of ``N`` blades (one isolated family, the engine
    order's forcing) amplifies the largest blade response more.

    >>> round(whitehead_bound(24), 4)
    2.9495
    """
    return 0.5 * (1.0 + math.sqrt(integer("sectors", sectors, 2)))


def random_mistuning(sectors: int, samples: int, std: float, seed: int) -> np.ndarray:
    """``(samples, N)`` blade stiffness deviations, normal with standard deviation ``std``, reproducible by ``seed``.

    >>> d = random_mistuning(4, 2, 0.05, seed=7)
    >>> d.shape, bool(np.array_equal(d, random_mistuning(4, 2, 0.05, seed=7)))
    ((2, 4), True)
    """
    n, count = integer("sectors", sectors, 2), integer("samples", samples, 1)
    std = positive("std", std, "> 0 (the standard deviation of the blades' stiffness deviations, e.g. 0.02)")
    if std >= 0.3:
        raise ValueError(f"std must be < 0.3 (small deviations: the model is linear in them), got {std!r}")
    seed = integer("seed", seed, 0)
    return np.random.default_rng(seed).normal(0.0, std, (count, n))


def sample_peak(delta, *, model: MistuningModel, order: int, frequencies, zeta: float, force,
                response) -> tuple[float, int, float]:
    """One sample's task: ``(amplitude, blade, frequency)`` of its largest blade response
    (:func:`~bladecase.reduction.mistuning.peak_response`), a module-level function for any executor.

    >>> from bladecase.reduction.mistuning import lumped_disk, mistuning_model
    >>> sector, kb = lumped_disk(6)
    >>> m = mistuning_model(sector, kb)
    >>> sample_peak(np.zeros(6), model=m, order=0, frequencies=family_band(m), zeta=0.01, force=1, response=1)[1]
    0
    """
    return peak_response(model, delta, order, frequencies, zeta=zeta, force=force, response=response)


@dataclass(frozen=True)
class MistuningStatistics:
    """The amplification factors of random mistuning samples (:func:`mistuning_statistics`).

    Attributes
    ----------
    deltas : (S, N) ndarray
        Each sample's blade deviations.
    factors : (S,) ndarray
        Each sample's amplification factor (its largest blade amplitude ÷ the tuned disk's).
    blades : (S,) int ndarray
        The blade that responds most in each sample.
    frequencies : (S,) ndarray
        Where (Hz).
    tuned : float
        The tuned disk's largest blade amplitude.
    bound : float
        Whitehead's bound ``½(1 + √N)``.
    """

    deltas: np.ndarray
    factors: np.ndarray
    blades: np.ndarray
    frequencies: np.ndarray
    tuned: float
    bound: float

    @property
    def worst(self) -> int:
        """The sample of the largest amplification factor."""
        return int(np.argmax(self.factors))

    def percentiles(self, q=PERCENTILES) -> dict[float, float]:
        """``{q: the q-th percentile of the amplification factor}``."""
        return {float(p): float(v) for p, v in zip(np.atleast_1d(q), np.percentile(self.factors, np.atleast_1d(q)))}

    def summary(self) -> dict:
        """The numbers of a report: samples, mean, percentiles, largest and its sample, Whitehead's bound."""
        return {"samples": int(self.factors.size), "mean": float(self.factors.mean()),
                "percentiles": {f"p{int(q)}": v for q, v in self.percentiles().items()},
                "largest": float(self.factors.max()), "largest_sample": self.worst,
                "largest_blade": int(self.blades[self.worst]), "whitehead_bound": self.bound}


def mistuning_statistics(model: MistuningModel, order: int, *, std: float, samples: int, seed: int, zeta: float,
                         force, response, frequencies=None, executor=None, progress: bool = False
                         ) -> MistuningStatistics:
    """The amplification factor of ``samples`` random mistunings (``std``, ``seed``) under engine order ``order``.

    ``frequencies``: the sweep (Hz; default :func:`~bladecase.reduction.mistuning.family_band`); ``executor``: any
    executor of :mod:`bladecase.study.executor` (``map(fn, items, shared=…)``; ``None``: in this process, one
    after the other); the other arguments as :func:`~bladecase.reduction.mistuning.forced_response`.
    """
    if not isinstance(model, MistuningModel):
        raise ValueError(f"model must be a MistuningModel (mistuning_model, fmm_model), got {type(model).__name__}")
    deltas = random_mistuning(model.sectors, samples, std, seed)
    hz = family_band(model) if frequencies is None else np.asarray(frequencies, dtype=float)
    shared = {"model": model, "order": order, "frequencies": hz, "zeta": zeta, "force": force, "response": response}
    tuned = sample_peak(np.zeros(model.sectors), **shared)[0]
    if tuned == 0:
        raise ValueError(f"engine order {order} does not excite the modes of this model at the response (the tuned "
                         "response is zero): choose another force or response dof")
    items = list(deltas)
    if executor is None:
        peaks = [sample_peak(d, **shared) for d in items]
    else:
        peaks = executor.map(sample_peak, items, shared=shared, desc="mistuning samples", progress=progress)
    amp, blades, where = (np.asarray(v) for v in zip(*peaks))
    return MistuningStatistics(deltas, amp / tuned, blades.astype(int), where, float(tuned),
                               whitehead_bound(model.sectors))


def _blade_amplitude(x: np.ndarray, coupling, waves, lam, rates, Fr, row, limit, f0,
                     scale) -> tuple[float, np.ndarray]:
    """Blade 0's amplitude ``|x₀|`` at the frequency ``f0 + scale·x[-1]`` (Hz) with the deviations
    ``limit·x[:-1]``, and its exact gradient: ``∂x₀ = −gᵀ (∂A) q`` with ``Aq = F``, ``Aᵀg = row``."""
    w = 2.0 * math.pi * (f0 + scale * x[-1])
    A = coupling * (waves @ (limit * x[:-1]))
    A[np.diag_indices_from(A)] += lam + 1j * w * rates - w * w
    q, g = np.linalg.solve(A, Fr), np.linalg.solve(A.T, row)
    x0 = row @ q
    dx = np.append(-limit * np.einsum("p,pq,pqj,q->j", g, coupling, waves, q),
                   -2.0 * math.pi * scale * np.sum(g * (1j * rates - 2.0 * w) * q))
    a = abs(x0)
    return a, np.real(np.conj(x0) * dx) / a


def worst_mistuning(model: MistuningModel, order: int, *, limit: float, zeta: float, force, response,
                    frequencies=None, starts: int = 4, seed: int = 0) -> tuple[np.ndarray, float]:
    """``(delta, factor)``: a mistuning pattern within ``|δ_j| <= limit`` that maximises the amplification factor.

    Blade 0's amplitude at one frequency is a smooth function of ``(δ, ω)``: it is maximised over both by a bounded
    quasi-Newton search (L-BFGS-B, exact gradient) from the tuned peak and ``starts`` random patterns
    (``seed``); the best pattern's factor is then the refined peak over every blade and the sweep
    (:func:`~bladecase.reduction.mistuning.amplification`).  A local maximum: the largest found, not proved the
    largest; by Whitehead it never exceeds ``½(1 + √N)``.

    >>> from bladecase.reduction.mistuning import lumped_disk, mistuning_model
    >>> sector, kb = lumped_disk(4)
    >>> delta, factor = worst_mistuning(mistuning_model(sector, kb), 1, limit=0.02, zeta=0.005, force=1,
    ...                                 response=1, starts=1)
    >>> bool(1.0 < factor <= whitehead_bound(4))
    True
    """
    limit = positive("limit", limit)
    n = model.sectors
    hz = family_band(model) if frequencies is None else np.asarray(frequencies, dtype=float)
    kw = {"model": model, "order": order, "frequencies": hz, "zeta": zeta, "force": force, "response": response}
    tuned, _, f0 = sample_peak(np.zeros(n), **kw)
    Fr, E = _load(model, order, force, response)
    j = np.arange(n)
    waves = np.exp(2j * math.pi * np.multiply.outer(model.diameters[None, :] - model.diameters[:, None], j) / n) / n
    rates = 2.0 * positive("zeta", zeta) * np.sqrt(model.lam)
    args = (model.coupling, waves, model.lam, rates, Fr, E[0], limit, f0, float(hz[-1] - hz[0]) / 2)
    rng = np.random.default_rng(integer("seed", seed, 0))
    best = (-np.inf, np.zeros(n))
    for x0 in [np.zeros(n)] + [rng.uniform(-1, 1, n) for _ in range(integer("starts", starts, 0))]:
        res = minimize(lambda x: tuple(-v for v in _blade_amplitude(x, *args)), np.append(x0, 0.0), jac=True,
                       method="L-BFGS-B", bounds=[(-1.0, 1.0)] * n + [(-1.0, 1.0)])
        if -res.fun > best[0]:
            best = (-res.fun, limit * res.x[:-1])
    delta = np.clip(best[1], -limit, limit)
    return delta, sample_peak(delta, **kw)[0] / tuned
