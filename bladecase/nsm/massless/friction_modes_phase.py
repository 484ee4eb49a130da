"""A nonlinear mode with stick–slip friction read off a forced steady state: at any point of a forced curve, the
response's fundamental harmonic and its phase against the force give the single nonlinear mode's frequency and
damping ratio at that amplitude (:func:`phase_mode`), to check
:func:`~bladecase.nsm.massless.friction_modes_coulomb.coulomb_mode` at the same amplitude.

**The amplitude.** Both the mode's orbit and the forced response are measured by the fundamental harmonic of the
followed mode's open-phase modal coordinate, ``q(t) ≈ Re(c e^{iΩt})``, ``a₁ = |c|`` (:func:`fundamental`): a
contact on one side shifts the orbit's mean and adds harmonics, so its turning point is not the amplitude a
harmonic force sees.

**The single nonlinear mode.** Driven by the modal force ``Re(f e^{iΩt})`` (``f = φᵀF``, complex), the mode of
frequency ``ω(a₁)`` and ratio ``ζ(a₁)`` answers ``(ω² − Ω² + 2iζκωΩ) c = f``, where ``κ = ∫x'ᵀMx' dt / πΩa₁²``
(over a period; 1 for a harmonic orbit) carries the kinetic energy of the orbit's higher harmonics into the energy
balance: the force puts in ``πa₁² Im(f/c)`` a period, the mode's damping takes out ``2ζω∫x'ᵀMx' dt``. So one
forced point gives ``ω² = Ω² + Re(f/c)`` and ``ζκ = Im(f/c) / 2ωΩ``, at its own ``a₁``, compared with the mode's
``ζ·κ`` (:func:`kinetic_factor`). Unlike a width read from the amplitudes of two flanks alone, it needs no second
point at the same amplitude and no common ``ω`` between them: on a hardening mode the upper flank leans towards the
fold, where two hundredths of a hertz move the width's ratio by a fifth.

>>> import numpy as np
>>> from bladecase.nsm import Damping
>>> from bladecase.nsm.massless.nodes import NodalSystem
>>> from bladecase.nsm.massless.friction import Friction
>>> from bladecase.nsm.massless.friction_modes_forced import forced_point
>>> s = NodalSystem(np.eye(2), np.diag([1.0, 4.0]), np.array([[0.0], [1.0]]), [[1e-3]], gap=[10.0])
>>> f = Friction(0.4, T=[[1.0], [0.0]], C_tt=[[0.5]], model="coulomb")
>>> p = forced_point(s, f, [0.02j, 0.0], 0.98, Damping(zeta=0.01), rtol=1e-10, max_periods=3000)
>>> w, zk, a1 = phase_mode(p, [0.02j, 0.0])           # far from the casing: the linear mode, ω = 1, ζ = 0.01
>>> round(w, 8), round(zk, 8)
(1.0, 0.01)
"""

from __future__ import annotations

import numpy as np

from .friction_coulomb import CoulombTrajectory
from .friction_modes_coulomb import CoulombMode, orbit_kinetic
from .friction_modes_forced import ForcedPoint

__all__ = ["fundamental", "kinetic_factor", "phase_mode"]

#: Samples per period for the fundamental harmonic (midpoint rule: spectral for a smooth periodic signal).
SAMPLES = 4000


def fundamental(tr: CoulombTrajectory, t0: float, period: float, mode: int = 0, samples: int = SAMPLES) -> complex:
    """The complex fundamental harmonic ``c`` of the open-phase modal coordinate ``mode`` of ``tr`` over
    ``[t0, t0 + period]``, against the clock of ``tr`` (``q ≈ Re(c e^{2πit/period})``).

    >>> import numpy as np
    >>> from bladecase.nsm.massless.nodes import NodalSystem
    >>> from bladecase.nsm.massless.friction import Friction
    >>> from bladecase.nsm.massless.friction_coulomb import CoulombFlight
    >>> s = NodalSystem(np.eye(2), np.diag([1.0, 4.0]), np.array([[0.0], [1.0]]), [[1e-3]], gap=[10.0])
    >>> fl = CoulombFlight(s, Friction(0.4, T=[[1.0], [0.0]], C_tt=[[0.5]], model="coulomb"), None, sliding=0.0)
    >>> tr = fl.simulate(np.array([0.5, 0.0]), np.zeros(2), 2 * np.pi)     # q = 0.5 cos t, no contact
    >>> c = fundamental(tr, 0.0, 2 * np.pi)
    >>> round(c.real, 9), round(abs(c.imag), 9)
    (0.5, 0.0)
    """
    if not (np.isfinite(period) and period > 0):
        raise ValueError(f"period must be a finite number > 0, got {period!r}")
    s = tr.system
    t = t0 + period * (np.arange(samples) + 0.5) / samples
    x, _ = tr.state(t)
    q = s.modes[1][:, mode] @ (s.M @ x)
    return complex(2 * np.mean(q * np.exp(-2j * np.pi * t / period)))


def kinetic_factor(mode: CoulombMode, index: int = 0) -> tuple[float, float]:
    """The fundamental amplitude ``a₁`` of :func:`coulomb_mode`'s orbit (its followed mode ``index``) and its
    kinetic factor ``κ = ∫x'ᵀMx' dt / πωa₁²`` over the period (module docstring): ``(a₁, κ)``."""
    a1 = abs(fundamental(mode.orbit, 0.0, mode.period, index))
    return a1, orbit_kinetic(mode.orbit, 0.0, mode.period) / (np.pi * mode.frequency * a1**2)


def phase_mode(point: ForcedPoint, shape, mode: int = 0) -> tuple[float, float, float]:
    """The single nonlinear mode at a forced steady state ``point`` (its last period) under
    ``Re(shape · e^{iΩt})``: ``(ω, ζκ, a₁)`` — the mode's frequency (rad/s), its damping ratio times the kinetic
    factor, and the fundamental amplitude at which they hold (module docstring)."""
    tr = point.trajectory
    T = 2 * np.pi / point.frequency
    c = fundamental(tr, tr.t_end - T, T, mode)
    phi = tr.system.modes[1][:, mode]
    f = complex(phi @ np.asarray(shape, dtype=complex))
    d = f / c
    w2 = point.frequency**2 + d.real
    if w2 <= 0:
        raise ValueError(f"the forced point at {point.frequency:.6g} rad/s does not answer as a single mode "
                         f"(ω² = {w2:.3g})")
    w = float(np.sqrt(w2))
    return w, float(d.imag / (2 * w * point.frequency)), float(abs(c))
