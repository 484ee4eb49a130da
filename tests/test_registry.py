"""The reduction registry (``bladecase.reduction.registry``), factor reuse, and the import paths kept for callers.

Reference model: the committed plane-stress plate ``meshes/plate.msh`` (P1,
1084 free dofs), contact at its ``contact`` node, normal ``+y``, gap 0.1 mm.
The Guyan reduction below is the example of the registry's docstring; its
reference is the dense static condensation ``K_bb - K_bi K_ii⁻¹ K_ib``.
"""

from __future__ import annotations

import importlib
from pathlib import Path

import numpy as np
import pytest

import bladecase as bc
from bladecase.fe import stiffness_factor
from bladecase.linalg import spd_factor
from bladecase.reduction import METHODS, Contact, ReducedModel, Registry, reduce
from bladecase.reduction.methods.common import constraint, projected_system

MESHES = Path(__file__).resolve().parent.parent / "meshes"
GAP = 1e-4


@pytest.fixture(scope="module")
def plate() -> bc.FEModel:
    return bc.assemble(bc.load_mesh(MESHES / "plate.msh"), "Ti-6Al-4V", order=1, thickness=0.002)


@pytest.fixture(scope="module")
def contact(plate) -> Contact:
    return Contact(int(plate.mesh.group("contact")[0]), [0.0, 1.0], GAP)


# --------------------------------------------------------------------------- METHODS is the tuple it was


def test_methods_behave_as_the_tuple_of_names():
    names = ("full", "modal", "lanczos", "lanczos-si", "craig-bampton", "massless", "massless-lanczos",
             "massless-modal")
    assert METHODS == names and tuple(METHODS) == names and list(METHODS) == list(names)
    assert len(METHODS) == 8 and METHODS[0] == "full" and METHODS[-1] == "massless-modal"
    assert METHODS[1:3] == ("modal", "lanczos") and METHODS.index("lanczos-si") == 3
    assert "modal" in METHODS and "guyan" not in METHODS and ["modal"] not in METHODS and None not in METHODS
    assert ", ".join(METHODS) == ("full, modal, lanczos, lanczos-si, craig-bampton, massless, massless-lanczos, "
                                  "massless-modal")
    assert repr(METHODS) == repr(names)
    assert METHODS.entry("full").sized is False and METHODS.entry("modal").sized is True
    assert list(METHODS.summaries()) == list(names)


def test_registry_rejects_bad_registrations():
    r = Registry("demo method")
    r.register("a", lambda *args, **kwargs: None, "first")
    with pytest.raises(ValueError, match="demo method 'a' is already registered"):
        r.register("a", lambda *args, **kwargs: None, "again")
    with pytest.raises(ValueError, match="must be a non-empty string"):
        r.register("", lambda *args, **kwargs: None, "nameless")
    with pytest.raises(ValueError, match="the builder of demo method 'b' must be callable"):
        r.register("b", "not a function", "broken")
    with pytest.raises(ValueError, match=r"unknown demo method 'c' \(valid: 'a'\)"):
        r.entry("c")
    assert r.unregister("a").summary == "first" and len(r) == 0
    with pytest.raises(ValueError, match=r"unknown demo method 'a' \(valid: \)"):
        r.unregister("a")


# --------------------------------------------------------------------------- adding a method


def guyan(model, contact, size=None, factor=None):
    """The registry docstring's example, verbatim but for the names."""
    b = contact.dofs(model)
    inner = np.setdiff1d(np.arange(model.n_dofs), b)
    K_ii = model.K[inner][:, inner]
    V = np.zeros((model.n_dofs, b.size))
    V[b, np.arange(b.size)] = 1.0
    V[inner] = -spd_factor(K_ii, "K_ii").solve(model.K[inner][:, b].toarray())
    return ReducedModel("guyan", b.size, projected_system(model, contact, V), V, model, contact)


def test_a_new_method_is_one_builder_and_one_registration(plate, contact):
    calls = []

    def build(model, contact, size=None, factor=None):
        calls.append((size, factor))
        return guyan(model, contact, size, factor)

    METHODS.register("guyan", build, "static condensation onto the contact node's dofs", sized=False)
    try:
        assert "guyan" in METHODS and METHODS[-1] == "guyan"
        reduced = reduce(plate, contact, "guyan")
    finally:
        METHODS.unregister("guyan")
    assert "guyan" not in METHODS and len(METHODS) == 8
    assert calls == [(None, None)] and reduced.method == "guyan" and reduced.n == 2
    K = plate.K.toarray()
    b = contact.dofs(plate)
    i = np.setdiff1d(np.arange(plate.n_dofs), b)
    schur = K[np.ix_(b, b)] - K[np.ix_(b, i)] @ np.linalg.solve(K[np.ix_(i, i)], K[np.ix_(i, b)])
    np.testing.assert_allclose(reduced.system.K, schur, rtol=1e-9)
    np.testing.assert_allclose(reduced.system.w, constraint(plate, contact)[b], rtol=0, atol=0)


# --------------------------------------------------------------------------- one factorisation for every stage


def test_one_factor_serves_frequencies_and_reductions(plate, contact):
    f = stiffness_factor(plate)
    assert f.is_of(plate.K) and f.n == plate.n_dofs
    np.testing.assert_allclose(bc.natural_frequencies(plate, 6, factor=f), bc.natural_frequencies(plate, 6),
                               rtol=1e-12)
    for method in ("modal", "lanczos-si", "craig-bampton", "lanczos"):
        a = reduce(plate, contact, method, 10, factor=f).system.spectrum
        b = reduce(plate, contact, method, 10).system.spectrum
        np.testing.assert_allclose(a.omega, b.omega, rtol=1e-12)
        np.testing.assert_allclose(np.abs(a.b), np.abs(b.b), rtol=1e-9, atol=1e-12 * np.abs(b.b).max())


def test_a_factor_of_another_matrix_is_refused(plate, contact):
    other = spd_factor(plate.K.copy(), "K")
    for call in (lambda: bc.natural_frequencies(plate, 3, factor=other),
                 lambda: reduce(plate, contact, "modal", 3, factor=other),
                 lambda: reduce(plate, contact, "lanczos-si", 3, factor=spd_factor(plate.M, "M"))):
        with pytest.raises(ValueError, match="factor must be None or the factorisation of this model's K"):
            call()
    with pytest.raises(ValueError, match="sigma = 0 only"):
        bc.lanczos_chain(plate, 3, contact=contact, shift_invert=True, sigma=1e6, factor=stiffness_factor(plate))


def test_stiffness_factor_checks_rigid_body_modes():
    mesh = bc.load_mesh(MESHES / "plate.msh")
    free = bc.assemble(mesh, "Ti-6Al-4V", order=1, thickness=0.002, clamp=None)
    with pytest.raises(ValueError, match=r"K is singular: the model is not clamped \(no clamp\?\)"):
        stiffness_factor(free)


# --------------------------------------------------------------------------- import paths


OLD_PATHS = {
    "bladecase.fe.assembly": ["DofMap", "FEModel", "Material", "assemble", "natural_frequencies", "load_model",
                              "save_model", "model_to_arrays", "model_from_arrays", "sparse_to_arrays",
                              "sparse_from_arrays", "AL6061T6", "INCONEL718", "STEEL", "TI6AL4V", "PRESETS",
                              "MASS_KINDS", "PLANE_KINDS", "ORDERS", "MODEL_FORMAT"],
    "bladecase.fe.geometry": ["BladeGeometry", "PlateGeometry", "blade_mesh", "cad_volume", "naca_section",
                              "naca_parameters", "SECTION_POINTS", "TIP_ZONE", "CONTACT_RTOL"],
    "bladecase.fe.mesh": ["Mesh", "load_mesh", "save_mesh", "from_meshio", "GROUP_PREFIX", "_P2_EDGES"],
    "bladecase.reduction.lanczos": ["LanczosChain", "MassFactor", "PerDofDefect", "SymmetryBasis", "lanczos_chain",
                                    "mass_factor", "per_dof_defect", "per_dof_law", "chain_jacobi",
                                    "chain_grounding", "BREAKDOWN_RTOL", "KAPPA_ROUNDOFF"],
    "bladecase.reduction.methods": ["FULL_LIMIT", "METHODS", "ReducedModel", "reduce", "save_reduced",
                                    "load_reduced", "node_operator"],
    "bladecase.reduction.contact": ["Contact", "radial_normal"],
}

#: ``__all__`` of bladecase.fe and bladecase.reduction before the split: each must stay.
OLD_ALL = {
    "bladecase.fe": ["BladeGeometry", "DofMap", "FEModel", "Material", "Mesh", "PlateGeometry", "assemble",
                     "blade_mesh", "load_mesh", "load_model", "natural_frequencies", "save_mesh", "save_model"],
    "bladecase.reduction": ["FULL_LIMIT", "METHODS", "Contact", "LanczosChain", "MassFactor", "PerDofDefect",
                            "ReducedModel", "SymmetryBasis", "lanczos_chain", "load_reduced", "mass_factor",
                            "per_dof_defect", "radial_normal", "reduce", "save_reduced"],
}


@pytest.mark.parametrize("module", sorted(OLD_PATHS))
def test_old_module_paths_still_import(module):
    mod = importlib.import_module(module)
    for name in OLD_PATHS[module]:
        assert getattr(mod, name) is not None, f"{module}.{name}"


@pytest.mark.parametrize("package", sorted(OLD_ALL))
def test_subpackages_export_every_public_name(package):
    mod = importlib.import_module(package)
    assert set(OLD_ALL[package]) <= set(mod.__all__)
    for name in mod.__all__:
        assert getattr(mod, name) is not None, f"{package}.{name}"
