"""The linear Lagrange (P1) triangle, vectorized over points: the facts the P1 element adds
to the conventions of :mod:`signorini.fem.p2` (same reference triangle, barycentric
coordinates and their gradients, interleaved vector DOFs ``2 * a + c``; 3 local nodes, the
vertices). Its basis is the barycentric coordinates, so p2 states them (and their gradients,
:data:`~signorini.fem.p2.GRAD_BARYCENTRIC`) once and P1 reads them; the facts of P1 on an
edge are :data:`signorini.fem.facet_element.P1_INTERVAL`'s.

A P1 field is a P2 field whose edge-midpoint values are the means of its vertex values: the
other kernels of the package (gradients, stresses, tractions, error norms) read P1 fields in
that form (:meth:`signorini.fem.element.Element.cell_coefficients`).
"""

from __future__ import annotations

import numpy as np

from .p2 import GRAD_BARYCENTRIC, barycentric
from .p2 import REFERENCE_NODES as _P2_NODES

__all__ = ["REFERENCE_NODES", "basis", "basis_barycentric", "edge_basis", "grad_basis"]

#: Reference coordinates of the 3 local nodes, shape (3, 2): the vertices, the first three
#: of the P2 nodes (read-only).
REFERENCE_NODES = _P2_NODES[:3]


def basis_barycentric(bary: np.ndarray) -> np.ndarray:
    """Values ``(..., 3)`` of the 3 P1 basis functions: the barycentric coordinates."""
    return np.array(bary, dtype=np.float64)


def basis(xi: np.ndarray) -> np.ndarray:
    """Values ``(q, 3)`` of the 3 reference P1 basis functions at ``xi (q, 2)``."""
    return barycentric(xi)


def grad_basis(xi: np.ndarray) -> np.ndarray:
    """Reference gradients ``(q, 3, 2)`` of the 3 P1 basis functions (constant): those of the
    barycentric coordinates, :data:`~signorini.fem.p2.GRAD_BARYCENTRIC`."""
    q = np.atleast_2d(np.asarray(xi, dtype=np.float64)).shape[0]
    return np.broadcast_to(GRAD_BARYCENTRIC, (q, 3, 2)).copy()


def edge_basis(t: np.ndarray) -> np.ndarray:
    """P1 basis ``(q, 2)`` on an edge in the node order (start, end): ``1 - t``, ``t``."""
    t = np.asarray(t, dtype=np.float64)
    return np.column_stack([1.0 - t, t])
