"""The Lagrange elements a space may use, P2 (the paper's) and P1, as records of their facts:
the one place where a caller asks what differs between them (docs/method.md, *P1 elements
and their estimator*).

An :class:`Element` holds the reference basis (values, gradients, on an edge), the number of
nodes per cell and per edge, the weights of the contact boundary (``m_z`` of the contact force
density (4.1) and ``w_z`` of the consistent pressure, per edge as fractions of its length),
the pieces ``γ̃_p`` of a contact edge that belong to each of its nodes (η6, η8), the VTK cell
type, and how a field of the element is read as a P2 field: a P1 field is the P2 field whose
midpoint values are the means of its vertex values (exact on affine cells), so every kernel
that evaluates a field (gradients, stresses, tractions, error norms) is written once, for P2
coefficients.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..mesh.reference import TRIANGLE
from . import p1, p2

__all__ = ["ELEMENTS", "Element", "P1", "P2", "element_of"]


@dataclass(frozen=True, eq=False)
class Element:
    """The facts of one Lagrange triangle.

    Attributes
    ----------
    name : str
        ``"P1"`` or ``"P2"``.
    n_local : int
        Nodes per cell (3 vertices, then for P2 the midpoints of local edges 0, 1, 2).
    n_edge : int
        Nodes per edge, ``[start, end]`` (P1) or ``[start, end, midpoint]`` (P2).
    basis, grad_basis : callables
        Reference values ``(q, n_local)`` and gradients ``(q, n_local, 2)`` at ``xi (q, 2)``.
    edge_basis : callable
        Values ``(q, n_edge)`` on an edge at ``t (q,)``.
    reference_nodes : (n_local, 2) float array
    hat_share, basis_share : tuples of n_edge floats
        ``∫_e φ_z ds / |e|`` (the hat of the contact force density s_z = Λ_z / m_z, (4.1):
        the half-edge hats of Q^h (3.6) for P2, the P1 hat for P1) and ``∫_e ψ_z ds / |e|``
        (the basis function, the consistent pressure's ``w_z``) of each edge node on a
        straight edge.
    hat_pieces : tuple of ``(lo, hi, column, (φ(0), φ'))``
        The pieces ``γ̃_p`` of [0, 1] that belong to each edge node (``column``), with the
        hat ``φ_p(t) = φ(0) + φ' t`` there (η6): the thirds for P2 (paper (4.12)), the halves
        for P1.
    node_parts : tuple of ``(lo, hi, column)``
        The same pieces without the hat (η8).
    vtk_cell : str
        meshio's cell type: ``"triangle6"`` or ``"triangle"``.
    """

    name: str
    n_local: int
    n_edge: int
    basis: Callable[[np.ndarray], np.ndarray]
    grad_basis: Callable[[np.ndarray], np.ndarray]
    edge_basis: Callable[[np.ndarray], np.ndarray]
    reference_nodes: np.ndarray
    hat_share: tuple[float, ...]
    basis_share: tuple[float, ...]
    hat_pieces: tuple
    node_parts: tuple
    vtk_cell: str

    def __repr__(self) -> str:
        return self.name

    @property
    def degree(self) -> int:
        """The polynomial degree k: 2 for P2, 1 for P1. The energy error of a smooth solution
        (and η_h with it) decays at best like ``h^k``, i.e. ``N_dof^{-k/2}`` in 2D."""
        return 2 if self.n_local == 6 else 1

    def cell_coefficients(self, u_cell: np.ndarray) -> np.ndarray:
        """The P2 coefficients ``(m, 12)`` of fields of this element with interleaved cell
        coefficients ``u_cell (m, 2 n_local)``: unchanged for P2; for P1 the vertex values,
        then each local edge's midpoint value, the mean of its two vertices'."""
        if self.n_local == 6:
            return u_cell
        u = np.asarray(u_cell, dtype=np.float64).reshape(-1, 3, 2)
        start, end = TRIANGLE.edges.T
        mid = 0.5 * (u[:, start] + u[:, end])
        return np.concatenate([u, mid], axis=1).reshape(-1, 12)

    def edge_values(self, values: np.ndarray) -> np.ndarray:
        """Per-edge nodal data ``(k, n_edge, ...)`` as ``(k, 3, ...)`` at ``[start, end,
        midpoint]``: unchanged for P2; for P1 the midpoint gets the mean of the ends (so the
        quadratic through the three is the linear interpolant)."""
        values = np.asarray(values, dtype=np.float64)
        if self.n_edge == 3:
            return values
        mid = 0.5 * (values[:, 0] + values[:, 1])
        return np.concatenate([values, mid[:, None]], axis=1)


#: P2: the half-edge hats of Q^h are linear on [0, 1/3] (start), [2/3, 1] (end) and on the two
#: halves of the middle third (midpoint), paper (3.6), (4.12)
P2 = Element(
    name="P2",
    n_local=6,
    n_edge=3,
    basis=p2.basis,
    grad_basis=p2.grad_basis,
    edge_basis=p2.edge_basis,
    reference_nodes=p2.REFERENCE_NODES,
    hat_share=(1 / 4, 1 / 4, 1 / 2),
    basis_share=(1 / 6, 1 / 6, 2 / 3),
    hat_pieces=(
        (0.0, 1 / 3, 0, (1.0, -2.0)),
        (2 / 3, 1.0, 1, (-1.0, 2.0)),
        (1 / 3, 0.5, 2, (0.0, 2.0)),
        (0.5, 2 / 3, 2, (2.0, -2.0)),
    ),
    node_parts=((0.0, 1 / 3, 0), (2 / 3, 1.0, 1), (1 / 3, 2 / 3, 2)),
    vtk_cell=TRIANGLE.vtk_p2_name,
)

#: P1: the hat φ_z is the basis function (m_z = w_z = |e|/2 per edge at a vertex), γ̃_p the
#: half of each contact edge next to p (Krause–Veeser–Walloth's choice for linear elements)
P1 = Element(
    name="P1",
    n_local=3,
    n_edge=2,
    basis=p1.basis,
    grad_basis=p1.grad_basis,
    edge_basis=p1.edge_basis,
    reference_nodes=p1.REFERENCE_NODES,
    hat_share=(1 / 2, 1 / 2),
    basis_share=(1 / 2, 1 / 2),
    hat_pieces=((0.0, 0.5, 0, (1.0, -1.0)), (0.5, 1.0, 1, (0.0, 1.0))),
    node_parts=((0.0, 0.5, 0), (0.5, 1.0, 1)),
    vtk_cell=TRIANGLE.vtk_name,
)

#: the elements by name
ELEMENTS: dict[str, Element] = {"P1": P1, "P2": P2}


def element_of(element: str | Element, argument: str = "element") -> Element:
    """The :class:`Element` named ``element`` (``"P1"`` or ``"P2"``, any case), or the element
    itself.

    Raises
    ------
    ValueError
        Naming ``argument`` and the choices, for anything else.
    """
    if isinstance(element, Element):
        return element
    key = element.upper() if isinstance(element, str) else None
    if key not in ELEMENTS:
        raise ValueError(f"{argument} must be one of {tuple(ELEMENTS)}, got {element!r}")
    return ELEMENTS[key]
