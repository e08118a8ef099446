"""The linear Lagrange (P1) triangle, vectorized over points: the facts the P1 element adds
to the conventions of :mod:`signorini.fem.p2` (same reference triangle, barycentric
coordinates, interleaved vector DOFs ``2 * a + c``; 3 local nodes, the vertices).

A P1 field is a P2 field whose edge-midpoint values are the means of its vertex values: the
other kernels of the package (gradients, stresses, tractions, error norms) read P1 fields in
that form (:meth:`signorini.fem.element.Element.cell_coefficients`).
"""

from __future__ import annotations

import numpy as np

from .p2 import barycentric

__all__ = ["REFERENCE_NODES", "basis", "basis_barycentric", "edge_basis", "grad_basis"]

#: Reference coordinates of the 3 local nodes, shape (3, 2).
REFERENCE_NODES = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
REFERENCE_NODES.setflags(write=False)

_GRAD_L = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])


def basis_barycentric(bary: np.ndarray) -> np.ndarray:
    """Values ``(..., 3)`` of the 3 P1 basis functions: the barycentric coordinates."""
    return np.array(bary, dtype=np.float64)


def basis(xi: np.ndarray) -> np.ndarray:
    """Values ``(q, 3)`` of the 3 reference P1 basis functions at ``xi (q, 2)``."""
    return barycentric(xi)


def grad_basis(xi: np.ndarray) -> np.ndarray:
    """Reference gradients ``(q, 3, 2)`` of the 3 P1 basis functions (constant)."""
    q = np.atleast_2d(np.asarray(xi, dtype=np.float64)).shape[0]
    return np.broadcast_to(_GRAD_L, (q, 3, 2)).copy()


def edge_basis(t: np.ndarray) -> np.ndarray:
    """P1 basis ``(q, 2)`` on an edge in the node order (start, end): ``1 - t``, ``t``."""
    t = np.asarray(t, dtype=np.float64)
    return np.column_stack([1.0 - t, t])
