"""``bladecase.post.disk.safe_plot``: the SAFE (ZZENF) diagram draws each mode family and the engine-order zig-zag
(engine order e at e·Ω/2π on the nodal diameter k ≡ ±e mod N)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.sparse as sp
from matplotlib.figure import Figure

from bladecase.fe.cyclic import CyclicSector, cyclic_spectrum, engine_order_diameter
from bladecase.post.disk.safe_plot import engine_order_zigzag, safe_figure


def test_zigzag_folds_engine_orders_onto_nodal_diameters():
    n, speed = 12, 2 * math.pi * 50.0          # 3000 rpm: EO e at 50 e Hz
    e, k, f = engine_order_zigzag(n, speed, 1220.0)
    assert e.tolist() == list(range(26)) and np.allclose(f, 50.0 * e, rtol=1e-14)
    # k ≡ ±e (mod N), in 0..N/2, by brute force
    for order, nd in zip(e, k):
        assert nd in range(n // 2 + 1) and ((order - nd) % n == 0 or (order + nd) % n == 0)
    assert k[:14].tolist() == [0, 1, 2, 3, 4, 5, 6, 5, 4, 3, 2, 1, 0, 1]
    assert engine_order_diameter(7, 13) == 6 and engine_order_diameter(13, 13) == 0


def test_figure_has_families_and_the_zigzag_of_a_lumped_disk():
    n = 12
    K = sp.csr_array([[3.0 + 1.0 + 0.7, -1.0, -0.7], [-1.0, 1.0, 0.0], [-0.7, 0.0, 0.7]]) * 1e6
    sector = CyclicSector(K, sp.csr_array(np.diag([2.0, 0.5, 0.0])), n, left=[0], right=[2])
    spectrum = cyclic_spectrum(sector, 2)
    speed = 2 * math.pi * 40.0
    fig = safe_figure(spectrum, n, speed=speed)
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    fam = [line for line in ax.lines if line.get_label().startswith("family")]
    assert len(fam) == 2
    for j, line in enumerate(fam):
        assert line.get_xdata().tolist() == list(range(n // 2 + 1))
        assert np.allclose(line.get_ydata(), [spectrum[k].frequencies[j] for k in range(n // 2 + 1)], rtol=1e-14)
    zig = next(line for line in ax.lines if line.get_label().startswith("engine orders"))
    top = max(m.frequencies.max() for m in spectrum.values()) * 1.05
    e = np.arange(int(math.ceil(top / 40.0)) + 1)
    assert zig.get_label() == "engine orders at 2400 rpm"
    assert np.allclose(zig.get_ydata(), 40.0 * e) and zig.get_xdata().tolist() == [
        min(x % n, n - x % n) for x in e]
    labels = {t.get_text() for t in ax.texts}
    assert "EO 1" in labels and f"EO {e[-1]}" not in labels  # the last order lies above the axis
    with pytest.raises(ValueError, match=r"nodal diameters \[7\] are outside 0..6"):
        safe_figure({7: [1.0]}, n)
    with pytest.raises(ValueError, match="speed must be a finite number > 0"):
        safe_figure(spectrum, n, speed=-1.0)
