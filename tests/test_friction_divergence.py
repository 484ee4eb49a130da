"""A friction phase that grows without oscillating is called a divergence, one that oscillates a flutter (with its
frequency): the refusal names which, computed from the phase's growing root."""

import numpy as np
import pytest

from bladecase.nsm.massless.friction import Friction, simulate_friction
from bladecase.nsm.massless.nodes import NodalSystem


def _system():
    return NodalSystem(np.eye(2), np.diag([1.0, 1.2]), np.array([[1.0], [1.0]]), [[0.01]], gap=[0.5])


def test_real_growing_root_is_a_divergence():
    """``K = D + k_c(w − μT)wᵀ`` with ``k_c = 100``, ``μT = (0, 2.5)``: ``det K = 1.2 + 100(2.2 − 2.5) < 0``, real
    eigenvalues of both signs: the phase drifts (a real root ``+√|κ|``)."""
    with pytest.raises(ValueError, match=r"friction-induced divergence: the phase's stiffness is no longer "
                                         r"positive, it drifts without oscillating"):
        simulate_friction(_system(), Friction(0.5, T=np.array([[0.0], [5.0]])), [0.6, 0.0], [0.0, 0.0], 5.0)


def test_complex_growing_root_is_a_flutter_with_its_frequency():
    """``μT = (0, 2)``: ``λ² − 2.2λ + 1.2 + 0.2k_c`` → ``λ = 1.1 ± i√(21.2 − 1.21)``: κ complex, the growing roots of
    the first-order system oscillate at ``Im √(−κ)/2π``."""
    kappa = np.roots([1.0, -2.2, 1.2 + 0.2 * 100])
    root = np.sqrt(-kappa.astype(complex))
    growing = root[np.argmax(root.real)]
    with pytest.raises(ValueError, match=rf"friction-induced flutter, an oscillation of "
                                         rf"{abs(growing.imag) / 2 / np.pi:.4g} Hz"):
        simulate_friction(_system(), Friction(0.5, T=np.array([[0.0], [4.0]])), [0.6, 0.0], [0.0, 0.0], 5.0)
