"""Products of a batch of rows by a small matrix that round each row the same whatever rows
stand beside it.

``np.matmul`` hands a product ``(m, s) @ (s, n)`` to the BLAS, whose kernels sum the ``s``
terms of an entry in an order (with fused multiply-adds or not) that depends on the kernel the
library picked for the CPU, on the threads it splits ``m`` over, and on where the row falls in
the kernel's tiles of rows: the same row is rounded differently in a batch of another size
(measured with OpenBLAS's Haswell, SkylakeX and Zen kernels; its Sandybridge kernel happens to
agree). Where a result must be the same bit for bit whatever rows are computed beside it — a
rank's rows of the stiffness matrix against the serial ones (docs/parallel.md, *What is
distributed*) — :func:`rows_times` forms it with ``np.einsum`` instead, which calls no BLAS
(``optimize=False``): NumPy's own loop adds ``a[i, k] b[k, :]`` into row ``i`` for ``k = 0 …
s - 1`` in turn, the inner loop running along the ``n`` columns, so row ``i`` depends on
``a[i]`` and ``b`` alone, for any ``m``. ``tests/fem/test_fixed_order.py`` checks this on
subsets of rows of every size that the assembly meets, a single row included.

Its speed is the BLAS product's at the element stiffness's shapes (10 or 70 factors, 144
entries): docs/parallel.md, *What is distributed*.
"""

from __future__ import annotations

import numpy as np

__all__ = ["rows_times"]


def rows_times(a: np.ndarray, b: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """``a @ b`` for ``a (m, s)`` and ``b (s, n)`` without the BLAS: row ``i`` of the result
    depends on ``a[i]`` and ``b`` only, bit for bit, whatever ``m`` and the other rows.

    Parameters
    ----------
    a : (m, s) float64 array
    b : (s, n) float64 array
    out : (m, n) float64 array, optional
        Receives the result (it must not overlap ``a`` or ``b``).

    Returns
    -------
    (m, n) float64 array
    """
    return np.einsum("ms,sn->mn", a, b, out=out, optimize=False)
