"""Which reduced model can I trust? A model-comparison study with the Python API, cell by cell.

The committed 2-D plate (``meshes/plate.vtu``, P1, lumped mass, clamped at its root) with its tip node against
a casing 0.1 mm away. Three reduction methods at two sizes each get the same 1-ipp search; each is compared with
the FE model: its modes matched to FE modes by shape (MAC), the contact's impact mass ``1/Σb²`` and static
compliance against the FE values, its admissible arcs, and what it all means in words
(:mod:`bladecase.post.comparison.compare`). The same study from a TOML file: ``[reduction] methods = [...]``,
``sizes = [...]`` (docs/study.md); ``bladecase.run`` then returns it all in ``RunResult.models``.

Run: ``python examples/compare_models.py [--out DIR] [--low]``.
"""

from __future__ import annotations

import pathlib
import sys
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import _paper as paper  # noqa: E402  (the examples' shared command line)

import bladecase as bc  # noqa: E402
from bladecase.io import save_figure  # noqa: E402
from bladecase.post.comparison.compare import ModelResult, fe_reference  # noqa: E402
from bladecase.post.comparison.diagnose import diagnose  # noqa: E402
from bladecase.post.comparison.plots import convergence_plot, overlay_plot, spectral_plot  # noqa: E402
from bladecase.post.comparison.table import comparison_rows, write_comparison_csv  # noqa: E402

PLATE = pathlib.Path(__file__).resolve().parent.parent / "meshes" / "plate.vtu"


def main(out: str, resolution: str = "full") -> list[pathlib.Path]:
    out_dir = pathlib.Path(out)
    out_dir.mkdir(parents=True, exist_ok=True)
    sizes = (6, 12) if resolution == "low" else (6, 12, 24)

    # %% the FE model, its contact and its modes (one factorisation of K serves everything)
    model = bc.assemble(bc.load_mesh(PLATE), "Ti-6Al-4V", order=1, mass="lumped", thickness=0.002)
    factor = bc.stiffness_factor(model)
    contact = bc.Contact.farthest(model, (0.0, 1.0), normal=(0.0, 1.0), gap=1e-4, group="tip")
    fe = fe_reference(model, contact, 12, factor=factor)
    T1 = 1 / fe.frequencies[0]
    print(f"FE: {model}; f1 = {fe.frequencies[0]:.2f} Hz; impact mass {fe.impact_mass:.3g} kg, "
          f"static compliance {fe.static_compliance:.3g} m/N")

    # %% every model: reduce, then the same search (the 1-ipp backbone below T1)
    models = []
    for method in ("modal", "craig-bampton", "lanczos-si"):
        for size in sizes:
            t0 = time.perf_counter()
            reduced = bc.reduce(model, contact, method, size, factor=factor)
            t1 = time.perf_counter()
            branch = bc.backbone(reduced.system, np.linspace(0.5 * T1, 0.9999 * T1, 300)).compact()
            models.append(ModelResult(reduced, [branch], t1 - t0, time.perf_counter() - t1))

    # %% the comparison: one row per model, and what it means in words
    rows = comparison_rows(models, fe, fractions=(0.6, 0.8, 0.95))
    write_comparison_csv(rows, out_dir / "compare_models.csv")
    for r in rows[1:]:  # rows[0]: the FE model itself
        print(f"{r['model']:>18}: {r['dofs']:>5} dofs, modes matched {r.get('modes_matched')}/"
              f"{r.get('modes_checked')}, impact mass kept {r['impact_mass_kept'] or float('nan'):.3g}, "
              f"arcs {r.get('admissible_arcs')}, {r.get('convergence') or ''}")
    print(*diagnose(rows, fe), sep="\n")

    # %% the pictures: every model on shared axes, convergence with size, the contact spectral measure
    paths = []
    for name, fig in (("compare_models_overlay.png", overlay_plot(models, fe, title="plate: every model")),
                      ("compare_models_convergence.png", convergence_plot(rows, title="plate: convergence")),
                      ("compare_models_spectrum.png", spectral_plot(models, fe, title="plate: contact spectrum"))):
        save_figure(fig, out_dir / name, dpi=90 if resolution == "low" else 140)
        paths.append(out_dir / name)
    return paths


if __name__ == "__main__":
    paper.run(main, __doc__)
