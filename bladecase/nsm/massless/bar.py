"""The 1-D benchmark of the contact models: a bar fixed at ``x = 0``, gap at ``x = L``, and its continuum solution.

:func:`bar` builds the linear-element bar (lumped mass) with either contact model; :func:`bar_continuum_energy`
and :func:`bar_continuum_field` give the exact one-contact-phase nonsmooth mode of the continuous bar.

Continuum (d'Alembert, time unit ``L/c``, ``c = sqrt(EA/ρA)``): ``u = f(t + x) - f(t - x)``, ``g = f'``. An open
end gives ``g(t+1) = -g(t-1)``, a closed end ``g(t+1) = g(t-1)`` with ``g(t-1) <= 0`` (compression); the energy
``(EA/L)∫_{t-1}^{t+1} g²`` is conserved, so ``|g|`` is 2-periodic — and constant when ``T/2`` is irrational. The
one-contact-phase solution is the square wave ``g = -C`` on ``[0, 2)``, ``+C`` on ``[2, T)`` (mod ``T``),
``3 < T < 4``: the contact lasts ``4 - T`` (``t ∈ [T-1, 3)``), ``u(L) = C(2T - 6) = d`` there, hence

    C = d / (2T - 6),        E = (EA/L) d² / (2 (T - 3)²).

``tests/test_massless.py`` checks it independently (Signorini conditions on a fine grid, energy by quadrature).

>>> round(float(bar_continuum_energy(3.45, gap=0.5)), 6)
0.617284
>>> bar(4, gap=0.5, contact="massless")
MasslessSystem(n=3, gap=0.5, kc=4)
"""

from __future__ import annotations

import numpy as np

from ..system import LinearSystem, chain
from .model import MasslessSystem, condense, redistribute_mass

CONTACT_MODELS = ("newton", "massless")


def _positive(name: str, value) -> float:
    v = float(value)
    if not (np.isfinite(v) and v > 0):
        raise ValueError(f"{name} must be finite and > 0, got {value!r}")
    return v


def bar(n: int, gap: float, length: float = 1.0, EA: float = 1.0, rhoA: float = 1.0,
        contact: str = "massless", casing: float = float("inf")) -> LinearSystem | MasslessSystem:
    """A bar of ``n`` linear elements, fixed at ``x = 0``, contact at ``x = length`` with clearance ``gap``.

    Lumped (row-sum) mass. ``contact="newton"``: the seed's model, a spring–mass chain whose end node (mass
    ``ρA h/2``) impacts (:class:`~bladecase.nsm.LinearSystem`). ``contact="massless"``: the end node's mass is moved
    to the two nodes before it (total mass and centre of mass kept: ``+ρA h`` at ``L - h``, ``-ρA h/2`` at
    ``L - 2h``), and the model is condensed (:class:`~bladecase.nsm.massless.model.MasslessSystem`); ``casing``: the
    stiffness of a compliant casing in series with the end (``inf``: rigid; the massless model only).
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 3:
        raise ValueError(f"n (elements) must be an integer >= 3, got {n!r}")
    gap, length, EA, rhoA = (_positive(k, v) for k, v in
                             (("gap", gap), ("length", length), ("EA", EA), ("rhoA", rhoA)))
    if contact not in CONTACT_MODELS:
        raise ValueError(f"contact must be one of {', '.join(CONTACT_MODELS)}, got {contact!r}")
    h = length / n
    masses = np.full(n, rhoA * h)
    masses[-1] = rhoA * h / 2
    if contact == "newton":
        if float(casing) != float("inf"):
            raise ValueError(f"casing = {casing!r}: Newton's impact law needs a rigid casing (casing=inf); a compliant "
                             "casing is taken by contact='massless'")
        return chain(n, k=EA / h, m=masses, gap=gap)
    coords = h * np.arange(1, n + 1)
    masses = redistribute_mass(masses, coords, n - 1, np.array([n - 3, n - 2]))
    K = chain(n, k=EA / h, m=1.0, gap=gap).K
    w = np.zeros(n)
    w[-1] = 1.0
    return condense(np.diag(masses), K.toarray() if hasattr(K, "toarray") else K, w, gap, casing)


def bar_continuum_energy(T, gap: float, length: float = 1.0, EA: float = 1.0, rhoA: float = 1.0):
    """Energy of the continuous bar's one-contact-phase nonsmooth mode at period ``T`` (``3 < T c/L < 4``)."""
    tau = np.asarray(T, float) * np.sqrt(EA / rhoA) / length
    if np.any((tau <= 3) | (tau >= 4)):
        raise ValueError(f"the one-phase continuum mode exists for 3 < T·c/L < 4, got {tau}")
    return EA / length * gap**2 / (2 * (tau - 3) ** 2)


def bar_continuum_band_energy(T: float, gap: float, modes: int) -> float:
    """Part of :func:`bar_continuum_energy` held by the lowest ``modes`` fixed–free modes (unit bar).

    At mid-open (``t = 1``) the bar is uniformly strained, ``u = -2Cx``, ``u_t = 0``; on the modes
    ``√2 sin(ω_j x)``, ``ω_j = (2j - 1)π/2``, it holds ``E_j = 4C²/ω_j²`` (``Σ_j E_j = 2C² = E``).
    """
    if not 3 < T < 4:
        raise ValueError(f"the one-phase continuum mode exists for 3 < T < 4, got {T!r}")
    C = gap / (2 * T - 6)
    omega = (2 * np.arange(1, int(modes) + 1) - 1) * np.pi / 2
    return float(4 * C**2 * np.sum(1 / omega**2))


def bar_continuum_field(T: float, gap: float):
    """``(u, u_t, u_x)`` of that mode for the unit bar (``L = EA = ρA = 1``), vectorised callables of ``(x, t)``."""
    if not 3 < T < 4:
        raise ValueError(f"the one-phase continuum mode exists for 3 < T < 4, got {T!r}")
    C = gap / (2 * T - 6)

    def g(s):
        return np.where(np.mod(s, T) < 2, -C, C)

    def G(s):  # antiderivative of g
        k, r = np.divmod(np.asarray(s, float), T)
        return k * C * (T - 4) + np.where(r < 2, -C * r, C * (r - 4))

    return (lambda x, t: G(t + x) - G(t - x), lambda x, t: g(t + x) - g(t - x), lambda x, t: g(t + x) + g(t - x))
