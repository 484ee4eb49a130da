"""``png``: the frequency–energy plot of every model of a run, one panel per model (``frequency_energy.png``);
admissible arcs solid where Floquet-stable, dashed where unstable."""

from __future__ import annotations

from pathlib import Path

from ...io import save_figure
from ..plots import frequency_energy, new_figure
from .registry import PlotScene


def write(scene: PlotScene, folder: Path, formats: set[str]) -> dict[str, str]:
    """One panel per model, the full FE frequencies as dotted lines; returns ``{"frequency_energy_plot": name}``."""
    fig = new_figure(figsize=(8, 4.6 * len(scene.models)), layout="constrained")
    axes = fig.subplots(len(scene.models), 1, squeeze=False)[:, 0]
    for ax, (label, branches) in zip(axes, scene.models):
        title = f"{scene.title}: {label}"
        if branches:
            frequency_energy(branches, ax=ax, title=title, time_unit="s", energy_unit="J", stability=True)
        else:
            ax.set_title(title + ": no family found")
        lo, hi = ax.get_xlim()
        shown = [f for f in scene.reference_hz if lo <= f <= hi]
        for j, fj in enumerate(shown):
            ax.axvline(fj, color="0.4", ls=":", lw=1.0, label="full FE frequencies" if j == 0 else None)
        if shown:
            ax.legend(fontsize="small")
    name = "frequency_energy.png"
    save_figure(fig, folder / name, dpi=120)
    return {"frequency_energy_plot": name}
