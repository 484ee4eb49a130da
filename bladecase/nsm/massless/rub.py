"""The rub response of a blade turning inside an out-of-round casing, at one speed or over a range of speeds.

The blade (a :class:`~bladecase.nsm.massless.nodes.NodalSystem`: one massless contact per tip node) turns at
``Ω`` inside a casing with ``n`` lobes of amplitude ``a``: node ``j``, at the angle ``φ_j`` about the engine axis,
sees the clearance ``g_j(t) = d_j − a cos(n(Ωt + φ_j))``, whose period is the lobe passing ``2π/(nΩ)``. Starting
at rest, the response is simulated exactly (:func:`~bladecase.nsm.massless.nodes.simulate_nodes`: closed-form
flights, certified switches) over ``revolutions`` turns; the last ``window`` turns give the figures an engineer
reads — the peak normal displacement of each node (m, outwards), the peak contact force on each node (N), the
fraction of the revolution each node spends in contact, the casing's peak penetration at each node (compliant
casing, m), the nodes that touch, the peak of the total force ``Σ_j λ_j`` and the nodes' forces at that instant,
and — given the nodes' tributary areas — the largest area in contact.

**Settled, or run on.** The response has settled when the window's peaks match the previous window's within 2 %.
If not, the same simulation **runs on** from where it stopped, a window at a time, up to ``max_revolutions``
(default ``10 × revolutions``), until it settles. At every check the state sampled once per lobe passing (the
return map ``y_k = (q, q'/nΩ)`` in the open-phase modal coordinates) is also searched for a period of ``q``
lobe passings (:func:`characterise`): a response that repeats every ``q`` lobe passings (a sub-harmonic when
``q > 1``) is steady when its peaks over a window of a whole number of periods match those of the same span
before; its figures are read over that span. A response that never settles within the cap is characterised from
its return map over the last half of the run: ``transient`` (still converging: the change window to window
falls steadily), ``quasi-periodic`` (regular — the 0-1 test for chaos gives ``K`` near 0 — but repeating at no
period: a second frequency incommensurate with the lobes') or ``irregular`` (``K`` near 1: chaotic, or wandering).

A sweep in speed (:func:`rub_sweep`) runs the speeds through an executor (each speed on its own).

>>> import numpy as np
>>> from bladecase.nsm import Damping
>>> from bladecase.nsm.massless.nodes import NodalSystem
>>> s = NodalSystem(np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2), np.diag([0.5, 0.5]),
...                 gap=[1.0, 1.0], casing=[4.0, 4.0])
>>> r = rub_response(s, speed=0.4, lobes=3, amplitude=1.2, angles=[0.0, 0.3], damping=Damping(zeta=0.05),
...                  revolutions=30, window=5)
>>> r.touching, bool(r.peak_force.max() > 0), r.settled, r.response, r.revolutions_run
((0, 1), True, True, 'settled', 30)
>>> bool(r.peak_force.max() <= r.total_force <= r.peak_force.sum()), bool(r.total_force == r.force_at_peak.sum())
(True, True)
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from .friction import friction_flight, sliding_check
from .friction_energy import energy_balance
from .nodes import NodalFlight, NodalSystem, NodalTrajectory, Rub, simulate_nodes

__all__ = ["Character", "RubResponse", "characterise", "rub_response", "rub_run", "rub_sweep", "zero_one_test"]

#: Relative change of the window's peaks against the previous window's below which the response has settled; also
#: the return map's recurrence error (relative to the state's size) below which it repeats.
SETTLED_RTOL = 0.02

#: Samples per revolution and per period of the highest mode of interest used for the peaks.
SAMPLES_PER_PERIOD = 24

#: ``max_revolutions`` when not given: this many times ``revolutions``.
RUN_ON_FACTOR = 10

#: A period ``q > 1`` of the return map counts only when its recurrence error is below this share of the
#: smallest distance between the ``q`` points of one period (a quasi-periodic map comes back near itself after
#: ``q`` steps where its rotation number is near ``p/q``, but then its ``q`` points are spread along a curve about
#: as far apart as that error).
DISTINCT = 0.5

#: A response whose peaks have settled while its state still differs from one lobe passing to the next follows the
#: period ``q`` whose recurrence error is below this share of the error at one passing (its transient has not died
#: out, yet it clearly repeats every ``q``).
SUBHARMONIC_SHARE = 0.25

#: The 0-1 test's ``K`` above which a response that repeats at no period is ``irregular`` (chaotic).
CHAOS_K = 0.5

#: A transient: what is left of it falls by at least ``TRANSIENT_DECAY`` per window — either the return map is a
#: linear map (an affine least-squares fit on its leading principal components predicts the next sample with R² of
#: at least ``LINEAR_R2``: the response is close to its fixed point) whose slowest mode decays that fast, or the log
#: of the change from one window to the next falls along a line (R² of at least ``TRANSIENT_R2``).
TRANSIENT_DECAY, TRANSIENT_R2, LINEAR_R2 = 0.8, 0.6, 0.99

#: Principal components of the return map fitted by a linear map.
LINEAR_RANK = 6


@dataclass(frozen=True)
class Character:
    """What a response is, from its state sampled once per forcing period (:func:`characterise`).

    ``kind``: ``"periodic"`` (it repeats every ``period`` forcing periods; ``1``: it has settled at the forcing's
    own period), ``"transient"`` (still converging: the change over ``lag`` samples is multiplied by ``decay``
    every ``lag`` samples), ``"quasi-periodic"`` (regular — the 0-1 test's ``k`` near 0 — without a period;
    ``rotation``: the strongest line of the sampled sequence, in cycles per forcing period) or ``"irregular"``
    (``k`` near 1). ``error``: the recurrence error at ``period`` (relative to the state's size), or the last
    change over ``lag`` samples; ``samples``: how many samples it was told from (the 0-1 test wants a few
    hundred)."""

    kind: str
    period: int | None = None
    error: float = float("nan")
    k: float | None = None
    decay: float | None = None
    rotation: float | None = None
    samples: int | None = None

    @property
    def label(self) -> str:
        """``settled``, ``periodic-q``, ``transient``, ``quasi-periodic`` or ``irregular``."""
        if self.kind == "periodic":
            return "settled" if self.period == 1 else f"periodic-{self.period}"
        return self.kind


def _as_samples(y) -> np.ndarray:
    y = np.asarray(y, dtype=float)
    y = y.reshape(-1, 1) if y.ndim == 1 else y
    if y.ndim != 2 or y.shape[0] < 2 or not np.all(np.isfinite(y)):
        raise ValueError(f"the samples must be a finite (N,) or (N, d) array with N >= 2, got shape {y.shape}")
    return y


def _recurrence(y: np.ndarray, q: int, scale: float) -> float:
    """The largest distance between the last ``q`` samples and each earlier whole block of ``q``, over ``scale``."""
    r = y.shape[0] // q
    blocks = y[y.shape[0] - r * q:].reshape(r, q, -1)
    return float(np.linalg.norm(blocks - blocks[-1], axis=2).max() / scale)


def _period(y: np.ndarray, scale: float, rtol: float, max_period: int) -> tuple[int, float] | None:
    """The smallest ``q <= max_period`` (with at least 3 whole blocks) at which the samples repeat (see
    :data:`DISTINCT`), with its recurrence error."""
    for q in range(1, min(max_period, y.shape[0] // 3) + 1):
        err = _recurrence(y, q, scale)
        if err > rtol:
            continue
        if q > 1:
            last = y[-q:]
            d = np.linalg.norm(last[:, None] - last[None], axis=2)[np.triu_indices(q, 1)].min() / scale
            if err > DISTINCT * d:
                continue
        return q, err
    return None


def _linear_decay(y: np.ndarray, lag: int) -> tuple[float, float]:
    """The return map fitted by an affine map on its leading principal components: the factor its slowest mode is
    multiplied by over ``lag`` samples, and the fit's R² (one step ahead)."""
    centred = y - y.mean(axis=0)
    _, sv, vt = np.linalg.svd(centred, full_matrices=False)
    r = int(min(LINEAR_RANK, (sv > 1e-6 * sv[0]).sum(), max(1, (y.shape[0] - 2) // 4)))
    z = centred @ vt[:r].T
    X = np.c_[z[:-1], np.ones(z.shape[0] - 1)]
    coef = np.linalg.lstsq(X, z[1:], rcond=None)[0]
    spread = ((z[1:] - z[1:].mean(axis=0)) ** 2).sum()
    r2 = 1 - ((z[1:] - X @ coef) ** 2).sum() / spread if spread > 0 else 0.0
    return float(np.abs(np.linalg.eigvals(coef[:r].T)).max() ** lag), float(r2)


def zero_one_test(phi, cs: int = 64) -> float:
    """Gottwald and Melbourne's 0-1 test for chaos on a scalar sequence (the correlation method with the oscillating
    term removed, the median over ``cs`` frequencies ``c`` in ``(π/5, 4π/5)``): ``K`` near 0 for a regular
    (periodic or quasi-periodic) sequence, near 1 for a chaotic or random one.

    >>> k = np.arange(600)
    >>> regular = zero_one_test(np.cos(2 * np.pi * np.sqrt(2) * k) + 0.3 * np.cos(2 * np.pi * np.sqrt(3) * k))
    >>> random = zero_one_test(np.random.default_rng(1).standard_normal(600))
    >>> bool(abs(regular) < 0.2), bool(random > 0.8)
    (True, True)
    """
    phi = np.asarray(phi, dtype=float).reshape(-1)
    n_all = phi.size
    ncut = max(n_all // 10, 3)
    if n_all < 20 or np.ptp(phi) == 0:
        return 0.0
    golden = (np.sqrt(5) - 1) / 2
    c = np.pi / 5 + 3 * np.pi / 5 * (((np.arange(cs) + 0.5) * golden) % 1.0)  # spread, no resonant c by design
    j = np.arange(1, n_all + 1)
    pc = np.cumsum(phi * np.cos(np.outer(c, j)), axis=1)
    qc = np.cumsum(phi * np.sin(np.outer(c, j)), axis=1)
    n = np.arange(1, ncut + 1)
    M = np.empty((cs, ncut))
    for i, lag in enumerate(n):
        M[:, i] = ((pc[:, lag:] - pc[:, :-lag]) ** 2 + (qc[:, lag:] - qc[:, :-lag]) ** 2).sum(axis=1) / n_all
    D = M - phi.mean() ** 2 * (1 - np.cos(np.outer(c, n))) / (1 - np.cos(c))[:, None]
    Dc = D - D.mean(axis=1, keepdims=True)
    nc = n - n.mean()
    den = np.sqrt((Dc**2).sum(axis=1) * (nc**2).sum())
    K = np.where(den > 0, Dc @ nc / np.where(den > 0, den, 1.0), 0.0)
    return float(np.median(K))


def characterise(samples, rtol: float = SETTLED_RTOL, max_period: int | None = None, lag: int | None = None,
                 scale: float | None = None) -> Character:
    """What a response is, from its state ``samples`` (``(N, d)``, or ``(N,)``) taken once per forcing period (its
    return map), the latest last: periodic with the smallest period ``q <= max_period`` (default ``N // 3``;
    ``0``: do not look for one) at which every whole block of ``q`` samples matches the last within ``rtol`` of
    ``scale`` (default: the largest sample's norm); else a transient, if the change over ``lag`` samples (default
    ``N // 8``) falls steadily; else quasi-periodic or irregular by the 0-1 test (:func:`zero_one_test`) on the
    samples' principal component. See :class:`Character`.

    >>> k = np.arange(240)
    >>> characterise(np.c_[np.cos(2 * np.pi * k / 3), np.sin(2 * np.pi * k / 3) + 2.0]).label
    'periodic-3'
    >>> qp = characterise(np.c_[np.cos(2 * np.pi * np.sqrt(2) * k), np.sin(2 * np.pi * np.sqrt(2) * k)])
    >>> qp.label, round(qp.rotation, 2)       # √2 mod 1 = 0.414 of a turn per forcing period
    ('quasi-periodic', 0.41)
    >>> characterise(np.random.default_rng(0).standard_normal((240, 3))).label
    'irregular'
    >>> characterise(np.c_[1 + 0.5 * np.exp(-k / 40) * np.cos(0.9 * k)]).label
    'transient'
    """
    y = _as_samples(samples)
    N = y.shape[0]
    scale = float(np.linalg.norm(y, axis=1).max()) if scale is None else float(scale)
    if not scale > 0:
        return Character("periodic", 1, 0.0)
    found = _period(y, scale, rtol, N // 3 if max_period is None else int(max_period))
    if found is not None:
        return Character("periodic", found[0], found[1], samples=N)
    lag = max(1, N // 8 if lag is None else min(int(lag), N // 2))
    change = np.linalg.norm(y[lag:] - y[:-lag], axis=1) / scale
    decay = None
    if N >= 8 and np.ptp(y, axis=0).max() > 0:
        decay, r2 = _linear_decay(y, lag)
        if decay < TRANSIENT_DECAY and r2 >= LINEAR_R2:
            return Character("transient", None, float(change[-1]), decay=decay, samples=N)
    if change.size >= 4 and change.min() > 0:
        k = np.arange(change.size)
        slope, icept = np.polyfit(k, np.log(change), 1)
        resid = np.log(change) - (icept + slope * k)
        r2 = 1 - (resid**2).sum() / max(((np.log(change) - np.log(change).mean()) ** 2).sum(), 1e-300)
        if np.exp(slope * lag) < TRANSIENT_DECAY and r2 >= TRANSIENT_R2:
            return Character("transient", None, float(change[-1]), decay=float(np.exp(slope * lag)), samples=N)
    centred = y - y.mean(axis=0)
    pc = centred @ np.linalg.svd(centred, full_matrices=False)[2][0]
    K = zero_one_test(pc)
    if K >= CHAOS_K:
        return Character("irregular", None, float(change[-1]), k=K, samples=N)
    spectrum = np.abs(np.fft.rfft(pc * np.hanning(N))) ** 2
    rotation = float(np.fft.rfftfreq(N)[1 + int(np.argmax(spectrum[1:]))]) if N > 2 else None
    return Character("quasi-periodic", None, float(change[-1]), k=K, rotation=rotation, samples=N)


@dataclass(frozen=True)
class RubResponse:
    """The rub response at one speed (module docstring); per-node arrays follow ``system.nodes``.

    ``response``: ``settled``, ``periodic-q`` (repeating every ``q`` lobe passings: ``period``), ``transient``,
    ``quasi-periodic`` or ``irregular`` (:class:`Character`); ``settled`` is true for the first two (a steady
    response: its figures repeat). ``revolutions_run``: revolutions simulated (more than ``revolutions`` when it
    ran on); ``read_revolutions``: the span the figures are read on (the window, or a whole number of periods);
    ``detail``: the characterisation's numbers (``k``, ``decay``, ``rotation``, ``error``)."""

    speed: float
    lobes: int
    amplitude: float
    revolutions: int
    window: int
    nodes: tuple
    peak_displacement: np.ndarray
    peak_force: np.ndarray
    contact_fraction: np.ndarray
    penetration: np.ndarray
    switches: int
    settled: bool
    change: float
    total_force: float = 0.0
    force_at_peak: np.ndarray | None = None
    loaded_area: float | None = None
    response: str = "settled"
    period: int | None = None
    revolutions_run: int = 0
    read_revolutions: float = 0.0
    max_revolutions: int = 0
    detail: dict = field(default_factory=dict)
    friction: dict = field(default_factory=dict)

    @property
    def touching(self) -> tuple:
        """The nodes that touch the casing in the window (their labels)."""
        return tuple(k for k, f in zip(self.nodes, self.contact_fraction) if f > 0)

    @property
    def tip_displacement(self) -> float:
        """The largest peak normal displacement over the nodes (m)."""
        return float(self.peak_displacement.max())

    def as_dict(self) -> dict:
        """Plain numbers and lists (for JSON)."""
        d = asdict(self)
        return {k: (v.tolist() if isinstance(v, np.ndarray) else list(v) if isinstance(v, tuple) else v)
                for k, v in d.items()}


def _peaks(tr, flight: NodalFlight, t0: float, t1: float, samples: int) -> tuple[np.ndarray, ...]:
    """Per node over ``[t0, t1]`` (sampled, the switches included): peak normal displacement, force and casing
    yield; then the nodes' forces at the sample of the largest total force."""
    s = flight.system
    t = np.unique(np.r_[np.linspace(t0, t1, samples), tr.starts[(tr.starts >= t0) & (tr.starts <= t1)]])
    x, _, lam = tr.sample(t)
    u = s.W.T @ x - s.flexibility @ lam  # the nodes' own normal displacements
    pen = lam / s.casing[:, None]
    return u.max(axis=1), lam.max(axis=1), pen.max(axis=1), lam[:, int(np.argmax(lam.sum(axis=0)))]


def _loaded_area(tr, areas: np.ndarray, t0: float, t1: float) -> float:
    """The largest ``Σ_{j closed} A_j`` over the phases that overlap ``[t0, t1]`` (exact: from the phases)."""
    ends = np.r_[tr.starts[1:], tr.t_end]
    live = (ends > t0) & (tr.starts < t1)
    return float((tr.active[live] @ areas).max(initial=0.0))


def _change(now: tuple, before: tuple, gap: np.ndarray) -> float:
    """The relative change of the peaks (displacement over the larger of its peak and the clearance; force over
    its peak) from ``before`` to ``now``."""
    scale = max(float(np.abs(now[0]).max()), float(gap.max()))
    return float(max(np.abs(now[0] - before[0]).max() / scale,
                     np.abs(now[1] - before[1]).max() / max(float(now[1].max()), 1e-300)))


def _join(tail: NodalTrajectory | None, seg: NodalTrajectory, offset: float, keep_from: float) -> NodalTrajectory:
    """``seg`` (simulated from ``t = 0``) continued after ``tail`` at the time ``offset`` (a whole number of lobe
    passings: the casing's clearances, hence each phase's particular solution, are the same at ``t`` and
    ``t + offset``), without the phases of ``tail`` that end before ``keep_from``."""
    starts = seg.starts + offset
    if tail is None:
        return NodalTrajectory(seg.flight, starts, seg.active, seg.q, seg.p, seg.t_end + offset, seg.complete,
                               seg.amplitudes)
    ends = np.r_[tail.starts[1:], tail.t_end]
    keep = ends > keep_from
    return NodalTrajectory(seg.flight, np.r_[tail.starts[keep], starts], np.r_[tail.active[keep], seg.active],
                           np.c_[tail.q[:, keep], seg.q], np.c_[tail.p[:, keep], seg.p], seg.t_end + offset,
                           seg.complete, np.r_[tail.amplitudes[keep], seg.amplitudes])


def _strobe(seg: NodalTrajectory, fl: NodalFlight, passing: float, count: int) -> np.ndarray:
    """The modal state ``(q, q'/ν)`` at the first ``count`` lobe passings ``k·passing`` of ``seg`` (rows)."""
    x, v = seg.state(np.arange(count) * passing)
    q, p = fl.encode(x, v)
    return np.r_[q, p / fl.nu].T


def _checked(revolutions, window, max_revolutions, speed) -> tuple[int, float]:
    if isinstance(revolutions, bool) or int(revolutions) != revolutions or revolutions < 2:
        raise ValueError(f"revolutions must be an integer >= 2, got {revolutions!r}")
    if isinstance(window, bool) or int(window) != window or not 1 <= window <= revolutions // 2:
        raise ValueError(f"window must be an integer in 1..revolutions/2 = {revolutions // 2}, got {window!r}")
    cap = RUN_ON_FACTOR * int(revolutions) if max_revolutions is None else max_revolutions
    if isinstance(cap, bool) or int(cap) != cap or cap < revolutions:
        raise ValueError(f"max_revolutions must be an integer >= revolutions = {revolutions}, got {max_revolutions!r}")
    speed = float(speed)
    if not (np.isfinite(speed) and speed > 0):
        raise ValueError(f"speed must be a finite number > 0 (rad/s), got {speed!r}")
    return int(cap), speed


def rub_response(system: NodalSystem, speed: float, lobes: int, amplitude: float, angles, damping=None,
                 revolutions: int = 40, window: int = 10, max_switches: int = 2_000_000,
                 areas=None, max_revolutions: int | None = None, friction=None,
                 flight: NodalFlight | None = None) -> RubResponse:
    """The rub response at ``speed`` (rad/s) from rest, over ``revolutions`` turns and on, a ``window`` at a time,
    until it settles or ``max_revolutions`` (default ``10 × revolutions``) have run; read on the last ``window``
    (or a whole number of its periods) and characterised when it did not settle (module docstring). ``angles``: each
    contact node's angle about the engine axis (rad); ``damping``: a :class:`~bladecase.nsm.damping.Damping` of the
    open-phase modes (``None``: undamped); ``areas``: each node's tributary area (m², ``(m,)``) for the largest
    loaded area (``loaded_area``; ``None`` without); ``max_switches``: over the whole run; ``friction``: a
    :class:`~bladecase.nsm.massless.friction.Friction` at the contact nodes (``None`` or ``μ = 0``: none, the
    results bit for bit those without); ``flight``: the flight to fly (its phases reused: it must be of this
    system, damping, casing and friction; default: a new one)."""
    return rub_run(system, speed, lobes, amplitude, angles, damping, revolutions, window, max_switches, areas,
                   max_revolutions, friction, flight)[0]


def rub_run(system: NodalSystem, speed: float, lobes: int, amplitude: float, angles, damping=None,
            revolutions: int = 40, window: int = 10, max_switches: int = 2_000_000,
            areas=None, max_revolutions: int | None = None, friction=None,
            flight: NodalFlight | None = None) -> tuple[RubResponse, NodalTrajectory]:
    """:func:`rub_response` with the trajectory it read its figures on (at least its last two windows, the clock
    from the start of the run: the figures' span ends at its ``t_end``) — for what a caller reads on top of the
    figures (e.g. a bladed disk's nodal diameters, :mod:`bladecase.nsm.massless.disk_rub`).

    >>> import numpy as np
    >>> s = NodalSystem(np.eye(1), np.eye(1), np.eye(1), np.eye(1), gap=[0.5])
    >>> r, tr = rub_run(s, speed=0.3, lobes=2, amplitude=0.8, angles=[0.0], revolutions=4, window=1)
    >>> bool(np.isclose(tr.t_end, r.revolutions_run * 2 * np.pi / 0.3))
    True
    """
    cap, speed = _checked(revolutions, window, max_revolutions, speed)
    if areas is not None:
        areas = np.asarray(areas, dtype=float)
        if areas.shape != (system.m,):
            raise ValueError(f"areas must hold one value per contact node ({system.m}), got shape {areas.shape}")
    rub = Rub(lobes, amplitude, speed, angles)
    if flight is not None:
        fl = flight
    else:
        fl = NodalFlight(system, damping, rub) if friction is None else friction_flight(system, friction, damping, rub)
    turn = 2 * np.pi / speed
    passing = turn / lobes
    W = window * lobes  # lobe passings per window
    omega = system.modes[0]
    per_turn = max(SAMPLES_PER_PERIOD * lobes, int(np.ceil(SAMPLES_PER_PERIOD * omega[0] / speed)) * 4)
    per_passing = int(np.ceil(per_turn / lobes))  # a grid with the same phases in every lobe passing

    def peaks(span: int) -> tuple[tuple, tuple]:  # over the last `span` lobe passings, and the span before
        end = tail.t_end
        return (_peaks(tail, fl, end - span * passing, end, span * per_passing + 1),
                _peaks(tail, fl, end - 2 * span * passing, end - span * passing, span * per_passing + 1))

    x, v, done, switches, tail, strobes = np.zeros(system.n), np.zeros(system.n), 0, 0, None, []
    run = revolutions
    while True:
        seg = simulate_nodes(system, x, v, run * turn, flight=fl, max_switches=max(max_switches - switches, 1))
        switches += int(seg.switch_times.size)
        if not seg.complete:
            raise ValueError(f"the rub response at {speed:.6g} rad/s needed more than {max_switches} switches in "
                             f"{done + run} revolutions")
        tail = _join(tail, seg, done * turn, (done + run - 2 * window) * turn - passing)
        strobes.append(_strobe(seg, fl, passing, run * lobes))
        done += run
        x, v = seg.x_end, seg.v_end
        now, before = peaks(W)
        change, span, period = _change(now, before, system.gap), W, 1
        y = np.concatenate(strobes)[-2 * W:]
        scale = float(np.linalg.norm(y, axis=1).max()) or 1.0
        found = _period(y, scale, SETTLED_RTOL, (2 * W) // 3)
        if found is None and change <= SETTLED_RTOL:  # settled by its peaks: the period its state follows
            found = _period(y, scale, SUBHARMONIC_SHARE * _recurrence(y, 1, scale), (2 * W) // 3)
        if found is not None and found[0] > 1:  # a sub-harmonic: its peaks over whole numbers of periods
            q = found[0]
            q_now, q_before = peaks(q * (W // q))
            q_change = _change(q_now, q_before, system.gap)
            if q_change <= SETTLED_RTOL:
                now, change, span, period = q_now, q_change, q * (W // q), q
                break
        if change <= SETTLED_RTOL or done + window > cap:
            break
        run = window
    settled = change <= SETTLED_RTOL
    if settled:
        character = Character("periodic", period, change)
    else:  # never settled within the cap: what it is, from the return map over the last half of the run
        y = np.concatenate(strobes)
        y = y[-max(2 * W, y.shape[0] // 2):]
        character = characterise(y, max_period=0, lag=W)
        period = None
    end = tail.t_end
    t0 = end - span * passing
    fraction = tail.contact_time(t0, end) / (span * passing)
    loaded = None if areas is None else _loaded_area(tail, areas, t0, end)
    detail = {k: getattr(character, k) for k in ("k", "decay", "rotation", "samples")
              if getattr(character, k) is not None}
    rubbed = _friction_figures(tail, speed, window) if getattr(fl, "friction", None) is not None else {}
    return RubResponse(speed, int(lobes), float(amplitude), int(revolutions), int(window), system.nodes, now[0],
                       now[1], fraction, now[2], switches, settled, change, float(now[3].sum()), now[3], loaded,
                       character.label, period, int(done), span / lobes, cap, detail, rubbed), tail


def _friction_figures(tail: NodalTrajectory, speed: float, window: int) -> dict:
    """The friction's figures of a rub (``μ > 0``): the energy balance of the last revolution (J: casing input,
    friction work on the vibration, damping, stored change, residual), the worst relative residual over the window's
    revolutions, and the sliding check over the window (each node's ``max|z'| / ΩR``)."""
    turn = 2 * np.pi / speed
    end = tail.t_end
    revs = [energy_balance(tail, end - (k + 1) * turn, end - k * turn) for k in range(window)]
    last = revs[0]
    out = {"mu": float(tail.flight.friction.mu), "casing_j": last.casing, "friction_j": last.friction,
           "damping_j": last.damping, "stored_change_j": last.stored_change, "residual_j": last.residual,
           "relative_residual": max(abs(e.relative) for e in revs), "quadrature_error_j": last.quadrature_error}
    if tail.flight.friction.radius is not None:
        check = sliding_check(tail, speed, end - window * turn, end)
        out.update(sliding_ratio=float(check.ratio.max()), sliding_node_ratio=check.ratio.tolist(),
                   rotation_dominated=bool(check.ok), sliding_limit=check.limit, sliding_message=check.message)
    return out


def _one(args) -> RubResponse:
    system, speed, lobes, amplitude, angles, damping, revolutions, window, cap, friction = args
    return rub_response(system, speed, lobes, amplitude, angles, damping, revolutions, window, max_revolutions=cap,
                        friction=friction)


def rub_sweep(system: NodalSystem, speeds, lobes: int, amplitude: float, angles, damping=None,
              revolutions: int = 40, window: int = 10, executor=None, progress=None,
              max_revolutions: int | None = None, friction=None) -> list[RubResponse]:
    """:func:`rub_response` at every speed of ``speeds`` (rad/s), through ``executor`` (anything with a ``map``
    of a function over a list, e.g. the study's executors; default: in turn)."""
    speeds = np.asarray(speeds, dtype=float).reshape(-1)
    if speeds.size == 0 or not np.all(np.isfinite(speeds)) or np.any(speeds <= 0):
        raise ValueError(f"speeds must be finite numbers > 0 (rad/s), got {speeds.tolist()}")
    jobs = [(system, float(w), lobes, amplitude, tuple(np.asarray(angles, dtype=float).tolist()), damping,
             revolutions, window, max_revolutions, friction) for w in speeds]
    if executor is None:
        out = []
        for job in jobs:
            out.append(_one(job))
            if progress is not None:
                progress()
        return out
    return list(executor.map(_one, jobs))
