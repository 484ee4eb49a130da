"""What the forced–damped simulations of both contact models share: modal damping, the forcing inputs and the
energy budget of a forced run.

:class:`Damping` (Rayleigh ``C = αK + βM`` or modal ratios ``ζ_j``), :func:`forcing_inputs` (the checked forcing
period, damping and load vector) and :class:`EnergyBalance` (``final - initial = work - dissipated - impact_loss``,
by Gauss–Legendre quadrature with :data:`QUAD_NODES` nodes per panel) are used by Newton's impact law
(:mod:`bladecase.nsm.newton.forced`), by the massless contact model (:mod:`bladecase.nsm.massless.forced`) and by
the forcing-period sweeps (:mod:`bladecase.nsm.sweep`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .system import LinearSystem

__all__ = ["QUAD_NODES", "Damping", "EnergyBalance", "forcing_inputs"]

#: Gauss–Legendre nodes per quadrature panel of the energy balance of a forced run
#: (:meth:`~bladecase.nsm.newton.forced.ForcedTrajectory.energy_balance`,
#: :meth:`~bladecase.nsm.massless.forced.MasslessForcedTrajectory.energy_balance`; panels of at most
#: half the shortest period: the integrands are entire functions, the error is at round-off level).
QUAD_NODES = 20


def _finite_nonneg(name: str, value) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a finite number >= 0, got {value!r}") from None
    if not np.isfinite(v) or v < 0:
        raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    return v


@dataclass(frozen=True)
class Damping:
    """Modal damping: Rayleigh ``C = αK + βM`` or modal damping ratios ``ζ_j`` (not both).

    In M-normalised modal coordinates ``ΦᵀCΦ = diag(2σ_j)``, ``σ_j = ζ_j ω_j`` with
    ``ζ_j = (α ω_j + β/ω_j)/2`` for Rayleigh damping.

    >>> import numpy as np
    >>> Damping(alpha=0.01).ratios(np.array([1.0, 4.0])).tolist()      # C = αK: ζ_j = αω_j/2
    [0.005, 0.02]
    >>> Damping(zeta=[0.02, 0.05]).rates(np.array([1.0, 4.0])).tolist()
    [0.02, 0.2]
    """

    alpha: float = 0.0
    beta: float = 0.0
    zeta: tuple[float, ...] | float | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "alpha", _finite_nonneg("alpha", self.alpha))
        object.__setattr__(self, "beta", _finite_nonneg("beta", self.beta))
        if self.zeta is not None:
            try:
                if isinstance(self.zeta, (str, bytes)):
                    raise TypeError
                z = np.atleast_1d(np.asarray(self.zeta, dtype=float))
            except (TypeError, ValueError):
                z = np.array([np.nan])  # refused below
            if z.ndim != 1 or z.size == 0 or not np.all(np.isfinite(z)) or np.any(z < 0):
                raise ValueError(f"zeta must be a damping ratio >= 0 or a sequence of them, got {self.zeta!r}")
            if self.alpha or self.beta:
                raise ValueError("give either Rayleigh coefficients (alpha, beta) or modal ratios zeta, not both")
            object.__setattr__(self, "zeta", float(z[0]) if np.ndim(self.zeta) == 0 else tuple(z.tolist()))

    def ratios(self, omega: np.ndarray) -> np.ndarray:
        """Damping ratios ``ζ_j`` of the modes of angular frequencies ``omega``."""
        omega = np.asarray(omega, dtype=float)
        if self.zeta is None:
            return 0.5 * (self.alpha * omega + self.beta / omega)
        z = np.asarray(self.zeta, dtype=float)
        if z.ndim == 1 and z.size != omega.size:
            raise ValueError(f"zeta has {z.size} ratios but the system has {omega.size} modes")
        return np.broadcast_to(z, omega.shape).astype(float)

    def rates(self, omega: np.ndarray) -> np.ndarray:
        """Decay rates ``σ_j = ζ_j ω_j``."""
        return self.ratios(omega) * np.asarray(omega, dtype=float)

    def matrix(self, system: LinearSystem) -> np.ndarray:
        """The dense damping matrix ``C`` (``αK + βM``, or ``MΦ diag(2ζω) ΦᵀM`` for modal ratios)."""
        M = system.M.toarray() if hasattr(system.M, "toarray") else np.asarray(system.M)
        K = system.K.toarray() if hasattr(system.K, "toarray") else np.asarray(system.K)
        if self.zeta is None:
            return self.alpha * K + self.beta * M
        sp = system.spectrum
        MP = M @ sp.phi
        return MP @ np.diag(2 * self.rates(sp.omega)) @ MP.T


def _real(name: str, value, what: str = "finite number") -> float:
    """``float(value)`` of a number (not a bool, not a string), else ``ValueError`` naming ``name``."""
    try:
        if isinstance(value, (bool, np.bool_, str, bytes)):
            raise TypeError
        return float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a {what}, got {value!r}") from None


def forcing_inputs(n: int, period, amplitude: float, damping, load):
    """Checked ``(period, Ω, damping, load)`` of a forced flight of ``n`` dofs (``load=None``: every dof)."""
    if period is None:
        if amplitude != 0:
            raise ValueError("a forcing period is needed when the amplitude is not 0")
        Omega = 0.0
    else:
        period = _real("period", period, "finite number > 0")
        if not np.isfinite(period) or period <= 0:
            raise ValueError(f"period must be finite and > 0, got {period!r}")
        Omega = 2 * np.pi / period
    damping = Damping() if damping is None else damping
    if not isinstance(damping, Damping):
        raise ValueError(f"damping must be a Damping (e.g. Damping(alpha=0.005)) or None, got {damping!r}")
    try:
        if isinstance(load, (str, bytes)):
            raise TypeError
        f = np.ones(n) if load is None else np.asarray(load, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ValueError(f"load must be a finite vector of {n} entries (or None: a unit force on every dof), got "
                         f"{load!r}") from None
    if f.shape != (n,) or not np.all(np.isfinite(f)):
        raise ValueError(f"load must be a finite vector of {n} entries, got shape {f.shape}")
    return period, Omega, damping, f


@dataclass(frozen=True)
class EnergyBalance:
    """Energy budget of a forced run: ``final - initial = work - dissipated - impact_loss`` (``residual``
    is the difference, round-off for an exact simulation)."""

    initial: float
    final: float
    work: float
    dissipated: float
    impact_loss: float

    @property
    def residual(self) -> float:
        return self.final - self.initial - self.work + self.dissipated + self.impact_loss
