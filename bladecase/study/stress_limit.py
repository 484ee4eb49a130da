"""Where the model stops being the blade: the elastic limit of the nonsmooth modes' arcs (``[material]
yield_strength``).

The FE model is linear elastic. An orbit whose stress somewhere in the blade exceeds the material's yield strength is
beyond the model: the blade would yield, and the figures of that orbit describe no real blade. With ``[material]
yield_strength`` given (Pa), a study cuts every admissible arc where an orbit's **peak von Mises stress** — the
largest over the sampled instants of the period (:data:`~bladecase.study.render.ENGINEERING_SAMPLES` per period and
:data:`~bladecase.study.render.PHASE_SAMPLES` per contact phase, as the tip amplitude is sampled) and over every node
of the mesh (the nodal stress, :func:`bladecase.fe.stress.nodal_stress`: each element's stress at its nodes averaged
over the elements that share it) — exceeds it, as :mod:`~bladecase.study.validity` cuts at the amplitude limit; the
report and ``summary.json`` say where each arc was cut and why (the stress, where in the blade and when). The
every-node family (``[contact] points = "nodes"``) is cut at its first orbit beyond the yield strength
(:func:`cut_nodal_family`), as at the amplitude limit.

The stress is linear in the displacement, and the displacement of a reduced model's orbit is a combination of a few
vectors: ``u(t) = V x(t)`` (+ ``closed_shape · λ(t)`` for the massless contact model, + ``closed_shapes · λ(t)``
with one force per node for the every-node model). The nodal stress of each
vector is computed once per model (:func:`bladecase.fe.stress.stress_modes`, one pass over the cells); an orbit's
stress at its sampled instants is then ``σ(t) = Σ_j c_j(t) σ_j`` (one product), its von Mises equivalent and its peak.
A model with many vectors (the ``full`` method) expands each orbit's sampled displacements instead. At speed
(``[rotation]``: a model linearised about its centrifugal state) the steady centrifugal stress is added at every
instant (``σ₀ + σ(t)``; its Cauchy stress when the state is geometrically nonlinear): the blade yields under both.

The peak is a nodal value of the mesh: at a sharp re-entrant corner of the clamp the exact stress is singular, and
the nodal peak there grows under refinement; a limit it crosses first at such a corner is the model's clamp, not the
blade's — read where the cut happened (``at_mm``).

>>> from bladecase.study.schema import loads
>>> from bladecase.study.stages import build_contact, build_mesh, build_model, build_reduced
>>> s = loads('study = {name = "s"}\\ngeometry = {kind = "plate", span = 0.1, chord = 0.02, size = 0.01}\\n'
...           'fem = {order = 1, thickness = 0.002}\\ncontact = {clearance = 1e-4, model = "massless", '
...           'casing_stiffness = 1e6, face = "tip", normal = [1.0, 0.0]}\\n'
...           'reduction = {method = "massless", size = 4}\\nsearch = {ipp = [1]}\\n')
>>> model = build_model(s, build_mesh(s))
>>> reduced = build_reduced(s, model, build_contact(s, model))
>>> stress = orbit_stress(reduced)      # its basis's vectors and the closed phase's shape, 6 components at each node
>>> stress.modes.shape == (reduced.n + 1, len(stress.points), 6)
True
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np

from .. import log
from ..fe.stress import fe_node_points, stress_modes
from ..reduction import MasslessReducedModel, ReducedModel
from ..reduction.nodes import NodalReducedModel

__all__ = ["MAX_MODES", "MISES", "OrbitStress", "band_cut", "cut_nodal_family", "model_cuts", "orbit_stress",
           "orbit_times", "stress_cuts"]

#: The expansions whose vectors :func:`orbit_stress` combines: ``u = V x`` plus these shapes times these forces.
_EXPANSIONS = (ReducedModel.free_dofs, MasslessReducedModel.free_dofs, NodalReducedModel.free_dofs)

#: Above this many vectors a model's orbits are expanded instant by instant (their stress computed per orbit).
MAX_MODES = 256
#: Values of the stress ``(instants × nodes × 6)`` held at once when an orbit's peak is taken.
BATCH_VALUES = 4_000_000

#: Nodes of highest stress bound evaluated first by :meth:`OrbitStress.peak` (the others only where their bound
#: reaches the peak found there).
PROBE_NODES = 64

_R2, _R3 = np.sqrt(0.5), np.sqrt(3.0)
#: ``|MISES σ|`` is the von Mises stress of ``σ`` in Voigt order (:func:`bladecase.fe.stress.von_mises_voigt`):
#: ``½[(σxx−σyy)² + (σyy−σzz)² + (σzz−σxx)²] + 3(σxy² + σyz² + σzx²)`` as a sum of six squares, so that an orbit's
#: von Mises stress is a norm of a linear combination of mapped stresses.
MISES = np.array([[_R2, -_R2, 0, 0, 0, 0], [0, _R2, -_R2, 0, 0, 0], [-_R2, 0, _R2, 0, 0, 0],
                  [0, 0, 0, _R3, 0, 0], [0, 0, 0, 0, _R3, 0], [0, 0, 0, 0, 0, _R3]])


def orbit_times(orbit) -> np.ndarray:
    """The instants at which an orbit's stress (and tip amplitude, :func:`~bladecase.study.render.orbit_engineering`)
    is sampled: :data:`~bladecase.study.render.ENGINEERING_SAMPLES` over the period and
    :data:`~bladecase.study.render.PHASE_SAMPLES` in each contact phase."""
    from .render import ENGINEERING_SAMPLES, PHASE_SAMPLES

    T = float(orbit.T)
    intervals = [tuple(map(float, c)) for c in getattr(orbit, "contact_intervals", [])]
    return np.unique(np.mod(np.concatenate([np.linspace(0.0, T, ENGINEERING_SAMPLES, endpoint=False)]
                                           + [np.linspace(a, b, PHASE_SAMPLES) for a, b in intervals]), T))


@dataclasses.dataclass
class OrbitStress:
    """The nodal stress of a reduced model's orbits (the module). ``modes`` ``(k, N, 6)``: the stress of each vector
    of the expansion (``None``: expanded per orbit); ``points`` ``(N, 3)``: where the ``N`` nodes are (m)."""

    reduced: ReducedModel
    modes: np.ndarray | None
    points: np.ndarray
    steady: np.ndarray | None = None  #: ``(N, 6)``: the centrifugal prestress at speed (``None``: at rest)

    def coefficients(self, x: np.ndarray) -> np.ndarray:
        """The weights ``(k, instants)`` of :attr:`modes` for reduced states ``x`` ``(n, instants)``."""
        kind = type(self.reduced).free_dofs
        if kind is MasslessReducedModel.free_dofs:
            return np.vstack([x, np.atleast_2d(self.reduced.multiplier(x))])
        if kind is NodalReducedModel.free_dofs:
            return np.vstack([x, np.asarray(self.reduced.system.forces(x)).reshape(-1, x.shape[1])])
        return x

    def field(self, x: np.ndarray) -> np.ndarray:
        """The stress ``(instants, N, 6)`` of reduced states ``x`` ``(n, instants)`` (Pa, :data:`VOIGT` order)."""
        if self.modes is None:
            out = stress_modes(self.reduced.model, self.reduced.free_dofs(x)).reshape(x.shape[1], -1, 6)
        else:
            k, n, _ = self.modes.shape
            out = (self.coefficients(x).T @ self.modes.reshape(k, n * 6)).reshape(x.shape[1], n, 6)
        return out if self.steady is None else out + self.steady

    @functools.cached_property
    def _mises(self) -> tuple[np.ndarray | None, np.ndarray | None]:
        """:attr:`modes` and :attr:`steady` mapped by :data:`MISES` (``(k, N, 6)``, ``(N, 6)``)."""
        modes = None if self.modes is None else self.modes @ MISES.T
        return modes, None if self.steady is None else self.steady @ MISES.T

    @functools.cached_property
    def _norms(self) -> tuple[np.ndarray, np.ndarray]:
        """Each mapped mode's von Mises stress at each node ``(k, N)``, and the prestress's ``(N,)`` (0 at rest)."""
        modes, steady = self._mises
        return (np.linalg.norm(modes, axis=2),
                np.zeros(modes.shape[1]) if steady is None else np.linalg.norm(steady, axis=1))

    def mises_squared(self, x: np.ndarray, nodes: np.ndarray | None = None) -> np.ndarray:
        """The squared von Mises stress ``(instants, len(nodes))`` of reduced states ``x`` ``(n, instants)`` at
        ``nodes`` (default every node; Pa²): one product with the mapped stresses (:data:`MISES`), squares summed."""
        modes, steady = self._mises
        if modes is None:
            y = self.field(x) @ MISES.T
            y = y if nodes is None else y[:, nodes]
        else:
            sub = modes if nodes is None else modes[:, nodes]
            y = (self.coefficients(x).T @ sub.reshape(sub.shape[0], -1)).reshape(x.shape[1], -1, 6)
            if steady is not None:
                y += steady if nodes is None else steady[nodes]
        np.square(y, out=y)
        return (y.reshape(-1, 6) @ np.ones(6)).reshape(y.shape[:2])

    def _peak_at(self, x: np.ndarray, nodes: np.ndarray) -> tuple[float, int, int]:
        """``(peak², instant, node)`` of the squared von Mises stress over the states ``x`` at ``nodes``."""
        step = max(1, BATCH_VALUES // (6 * max(len(nodes), 1)))
        best, where = -1.0, (0, int(nodes[0]))
        for a in range(0, x.shape[1], step):
            vm2 = self.mises_squared(x[:, a:a + step], nodes)
            i, j = np.unravel_index(int(np.argmax(vm2)), vm2.shape)
            if vm2[i, j] > best:
                best, where = float(vm2[i, j]), (a + i, int(nodes[j]))
        return best, *where

    def peak(self, orbit) -> dict:
        """The orbit's peak von Mises stress over its sampled instants and every node: ``von_mises_pa``, where
        (``at_mm``, the node's position) and when (``t_over_T``).

        Exact over every node, evaluated at few: a node's von Mises stress never exceeds ``Σ_j max_t|c_j(t)| ·
        vm(σ_j) + vm(σ₀)`` there (the triangle inequality of the norm it is), so once the most promising nodes give
        a peak, only the nodes whose bound reaches it are evaluated."""
        times = orbit_times(orbit)
        x, _ = orbit.state(times)
        everything = np.arange(self.points.shape[0])
        if self.modes is None:
            best, i, node = self._peak_at(x, everything)
        else:
            norms, steady = self._norms
            bound = np.abs(self.coefficients(x)).max(axis=1) @ norms + steady
            first = np.argsort(bound)[-PROBE_NODES:]
            best, i, node = self._peak_at(x, first)
            rest = np.setdiff1d(np.flatnonzero(bound >= np.sqrt(best) * (1 - 1e-12)), first)
            if rest.size:
                more = self._peak_at(x, rest)
                if more[0] > best:
                    best, i, node = more
        return {"von_mises_pa": float(np.sqrt(best)),
                "at_mm": [float(c) for c in np.round(self.points[node] * 1e3, 4)],
                "t_over_T": float(times[i] / orbit.T)}

    def __call__(self, orbit) -> float:
        """The orbit's peak von Mises stress (Pa)."""
        return self.peak(orbit)["von_mises_pa"]


def orbit_stress(reduced: ReducedModel) -> OrbitStress:
    """The stress of ``reduced``'s orbits: the nodal stress of each vector of its expansion computed once (its basis,
    and the massless model's closed-phase shape), or, for a model of more than :data:`MAX_MODES` vectors or another
    expansion, per orbit."""
    model = reduced.model
    points = fe_node_points(model)
    steady = _prestress(model)
    kind = type(reduced).free_dofs
    shapes = {MasslessReducedModel.free_dofs: lambda: reduced.closed_shape[:, None],
              NodalReducedModel.free_dofs: lambda: reduced.closed_shapes}.get(kind, lambda: np.zeros((model.n_dofs, 0)))
    if kind not in _EXPANSIONS or reduced.n + shapes().shape[1] > MAX_MODES:
        return OrbitStress(reduced, None, points, steady)
    V = reduced.basis.toarray() if hasattr(reduced.basis, "toarray") else np.asarray(reduced.basis)
    V = np.column_stack([V, shapes()])
    return OrbitStress(reduced, stress_modes(model, V), points, steady)


def _prestress(model) -> np.ndarray | None:
    """The centrifugal prestress ``(N, 6)`` of a model at speed (:func:`bladecase.fe.rotation.spun_state`), ``None``
    at rest."""
    from ..fe.rotation import spun_state
    from ..fe.stress import VOIGT, nodal_stress

    state = spun_state(model)
    if state is None:
        return None
    _, _, u0, static = state
    sigma = nodal_stress(model, u0, "cauchy" if static == "nonlinear" else "linear")
    rows, cols = zip(*VOIGT)
    return sigma[:, rows, cols]


def model_cuts(reduced: ReducedModel, families: list, yield_strength: float) -> tuple[list, list[dict]]:
    """``families`` of ``reduced`` with their arcs cut where an orbit's peak von Mises stress exceeds
    ``yield_strength`` (Pa), and one record per cut: :func:`~bladecase.study.validity.cut_arcs`'s (``von_mises_beyond``,
    ``von_mises_cut`` in Pa) with where and when the first orbit beyond peaks (``at_mm``, ``t_over_T``)."""
    from .validity import cut_arcs

    stress = orbit_stress(reduced)
    cut, cuts = cut_arcs(families, [stress] * len(families), yield_strength, name="von_mises")
    for c in cuts:
        peak = stress.peak(families[c["family"]].orbits[c["orbit_beyond"]])
        c.update(at_mm=peak["at_mm"], t_over_T=peak["t_over_T"])
    return cut, cuts


def stress_cuts(searched: list, found: list, yield_strength: float) -> tuple[list, list[dict]]:
    """Every model's families (``found[i]`` of ``searched[i]``) cut at ``yield_strength`` (:func:`model_cuts`), and
    the main model's cuts, each logged."""
    out, main = [], []
    for n, (reduced, fams) in enumerate(zip(searched, found)):
        cut, cuts = model_cuts(reduced, fams, yield_strength)
        out.append(cut)
        if n == 0:
            main = cuts
    for c in main:
        at = (f"its last orbit within it, T = {c['T_cut']:.8g} s ({1 / c['T_cut']:.6g} Hz, "
              f"{c['von_mises_cut'] / 1e6:.4g} MPa)" if c["T_cut"] else "none of its orbits is within it")
        log.warning("family %d: an admissible arc is cut at the elastic limit: the peak von Mises stress is %.4g MPa "
                    "at T = %.8g s (at %s mm, t/T = %.3f), above [material] yield_strength = %.4g MPa; %s",
                    c["family"], c["von_mises_beyond"] / 1e6, c["T_beyond"], c["at_mm"], c["t_over_T"],
                    yield_strength / 1e6, at)
    return out, main


def band_cut(reduced: ReducedModel, families: list, yield_strength: float) -> tuple[list, dict | None]:
    """One speed of the Campbell diagram: ``families`` cut at ``yield_strength`` (:func:`model_cuts`) and the record
    of the band's cut (``None``: not cut): the lowest frequency beyond the limit, its peak von Mises stress, where
    and when, and the last orbit within (``f_cut_hz``, ``von_mises_cut_pa``)."""
    cut, cuts = model_cuts(reduced, families, yield_strength)
    if not cuts:
        return families, None
    c = min(cuts, key=lambda c: 1.0 / c["T_beyond"])
    return cut, {"yield_strength_pa": float(yield_strength), "f_beyond_hz": 1.0 / c["T_beyond"],
                 "von_mises_beyond_pa": c["von_mises_beyond"], "at_mm": c["at_mm"], "t_over_T": c["t_over_T"],
                 "f_cut_hz": None if c["T_cut"] is None else 1.0 / c["T_cut"], "von_mises_cut_pa": c["von_mises_cut"]}


def cut_nodal_family(family, nodal: NodalReducedModel, yield_strength: float) -> tuple[object, dict | None]:
    """The every-node ``family`` (:class:`~bladecase.nsm.massless.NodalFamily` of ``nodal``) cut at its first orbit
    whose peak von Mises stress exceeds ``yield_strength`` (Pa; :func:`~bladecase.study.validity.first_beyond`,
    :func:`~bladecase.study.validity.cut_family`: its ``end`` of kind ``"yield_strength"``), and the record of the
    cut (``None``: none). Logged."""
    from .validity import cut_family, first_beyond

    stress = orbit_stress(nodal)
    k, values = first_beyond(family.orbits, stress, yield_strength)
    if k is None:
        return family, None
    beyond, last = family.orbits[k], (family.orbits[k - 1] if k else None)
    peak = stress.peak(beyond)
    cut = {"index": k, "yield_strength_pa": float(yield_strength), "frequency_beyond_hz": float(beyond.frequency),
           "energy_beyond_j": float(beyond.energy), "von_mises_beyond_pa": values[k], "at_mm": peak["at_mm"],
           "t_over_T": peak["t_over_T"], "frequency_cut_hz": None if last is None else float(last.frequency),
           "energy_cut_j": None if last is None else float(last.energy),
           "von_mises_cut_pa": None if last is None else values[k - 1], "orbits_beyond": len(family.orbits) - k}
    stop = (f"cut at the elastic limit: at {beyond.frequency:.6g} Hz ({beyond.energy:.4g} J) the peak von Mises stress "
            f"is {values[k] / 1e6:.4g} MPa (at {peak['at_mm']} mm), above [material] yield_strength = "
            f"{yield_strength / 1e6:.4g} MPa")
    end = {"kind": "yield_strength", "frequency_hz": cut["frequency_cut_hz"], "energy_j": cut["energy_cut_j"], **cut}
    log.warning("every face node a contact: the family is %s; its figures stop at %s", stop,
                "its first orbit" if last is None else f"{last.frequency:.6g} Hz ({last.energy:.4g} J)")
    return cut_family(family, k, stop, end), cut
