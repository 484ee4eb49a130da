"""Floquet stability of periodic orbits with impacts: monodromy with saltation matrices (theory §6).

State ``z = (x, v)``, flight ``z' = F(z) = (v, a)``, ``a = -M⁻¹Kx``; impact surface ``h(z) = wᵀx - d = 0``;
reset (Newton's law in Moreau's form, restitution 1) ``z⁺ = (x, R v⁻)``, ``R = I - 2 M⁻¹w wᵀ/μ``,
``μ = wᵀM⁻¹w``.  A perturbation ``δz⁻`` of the pre-impact state reaches the surface ``δt = -wᵀδx/u`` later
(``u = wᵀv⁻ > 0``, the normal approach velocity), and is mapped to ``δz⁺ = S δz⁻`` with the saltation matrix
``S = D + (F(z⁺) - D F(z⁻)) ∇hᵀ / (∇hᵀF(z⁻))``, ``D = blockdiag(I, R)``, ``∇h = (w, 0)``.  Here
``F(z⁺) - D F(z⁻) = (v⁺ - v⁻, (I - R) a) = (-2 M⁻¹w u/μ, 2 M⁻¹w α/μ)`` with ``α = wᵀa = -wᵀM⁻¹Kx`` the normal
acceleration at the impact, hence, for Newton's law::

    S = [[ R,                          0 ],
         [ (2α/(μu)) M⁻¹w wᵀ,          R ]]

(the change of impact time turns the position block into the reflection ``R`` as well, and couples the normal
position to the velocities through the normal acceleration).  ``det S = det(R)² = 1``.

The monodromy from the post-impact state at ``t = 0`` over one period is ``S_k E(σ_k) ⋯ S_1 E(σ_1)`` with the
exact flight propagators ``E(σ_i)`` (flight ``i`` lasts ``σ_i = t_i - t_{i-1}``): every mode a rotation of
its phase plane, built from the system's eigenpairs (no finite differences, no ODE solver).  It is formed in
the energy coordinates ``y = (Ωq, p)`` (``q = ΦᵀMx``, ``p = ΦᵀMv``: flights are orthogonal rotations there) and
returned in ``(x, v)``.

Trivial multipliers: the flow direction ``f = F(z(0⁺))`` is fixed by the monodromy and the energy gradient
``e = ∇E`` is a fixed left vector (energy is conserved by flights and impacts), with ``eᵀf = 0``.  In an
orthonormal basis ``[f̂, U, ê]`` the monodromy is block upper triangular: the two trivial multipliers (time shift,
energy direction of the family) are its corner entries, and the ``2n - 2`` non-trivial ones are the eigenvalues
of the middle block — the linearised Poincaré map on the energy surface.  This deflation uses no eigenvalue of
the double (Jordan) multiplier 1, which a plain eigensolver would split by ``~√ε``.  The non-trivial multipliers
come in reciprocal pairs (the map is symplectic): ``stable`` means all of them lie on the unit circle (within
``tol``), i.e. linear (spectral) stability — not a proof of nonlinear (Lyapunov) stability.

>>> from bladecase.nsm import chain, orbit_1ipp
>>> fl = floquet(orbit_1ipp(chain(2, k=1.0, m=0.5, gap=1.0), 6.6))
>>> fl.stable, round(fl.max_modulus, 6), fl.verdict
(False, 1.149875, 'unstable: a multiplier -1.15 (flip) leaves the unit circle')
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from .. import log

__all__ = ["FLOQUET_TOL", "Floquet", "branch_stability", "floquet", "stable_arcs"]

#: Default tolerance: trivial multipliers within ``FLOQUET_TOL·‖monodromy‖₂`` of 1, stable when every
#: non-trivial ``|μ| <= 1 + FLOQUET_TOL``.
FLOQUET_TOL = 1e-6


@dataclass(frozen=True, eq=False)
class Floquet:
    """Floquet multipliers of a periodic orbit and what they say.

    Attributes
    ----------
    monodromy : (2n, 2n) ndarray
        Linearised one-period map of ``(x, v)`` from the post-impact state at ``t = 0``, saltation included
        (or the matrix an orbit's own ``monodromy()`` gave, in its coordinates).
    multipliers : (2n,) complex ndarray
        Its eigenvalues, sorted by modulus, descending.
    trivial : (int, int)
        Indices in :attr:`multipliers` of the two trivial multipliers at 1 (time shift, energy direction).
    max_modulus : float
        Largest ``|μ|`` of the non-trivial multipliers (NaN when there are none: one degree of freedom).
    stable : bool
        Every non-trivial ``|μ| <= 1 + tol`` (linear stability).
    verdict : str
        The same in words.
    tol : float
        The tolerance used.
    """

    monodromy: np.ndarray
    multipliers: np.ndarray
    trivial: tuple[int, int]
    max_modulus: float
    stable: bool
    verdict: str
    tol: float = FLOQUET_TOL

    @property
    def nontrivial(self) -> np.ndarray:
        """The ``2n - 2`` non-trivial multipliers (sorted by modulus, descending)."""
        return np.delete(self.multipliers, list(self.trivial))


def _check_tol(tol) -> float:
    try:
        t = float(tol)
    except (TypeError, ValueError):
        raise ValueError(f"tol must be a positive number, got {tol!r}") from None
    if not np.isfinite(t) or not 0 < t < 1:
        raise ValueError(f"tol must be a finite number in (0, 1), got {tol!r}")
    return t


def _newton_monodromy(orbit) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(Y, f, e, to_xv, from_xv)``: monodromy in ``y = (Ωq, p)``, flow direction and energy gradient at
    ``z(0⁺)`` in ``y``, and the changes of coordinates ``(x, v) = to_xv y``, ``y = from_xv (x, v)``."""
    system = orbit._bound()
    spec = system.spectrum
    om, b, phi = spec.omega, spec.b, spec.phi
    m = om.size
    mu = float(b @ b)
    times = np.asarray(orbit.impact_times, dtype=float)
    lam = np.asarray(orbit.impulses, dtype=float)
    # Post-impact modal states at the impacts (all modes: the orbit moves only the active ones).
    qa, pa = orbit.modal_state(times)
    q = np.zeros((m, times.size))
    p = np.zeros_like(q)
    q[spec.active], p[spec.active] = qa, pa
    p_pre = p + np.multiply.outer(b, lam)  # p⁺ = p⁻ - Λ b
    u = b @ p_pre  # wᵀv⁻
    alpha = -(b * om**2) @ q  # wᵀa at each impact
    bad = np.flatnonzero(~(np.abs(u) > 0) | ~np.isfinite(u))
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"impact {i + 1} of the orbit (t = {times[i]!r}) is grazing (normal velocity {u[i]!r}): "
                         "the saltation matrix, hence the Floquet multipliers, are undefined there")
    c = 2 * alpha / (mu * u)
    bo, bi = b * om, b / om  # Ωb and Ω⁻¹b: the position block of S in y is Ω H Ω⁻¹
    sigma = np.diff(np.concatenate([[0.0], times]))
    Y = np.eye(2 * m)
    for sig, ci in zip(sigma, c):
        cs, sn = np.cos(om * sig)[:, None], np.sin(om * sig)[:, None]
        Yq, Yp = Y[:m], Y[m:]
        Yq, Yp = cs * Yq + sn * Yp, -sn * Yq + cs * Yp  # exact flight: a rotation per mode
        bq = bi @ Yq  # bᵀq of each column
        Yq = Yq - (2 / mu) * np.outer(bo, bq)
        Yp = Yp - (2 / mu) * np.outer(b, b @ Yp) + ci * np.outer(b, bq)
        Y = np.vstack([Yq, Yp])
    q0, p0 = q[:, -1], p[:, -1]  # z(0⁺) = z(T⁺)
    f = np.concatenate([om * p0, -om * (om * q0)])
    e = np.concatenate([om * q0, p0])
    M = system.M
    Mphi = M @ phi
    to_xv = sla.block_diag(phi / om, phi)
    from_xv = sla.block_diag(om[:, None] * Mphi.T, Mphi.T)
    return Y, f, e, to_xv, from_xv


def _fixed_vectors(Y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A right fixed vector ``f`` and a left one ``e`` of a monodromy, with ``eᵀf = 0``, from the SVD of
    ``Y - I`` (for orbits that give only their monodromy)."""
    U, _, Vt = np.linalg.svd(Y - np.eye(Y.shape[0]))
    e = U[:, -1]
    Vk = Vt[-2:].T  # the two smallest right singular vectors
    cc = Vk.T @ e
    f = Vk @ np.array([cc[1], -cc[0]]) if np.linalg.norm(cc) > 1e-8 else Vt[-1]
    return f - (e @ f) * e, e


def split_trivial(Y: np.ndarray, f: np.ndarray, e: np.ndarray) -> np.ndarray:
    """``Y`` in the orthonormal basis ``[f̂, U, ê]`` (``Y f = f`` and ``eᵀY = eᵀ`` at a periodic orbit of a
    conservative system: the flow direction ``f`` and the energy gradient ``e``): ``B[0, 0]`` and ``B[-1, -1]`` are
    the trivial multipliers, ``B[1:-1, 1:-1]`` the non-trivial block."""
    fh, eh = f / np.linalg.norm(f), e / np.linalg.norm(e)
    fh = fh - (eh @ fh) * eh
    fh /= np.linalg.norm(fh)
    U = sla.null_space(np.vstack([fh, eh]))
    Q = np.column_stack([fh, U, eh])
    return Q.T @ Y @ Q


def _deflate(Y: np.ndarray, f: np.ndarray, e: np.ndarray, tol: float) -> tuple[float, float, np.ndarray]:
    """Trivial multipliers ``(a, c)`` and the non-trivial block of ``Y`` (:func:`split_trivial`), checked."""
    B = split_trivial(Y, f, e)
    scale = max(1.0, float(np.linalg.norm(Y, 2)))  # backward error: exact for a matrix within tol·‖Y‖ of Y
    a, c = float(B[0, 0]), float(B[-1, -1])
    leak = max(float(np.abs(B[1:, 0]).max()), float(np.abs(B[-1, :-1]).max()))
    if max(abs(a - 1), abs(c - 1), leak) > tol * scale:
        raise ValueError(
            f"the monodromy does not have its two trivial multipliers at 1 within tol = {tol:g} (flow direction "
            f"×{a:.6g}, energy direction ×{c:.6g}, coupling {leak:.3g}): the orbit is not a periodic orbit of a "
            "conservative system to that tolerance")
    return a, c, B[1:-1, 1:-1]


def _kind(mu: complex, tol: float) -> str:
    if abs(mu.imag) <= tol * abs(mu):
        return f"a multiplier {mu.real:.3g} ({'flip' if mu.real < 0 else 'saddle'})"
    return f"a complex multiplier {mu.real:.3g}{mu.imag:+.3g}i (|μ| = {abs(mu):.4g})"


def floquet(orbit, tol: float = FLOQUET_TOL) -> Floquet:
    """Floquet multipliers of a periodic orbit with impacts (Newton's law, restitution 1).

    The monodromy is the product of the exact flight propagators and of the saltation matrices of the impacts
    (module docstring: ``S = [[R, 0], [(2α/(μu)) M⁻¹w wᵀ, R]]``).  An orbit with a ``monodromy()`` method (the
    massless contact model: saltation matrices are the identity) gives its own.  The two trivial multipliers
    (time shift and energy direction of the family) are split off exactly (module docstring) and checked to be
    1 within ``tol·‖monodromy‖₂`` (a backward error: exact for a matrix that close to the computed one); the
    orbit is ``stable`` when every other ``|μ| <= 1 + tol``.

    Raises
    ------
    ValueError
        ``orbit`` is not a bound periodic orbit, an impact is grazing (zero normal velocity), ``tol`` is not in
        (0, 1), or the trivial multipliers are not at 1 within ``tol``.

    Examples
    --------
    The two-mass chain of the seed paper: its admissible 1-ipp orbit of period 7 is stable, those of period 6.6
    (a flip) and 5.3 (a real multiplier > 1) are not:

    >>> from bladecase.nsm import chain, orbit_1ipp
    >>> s = chain(2, k=1.0, m=0.5, gap=1.0)
    >>> fl = floquet(orbit_1ipp(s, 7.0))
    >>> fl.stable, fl.verdict
    (True, 'linearly stable: all multipliers on the unit circle within 1e-06')
    >>> fl.monodromy.shape, fl.trivial, np.abs(fl.multipliers).round(9).tolist()
    ((4, 4), (0, 1), [1.0, 1.0, 1.0, 1.0])
    >>> fl.nontrivial.round(6).tolist()
    [(-0.528218+0.849109j), (-0.528218-0.849109j)]
    >>> round(float(np.linalg.det(fl.monodromy)), 9)
    1.0
    >>> floquet(orbit_1ipp(s, 5.3)).verdict
    'unstable: a multiplier 4.66 (saddle) leaves the unit circle'
    """
    tol = _check_tol(tol)
    if orbit is None:
        raise ValueError("floquet needs a periodic orbit, got None")
    if callable(getattr(orbit, "monodromy", None)):
        Y = np.asarray(orbit.monodromy(), dtype=float)
        if Y.ndim != 2 or Y.shape[0] != Y.shape[1] or Y.shape[0] % 2:
            raise ValueError(f"orbit.monodromy() must be a (2n, 2n) matrix, got shape {Y.shape}")
        monodromy = Y
        f, e = _fixed_vectors(Y)
    elif hasattr(orbit, "impact_times") and hasattr(orbit, "modal_state"):
        Y, f, e, to_xv, from_xv = _newton_monodromy(orbit)
        monodromy = to_xv @ Y @ from_xv
    else:
        raise ValueError(f"floquet needs a PeriodicOrbit (or an orbit with a monodromy() method), "
                         f"got {type(orbit).__name__}")
    a, c, B = _deflate(Y, f, e, tol)
    nontrivial = np.linalg.eigvals(B) if B.size else np.zeros(0, dtype=complex)
    values = np.concatenate([np.array([a, c], dtype=complex), nontrivial.astype(complex)])
    # by modulus, descending (ties within round-off: by |argument|, then the upper half-plane first)
    order = np.lexsort((-values.imag, np.abs(np.angle(values)), -np.round(np.abs(values), 12)))
    multipliers = values[order]
    trivial = tuple(sorted(int(np.flatnonzero(order == i)[0]) for i in (0, 1)))
    if nontrivial.size == 0:
        return Floquet(monodromy, multipliers, trivial, float("nan"), True,
                       f"linearly stable: one degree of freedom, only the trivial multipliers (at 1 within {tol:g})",
                       tol)
    worst = complex(nontrivial[np.argmax(np.abs(nontrivial))])
    max_modulus = float(abs(worst))
    stable = bool(max_modulus <= 1 + tol)
    if stable:
        verdict = f"linearly stable: all multipliers on the unit circle within {tol:g}"
    else:
        verdict = f"unstable: {_kind(worst, tol)} leaves the unit circle"
    return Floquet(monodromy, multipliers, trivial, max_modulus, stable, verdict, tol)


def branch_stability(branch, tol: float = FLOQUET_TOL, where=None) -> np.ma.MaskedArray:
    """Floquet stability of every orbit of a branch: a masked bool array, masked where there is no orbit
    (``None``, e.g. a resonant scan point) or where the multipliers are undefined (a grazing impact).
    ``where`` (bool per point, optional): only these points are analysed, the others are masked (e.g.
    ``branch.admissible`` for a plot of the admissible arcs).

    >>> from bladecase.nsm import backbone, chain
    >>> branch = backbone(chain(2, k=1.0, m=0.5, gap=1.0), [6.6, 7.0, 2 * np.pi / np.sqrt(3 - np.sqrt(5))])
    >>> branch_stability(branch).tolist()       # the last period is resonant: no orbit
    [False, True, None]
    """
    tol = _check_tol(tol)
    orbits = list(branch.orbits)
    if where is not None:
        where = np.asarray(where, dtype=bool)
        if where.shape != (len(orbits),):
            raise ValueError(f"where must hold one bool per point of the branch ({len(orbits)}), got shape "
                             f"{where.shape}")
        orbits = [o if w else None for o, w in zip(orbits, where)]
    out = np.zeros(len(orbits), dtype=bool)
    mask = np.ones(len(orbits), dtype=bool)
    failed = []
    for i, orbit in enumerate(orbits):
        if orbit is None:
            continue
        try:
            out[i] = floquet(orbit, tol).stable
            mask[i] = False
        except ValueError as exc:
            failed.append((i, exc))
    if failed:
        i, exc = failed[0]
        log.warning("stability of %d point(s) of the branch left out (masked), first point %d (T = %.9g): %s",
                    len(failed), i, orbits[i].T, exc)
    return np.ma.MaskedArray(out, mask=mask)


def stable_arcs(branch, tol: float = FLOQUET_TOL, stability=None) -> list[tuple[int, int]]:
    """Maximal runs of consecutive points of a branch that are admissible and stable, as ``(start, stop)``
    index pairs (``stop`` inclusive, like :class:`~bladecase.nsm.branches.Arc`).

    ``stability`` is the result of :func:`branch_stability` if already computed (or any per-point sequence of
    ``True``/``False``/``None``, e.g. ``Branch.stable`` once the orbits carry their stability; masked or ``None``
    points count as not stable).

    >>> from bladecase.nsm import backbone, chain
    >>> branch = backbone(chain(2, k=1.0, m=0.5, gap=1.0), np.linspace(6.0, 7.1, 12))
    >>> stable_arcs(branch)             # T = 6.0…6.4 and 6.7…7.1; the flip orbits of T = 6.5, 6.6 split them
    [(0, 4), (7, 11)]
    """
    stab = branch_stability(branch, tol) if stability is None else stability
    stab = np.ma.filled(np.ma.asarray(stab), False)
    stab = np.array([False if v is None else bool(v) for v in stab], dtype=bool)
    if stab.size != len(branch.orbits):
        raise ValueError(f"stability has {stab.size} entries for a branch of {len(branch.orbits)} points")
    good = np.array([o is not None and bool(o.admissible) for o in branch.orbits], dtype=bool) & stab
    edges = np.diff(np.concatenate([[0], good.astype(np.int8), [0]]))
    return [(int(a), int(b) - 1) for a, b in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1))]
