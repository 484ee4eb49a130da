"""Arrays read from stage files and given to the API: a bad one is one ``ValueError`` naming the file, the
field, the offending value and what is valid (exit 2 on the command line), never a traceback, never a silent
wrong answer.

Three kinds of stage file: user matrices (``backbone/modes --matrices F.npz`` → :class:`bladecase.LinearSystem`),
FE model files (:func:`bladecase.fe.load_model`), reduced model files (:func:`bladecase.reduction.load_reduced`);
and the arrays of the Python API (:class:`bladecase.LinearSystem`, :func:`bladecase.chain`).
Every system here is tiny (at most a 200-dof strip).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from _studies import PLATE, absolute
from skfem import MeshTri

import bladecase as bc
from bladecase.cli import main
from bladecase.fe import Mesh, assemble, load_model, model_to_arrays
from bladecase.reduction import Contact, load_reduced, reduce, save_reduced

K3 = np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]])  # a clamped 3-mass chain
FREE3 = np.array([[1.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]])  # the same chain free–free: singular


def _free_free(n: int, seed: int = 0) -> sp.csr_array:
    """A free–free chain of ``n`` masses with random springs: singular, yet its Cholesky may succeed by round-off."""
    k = np.random.default_rng(seed).uniform(0.1, 10.0, n - 1)
    d = np.zeros(n)
    d[:-1] += k
    d[1:] += k
    return sp.diags_array([d, -k, -k], offsets=[0, 1, -1], format="csr")


def _run(argv, capsys) -> tuple[int, str]:
    """Exit code and the one error line of ``main(argv)`` (no traceback)."""
    code = main([str(a) for a in argv])
    err = capsys.readouterr().err
    assert "Traceback" not in err and "unexpected" not in err, err
    lines = [line for line in err.splitlines() if "error" in line]
    assert len(lines) <= 1, err
    return code, lines[0] if lines else ""


# ----------------------------------------------------------------------------- user matrices (--matrices)

def _matrices(tmp_path, name="m.npz", **fields):
    base = {"M": np.eye(3), "K": K3, "w": 2, "gap": 1.0}
    base.update(fields)
    path = tmp_path / name
    np.savez(path, **{k: v for k, v in base.items() if v is not None})
    return path


BACKBONE = ["--periods", "1:12:5", "--quiet", "--no-progress"]


@pytest.mark.parametrize("fields, words", [
    ({"K": np.eye(3, dtype=bool)}, "K must hold numbers, got booleans (dtype bool)"),
    ({"M": np.eye(3, dtype=bool)}, "M must hold numbers, got booleans (dtype bool)"),
    ({"K": np.zeros((3, 3), dtype="datetime64[s]")}, "K must hold numbers, got dates"),
    ({"M": np.zeros((3, 3))}, "M is zero (all 3² entries 0), not positive definite"),
    ({"K": FREE3}, "K is not positive definite: smallest eigenvalue "),
    ({"K": FREE3}, "it must be > 0): "
                   "the solver needs K positive definite (no rigid-body motion): a free–free structure? clamp it"),
    ({"M": np.eye(10), "K": _free_free(10).toarray(), "w": 9},  # Cholesky passes or not, by round-off
     "a free–free structure? clamp it"),
    ({"K": np.diag([1.0, 1.0, 1e-15])},
     "K is singular to working precision, not positive definite: its smallest eigenvalue is at most 1e-15 <= "
     "1e-12 * max diag K = 1e-12"),
    ({"M": np.eye(4), "K": np.eye(4), "w": np.ones((2, 2))},
     "w must be a vector of 4 numbers (one per dof), got an array of shape (2, 2)"),
])
def test_bad_user_matrices_are_refused(tmp_path, capsys, fields, words):
    path = _matrices(tmp_path, **fields)
    code, line = _run(["backbone", "--matrices", path, *BACKBONE], capsys)
    assert code == 2 and words in line and path.name in line, line


@pytest.mark.parametrize("fields, words", [  # refused before this file too: kept refused
    ({"K": K3 + np.triu(np.full((3, 3), 0.1), 1)}, "K is not symmetric: max|K - Kᵀ| = 0.1 exceeds 1e-10 * max|K|"),
    ({"M": np.diag([1.0, -1.0, 1.0])}, "M is not positive definite: smallest eigenvalue -1"),
    ({"K": np.where(np.eye(3) > 0, np.nan, K3)}, "K contains 3 non-finite value(s) (NaN or inf)"),
    ({"M": np.full((3, 3), np.inf)}, "M contains 9 non-finite value(s)"),
    ({"K": np.ones((3, 2))}, "K must be a square matrix, got shape (3, 2)"),
    ({"K": np.eye(4)}, "K has shape (4, 4), expected (3, 3) to match M"),
    ({"w": np.ones(4)}, "w has 4 entries, expected 3 (one per dof)"),
    ({"gap": -1.0}, "gap must be a finite clearance > 0, got -1.0"),
    ({"gap": np.nan}, "gap must be a finite clearance > 0, got nan"),
    ({"M": np.array(1.0)}, "M must be a square matrix, got shape ()"),
    ({"M": np.array([["a"] * 3] * 3)}, "M must hold numbers, got text"),
])
def test_user_matrices_checks_that_already_held(tmp_path, capsys, fields, words):
    path = _matrices(tmp_path, **fields)
    code, line = _run(["backbone", "--matrices", path, *BACKBONE], capsys)
    assert code == 2 and words in line and path.name in line, line


def test_modes_with_bad_user_matrices(tmp_path, capsys):
    study = tmp_path / "s.toml"
    study.write_text('[study]\nname = "chain3"\n[search]\nipp = [1]\nperiods = [0.5, 0.9999]\n')
    path = _matrices(tmp_path, K=np.eye(3, dtype=bool))
    code, line = _run(["modes", study, "--matrices", path, "-o", tmp_path / "m.json", "--quiet", "--no-progress"],
                      capsys)
    assert code == 2 and "K must hold numbers, got booleans" in line and "m.npz" in line, line
    assert not (tmp_path / "m.json").exists()


def test_a_single_npy_array_is_not_a_matrices_file(tmp_path, capsys):
    np.save(tmp_path / "K.npy", K3)
    code, line = _run(["backbone", "--matrices", tmp_path / "K.npy", *BACKBONE], capsys)
    assert code == 2, line
    assert "K.npy': it is a single .npy array, not an .npz archive of named arrays M, K, w, gap" in line


# ----------------------------------------------------------------------------- --chain N and chain(n)

def test_chain_too_long_for_the_dense_solver(capsys):
    code, line = _run(["backbone", "--chain", "100000", "--gap", "1", "--periods", "1:2:3"], capsys)
    assert code == 2, line
    assert "--chain N must be <= 6000, got 100000: the solver is dense in N" in line and "80 GB" in line, line
    with pytest.raises(ValueError, match=r"chain length n must be <= 6000, got 100000: .* 80 GB"):
        bc.chain(100_000)
    with pytest.raises(ValueError, match="chain length n must be <= 6000, got 6001"):
        bc.chain(6001, gap=1.0)


def test_a_tridiagonal_system_above_the_dense_limit_is_refused_not_out_of_memory():
    n = bc.nsm.system.DENSE_LIMIT + 1
    K = sp.diags_array([np.full(n, 2.0), -np.ones(n - 1), -np.ones(n - 1)], offsets=[0, 1, -1], format="csr")
    s = bc.LinearSystem(sp.eye_array(n, format="csr"), K, n - 1, 1.0)
    with pytest.raises(ValueError, match=f"model has {n} dofs, above the dense eigen-solution limit 6000"):
        _ = s.spectrum


# ----------------------------------------------------------------------------- LinearSystem(M, K, w, gap)

@pytest.mark.parametrize("M, K, w, gap, words", [
    (np.eye(3), np.eye(3, dtype=bool), 2, 1.0, "K must hold numbers, got booleans (dtype bool)"),
    (np.eye(3), sp.csr_array(np.eye(3, dtype=bool)), 2, 1.0, "K must hold numbers, got booleans"),
    (np.eye(3, dtype=bool), K3, 2, 1.0, "M must hold numbers, got booleans"),
    (np.zeros((3, 3)), K3, 2, 1.0, "M is zero (all 3² entries 0), not positive definite"),
    (sp.csr_array((3, 3)), K3, 2, 1.0, "M is zero"),
    (np.eye(3), np.zeros((3, 3)), 2, 1.0, "K is zero"),
    (np.eye(3), FREE3, 2, 1.0, "free–free structure? clamp it"),
    (np.eye(10), _free_free(10).toarray(), 9, 1.0, "a free–free structure? clamp it"),
    (sp.eye_array(10, format="csr"), _free_free(10), 9, 1.0, "a free–free structure? clamp it"),
    (sp.eye_array(1000, format="csr"), _free_free(1000), 999, 1.0, "a free–free structure? clamp it"),
    (np.eye(3), np.diag([1.0, 1.0, 1e-15]), 2, 1.0, "K is singular to working precision"),
    (sp.eye_array(3, format="csr"), sp.diags_array([1.0, 1.0, 1e-15], format="csr"), 2, 1.0,
     "K is singular to working precision, not positive definite: its smallest eigenvalue is at most 1e-15"),
    (np.diag([1.0, 1e-14]), np.eye(2), 1, 1.0, "every degree of freedom needs a positive mass"),
    (np.eye(3), K3, True, 1.0, "w must be an integer contact dof (0..2) or a vector of 3 numbers, got True"),
    (np.eye(3), K3, np.array([False, False, True]), 1.0, "w must hold numbers, got booleans"),
    (np.eye(3), K3, ["a", "b", "c"], 1.0, "w must hold numbers, got text"),
    (np.eye(4), np.eye(4), np.ones((2, 2)), 1.0, "w must be a vector of 4 numbers"),
    (np.eye(3), K3, 2, True, "gap must be a finite clearance > 0, got True"),
])
def test_linear_system_refuses_bad_arrays(M, K, w, gap, words):
    with pytest.raises(ValueError) as info:
        bc.LinearSystem(M, K, w, gap)
    assert words in str(info.value)


def test_linear_system_still_takes_what_it_took():
    assert bc.LinearSystem(np.eye(3, dtype=int), K3.astype(int), 2, 1).n == 3  # integer matrices are numbers
    assert bc.LinearSystem(np.eye(3), K3 + 0j, np.array([[0.0], [0.0], [1.0]]), 1.0).w.tolist() == [0, 0, 1]
    assert bc.LinearSystem(np.eye(3), K3, np.uint8(2), np.float32(0.5)).gap == 0.5
    clamped = _free_free(1000).tolil()
    clamped[0, 0] += 1.0  # the same chain clamped at one end: smallest eigenvalue ~1e-7 of the diagonal
    assert bc.LinearSystem(sp.eye_array(1000, format="csr"), sp.csr_array(clamped), 999, 1.0).n == 1000


# ----------------------------------------------------------------------------- FE model and reduced model files

def _strip_model(mass="consistent"):
    t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5)).oriented()
    points = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    mesh = Mesh(points, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(points[:, 0] == 0)},
                source="strip")
    return mesh, assemble(mesh, "steel", order=1, thickness=0.002, mass=mass)


@pytest.fixture(scope="module")
def strip(tmp_path_factory):
    """The 2-D steel strip (200 free dofs): its FE model's arrays, a modal (4) and a massless (6) reduced model."""
    folder = tmp_path_factory.mktemp("arrays")
    mesh, model = _strip_model()
    contact = Contact.nearest(model, (0.1, 0.02), normal=(0.0, 1.0), gap=1e-4)
    save_reduced(reduce(model, contact, "modal", 4), folder / "reduced.npz")
    _, lumped = _strip_model("lumped")
    save_reduced(reduce(lumped, Contact.nearest(lumped, (0.1, 0.02), normal=(0.0, 1.0), gap=1e-4), "massless", 6),
                 folder / "massless.npz")
    study = folder / "plate.toml"
    study.write_text(absolute(PLATE) + "[output]\nformats = []\nreference = false\n")
    return {"mesh": mesh, "model": model, "arrays": model_to_arrays(model), "study": study,
            "reduced": folder / "reduced.npz", "massless": folder / "massless.npz"}


def _csr(name: str, A) -> dict:
    A = sp.csr_array(A)
    return {f"{name}/data": A.data, f"{name}/indices": A.indices, f"{name}/indptr": A.indptr,
            f"{name}/shape": np.array(A.shape)}


def _edited(arrays: dict, edit) -> dict:
    fields = dict(arrays)
    fields.update(edit(fields))
    return fields


def _with(a, index, value):
    a = np.array(a)
    a[index] = value
    return a


def _lowest_eigenvalue(model) -> float:
    return float(bc.natural_frequencies(model, 1)[0] * 2 * np.pi) ** 2


MODEL_CASES = [
    (lambda f: {"mesh/cells/triangle": _with(f["mesh/cells/triangle"], (0, 0), 10**6)},
     "field 'mesh/cells/triangle' must hold mesh nodes in 0..104, got 1000000 at [0, 0]"),
    (lambda f: {"mesh/cells/triangle": _with(f["mesh/cells/triangle"], (3, 1), -1)},
     "field 'mesh/cells/triangle' must hold mesh nodes in 0..104, got -1 at [3, 1]"),
    (lambda f: {"mesh/cells/triangle": f["mesh/cells/triangle"][:, :2]},
     "field 'mesh/cells/triangle' must have 3 nodes per triangle cell, got shape (160, 2)"),
    (lambda f: {"mesh/points": _with(f["mesh/points"], (3, 1), np.nan)},
     "field 'mesh/points' must hold finite numbers, got 1 NaN or inf (the first: nan at [3, 1])"),
    (lambda f: {"mesh/points": f["mesh/points"][:, :2]}, "field 'mesh/points' must be the (n_nodes, 3) coordinates"),
    (lambda f: {"mesh/dim": np.array(4)}, "field 'mesh/dim' must be 2 or 3, got 4"),
    (lambda f: {"mesh/groups/root": np.array([10**6])}, "field 'mesh/groups/root' must hold mesh nodes in 0..104"),
    (lambda f: {"mesh/cells/triangle": np.zeros((0, 3), dtype=int)}, "the mesh has no 2-D body cells"),
    (lambda f: {"dofs/coords": _with(f["dofs/coords"], (7, 0), np.inf)},
     "field 'dofs/coords' must hold finite numbers, got 1 NaN or inf (the first: inf at [7, 0])"),
    (lambda f: {"order": np.array(7)}, "field 'order' must be the element order, 1 or 2, got 7"),
    (lambda f: {"mass": np.array("heavy")}, "field 'mass' must be one of ('consistent', 'lumped'), got 'heavy'"),
    (lambda f: {"plane": np.array("weird")}, "field 'plane' must be one of ('stress', 'strain') for a 2-D model"),
    (lambda f: {"thickness": np.array(-1.0)}, "field 'thickness' must be a finite thickness > 0 for a 2-D model"),
    (lambda f: {"volume": np.array(np.nan)}, "field 'volume' must be a finite volume (area in 2-D) > 0, got nan"),
    (lambda f: {"rigid_modes": np.array(-1)}, "field 'rigid_modes' must be a count >= 0, got -1"),
    (lambda f: {"clamped": np.array([10**6])}, "field 'clamped' must hold mesh nodes in 0..104, got 1000000"),
    (lambda f: {"material": np.array([np.nan, 0.3, 7850.0])},
     "field 'material' ([E, nu, rho]): Young's modulus E must be a finite number > 0 (Pa), got nan"),
    (lambda f: {"dofs/node": _with(f["dofs/node"], 0, 10**6)}, "field 'dofs/node' must hold mesh nodes"),
    (lambda f: {"dofs/node": _with(f["dofs/node"], 0, f["dofs/node"][2])},
     "field 'dofs/node' gives one node two dofs in the same direction"),
    (lambda f: {"dofs/direction": _with(f["dofs/direction"], 0, 5)},
     "field 'dofs/direction' must hold directions of a 2-D model in 0..1, got 5 at [0]"),
    (lambda f: {"dofs/fe_index": _with(f["dofs/fe_index"], 0, 10**7)},
     "field 'dofs/fe_index' must hold dofs of the unclamped model in 0..209, got 10000000 at [0]"),
    (lambda f: {"dofs/fe_index": f["dofs/fe_index"][::-1].copy()}, "field 'dofs/fe_index' must be increasing"),
    (lambda f: {"dofs/n_total": np.array(-1)},
     "field 'dofs/n_total' must be a multiple of 2 (the dofs of every node) >= the 200 free dofs, got -1"),
    (lambda f: {"dofs/node": f["dofs/node"][:10]},
     "field 'dofs/node' must have shape (200,) (one entry per free dof of K), got (10,)"),
    (lambda f: {"K/indices": _with(f["K/indices"].astype(np.int64), 0, 2**40)},
     "field 'K/indices' must hold column indices of the 200 x 200 K in 0..199, got 1099511627776 at [0]"),
    (lambda f: {"K/indptr": f["K/indptr"][::-1].copy()}, "field 'K/indptr' must hold 201 non-decreasing row offsets"),
    (lambda f: {"K/shape": np.array([2**40, 2**40])}, "field 'K/indptr' must hold 1099511627777 non-decreasing"),
    (lambda f: {"K/data": _with(f["K/data"], 5, np.nan)}, "field 'K/data' must hold finite numbers, got 1 NaN"),
    (lambda f: {"K/data": f["K/data"] != 0}, "field 'K/data' must hold numbers, got dtype bool"),
    (lambda f: _csr("K", sp.csr_array((f["K/data"], f["K/indices"], f["K/indptr"]))[:198, :198]),
     "field 'M/shape' must be the shape of K, (198, 198), got (200, 200)"),
    (lambda f: _csr("K", sp.csr_array((f["K/data"], f["K/indices"], f["K/indptr"]))[:, :198]),
     "field 'K/shape' must be square (n_free x n_free), got (200, 198)"),
    (lambda f: {"M/data": np.zeros_like(f["M/data"])},
     "field 'M/data' must give M a positive diagonal (M is positive definite), got M[0,0] = 0 (free dof 0: node 5"),
    (lambda f: _csr("K", sp.csr_array((f["K/data"], f["K/indices"], f["K/indptr"])) + sp.csr_array(
        ([1e3], ([0], [1])), shape=(200, 200))), "K is not symmetric: max|K - Kᵀ| = 1e+03 exceeds 1e-10 * max|K|"),
    (lambda f: {"mass": np.array("lumped")}, "field 'M/data' must make M diagonal: the model's mass is 'lumped'"),
]


@pytest.mark.parametrize("edit, words", MODEL_CASES)
def test_bad_model_files_are_refused_naming_the_field(tmp_path, strip, edit, words):
    np.savez(tmp_path / "edited.npz", **_edited(strip["arrays"], edit))
    with pytest.raises(ValueError) as info:
        load_model(tmp_path / "edited.npz")
    assert words in str(info.value) and "edited.npz" in str(info.value), str(info.value)


def test_model_matrices_that_are_not_positive_definite(tmp_path, strip):
    model = strip["model"]
    M = model.M.tolil()
    M[0, 1] = M[1, 0] = 10 * model.M.diagonal().max()  # a positive diagonal, yet indefinite
    K = model.K - 1.1 * _lowest_eigenvalue(model) * model.M  # the first mode's stiffness made negative
    mesh, _ = _strip_model()
    free = model_to_arrays(assemble(mesh, "steel", order=1, thickness=0.002, clamp=None))
    for fields, words in [
        ({**strip["arrays"], **_csr("M", M)}, "M is not positive definite: its LDLᵀ factorisation has a pivot"),
        ({**strip["arrays"], **_csr("K", K)}, "K is not positive definite: its LDLᵀ factorisation has a pivot"),
        ({**free, "rigid_modes": np.array(0)}, "K is not positive definite"),  # free–free, rigid modes hidden
    ]:
        np.savez(tmp_path / "edited.npz", **fields)
        with pytest.raises(ValueError) as info:
            load_model(tmp_path / "edited.npz")
        assert words in str(info.value) and "edited.npz" in str(info.value), str(info.value)
        assert "K" not in words or "is the model clamped?" in str(info.value)
    np.savez(tmp_path / "free.npz", **free)  # an unclamped model, said so: read; the reduction refuses it
    assert load_model(tmp_path / "free.npz").rigid_modes == 3


def test_bad_model_file_on_the_command_line(tmp_path, strip, capsys):
    np.savez(tmp_path / "edited.npz", **_edited(strip["arrays"], lambda f: {"order": np.array(7)}))
    code, line = _run(["reduce", strip["study"], "--model", tmp_path / "edited.npz", "-o", tmp_path / "r.npz"],
                      capsys)
    assert code == 2 and "edited.npz: field 'order' must be the element order, 1 or 2, got 7" in line, line
    np.save(tmp_path / "model.npy", np.eye(2))
    code, line = _run(["reduce", strip["study"], "--model", tmp_path / "model.npy", "-o", tmp_path / "r.npz"],
                      capsys)
    assert code == 2 and "model.npy': it is a single .npy array, not an .npz archive" in line, line


def _reduced_arrays(path) -> dict:
    with np.load(path) as data:
        return {k: data[k] for k in data.files}


REDUCED_CASES = [
    ("reduced", lambda f: {"basis": f["basis"][:, :3]},
     "field 'basis' must be 200 x 4 (a row per free dof of the model, a column per reduced dof), got shape (200, 3)"),
    ("reduced", lambda f: {"basis": f["basis"][:100]}, "field 'basis' must be 200 x 4"),
    ("reduced", lambda f: {"basis": _with(f["basis"], (0, 0), np.nan)}, "field 'basis' must hold finite numbers"),
    ("reduced", lambda f: {"gap": np.array(2e-4)},
     "field 'gap' must be the contact's clearance (field 'contact/gap' = 0.0001), got 0.0002"),
    ("reduced", lambda f: {"contact/node": np.array(10**6)},
     "the contact (fields 'contact/...') does not fit the model: contact node 1000000 is not a mesh node"),
    ("reduced", lambda f: {"contact/node": np.array(0)}, "contact node 0 is clamped"),
    ("reduced", lambda f: {"contact/normal": np.array([0.0, 0.0, 1.0])}, "does not fit a 2-D model"),
    ("reduced", lambda f: {"contact/normal": np.array([np.nan, 1.0])}, "field 'contact/normal' must hold finite"),
    ("reduced", lambda f: {"method": np.array("guyan")}, "field 'method' must be one of the reduction methods"),
    ("reduced", lambda f: {"size": np.array(0)}, "field 'size' must be the size asked for (an integer >= 1) or -1"),
    ("reduced", lambda f: {"Kr": np.diag([0.0, 1.0, 2.0, 3.0]) * f["Kr"].max()},
     "the reduced system (fields 'Mr', 'Kr', 'w', 'gap'): K is not positive definite"),
    ("reduced", lambda f: {"Kr": f["Kr"] + np.triu(np.full((4, 4), f["Kr"].max()), 1)},
     "the reduced system (fields 'Mr', 'Kr', 'w', 'gap'): K is not symmetric"),
    ("reduced", lambda f: {"Mr": np.zeros((4, 4))}, "M is zero (all 4² entries 0), not positive definite"),
    ("reduced", lambda f: {"model/K/data": _with(f["model/K/data"], 3, np.nan)},
     "field 'model/K/data' must hold finite numbers"),
    ("reduced", lambda f: {"model/mesh/cells/triangle": _with(f["model/mesh/cells/triangle"], (0, 0), 10**6)},
     "field 'model/mesh/cells/triangle' must hold mesh nodes in 0..104"),
    ("massless", lambda f: {"Sr": f["Sr"] + np.triu(np.full(f["Sr"].shape, f["Sr"].max()), 1)},
     "Sr is not symmetric"),
    ("massless", lambda f: {"Sr": -f["Sr"]}, "Sr is not positive definite"),
    ("massless", lambda f: {"Mr": f["Mr"][:3, :3]}, "field 'Mr' must be 7 x 7 (one row and column per entry of 'w')"),
    ("massless", lambda f: {"closed_shape": f["closed_shape"][:5]},
     "field 'closed_shape' must have one entry per free dof of the model (200), got shape (5,)"),
    ("massless", lambda f: {"masses": _with(f["masses"], 0, -1.0)}, "field 'masses' must be >= 0, got -1.0"),
    ("massless", lambda f: {"basis": f["basis"][:, :2]}, "field 'basis' must be 200 x 7"),
]


@pytest.mark.parametrize("kind, edit, words", REDUCED_CASES)
def test_bad_reduced_files_are_refused_naming_the_field(tmp_path, strip, kind, edit, words):
    np.savez(tmp_path / "edited.npz", **_edited(_reduced_arrays(strip[kind]), edit))
    with pytest.raises(ValueError) as info:
        load_reduced(tmp_path / "edited.npz")
    assert words in str(info.value) and "edited.npz" in str(info.value), str(info.value)


def test_good_files_still_load(strip):
    assert load_reduced(strip["reduced"]).system.n == 4
    assert load_reduced(strip["massless"]).system.n == 7


def test_bad_reduced_file_on_the_command_line(tmp_path, strip, capsys):
    np.savez(tmp_path / "edited.npz",
             **_edited(_reduced_arrays(strip["reduced"]), lambda f: {"basis": f["basis"][:, :3]}))
    code, line = _run(["modes", strip["study"], "--reduced", tmp_path / "edited.npz", "-o", tmp_path / "m.json",
                       "--quiet", "--no-progress"], capsys)
    assert code == 2 and "edited.npz: field 'basis' must be 200 x 4" in line, line
