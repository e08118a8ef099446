"""The Lagrange elements a space may use, P2 (the paper's) and P1, as records of their facts:
the one place where a caller asks what differs between them (docs/method.md, *P1 elements
and their estimator*).

An :class:`Element` holds the cell's facts: its reference cell
(:data:`~signorini.mesh.reference.TRIANGLE`), the degree, the reference basis (values,
gradients), the number and reference coordinates of the nodes per cell, the VTK cell type,
and how a field of the element is read as a P2 field: a P1 field is the P2 field whose
midpoint values are the means of its vertex values (exact on affine cells), so every kernel
that evaluates a field (gradients, stresses, tractions, error norms) is written once, for P2
coefficients. What the boundary reads (the basis on a facet, the contact weights, the pieces
``γ̃_p``, nodal force → pressure) is the element's facet element, ``Element.facet``
(:class:`~signorini.fem.facet_element.FacetElement`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..mesh.reference import TETRAHEDRON, TRIANGLE, ReferenceCell
from . import p1, p2, p2_tet
from .facet_element import P1_INTERVAL, P2_INTERVAL, P2_TRIANGLE, FacetElement

__all__ = ["ELEMENTS", "ELEMENTS_ON", "Element", "FacetElement", "P1", "P2", "P2_TET", "element_of"]


@dataclass(frozen=True, eq=False)
class Element:
    """The facts of one Lagrange element on its reference cell.

    Attributes
    ----------
    name : str
        ``"P1"`` or ``"P2"``.
    degree : int
        The polynomial degree k: 2 for P2, 1 for P1. The energy error of a smooth solution
        (and η_h with it) decays at best like ``h^k``, i.e. ``N_dof^{-k/2}`` in 2D.
    reference : ReferenceCell
        The reference cell the element lives on (:data:`~signorini.mesh.reference.TRIANGLE`,
        or :data:`~signorini.mesh.reference.TETRAHEDRON` for :data:`P2_TET`).
    n_local : int
        Nodes per cell (the vertices, then for P2 the midpoints of the local edges in the
        order of ``reference.edges``).
    basis, grad_basis : callables
        Reference values ``(q, n_local)`` and gradients ``(q, n_local, dim)`` at ``xi (q,
        dim)``.
    reference_nodes : (n_local, dim) float array
    vtk_cell : str
        meshio's cell type: ``"triangle6"``, ``"triangle"`` or ``"tetra10"``.
    facet : FacetElement
        The element on a facet of the cell: its basis, nodes per facet, contact weights,
        pieces γ̃_p and nodal force → pressure.
    """

    name: str
    degree: int
    reference: ReferenceCell
    n_local: int
    basis: Callable[[np.ndarray], np.ndarray]
    grad_basis: Callable[[np.ndarray], np.ndarray]
    reference_nodes: np.ndarray
    vtk_cell: str
    facet: FacetElement

    def __repr__(self) -> str:
        return self.name

    def cell_coefficients(self, u_cell: np.ndarray) -> np.ndarray:
        """The P2 coefficients ``(m, n_components (n_vertices + n_edges))`` of fields of this
        element with interleaved cell coefficients ``u_cell (m, n_components n_local)``
        (``(m, 12)`` for a displacement on triangles): unchanged for P2; for P1 the vertex
        values, then each local edge's midpoint value (``reference.edges``), the mean of its
        two vertices'."""
        cell = self.reference
        n_p2 = cell.n_vertices + cell.n_edges
        if self.n_local == n_p2:
            return u_cell
        u = np.asarray(u_cell, dtype=np.float64)
        n_components = u.shape[-1] // self.n_local
        u = u.reshape(-1, cell.n_vertices, n_components)
        start, end = cell.edges.T
        mid = 0.5 * (u[:, start] + u[:, end])
        return np.concatenate([u, mid], axis=1).reshape(-1, n_p2 * n_components)


#: P2, the paper's element: vertex and edge-midpoint nodes, its facet element the P2 interval
P2 = Element(
    name="P2",
    degree=2,
    reference=TRIANGLE,
    n_local=6,
    basis=p2.basis,
    grad_basis=p2.grad_basis,
    reference_nodes=p2.REFERENCE_NODES,
    vtk_cell=TRIANGLE.vtk_p2_name,
    facet=P2_INTERVAL,
)

#: P1: vertex nodes, its facet element the P1 interval
P1 = Element(
    name="P1",
    degree=1,
    reference=TRIANGLE,
    n_local=3,
    basis=p1.basis,
    grad_basis=p1.grad_basis,
    reference_nodes=p1.REFERENCE_NODES,
    vtk_cell=TRIANGLE.vtk_name,
    facet=P1_INTERVAL,
)

#: P2 on the tetrahedron (VTK's tetra10: 4 vertices, then the midpoints of
#: ``TETRAHEDRON.edges``), its facet element the P2 triangle of a face
P2_TET = Element(
    name="P2",
    degree=2,
    reference=TETRAHEDRON,
    n_local=10,
    basis=p2_tet.basis,
    grad_basis=p2_tet.grad_basis,
    reference_nodes=p2_tet.REFERENCE_NODES,
    vtk_cell=TETRAHEDRON.vtk_p2_name,
    facet=P2_TRIANGLE,
)

#: the elements by name (on the triangle)
ELEMENTS: dict[str, Element] = {"P1": P1, "P2": P2}

#: the elements by reference cell, then name: one record per element *and* cell
ELEMENTS_ON: dict[str, dict[str, Element]] = {
    TRIANGLE.name: ELEMENTS,
    TETRAHEDRON.name: {"P2": P2_TET},
}


def element_of(
    element: str | Element, argument: str = "element", reference: ReferenceCell = TRIANGLE
) -> Element:
    """The :class:`Element` named ``element`` (``"P1"`` or ``"P2"``, any case) on the
    reference cell ``reference`` (a mesh's ``mesh.reference``; the triangle by default), or
    the element itself.

    Raises
    ------
    ValueError
        Naming ``argument`` and the choices, for anything else, and for an element given as a
        record that lives on another cell than ``reference``.
    """
    table = ELEMENTS_ON[reference.name]
    if isinstance(element, Element):
        if element.reference is not reference:
            raise ValueError(
                f"{argument} {element!r} lives on the {element.reference.name}, not on the "
                f"{reference.name}"
            )
        return element
    key = element.upper() if isinstance(element, str) else None
    if key not in table:
        on = "" if reference is TRIANGLE else f" on the {reference.name}"
        raise ValueError(f"{argument} must be one of {tuple(table)}{on}, got {element!r}")
    return table[key]
