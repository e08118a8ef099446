"""CSR helpers (signorini.algebra.sparse)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from linalg_problems import block_spd

from signorini.algebra.sparse import (
    abs_matvec,
    as_csr,
    csr_row_indices,
    diagonal_positions,
    list_indices,
    symmetry_defect,
    upper_positions,
)


def test_upper_positions_gather_the_upper_triangle():
    rng = np.random.default_rng(3)
    A = block_spd(4, 3, rng)
    A.data[::7] = 0.0  # explicit zeros are positions too
    positions, indptr = upper_positions(A)
    U = sp.csr_matrix((A.data[positions], A.indices[positions], indptr), shape=A.shape)
    assert np.array_equal(U.toarray(), np.triu(A.toarray()))
    assert positions.dtype == np.int32 and indptr[-1] == positions.size
    rows = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))
    assert positions.size == np.count_nonzero(A.indices >= rows) > U.count_nonzero()


def test_row_indices_and_diagonal_positions():
    A = sp.csr_matrix(np.array([[1.0, 2.0, 0.0], [2.0, 0.0, 3.0], [0.0, 3.0, 4.0]]))
    rows = csr_row_indices(A)
    assert np.array_equal(rows, [0, 0, 1, 1, 2, 2])
    assert np.array_equal(diagonal_positions(A, rows), [0, -1, 5])  # row 1 stores no diagonal


def test_as_csr_returns_canonical_csr_without_copy():
    A = sp.csr_matrix(np.array([[2.0, 1.0], [1.0, 2.0]]))
    assert as_csr(A) is A
    coo = sp.coo_matrix(([1.0, 2.0, 3.0], ([0, 0, 1], [1, 1, 0])), shape=(2, 2))
    B = as_csr(coo)  # duplicates summed, integer-free float64
    assert isinstance(B, sp.csr_matrix) and B.has_canonical_format
    assert np.array_equal(B.toarray(), [[0.0, 3.0], [3.0, 0.0]])
    assert as_csr(sp.csr_matrix(np.eye(2, dtype=np.int64))).dtype == np.float64


@pytest.mark.parametrize(
    "matrix,message",
    [
        (np.eye(3), "M must be a scipy sparse matrix, got ndarray"),
        (sp.csr_matrix(np.ones((2, 3))), r"M must be square, got shape \(2, 3\)"),
        (sp.csr_matrix(np.eye(2, dtype=complex)), "M must have real values"),
        (sp.csr_matrix(np.array([[np.inf, 0.0], [0.0, 1.0]])), "M has non-finite"),
    ],
)
def test_as_csr_rejects(matrix, message):
    with pytest.raises(ValueError, match=message):
        as_csr(matrix, "M")


def test_symmetry_defect_and_index_lists():
    A = sp.csr_matrix(np.array([[4.0, 1.0], [1.5, 2.0]]))
    assert symmetry_defect(A) == pytest.approx(0.5 / 4.0, rel=1e-15)
    assert symmetry_defect(sp.csr_matrix((3, 3))) == 0.0
    assert list_indices(np.arange(3)) == "0, 1, 2"
    assert list_indices(np.arange(8)) == "0, 1, 2, 3, 4 (and 3 more)"


@pytest.mark.parametrize(
    ("n", "density", "chunk"),
    [(1000, 0.01, 37), (500, 0.05, 1 << 20), (300, 0.0, 10), (200, 0.3, 5)],
)
def test_abs_matvec_equals_the_product_of_absolute_values(n, density, chunk):
    """Blocks smaller than a row, larger than the matrix, and an empty matrix."""
    A = sp.random(n, n, density, format="csr", random_state=1)
    A.data -= 0.5
    v = np.random.default_rng(0).standard_normal(n)
    expected = abs(A) @ np.abs(v)
    assert np.abs(abs_matvec(A, v, chunk=chunk) - expected).max(initial=0.0) <= 1e-13 * max(
        np.abs(expected).max(initial=0.0), 1.0
    )
