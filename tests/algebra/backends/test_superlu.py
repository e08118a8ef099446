"""SuperLU backend specifics (signorini.algebra.backends.superlu)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from linalg_problems import block_spd

from signorini.algebra import FactorizationError
from signorini.algebra.backends.superlu import SuperLULUSolver, SuperLUSolver


def test_pivot_check_is_what_rejects_an_indefinite_matrix():
    # diag(2, -1, 3): SuperLU factorizes it without complaint (as LU, which has no pivot
    # check); only the SPD solver's pivot check sees the negative pivot, and reports the equation
    A = sp.diags([2.0, -1.0, 3.0]).tocsr()
    unchecked = SuperLULUSolver(A)
    assert np.allclose(unchecked.solve(np.ones(3)), [0.5, -1.0, 1 / 3], rtol=1e-15)
    with pytest.raises(FactorizationError, match="not positive definite") as info:
        SuperLUSolver(A)
    assert (info.value.backend, info.value.equation) == ("scipy", 1)


def test_every_factorization_is_a_full_one():
    rng = np.random.default_rng(1)
    A = block_spd(6, 6, rng)
    solver = SuperLUSolver(A)
    solver.factorize(2.0 * A)  # same pattern: counted as one analysis, nothing reused
    assert not solver.reuses_analysis
    assert (solver.n_analyses, solver.n_factorizations) == (1, 2)
    b = rng.standard_normal(A.shape[0])
    assert np.allclose(2.0 * (A @ solver.solve(b)), b, rtol=0, atol=1e-10 * np.abs(b).max())
