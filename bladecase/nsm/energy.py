"""Where an orbit's energy sits: its split over the linear modes of its system (:func:`modal_energy_split`).

Between impacts (Newton) or during an open phase (massless), the linear modes are uncoupled, so each mode's energy
``½(q̇² + ω²q²)`` is constant on each flight; the split is its time average over the free flights of one period,
as a fraction of the total.  An orbit whose energy sits mostly in modes far above its own frequency — the
mesh-scale modes of a reduced or FE model — is an artefact of the discretisation, not a structural mode: the
study report says so in words (:func:`describe_split`).

>>> from bladecase.nsm import chain, orbit_1ipp
>>> split = modal_energy_split(orbit_1ipp(chain(2, k=1.0, m=0.5, gap=1.0), 6.0))
>>> split.frequencies.round(4).tolist(), split.shares.round(4).tolist()
([0.1391, 0.3642], [0.7622, 0.2378])
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ModalSplit", "describe_split", "modal_energy_split"]

#: Share of the energy above which an orbit is said to be dominated by the modes that hold it.
DOMINANT_SHARE = 0.5


@dataclass(frozen=True)
class ModalSplit:
    """Time-averaged share of an orbit's energy per linear mode (free flights / open phases).

    ``frequencies`` in cycles per time unit of the system (Hz for an FE model), ascending; ``shares`` sum to 1.
    """

    frequencies: np.ndarray
    shares: np.ndarray

    def above(self, frequency: float) -> float:
        """Share of the energy in modes above ``frequency``."""
        return float(self.shares[self.frequencies > frequency].sum())

    def top(self, count: int = 3) -> list[tuple[int, float, float]]:
        """``(mode number from 1, frequency, share)`` of the ``count`` modes holding most energy."""
        idx = np.argsort(self.shares)[::-1][:count]
        return [(int(i) + 1, float(self.frequencies[i]), float(self.shares[i])) for i in idx]

    def to_dict(self, count: int = 5) -> dict:
        return {"top_modes": [{"mode": m, "frequency": f, "share": s} for m, f, s in self.top(count)]}


def _newton(orbit) -> tuple[np.ndarray, np.ndarray]:
    md = orbit._modal
    edges = np.concatenate([[0.0], np.asarray(orbit.impact_times, float)])
    mids, widths = 0.5 * (edges[:-1] + edges[1:]), np.diff(edges)
    q, qd = orbit.modal_state(mids)
    per_mode = 0.5 * (qd**2 + (md.omega[:, None] * q) ** 2) @ widths
    return md.omega, per_mode


def _massless(orbit) -> tuple[np.ndarray, np.ndarray]:
    from .massless.phases import PhasedOrbit

    s = orbit._bound()
    o = s.open
    if not isinstance(orbit, PhasedOrbit):
        orbit = PhasedOrbit(s, "open", [orbit.alpha, orbit.beta], orbit.a)
    per_mode = np.zeros(s.n)
    for start, stop, kind in orbit.segments:
        if kind == 0:
            x, v = orbit.state(0.5 * (start + stop))
            q, p = o.modal(x[:, 0], v[:, 0])
            per_mode += 0.5 * (p**2 + (o.omega * q) ** 2) * (stop - start)
    return o.omega, per_mode


def modal_energy_split(orbit) -> ModalSplit:
    """The time-averaged share of ``orbit``'s energy per linear mode (open-phase modes for the massless model)."""
    omega, per_mode = _massless(orbit) if getattr(orbit, "contact_model", "newton") == "massless" else _newton(orbit)
    total = float(per_mode.sum())
    if not total > 0:
        raise ValueError("the orbit carries no energy in its free flights: no modal split")
    order = np.argsort(omega)
    return ModalSplit(omega[order] / (2 * np.pi), per_mode[order] / total)


def describe_split(split: ModalSplit, orbit_frequency: float, band: float | None = None, unit: str = "Hz") -> str:
    """One sentence on where the energy sits; flags an orbit dominated by modes above ``band`` (the reference
    model's highest frequency when given, else 10 × the orbit's frequency)."""
    top = ", ".join(f"{share:.0%} in mode {m} ({f:.4g} {unit})" for m, f, share in split.top(3) if share >= 0.01)
    limit = 10 * orbit_frequency if band is None else band
    high = split.above(limit)
    words = f"Energy: {top}."
    if high >= DOMINANT_SHARE:
        what = "the reference model's band" if band is not None else "ten times the orbit's frequency"
        words += (f" **Doubtful:** {high:.0%} of it sits in modes above {limit:.4g} {unit} ({what}) — mesh-scale "
                  "modes of the model, not a structural motion.")
    return words
