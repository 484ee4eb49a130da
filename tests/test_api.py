"""The public API is a contract: every name external scripts import from ``bladecase`` keeps importing."""

import subprocess
import sys
from pathlib import Path

import pytest

import bladecase

ROOT = Path(__file__).resolve().parents[1]

#: ``bladecase.__all__`` of release 0.1 (before the layout by stage): each must still import.
RELEASE_0_1 = [
    "Arc", "Backbone", "BladeGeometry", "Contact", "DofMap", "FEModel", "FULL_LIMIT", "Family", "Interval",
    "LanczosChain", "LinearSystem", "MassFactor", "Material", "Mesh", "PerDofDefect", "PeriodicOrbit",
    "PlateGeometry", "ReducedModel", "RunResult", "Spectrum", "Study", "StudyError", "SymmetryBasis",
    "Trajectory", "assemble", "backbone", "blade_mesh", "chain", "demo_study", "impact_matrices",
    "lanczos_chain", "load_mesh", "load_study", "make_orbit", "mass_factor", "natural_frequencies",
    "nonsmooth_mode", "orbit_1ipp", "orbits_kipp", "per_dof_defect", "radial_normal", "reduce", "run",
    "save_mesh", "simulate",
]


@pytest.mark.parametrize("name", RELEASE_0_1)
def test_release_names_still_import(name):
    assert name in bladecase.__all__
    assert getattr(bladecase, name) is not None


def test_all_is_importable():
    for name in bladecase.__all__:
        assert hasattr(bladecase, name), name


def test_ruff_is_clean():
    """The ruff configuration in pyproject.toml holds for the whole repository."""
    ruff = Path(sys.executable).with_name("ruff")
    if not ruff.exists():
        pytest.skip("ruff is not installed in this environment (it is in the [test] extra)")
    res = subprocess.run([str(ruff), "check", "--quiet", str(ROOT)], capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 0, res.stdout + res.stderr


def test_run_takes_the_path_of_a_study_file(tmp_path, monkeypatch):
    (tmp_path / "plate.vtu").write_bytes((Path(__file__).resolve().parents[1] / "meshes" / "plate.vtu").read_bytes())
    (tmp_path / "p.toml").write_text('[study]\nname = "p"\n[mesh]\npath = "plate.vtu"\n[fem]\norder = 1\n'
                                     'thickness = 0.002\n[contact]\nclearance = 1e-4\n[reduction]\nmethod = "modal"\n'
                                     'size = 4\n[search]\nipp = [1]\nscan = 3\n[output]\nformats = []\n'
                                     'reference = false\nanimate = 0\n')
    monkeypatch.chdir(tmp_path)
    result = bladecase.run("p.toml", progress=False)
    assert result.directory == Path("results/p") and (tmp_path / "results" / "p" / "summary.json").is_file()
    with pytest.raises(ValueError, match="study must be a Study .* or the path of a study file, got int 3"):
        bladecase.run(3)
