"""Which reduced model can I trust? The analysis of a comparison study (issue 12).

Plain functions over numpy data and the package's types; the table, CSV and diagnostics are in
:mod:`.table`, the figures in :mod:`.plots`.

- :func:`fe_reference` — what the full FE model contributes: its lowest modes, the contact's exact impact mass
  ``1/(wᵀM⁻¹w)`` and static compliance ``wᵀK⁻¹w`` (:class:`FEReference`);
- :class:`ModelResult` — one compared model as the study hands it over (reduced model, branches, timings);
- :func:`mac_matrix`, :func:`match_modes`, :func:`model_matches` — reduced modes against FE modes by mode shape
  (mass-weighted MAC), never by index: a mode without an FE counterpart is an artefact of the reduction;
- :func:`contact_spectrum`, :func:`kept_fraction` — the contact spectral data that decides impacts;
- :func:`arc_energies` — energies of the admissible orbits at given periods, on the admissible arcs only;
- :func:`choose_periods` — where to read them: inside the models' common admissible range (:class:`PeriodChoice`);
  :func:`largest_model` — the reference of the comparison.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp

from ...checks import integer, positive
from ...fe import FEModel, natural_frequencies, stiffness_factor
from ...linalg import SPDFactor, diagonal, spd_factor
from ...nsm import Branch, LinearSystem, MasslessSystem, Spectrum
from ...reduction import Contact, ReducedModel

__all__ = [
    "AUTO_PERIODS", "CLUSTER_RTOL", "MAC_THRESHOLD", "ContactSpectrum", "FEReference", "ModeMatch", "ModelResult",
    "PeriodChoice", "admissible_spans", "arc_energies", "choose_periods", "contact_spectrum", "fe_reference",
    "kept_fraction", "largest_model", "mac_matrix", "match_modes", "model_matches",
]

#: Default MAC a reduced mode needs with an FE mode to be its counterpart (above 0.5 the pairing is one-to-one).
MAC_THRESHOLD = 0.9
#: FE modes whose frequencies agree to this relative tolerance form one (repeated) mode: MAC with their span.
CLUSTER_RTOL = 1e-6


# ----------------------------------------------------------------------------- inputs


@dataclass(frozen=True, eq=False)
class FEReference:
    """The full FE model's part of a comparison (made by :func:`fe_reference`, or by hand from numpy data).

    Attributes
    ----------
    frequencies : (m,) ndarray
        The ``m`` lowest natural frequencies (Hz), ascending.
    modes : (n_free, m) ndarray
        Their mode shapes on the free dofs (M-normalised).
    M : (n_free, n_free) sparse
        The mass matrix (MAC weighting).
    w : (n_free,) ndarray
        The contact's constraint vector (``wᵀx`` = normal displacement of the contact).
    impact_mass, static_compliance : float
        Exact, over ALL modes: ``1/Σb² = 1/(wᵀM⁻¹w)`` and ``Σb²/ω² = wᵀK⁻¹w``.
    """

    frequencies: np.ndarray
    modes: np.ndarray = field(repr=False)
    M: sp.sparray = field(repr=False)
    w: np.ndarray = field(repr=False)
    impact_mass: float
    static_compliance: float

    @property
    def b(self) -> np.ndarray:
        """Contact participations ``b_j = wᵀφ_j`` of the computed modes."""
        return self.w @ self.modes

    @property
    def contact_motion(self) -> np.ndarray:
        """``|b_j| / (‖w‖₁ max_i |φ_ij|)`` in [0, 1]: how much mode ``j`` moves the contact compared with its
        largest dof displacement (near 0: the contact sits near a node line, or the normal is orthogonal to the
        mode's motion there)."""
        return np.abs(self.b) / (np.abs(self.w).sum() * np.abs(self.modes).max(axis=0))

    @property
    def n_dofs(self) -> int:
        return self.modes.shape[0]

    @property
    def omega(self) -> np.ndarray:
        return 2 * np.pi * np.asarray(self.frequencies, dtype=float)


def fe_reference(model: FEModel, contact: Contact, count: int, *, factor: SPDFactor | None = None) -> FEReference:
    """The ``count`` lowest FE modes and the exact contact measures of ``model`` (one factorisation of ``K``).

    Compute enough modes to cover the reduced models' frequencies of interest: a reduced mode above the highest
    FE mode computed cannot be checked (:func:`match_modes`).

    >>> import numpy as np
    >>> from skfem import MeshTri
    >>> from bladecase.fe import Mesh, assemble
    >>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 11), np.linspace(0, 0.02, 3))
    >>> p = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    >>> strip = assemble(Mesh(p, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(p[:, 0] == 0)}),
    ...                  "steel", order=1, thickness=0.002)
    >>> fe = fe_reference(strip, Contact.nearest(strip, (0.1, 0.02), normal=(0.0, 1.0), gap=1e-4), 3)
    >>> fe.frequencies.round(-1).tolist(), f"{fe.static_compliance:.3e} m/N"   # coarse P1: stiff
    ([2140.0, 11100.0, 12720.0], '7.008e-07 m/N')
    """
    if not isinstance(model, FEModel):
        raise ValueError(f"model must be an FEModel (from bladecase.assemble), got {type(model).__name__}")
    factor = factor if factor is not None else stiffness_factor(model)
    f, phi = natural_frequencies(model, count, return_modes=True, factor=factor)
    w = np.asarray(contact.w(model), dtype=float)
    m = diagonal(model.M)
    inv_mass = float(w @ (w / m)) if m is not None else float(w @ spd_factor(model.M, "M").solve(w))
    return FEReference(f, phi, sp.csr_array(model.M), w, 1.0 / inv_mass, float(w @ factor.solve(w)))


@dataclass(frozen=True, eq=False)
class ModelResult:
    """One compared model, as the study hands it over.

    Attributes
    ----------
    reduced : ReducedModel
        The model (a :class:`~bladecase.reduction.MasslessReducedModel` for the massless contact model).
    branches : list of Branch
        Every family the search found on ``reduced.system`` (all ``k``), admissible or not.
    build_s, search_s : float or None
        Wall-clock seconds to build the model and to search it (measured by the caller).
    name : str or None
        Its label; default ``"<method>-<size>"`` (``"<method>"`` when the size is ``None``, e.g. exact massless).
    """

    reduced: ReducedModel
    branches: list = field(default_factory=list, repr=False)
    build_s: float | None = None
    search_s: float | None = None
    name: str | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.reduced, ReducedModel):
            raise ValueError(f"reduced must be a ReducedModel (bladecase.reduce), got {type(self.reduced).__name__}")
        bad = [type(b).__name__ for b in self.branches if not isinstance(b, Branch)]
        if bad:
            raise ValueError(f"branches must be Branch objects (from nonsmooth_mode or backbone), got {bad[0]}")
        if self.name is None:
            size = self.reduced.size
            object.__setattr__(self, "name", self.method if size is None else f"{self.method}-{size}")

    method = property(lambda self: self.reduced.method, doc="The reduction method.")
    size = property(lambda self: self.reduced.size, doc="The size asked for (``None``: exact massless).")


# ----------------------------------------------------------------------------- contact spectral data


@dataclass(frozen=True, eq=False)
class ContactSpectrum:
    """The contact spectral measure of a model: ``b_j²`` at ``ω_j``, and what it decides.

    ``impact_mass`` = ``1/Σb²`` (Newton models: the mass the contact node shows an impact; ``None`` for the
    massless contact model, whose contact dofs carry no inertia: no impact law, nothing to compare);
    ``static_compliance`` = contact displacement per unit contact force (Newton: ``Σb²/ω²``; massless:
    ``1/k_c + Σb²/ω²`` over the open-phase modes — the Schur complement gives exactly the full model's
    ``wᵀK⁻¹w``, so this one IS comparable with the FE value); ``kc`` the massless model's contact stiffness.
    """

    omega: np.ndarray
    b2: np.ndarray
    contact_model: str
    impact_mass: float | None
    static_compliance: float
    kc: float | None = None

    @property
    def frequencies(self) -> np.ndarray:
        return self.omega / (2 * np.pi)


def contact_spectrum(source, *, kc: float | None = None) -> ContactSpectrum:
    """The :class:`ContactSpectrum` of a Spectrum, a LinearSystem, a MasslessSystem, a ReducedModel or an
    :class:`FEReference` (its computed modes, with the exact sums over all modes).

    A bare :class:`~bladecase.nsm.Spectrum` is a Newton model unless ``kc`` (massless: the open-phase spectrum and
    its contact stiffness) is given. Sums run over every mode of the (reduced) system, which is complete.

    >>> from bladecase.nsm import LinearSystem, condense
    >>> s = contact_spectrum(LinearSystem(np.eye(2), [[2.0, -1.0], [-1.0, 1.0]], w=1, gap=0.5))
    >>> s.b2.round(6).tolist(), round(s.impact_mass, 12), round(s.static_compliance, 12)  # 1/(wᵀM⁻¹w), wᵀK⁻¹w
    ([0.723607, 0.276393], 1.0, 2.0)
    >>> m = contact_spectrum(condense(np.diag([1.0, 0.0]), [[4.0, -3.0], [-3.0, 3.0]], [0.0, 1.0], gap=1.0))
    >>> m.contact_model, m.impact_mass, round(m.static_compliance, 12)   # springs 1 and 3 in series: 1 + 1/3
    ('massless', None, 1.333333333333)
    """
    if isinstance(source, ReducedModel):
        source = source.system
    if isinstance(source, FEReference):
        return ContactSpectrum(source.omega, np.asarray(source.b) ** 2, "newton", source.impact_mass,
                               source.static_compliance)
    if isinstance(source, MasslessSystem):
        source, kc = source.spectrum, source.kc_structure  # the structure's: the casing is not the blade's
    elif isinstance(source, LinearSystem):
        source = source.spectrum
    if not isinstance(source, Spectrum):
        raise ValueError("contact_spectrum takes a Spectrum, LinearSystem, MasslessSystem, ReducedModel or "
                         f"FEReference, got {type(source).__name__}")
    omega, b2 = np.asarray(source.omega, float), np.asarray(source.b, float) ** 2
    compliance = float(np.sum(b2 / omega**2))
    if kc is None:
        return ContactSpectrum(omega, b2, "newton", 1.0 / float(b2.sum()), compliance)
    kc = positive("kc", kc)
    return ContactSpectrum(omega, b2, "massless", None, 1.0 / kc + compliance, kc)


def kept_fraction(model_value: float | None, fe_value: float | None) -> float | None:
    """``model_value / fe_value``: how much of the FE value a model keeps (``None`` if either is missing or
    not finite, or the FE value is 0).

    >>> kept_fraction(3.0, 4.0), kept_fraction(None, 4.0)
    (0.75, None)
    """
    if model_value is None or fe_value is None:
        return None
    a, b = float(model_value), float(fe_value)
    return a / b if math.isfinite(a) and math.isfinite(b) and b != 0 else None


# ----------------------------------------------------------------------------- mode matching


def mac_matrix(phi: np.ndarray, M, psi: np.ndarray) -> np.ndarray:
    """``MAC_ij = |φ_iᵀMψ_j|² / ((φ_iᵀMφ_i)(ψ_jᵀMψ_j))`` for columns of ``phi`` (n, p) and ``psi`` (n, q);
    ``M`` sparse or dense (n, n), only multiplied with ``psi`` and ``phi`` (never made dense).

    >>> mac_matrix(np.eye(2), np.diag([1.0, 2.0]), np.array([[1.0, 1.0], [0.0, 1.0]])).round(4).tolist()
    [[1.0, 0.3333], [0.0, 0.6667]]
    """
    phi, psi = np.asarray(phi, float), np.asarray(psi, float)
    if phi.ndim != 2 or psi.ndim != 2 or phi.shape[0] != psi.shape[0] or M.shape != (phi.shape[0],) * 2:
        raise ValueError(f"phi {phi.shape}, M {M.shape} and psi {psi.shape} must be (n, p), (n, n), (n, q)")
    M_psi = np.asarray(M @ psi)
    cross = phi.T @ M_psi
    return cross**2 / np.outer(np.einsum("ij,ij->j", phi, np.asarray(M @ phi)), np.einsum("ij,ij->j", psi, M_psi))


@dataclass(frozen=True)
class ModeMatch:
    """A reduced mode (``index``, 0-based) and its FE counterpart (``fe_index``, or ``None``).

    ``mac`` is its MAC with the matched FE mode (with the span of a repeated FE frequency), else the best MAC;
    ``best_fe`` the FE mode of the best MAC; ``relative_error = f/f_FE − 1`` for a matched pair only;
    ``beyond_fe``: unmatched and above the highest FE frequency computed (unchecked, not called an artefact).
    """

    index: int
    fe_index: int | None
    mac: float
    best_fe: int
    frequency: float | None = None
    fe_frequency: float | None = None
    relative_error: float | None = None
    beyond_fe: bool = False

    @property
    def matched(self) -> bool:
        return self.fe_index is not None

    @property
    def artefact(self) -> bool:
        """No FE counterpart although in the range of the FE modes computed."""
        return not self.matched and not self.beyond_fe

    def describe(self) -> str:
        """E.g. ``"1610.3 Hz (FE 1, MAC 1.000, err +1.2e-10)"`` or ``"39157 Hz (no FE counterpart, …)"``."""
        f = "" if self.frequency is None else f"{self.frequency:.6g} Hz "
        if self.matched:
            err = "" if self.relative_error is None else f", err {self.relative_error:+.1e}"
            return f"{f}(FE {self.fe_index + 1}, MAC {self.mac:.3f}{err})"
        if self.beyond_fe:
            return f"{f}(above the FE modes computed)"
        return f"{f}(no FE counterpart; best MAC {self.mac:.2f} with FE {self.best_fe + 1})"


def _clusters(fe_frequencies: np.ndarray | None, p: int) -> list[np.ndarray]:
    if fe_frequencies is None:
        return [np.array([i]) for i in range(p)]
    f = np.asarray(fe_frequencies, dtype=float)
    cuts = np.flatnonzero(np.diff(f) > CLUSTER_RTOL * np.abs(f[1:])) + 1
    return np.split(np.arange(p), cuts)


def match_modes(fe_modes: np.ndarray, M, reduced_modes: np.ndarray, *, fe_frequencies=None, frequencies=None,
                threshold: float = MAC_THRESHOLD) -> list[ModeMatch]:
    """Pair each reduced mode (columns of ``reduced_modes``, expanded to the free dofs) with its FE counterpart.

    The counterpart is the FE mode of largest MAC (:func:`mac_matrix`) when that MAC is ``>= threshold``;
    otherwise the reduced mode has none (an artefact, e.g. a Lanczos Ritz vector mixing several FE modes).
    Never by index or nearest frequency. FE modes of one repeated frequency (``CLUSTER_RTOL``) count as one:
    the MAC with their span. ``threshold`` must be in (0.5, 1]: for M-orthonormal modes at most one pair per
    mode can then reach it. With ``frequencies`` (reduced) and ``fe_frequencies``, matched pairs get their
    relative frequency error, and an unmatched mode above the highest FE frequency is ``beyond_fe``.

    >>> fe = np.eye(3)                              # FE modes e₁, e₂, e₃ at 1, 2, 3 Hz (M = I)
    >>> red = np.array([[1.0, 0.0], [0.0, 1.0], [0.0, 1.0]])   # e₁, and a mix of e₂ and e₃
    >>> [m.describe() for m in match_modes(fe, np.eye(3), red, fe_frequencies=[1, 2, 3], frequencies=[1, 2.4])]
    ['1 Hz (FE 1, MAC 1.000, err +0.0e+00)', '2.4 Hz (no FE counterpart; best MAC 0.50 with FE 2)']
    """
    threshold = float(threshold)
    if not 0.5 < threshold <= 1.0:
        raise ValueError(f"threshold must be a MAC in (0.5, 1] (one-to-one pairing), got {threshold!r}")
    fe_modes, reduced_modes = np.asarray(fe_modes, float), np.asarray(reduced_modes, float)
    mac = mac_matrix(fe_modes, M, reduced_modes)
    p, q = mac.shape
    for name, arr, size in (("fe_frequencies", fe_frequencies, p), ("frequencies", frequencies, q)):
        if arr is not None and np.shape(arr) != (size,):
            raise ValueError(f"{name} must have one entry per mode ({size}), got shape {np.shape(arr)}")
    span = np.empty((p, q))  # MAC of every reduced mode with the span of each FE cluster, on all its members
    for c in _clusters(fe_frequencies, p):
        span[c] = mac[c].sum(axis=0)
    taken: set[int] = set()
    out = []
    fe_top = None if fe_frequencies is None else float(np.max(fe_frequencies))
    for j in np.argsort(-span.max(axis=0), kind="stable"):  # strongest pairs first: a member is taken once
        ranked = np.lexsort((-mac[:, j], -span[:, j]))  # best span, then best member of it
        free = [i for i in ranked if i not in taken]
        i = free[0] if free and span[free[0], j] >= threshold else None
        f = None if frequencies is None else float(frequencies[j])
        f_fe = None if i is None or fe_frequencies is None else float(fe_frequencies[i])
        err = None if f is None or f_fe is None else f / f_fe - 1.0
        beyond = i is None and f is not None and fe_top is not None and f > fe_top
        best = int(ranked[0])
        out.append(ModeMatch(int(j), None if i is None else int(i), float(span[best if i is None else i, j]),
                             best, f, f_fe, err, beyond))
        if i is not None:
            taken.add(int(i))
    return sorted(out, key=lambda m: m.index)


def model_matches(reduced: ReducedModel, fe: FEReference, *, modes: int = 8,
                  threshold: float = MAC_THRESHOLD) -> list[ModeMatch]:
    """:func:`match_modes` of a reduced model's modes, expanded to the free dofs (``V φ``; the open-phase modes
    of a massless model), against ``fe``: its lowest ``modes`` modes and every other mode below the highest FE
    frequency (higher ones cannot be checked and are left out; nothing ``n_free × n_reduced`` beyond them)."""
    modes = integer("modes", modes, 1)
    spec = reduced.system.spectrum
    f = spec.frequencies
    keep = np.flatnonzero((np.arange(f.size) < modes) | (f <= np.max(fe.frequencies)))
    psi = np.asarray(reduced.basis @ spec.phi[:, keep])
    found = match_modes(fe.modes, fe.M, psi, fe_frequencies=fe.frequencies, frequencies=f[keep], threshold=threshold)
    return [replace(m, index=int(keep[m.index])) for m in found]


# ----------------------------------------------------------------------------- energies on admissible arcs


def arc_energies(branches: Sequence[Branch], periods) -> list[np.ndarray]:
    """Energies of the admissible orbits at each of ``periods``, sorted, one array per period.

    Interpolated (linearly in ``T``, geometrically in ``E``) between consecutive computed points of an admissible
    arc only — never across a non-admissible stretch, never extrapolated beyond the arc's computed points (a
    period within 1e-12 of a computed point is that point). A curve that crosses a period several times (turning
    points, several families) gives several energies. Only the arcs' own points are read.

    >>> from bladecase.nsm import backbone, chain
    >>> bb = backbone(chain(2, k=1.0, m=0.5, gap=1.0), np.linspace(4.0, 12.0, 9))
    >>> [e.round(4).tolist() for e in arc_energies([bb], [4.5, 5.7, 6.0, 11.0])]  # 5.7: before arc 2's first point
    [[3.5559], [], [0.6028], []]
    """
    P = np.atleast_1d(np.asarray(periods, dtype=float))
    found: list[list[float]] = [[] for _ in P]
    for br in branches:
        for t, e in _arc_points(br):
            ok = np.isfinite(t) & np.isfinite(e) & (e > 0)
            seg = ok[:-1] & ok[1:] & (t[1:] != t[:-1])
            near = np.abs(P[:, None] - t[None, :]) <= 1e-12 * np.abs(t[None, :])
            Pa = np.where(near.any(axis=1), t[np.argmax(near, axis=1)], P)  # round-off next to a point: the point
            with np.errstate(divide="ignore", invalid="ignore"):
                a = (Pa[:, None] - t[None, :-1]) / (t[1:] - t[:-1])[None, :]
                logE = (1 - a) * np.log(e[:-1]) + a * np.log(e[1:])
            hit = seg[None, :] & (a >= 0) & (a < 1)
            ends = ok & ~np.r_[seg, False]  # a point no segment starts from: its period counts on its own
            at_end = ends[None, :] & (Pa[:, None] == t[None, :])
            for i in range(P.size):
                found[i] += np.exp(logE[i, hit[i]]).tolist() + e[at_end[i]].tolist()
    return [np.sort(np.array(v, dtype=float)) for v in found]


def _arc_points(br: Branch) -> list[tuple[np.ndarray, np.ndarray]]:
    """``(T, E)`` of the computed points of each admissible arc of ``br`` (no orbit outside an arc is read)."""
    T = br.T
    return [(np.asarray(T[a.start:a.stop + 1], dtype=float),
             np.array([np.nan if o is None else o.energy for o in br.orbits[a.start:a.stop + 1]], dtype=float))
            for a in br.arcs]


# ----------------------------------------------------------------------------- the comparison periods


def admissible_spans(branches: Sequence[Branch]) -> list[tuple[float, float]]:
    """The period ranges ``(lo, hi)`` where :func:`arc_energies` has an energy: the stretches between consecutive
    computed points of the admissible arcs (a lone point is ``(T, T)``), merged where they meet, ascending.

    >>> from bladecase.nsm import backbone, chain
    >>> admissible_spans([backbone(chain(2, k=1.0, m=0.5, gap=1.0), np.linspace(4.0, 12.0, 9))])
    [(4.0, 5.0), (6.0, 7.0)]
    """
    spans = []
    for br in branches:
        for t, e in _arc_points(br):
            ok = np.isfinite(t) & np.isfinite(e) & (e > 0)
            seg = ok[:-1] & ok[1:]
            spans += [(min(t[i], t[i + 1]), max(t[i], t[i + 1])) for i in np.flatnonzero(seg)]
            alone = ok & ~np.r_[False, seg] & ~np.r_[seg, False]
            spans += [(t[i], t[i]) for i in np.flatnonzero(alone)]
    merged: list[list[float]] = []
    for lo, hi in sorted(spans):
        if merged and lo <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], hi)
        else:
            merged.append([lo, hi])
    return [(float(lo), float(hi)) for lo, hi in merged]


def largest_model(entries: Sequence[ModelResult]) -> ModelResult | None:
    """The reference of a comparison: the model of most reduced dofs (the later one of a tie), ``None`` if empty."""
    entries = list(entries)
    return max(reversed(entries), key=lambda e: e.reduced.n) if entries else None


@dataclass(frozen=True)
class PeriodChoice:
    """The periods (× ``T1``) at which a comparison reads every model's energy, and why these.

    ``source``: ``"given"`` (asked for, and inside some model's arc), ``"intersection"`` (spread inside the
    intersection of every model's admissible arcs), ``"overlap"`` (inside the stretch where the most models' arcs
    overlap — the reference's first), ``"own arcs"`` (the arcs do not overlap: one period inside each model's own
    widest arc; or the only model with arcs), ``"none"`` (no model has an admissible arc: the given periods,
    or none); ``models``: the models whose arcs hold the periods; ``words``: the sentence for the log and report.
    """

    fractions: tuple[float, ...]
    source: str
    words: str
    models: tuple[str, ...] = ()
    T1: float | None = None

    def to_dict(self) -> dict:
        T1 = self.T1
        return {"fractions": list(self.fractions), "periods_s": None if T1 is None else
                [f * T1 for f in self.fractions], "T1_s": T1, "source": self.source, "models": list(self.models),
                "words": self.words}


#: How many periods a comparison spreads over the common admissible range.
AUTO_PERIODS = 5


def _spread(lo: float, hi: float, T1: float, count: int) -> list[float]:
    """``count`` fractions of ``T1`` evenly inside ``[lo, hi]`` (s), distinct in the energy columns' 10 digits;
    the middle alone when the range is narrower than that (a lone computed point: that point)."""
    P = lo + (hi - lo) * (np.arange(count) + 0.5) / count if hi - lo > 1e-8 * hi else [0.5 * (lo + hi)]
    out: dict[str, float] = {}
    for p in P:
        out.setdefault(f"{p / T1:.10g}", float(p / T1))
    return list(out.values())


def _regions(spans: dict[str, list[tuple[float, float]]]) -> list[tuple[float, float, frozenset]]:
    """Maximal stretches (lo, hi) covered by one set of models, degenerate points included."""
    edges = sorted({x for s in spans.values() for iv in s for x in iv})
    pieces = [(x, x) for x in edges] + list(zip(edges[:-1], edges[1:]))
    out = []
    for lo, hi in pieces:
        cover = frozenset(n for n, s in spans.items() if any(a <= lo and hi <= b for a, b in s))
        if cover:
            out.append((lo, hi, cover))
    out.sort()
    merged: list[list] = []
    for lo, hi, cover in out:  # join neighbouring pieces with the same models
        if merged and merged[-1][2] == cover and lo <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], hi)
        else:
            merged.append([lo, hi, cover])
    return [(lo, hi, c) for lo, hi, c in merged]


def _range_words(lo: float, hi: float, T1: float) -> str:
    return f"{lo / T1:.6g} T1" if hi - lo <= 1e-9 * hi else f"{lo / T1:.6g}–{hi / T1:.6g} T1"


def _names(names) -> str:
    names = list(names)
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


def choose_periods(entries: Sequence[ModelResult], T1: float, *, given: Sequence[float] | None = None,
                   reference: str | None = None, count: int = AUTO_PERIODS) -> PeriodChoice:
    """The periods (fractions of ``T1``) where a comparison reads the models' energies (:class:`PeriodChoice`).

    ``given`` periods are kept when at least one lies inside some model's admissible range. Otherwise (none
    given, or all outside every arc) ``count`` periods are spread inside the stretch where the admissible arcs
    (:func:`admissible_spans`) of the most models overlap — the ``reference`` model's arcs first (default: the
    largest model, :func:`largest_model`), then the most models, then the widest stretch; when no two models'
    arcs overlap, one period at the middle of each model's widest arc (the reference first, at most 8).

    >>> from types import SimpleNamespace as NS
    >>> from bladecase.nsm import backbone, chain
    >>> def model(name, k, T):   # what a comparison reads of a model: its name and its branches
    ...     return NS(name=name, branches=[backbone(chain(2, k=k, m=0.5, gap=1.0), T)])
    >>> a, b = model("a", 1.0, np.linspace(4.0, 12.0, 9)), model("b", 1.2, np.linspace(4.0, 12.0, 17))
    >>> admissible_spans(a.branches), admissible_spans(b.branches)
    ([(4.0, 5.0), (6.0, 7.0)], [(4.0, 5.0), (5.5, 6.5), (12.0, 12.0)])
    >>> c = choose_periods([a, b], 1.0, reference="b")
    >>> c.source, c.fractions    # the widest common stretch: [4, 5]
    ('intersection', (4.1, 4.3, 4.5, 4.7, 4.9))
    >>> choose_periods([a, b], 1.0, given=[6.25]).source    # inside a's and b's arcs: as asked
    'given'
    >>> print(*choose_periods([a, b], 1.0, given=[8.0], reference="b").words.split(": "), sep=":\\n")
    the compare_periods asked for (8 T1) miss every admissible arc:
    5 periods spread inside the intersection of the admissible arcs of a and b (4–5 T1)
    """
    T1 = positive("T1", T1)
    entries = list(entries)
    spans = {e.name: admissible_spans(e.branches) for e in entries}
    spans = {n: s for n, s in spans.items() if s}
    if given is not None:
        given = tuple(float(f) for f in given)
        inside = [f for f in given if any(lo <= f * T1 <= hi for s in spans.values() for lo, hi in s)]
        if inside:
            return PeriodChoice(given, "given", f"energies read at the periods asked for ({_fractions(given)} T1)",
                                tuple(n for n, s in spans.items() if any(lo <= f * T1 <= hi for f in given
                                                                         for lo, hi in s)), T1)
    missed = ("" if given is None else
              f"the compare_periods asked for ({_fractions(given)} T1) miss every admissible arc: ")
    if not spans:
        return PeriodChoice(given or (), "none", "no model has an admissible arc: no period to compare energies at",
                            (), T1)
    if reference is None and entries:
        reference = largest_model(entries).name
    best = max(_regions(spans), key=lambda r: (reference in r[2], len(r[2]), (r[1] - r[0]) / r[1]))
    lo, hi, cover = best
    if len(cover) >= 2 or len(spans) == 1:
        fractions = tuple(_spread(lo, hi, T1, count))
        models = tuple(n for n in spans if n in cover)
        where = _range_words(lo, hi, T1)
        n = f"{len(fractions)} period{'s' if len(fractions) > 1 else ''}"
        if len(spans) == 1:
            source, text = "own arcs", f"only {models[0]} has an admissible arc: {n} inside it ({where})"
        elif len(cover) == len(spans):
            source = "intersection"
            text = (f"{n} {'spread ' if len(fractions) > 1 else ''}inside the intersection of the admissible arcs "
                    f"of {_names(models)} ({where})")
        else:
            source = "overlap"
            out = [m for m in spans if m not in cover]
            text = (f"{n} inside {where}, where the admissible arcs of {_names(models)} overlap "
                    f"({_names(out)} {'has' if len(out) == 1 else 'have'} no admissible arc there)")
        none = [e.name for e in entries if e.name not in spans]
        if none:
            text += f"; {_names(none)} found no admissible arc"
        return PeriodChoice(fractions, source, missed + text, models, T1)
    order = sorted(spans, key=lambda n: (n != reference, list(spans).index(n)))[:8]
    picks = {}
    for n in order:
        a, b = max(spans[n], key=lambda s: s[1] - s[0])
        picks[n] = 0.5 * (a + b) / T1
    fractions = tuple(sorted({f"{f:.10g}": f for f in picks.values()}.values()))
    text = ("the models' admissible arcs do not overlap: one period inside each model's own widest arc ("
            + ", ".join(f"{n} at {f:.10g} T1" for n, f in picks.items()) + ")")
    return PeriodChoice(fractions, "own arcs", missed + text, tuple(picks), T1)


def _fractions(fractions) -> str:
    return ", ".join(f"{f:.10g}" for f in fractions)
