"""Frequency–energy figures (``bladecase.post.plots``): pyplot-free, labelled with units, every mark in the legend.

References: matplotlib's own state (pyplot's figure registry, ``sys.modules``
in a fresh interpreter), the PNG signature, and the backbone's data.
"""

from __future__ import annotations

import io
import subprocess
import sys

import numpy as np
import pytest
from matplotlib.figure import Figure

from bladecase.post.plots import axis_labels, frequency_energy

PNG = b"\x89PNG\r\n\x1a\n"


def test_figure_without_pyplot_state(two_dof_backbone):
    import matplotlib.pyplot as plt

    before = plt.get_fignums()
    fig = frequency_energy([two_dof_backbone])
    assert isinstance(fig, Figure)
    assert plt.get_fignums() == before  # not registered with pyplot: nothing to close, nothing leaks
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=40)
    assert buf.getvalue().startswith(PNG)
    assert fig._repr_png_().startswith(PNG)  # a notebook shows it even without pyplot


def test_library_never_imports_pyplot():
    """In a fresh interpreter: the post modules, a figure made and saved, and pyplot was never imported
    (so no backend was selected or switched)."""
    code = (
        "import io, sys, numpy as np\n"
        "import bladecase.post.plots, bladecase.post.grid, bladecase.post.vtk, bladecase.post.animation\n"
        "from bladecase.nsm import backbone, chain\n"
        "bb = backbone(chain(2, k=1.0, m=0.5, gap=1.0), np.linspace(2.0, 8.0, 20))\n"
        "bladecase.post.plots.frequency_energy([bb]).savefig(io.BytesIO(), format='png', dpi=30)\n"
        "assert 'matplotlib.pyplot' not in sys.modules, 'pyplot was imported'\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr


def test_labels_and_units(two_dof_backbone):
    ax = frequency_energy([two_dof_backbone]).axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("frequency 1/T", "energy E")  # dimensionless chain
    ax = frequency_energy([two_dof_backbone], time_unit="s", energy_unit="J", title="SI").axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel(), ax.get_title()) == ("frequency 1/T (Hz)", "energy E (J)", "SI")
    assert axis_labels("ms") == ("frequency 1/T (1/ms)", "energy E")
    for bad in ("", 3):
        with pytest.raises(ValueError, match="time_unit"):
            frequency_energy([two_dof_backbone], time_unit=bad)
    with pytest.raises(ValueError, match="energy_unit"):
        axis_labels(energy_unit=" ")


def test_every_mark_in_the_legend(two_dof_backbone):
    bb = two_dof_backbone
    assert bb.admissible.any() and (~bb.admissible & np.isfinite(bb.energy)).any() and bb.intervals
    ax = frequency_energy([bb]).axes[0]
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert legend == ["non-admissible orbits", "1 ipp (admissible)", "ends of admissible arcs",
                      r"linear frequencies $\omega_j/2\pi$"]
    # each label once, on a drawn artist (a later ax.legend() keeps them)
    labels = ax.get_legend_handles_labels()[1]
    assert sorted(labels) == sorted(legend)
    # every drawn line is either labelled or of a labelled kind: no unexplained mark
    kinds = {(ln.get_linestyle(), ln.get_marker()) for ln in ax.get_lines()}
    labelled = {(ln.get_linestyle(), ln.get_marker()) for ln in ax.get_lines() if not ln.get_label().startswith("_")}
    assert kinds == labelled


def test_draws_into_given_axes(two_dof_backbone):
    fig = Figure()
    ax = fig.add_subplot()
    assert frequency_energy([two_dof_backbone], ax=ax, linear=False) is fig
    assert r"linear frequencies $\omega_j/2\pi$" not in ax.get_legend_handles_labels()[1]
    assert ax.get_yscale() == "log"


def test_frequency_energy_readability_options():
    """Arcs narrower than a pixel become markers; non-admissible dots are optional; linear frequencies labelled."""
    import numpy as np

    from bladecase.nsm import Arc, Branch, backbone, chain
    from bladecase.post.plots import frequency_energy

    system = chain(2, k=1.0, m=0.5, gap=1.0)
    bb = backbone(system, np.linspace(2.0, 8.0, 61))
    i = int(np.flatnonzero(bb.admissible)[3])
    narrow = Branch(system, 1, bb.orbits, [Arc(i, i, bb.T[i], bb.T[i] * (1 + 1e-9))], periods=bb.periods)
    ax = frequency_energy([bb, narrow], nonadmissible=False).axes[0]
    labels = ax.get_legend_handles_labels()[1]
    assert "1 ipp (admissible arc narrower than a pixel)" in labels and "non-admissible orbits" not in labels
    texts = [t.get_text() for t in ax.texts]
    assert texts == ["1", "2"]  # both linear frequencies (0.139, 0.364) lie in 1/8 … 1/2
    assert "non-admissible orbits" in frequency_energy([bb]).axes[0].get_legend_handles_labels()[1]
