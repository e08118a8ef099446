"""CSR helpers (signorini.algebra.sparse)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from linalg_problems import block_spd, p2_elasticity

from signorini.algebra.sparse import (
    abs_matvec,
    as_csr,
    block_upper_positions,
    csr_row_indices,
    diagonal_positions,
    in_node_blocks,
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


def test_block_upper_positions_gather_the_upper_block_triangle():
    """On a P2 stiffness matrix (λ ≠ μ: off-diagonal node blocks are not symmetric) the
    positions give each upper block (w ≥ z) row by row, in BSR form; explicit zeros count."""
    A, _ = p2_elasticity(4, 3, lam=2.0, mu=0.5)
    A.data[::7] = 0.0
    positions, indptr, columns = block_upper_positions(A)
    n = A.shape[0]
    B = sp.bsr_matrix((A.data[positions].reshape(-1, 2, 2), columns, indptr), shape=A.shape)
    upper_blocks = np.kron(np.triu(np.ones((n // 2, n // 2))), np.ones((2, 2)))
    assert np.array_equal(B.toarray(), A.toarray() * upper_blocks)
    rows = np.repeat(np.arange(n), np.diff(A.indptr))
    assert columns.size == np.count_nonzero(A.indices >= rows - rows % 2) // 4
    assert positions.dtype == np.int32 and indptr[-1] == columns.size
    off = np.flatnonzero(np.repeat(np.arange(n // 2), np.diff(indptr)) != columns)
    block = A.data[positions].reshape(-1, 2, 2)[off]
    assert np.abs(block - block.transpose(0, 2, 1)).max() > 0.1  # the test can tell the layout


def test_block_upper_positions_refuse_what_is_not_in_2x2_blocks():
    A, _ = p2_elasticity(3, 2)
    assert block_upper_positions(A) is not None
    assert block_upper_positions(sp.identity(5, format="csr")) is None  # odd size
    assert block_upper_positions(sp.identity(4, format="csr")) is None  # half blocks
    C = A.tocoo()
    one = np.flatnonzero((C.row == 2) & (C.col == 5))  # drop one entry of a block
    D = sp.csr_matrix(
        (np.delete(C.data, one), (np.delete(C.row, one), np.delete(C.col, one))), shape=A.shape
    )
    assert block_upper_positions(D) is None
    # rows 2z and 2z + 1 with different node columns (each in column pairs)
    E = sp.csr_matrix(np.kron(np.eye(2), np.ones((2, 2))))
    F = sp.csr_matrix(
        ([1.0, 1.0, 1.0, 1.0, 1.0, 1.0], [0, 1, 2, 3, 2, 3], [0, 2, 4, 6]), shape=(3, 4)
    )
    G = sp.vstack([F, sp.csr_matrix(([1.0, 1.0], [2, 3], [0, 2]), shape=(1, 4))]).tocsr()
    assert block_upper_positions(E) is not None and block_upper_positions(G) is None


def test_in_node_blocks_judges_one_process_rows():
    """A process's rows of a node-blocked matrix (global columns) are in blocks when they
    start at a node's first row; rows split inside a node, or a scalar pattern, are not."""
    A, _ = p2_elasticity(4, 3)
    for lo, hi, expected in ((10, 30, True), (0, A.shape[0], True), (11, 31, False)):
        first, last = A.indptr[lo], A.indptr[hi]
        indptr = A.indptr[lo : hi + 1] - first
        assert in_node_blocks(indptr, A.indices[first:last]) is expected, (lo, hi)
    L = sp.diags([np.ones(7), np.ones(8), np.ones(7)], [-1, 0, 1], format="csr")
    assert not in_node_blocks(L.indptr, L.indices)


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
