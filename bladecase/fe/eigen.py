"""Natural frequencies and mode shapes of a clamped :class:`~bladecase.fe.model.FEModel`.

Both go through :mod:`bladecase.linalg`: :func:`stiffness_factor` factorises ``K``
once (after checking that the clamp leaves no rigid-body motion), and
:func:`natural_frequencies` runs :func:`bladecase.linalg.lowest_modes` with it.
Pass the same factor to :func:`natural_frequencies` and to
:func:`bladecase.reduction.reduce` to factorise a model only once.
"""

from __future__ import annotations

import numpy as np

from ..checks import integer
from ..linalg import SPDFactor, check_factor, lowest_modes, spd_factor
from .model import FEModel

#: Hint of the error raised for a singular stiffness.
_SINGULAR_HINT = "no clamp? a part of the mesh not connected to the clamp?"


def _check_model(model) -> FEModel:
    if not isinstance(model, FEModel):
        raise ValueError(f"model must be an FEModel (from bladecase.assemble), got {type(model).__name__}")
    return model


def stiffness_factor(model: FEModel) -> SPDFactor:
    """The factorisation of ``model.K`` (:func:`bladecase.linalg.spd_factor`), after the rigid-body check.

    Compute it once and pass it as ``factor=`` to :func:`natural_frequencies` and
    :func:`bladecase.reduction.reduce` to factorise a model only once.

    Raises
    ------
    ValueError
        A model with rigid-body modes (no clamp, or a clamp that leaves a
        rotation free), or a ``K`` that is singular or not positive definite.
    """
    _check_rigid(_check_model(model))
    return spd_factor(model.K, "K", hint=_SINGULAR_HINT)


def _check_rigid(model: FEModel) -> None:
    if model.rigid_modes:
        if model.clamped.size == 0:
            why = "the model is not clamped (no clamp?)"
        else:
            why = (f"the clamp ({model.clamped.size} node(s)) leaves {model.rigid_modes} rigid-body motion(s) free: "
                   "no clamp on some part of the mesh, or clamped nodes on one point or one line")
        raise ValueError(f"K is singular: {why}; clamp a face of every part")


def natural_frequencies(model: FEModel, count: int, return_modes: bool = False, *, factor: SPDFactor | None = None,
                        method: str = "auto"):
    """The ``count`` lowest natural frequencies (Hz) of a clamped model.

    Shift-invert Lanczos about 0 with the sparse factorisation of ``K``
    (:func:`bladecase.linalg.lowest_modes`, :func:`stiffness_factor`): ARPACK's,
    or block Lanczos for a CHOLMOD factor of a large model (``method``); no
    dense matrix is formed unless more than half of the modes of a model of
    at most :data:`bladecase.linalg.DENSE_LIMIT` dofs are asked for.

    Parameters
    ----------
    model : FEModel
    count : int
        Number of frequencies, ``1 <= count < model.n_dofs``.
    return_modes : bool
        Also return the mode shapes.
    factor : SPDFactor or None
        ``stiffness_factor(model)``, to reuse a factorisation (computed here if ``None``).
    method : str
        ``"auto"``, ``"arpack"`` or ``"block"`` (:func:`bladecase.linalg.lowest_modes`).

    Returns
    -------
    f : (count,) ndarray
        Frequencies ``√λ / 2π`` in Hz, ascending.
    phi : (n_dofs, count) ndarray
        M-normalised mode shapes (``φᵀMφ = I``, each column's largest
        component positive), only if ``return_modes``.

    Raises
    ------
    ValueError
        ``count`` out of range; a model with rigid-body modes (no clamp, or a
        clamp that leaves a rotation free) or otherwise singular ``K``; a
        ``factor`` that is not this model's; an unknown ``method``.

    Examples
    --------
    A steel strip 100 × 20 × 2 mm clamped at ``x = 0`` (plane stress, P2):

    >>> import numpy as np
    >>> from skfem import MeshTri
    >>> from bladecase.fe import Mesh, assemble
    >>> t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5))
    >>> points = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    >>> strip = Mesh(points, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(points[:, 0] == 0)})
    >>> model = assemble(strip, "steel", thickness=0.002)
    >>> natural_frequencies(model, 3).round(-1)  # bending (Euler–Bernoulli: 1630 Hz), axial (12620 Hz)
    array([ 1590.,  8570., 12650.])
    """
    _check_model(model)
    n = model.n_dofs
    count = integer("count", count, 1, n, strict_high=True, note=" (the number of free dofs)")
    factor = check_factor(factor, model.K, "this model's K", "bladecase.fe.stiffness_factor(model)")
    _check_rigid(model)
    lam, phi = lowest_modes(model.K, model.M, count, factor=factor, hint=_SINGULAR_HINT, method=method)
    f = np.sqrt(lam) / (2 * np.pi)
    return (f, phi) if return_modes else f
