"""What the verdict reads from a run's summary: the modes the contact sees, the main family, the searched
periods (:class:`_Base`)."""

from __future__ import annotations

import math

from .words import GRAZING_RTOL, UNSEEN_B, WEAK_B2, _pct, _pcts, massless_summary


class _Base:
    """The summary's data the three sentences are made of, and the reason codes collected."""


    def __init__(self, summary: dict, modes: dict | None):
        self.s, self.modes = summary, modes
        self.codes: list[str] = []
        self.massless = massless_summary(summary)
        r = summary["reduction"]
        self.f = [float(x) for x in r.get("frequencies_hz") or []]
        self.b2 = [float(x) for x in r.get("contact_weights_b2") or []][: len(self.f)]
        top = max((math.sqrt(max(b, 0.0)) for b in self.b2), default=0.0)
        #: modes the contact sees at all (as the T<j> period unit counts them)
        self.seen = [j for j, b in enumerate(self.b2) if math.sqrt(max(b, 0.0)) > UNSEEN_B * top]
        self.weak = self._weak_modes()
        s = summary["search"]
        self.unit, self.unit_s = s.get("period_unit", "s"), float(s.get("period_unit_s") or 1.0)
        self.periods = [float(x) for x in s["periods"]]
        self.T_lo, self.T_hi = self.periods[0] * self.unit_s, self.periods[1] * self.unit_s
        self.T1 = (1 / self.f[self.seen[0]]) if self.seen and self.f[self.seen[0]] > 0 else None
        self.fams = summary.get("families") or []
        self.with_arcs = [(i, f) for i, f in enumerate(self.fams) if f.get("admissible_arcs")]
        self.anims = (summary.get("files") or {}).get("animations") or []
        self.main = self._main_family()

    # --- helpers on the data

    def code(self, *codes: str) -> None:
        for c in codes:
            if c not in self.codes:
                self.codes.append(c)

    def _weak_modes(self) -> list[int]:
        """The modes whose ``b²`` is below :data:`WEAK_B2` of the largest (over the modes with an FE counterpart
        when the summary matches them: the massless attachment mode or mesh-scale modes do not set the scale)."""
        if not self.b2:
            return []
        largest = max(self.b2[j] for j in self._b2_pool())
        return [j for j, b in enumerate(self.b2) if largest > 0 and b < WEAK_B2 * largest]

    def _b2_pool(self) -> list[int]:
        """The modes whose ``b²`` sets the scale: those with an FE counterpart (all, without the matching)."""
        matches = self.s["reduction"].get("fe_match")
        pool = [j for j in range(len(self.b2))
                if matches is None or (j < len(matches) and matches[j] and matches[j].get("fe_mode") is not None)]
        return pool or list(range(len(self.b2)))

    def leading_weak(self) -> list[int]:
        """Modes 1..k, all weak (the contact group on their node line)."""
        out = []
        for j in range(len(self.b2)):
            if j not in self.weak:
                break
            out.append(j)
        return out

    def _main_family(self) -> tuple[int, dict] | None:
        """The family with the widest admissible arc (relative, in frequency), as the animations choose."""
        def width(item):
            i, fam = item
            return (max((a["f_hi"] - a["f_lo"]) / a["f_hi"] for a in fam["admissible_arcs"]),
                    fam.get("admissible_orbits", 0), -i)
        return max(self.with_arcs, key=width) if self.with_arcs else None

    def grown_from(self, f_lo: float, f_hi: float) -> int | None:
        """The mode (0-based) whose linear frequency is nearest (in ratio) to the middle of ``[f_lo, f_hi]``,
        among the modes the contact sees."""
        mid = math.sqrt(f_lo * f_hi)
        pool = [j for j in self.seen if self.f[j] > 0] or [j for j in range(len(self.f)) if self.f[j] > 0]
        return min(pool, key=lambda j: abs(math.log(mid / self.f[j]))) if pool else None

    def where(self, f_lo: float, f_hi: float, j: int, named: bool = True) -> str:
        """Where ``[f_lo, f_hi]`` lies relative to the linear frequency of mode ``j`` (``named``: say which, else
        ``it``)."""
        fj = self.f[j]
        lo, hi = f_lo / fj - 1, f_hi / fj - 1
        lin = f"the linear frequency of mode {j + 1}, {fj:.1f} Hz" if named else "it"
        if abs(lo) <= GRAZING_RTOL:
            return f"from grazing to {_pct(hi)} % above {lin}"
        if lo > 0:
            return f"{_pcts(lo, hi)} % above {lin}"
        if hi < 0:
            return f"{_pcts(-hi, -lo)} % below {lin}"
        return f"from {_pct(-lo)} % below to {_pct(hi)} % above {lin}"

    def range_words(self) -> str:
        a, b = self.periods
        unit = "s" if self.unit == "s" else f"× {self.unit}"
        secs = "" if self.unit == "s" else f" (= [{self.T_lo:.6g}, {self.T_hi:.6g}] s)"
        return f"[{a:g}, {b:g}] {unit}{secs}"

    def in_units(self, T: float) -> str:
        """A period in the study's period unit: ``1.0 T1``, ``0.00475 s``."""
        if self.unit == "s":
            return f"{T:.6g} s"
        v = f"{T / self.unit_s:.4g}"
        return f"{v}{'' if '.' in v or 'e' in v else '.0'} {self.unit}"

    def grazing_in_range(self) -> list[int]:
        """The modes the contact sees whose linear period lies in the searched range."""
        return [j for j in self.seen if self.f[j] > 0 and self.T_lo <= 1 / self.f[j] <= self.T_hi]

    def arcs(self, fam: dict) -> list[dict]:
        return fam.get("admissible_arcs") or []

    def phases(self, k: int) -> str:
        if self.massless:
            return "one contact phase per period" if k == 1 else f"{k} contact phases per period"
        return "one impact per period" if k == 1 else f"{k} impacts per period"

    # --- line 1: what was found
