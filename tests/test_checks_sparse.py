"""The matrix checks take a sparse matrix in any scipy format (a diagonal ``dia_array`` included), never densified."""

import numpy as np
import pytest
import scipy.sparse as sp

from bladecase.checks import symmetric


@pytest.mark.parametrize("fmt", ["csr", "csc", "coo", "dia", "lil", "dok"])
def test_symmetric_takes_every_sparse_format(fmt):
    symmetric("M", sp.diags_array(np.arange(1.0, 5.0)).asformat(fmt))
    a = sp.csr_array(np.array([[2.0, 1.0], [0.0, 2.0]])).asformat(fmt)
    with pytest.raises(ValueError, match=r"^M is not symmetric: max\|M - Mᵀ\| = 1 exceeds 1e-10 \* max\|M\| = 2e-10$"):
        symmetric("M", a)
