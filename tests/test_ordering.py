"""METIS's nested-dissection ordering of CHOLMOD's factorisation (bladecase.ordering): a permutation that keeps
each node's dofs together, the same solutions as CHOLMOD's own AMD ordering, and less fill on a solid model."""

import numpy as np
import pytest
import scipy.sparse as sp
from skfem import MeshTet

from bladecase import linalg, ordering
from bladecase.fe import Mesh, assemble

pytest.importorskip("pymetis")
pytest.importorskip("cvxopt")


@pytest.fixture(scope="module")
def block():
    """A clamped steel block of linear tetrahedra, 12 × 12 × 12 cells: 6084 free dofs."""
    t = MeshTet.init_tensor(*3 * [np.linspace(0.0, 0.1, 13)])
    mesh = Mesh(t.p.T.copy(), {"tetra": t.t.T.copy()}, dim=3, groups={"root": np.flatnonzero(t.p[0] == 0)})
    return assemble(mesh, "steel", order=1)


def test_supervariables_are_the_nodes(block):
    labels = ordering.supervariables(block.K)
    node = block.dofs.node
    assert labels.max() + 1 == np.unique(node).size
    # one label per node, one node per label
    assert np.all(np.diff(labels[np.argsort(node, kind="stable")])[np.diff(np.sort(node)) == 0] == 0)
    assert np.unique(np.column_stack([labels, node]), axis=0).shape[0] == np.unique(node).size


def test_ordering_is_a_permutation_keeping_nodes_together(block):
    p = ordering.nested_dissection(block.K, min_size=0)
    n = block.K.shape[0]
    assert np.array_equal(np.sort(p), np.arange(n))
    node = block.dofs.node[p]
    starts = np.flatnonzero(np.r_[True, node[1:] != node[:-1]])
    assert starts.size == np.unique(node).size  # each node's dofs contiguous in the ordering
    assert ordering.nested_dissection(block.K) is None  # below MIN_SIZE: CHOLMOD's AMD


def test_metis_same_solution_less_fill(block, monkeypatch):
    b = np.random.default_rng(0).standard_normal(block.K.shape[0])
    monkeypatch.setenv(linalg.BACKEND_ENV, "cvxopt")
    amd = linalg.spd_factor(block.K, "K")
    monkeypatch.setattr(ordering, "MIN_SIZE", 0)
    nd = linalg.spd_factor(block.K, "K")
    x_amd, x_nd = amd.solve(b), nd.solve(b)
    fill_amd, fill_nd = amd.fill, nd.fill
    assert np.linalg.norm(x_nd - x_amd) <= 1e-10 * np.linalg.norm(x_amd)
    assert np.linalg.norm(block.K @ x_nd - b) <= 1e-10 * np.linalg.norm(b)
    assert fill_nd < 0.9 * fill_amd  # a 3-D solid: nested dissection leaves less fill
    L, d, perm = nd.ldlt()  # the factors hand out the METIS permutation: Pᵀ K P = L D Lᵀ
    p = np.argsort(perm)  # (Pᵀx)[perm] = x: Pᵀ K P = K[p][:, p]
    Kp = sp.csr_array(block.K)[p][:, p]
    x = np.random.default_rng(1).standard_normal(Kp.shape[0])
    assert np.linalg.norm(Kp @ x - L @ (d * (L.T @ x))) <= 1e-12 * np.linalg.norm(Kp @ x)


def test_without_pymetis_amd(block, monkeypatch):
    import builtins

    real = builtins.__import__

    def no_metis(name, *args, **kwargs):
        if name == "pymetis":
            raise ImportError(name)
        return real(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_metis)
    assert ordering.nested_dissection(sp.csr_array(block.K), min_size=0) is None
