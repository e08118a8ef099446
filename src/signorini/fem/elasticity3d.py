"""3D elasticity on P2 tetrahedra besides the stiffness matrix: body forces and face
tractions, stresses and von Mises at points, and the energy, L² and H¹ error norms against a
known solution (docs/method.md, *Three dimensions*).

Every integral is written once against the groups of :mod:`signorini.fem.mapping3d` (the
geometry decides affine or isoparametric) and summed into interleaved DOFs ``3 node + c``
with ``np.bincount``. User functions take points ``x (..., 3)`` and return ``(..., 3)``
(a displacement, force density or traction) or ``(..., 3, 3)`` (a gradient,
``[..., i, j] = ∂u_i/∂x_j``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from .dofs import node_dofs
from .material import CellMaterials, Material, lame_parameters, on_cells, stress, von_mises
from .p2_tet import REFERENCE_NODES, basis, face_basis
from .quadrature import tetrahedron_rule, triangle_rule

if TYPE_CHECKING:
    from .space3d import P2TetSpace

__all__ = [
    "assemble_body_force_3d",
    "assemble_face_load_3d",
    "cell_stress_3d",
    "energy_error2_3d",
    "h1_seminorm_error2_3d",
    "l2_error2_3d",
    "nodal_stress_3d",
    "stress_divergence_3d",
    "von_mises_3d",
]

Field = Callable[[np.ndarray], np.ndarray]

#: the default rule for loads and errors: degree 4 (14 points), exact for f·φ with f quadratic
LOAD_DEGREE = 4


def _summed(dofs: np.ndarray, values: np.ndarray, n_dofs: int) -> np.ndarray:
    """``(n_dofs,)`` the sums of ``values`` over their DOFs (``np.bincount``)."""
    return np.bincount(dofs.ravel(), weights=values.ravel(), minlength=n_dofs)


def assemble_body_force_3d(space: P2TetSpace, f: Field, degree: int = LOAD_DEGREE) -> np.ndarray:
    """The load vector ``F[3 z + i] = ∫_Ω f_i φ_z dx`` of a body force density ``f``.

    Parameters
    ----------
    space : P2TetSpace
    f : callable
        ``f(x (..., 3)) -> (..., 3)``.
    degree : int
        The degree of the rule on the tetrahedron (:func:`~signorini.fem.quadrature.
        tetrahedron_rule`).

    Returns
    -------
    (n_dofs,) float array
    """
    xi, w = tetrahedron_rule(degree)
    phi = basis(xi)  # (q, 10)
    F = np.zeros(space.n_dofs)
    for g in space.mapping.groups:  # a loop over the (at most two) geometries
        fx = np.asarray(f(g.points(xi)), dtype=np.float64)  # (m, q, 3)
        local = np.einsum("mq,mqi,qa->mai", g.measure(w, xi), fx, phi)
        F += _summed(space.cell_dofs[g.cells], local, space.n_dofs)
    return F


def assemble_face_load_3d(
    space: P2TetSpace, facet_index: np.ndarray, g: Field, degree: int = LOAD_DEGREE
) -> np.ndarray:
    """The load vector ``G[3 z + i] = ∫_Γ g_i φ_z ds`` of a traction ``g`` on boundary faces
    (Neumann data).

    Parameters
    ----------
    space : P2TetSpace
    facet_index : (k,) int array
        Boundary faces (``mesh.part_facets(name)``).
    g : callable
        ``g(x (..., 3)) -> (..., 3)``, or ``g(x, n)`` with the outward unit normals ``n``
        broadcast to ``x`` if it takes two arguments (a pressure ``-p n``).
    degree : int
        The degree of the rule on the reference triangle.

    Returns
    -------
    (n_dofs,) float array
    """
    facet_index = np.asarray(facet_index, dtype=np.int64)
    s, w = triangle_rule(degree)
    psi = face_basis(s)  # (q, 6)
    dofs = node_dofs(space.facet_nodes(facet_index), 3).reshape(len(facet_index), 18)
    G = np.zeros(space.n_dofs)
    for rows, faces in space.boundary_facets(facet_index):
        x = faces.points(s)
        try:
            gx = g(x, np.broadcast_to(faces.normals(s), x.shape))
        except TypeError:
            gx = g(x)
        weight = faces.speeds(s) * w  # (k, q)
        local = np.einsum("kq,kqi,qa->kai", weight, np.asarray(gx, dtype=np.float64), psi)
        G += _summed(dofs[rows], local, space.n_dofs)
    return G


def cell_stress_3d(
    space: P2TetSpace, material: Material | CellMaterials, u: np.ndarray, xi: np.ndarray
) -> np.ndarray:
    """Stresses ``σ(u_h) (n_cells, q, 3, 3)`` of the field with nodal values ``u (n_nodes,
    3)`` at the reference points ``xi (q, 3)`` of every cell (Hooke's law in 3D)."""
    u_cell = space.cell_values(u)
    out = np.empty((space.mesh.n_cells, len(np.atleast_2d(xi)), 3, 3))
    for g in space.mapping.groups:
        grad = g.field_gradients(u_cell[g.cells], xi)
        out[g.cells] = stress(on_cells(material, g.cells), grad)
    return out


def nodal_stress_3d(
    space: P2TetSpace, material: Material | CellMaterials, u: np.ndarray
) -> np.ndarray:
    """``(n_nodes, 3, 3)`` σ(u_h) at the P2 nodes, each the mean of the values of the cells
    that share the node (:func:`cell_stress_3d` at the reference nodes; exact where σ is
    continuous and of degree ≤ 1), as 2D's :func:`~signorini.fem.postprocess.nodal_stress`."""
    sigma = cell_stress_3d(space, material, u, REFERENCE_NODES).reshape(-1, 9)
    nodes = space.cell_nodes.ravel()
    count = np.bincount(nodes, minlength=space.n_nodes)
    total = np.stack(
        [np.bincount(nodes, weights=sigma[:, k], minlength=space.n_nodes) for k in range(9)],
        axis=1,
    )  # a loop over the nine components
    return (total / np.maximum(count, 1)[:, None]).reshape(-1, 3, 3)


def stress_divergence_3d(hess: np.ndarray, material: Material | CellMaterials) -> np.ndarray:
    """``div σ(u) (m, ..., 3)`` from the Hessians ``hess (m, ..., 3, 3, 3)``,
    ``[..., i, j, k] = ∂_j ∂_k u_i`` (e.g. :meth:`~signorini.fem.mapping3d.AffineTetrahedra.
    field_hessians`): ``μ Δu_i + (λ + μ) ∂_i div u`` (the 3D law; a
    :class:`~signorini.fem.material.CellMaterials` of the leading axis' cells)."""
    lam, mu = lame_parameters(material, 3)
    laplace = np.einsum("...ijj->...i", hess)
    grad_div = np.einsum("...jji->...i", hess)
    shape = (-1,) + (1,) * (laplace.ndim - 1)
    lam = np.reshape(lam, shape) if np.ndim(lam) else lam
    mu = np.reshape(mu, shape) if np.ndim(mu) else mu
    return mu * laplace + (lam + mu) * grad_div


def von_mises_3d(
    space: P2TetSpace, material: Material | CellMaterials, u: np.ndarray, xi: np.ndarray
) -> np.ndarray:
    """The von Mises stress ``(n_cells, q)`` of :func:`cell_stress_3d`."""
    return von_mises(cell_stress_3d(space, material, u, xi))


def _integrated(space, density: Callable, degree: int) -> float:
    """``Σ_cells ∫ density(group, x, xi)`` with the degree-``degree`` rule, ``x`` the images
    ``(m, q, 3)`` of the rule's points ``xi`` in the group's cells."""
    xi, w = tetrahedron_rule(degree)
    total = 0.0
    for g in space.mapping.groups:
        total += float(np.sum(g.measure(w, xi) * density(g, g.points(xi), xi)))
    return total


def energy_error2_3d(
    space: P2TetSpace,
    u: np.ndarray,
    grad_exact: Field,
    material: Material | CellMaterials,
    degree: int = LOAD_DEGREE,
) -> float:
    """``‖u − u_h‖²_E = a(u − u_h, u − u_h)``, ``a(v, v) = ∫ 2 μ ε(v):ε(v) + λ (div v)²``.

    Parameters
    ----------
    space : P2TetSpace
    u : (n_nodes, 3) float array
        The discrete solution's nodal values.
    grad_exact : callable
        ``∇u(x (..., 3)) -> (..., 3, 3)``.
    material : Material or CellMaterials
    degree : int
    """
    u_cell = space.cell_values(u)

    def density(g, x, xi):
        lam, mu = lame_parameters(on_cells(material, g.cells), 3)
        e = grad_exact(x) - g.field_gradients(u_cell[g.cells], xi)
        eps = 0.5 * (e + np.swapaxes(e, -1, -2))
        lam, mu = (np.reshape(v, (-1, 1)) if np.ndim(v) else v for v in (lam, mu))
        return (
            2.0 * mu * np.einsum("mqij,mqij->mq", eps, eps)
            + lam * np.trace(eps, axis1=-2, axis2=-1) ** 2
        )

    return _integrated(space, density, degree)


def h1_seminorm_error2_3d(
    space: P2TetSpace, u: np.ndarray, grad_exact: Field, degree: int = LOAD_DEGREE
) -> float:
    """``|u − u_h|²_{H¹} = ∫ |∇(u − u_h)|²`` (Frobenius), arguments as
    :func:`energy_error2_3d`."""
    u_cell = space.cell_values(u)

    def density(g, x, xi):
        e = grad_exact(x) - g.field_gradients(u_cell[g.cells], xi)
        return np.einsum("mqij,mqij->mq", e, e)

    return _integrated(space, density, degree)


def l2_error2_3d(
    space: P2TetSpace, u: np.ndarray, u_exact: Field, degree: int = LOAD_DEGREE
) -> float:
    """``‖u − u_h‖²_{L²}`` against ``u_exact(x (..., 3)) -> (..., 3)``."""
    u_cell = space.cell_values(u)

    def density(g, x, xi):
        e = u_exact(x) - g.field_values(u_cell[g.cells], xi)
        return np.einsum("mqi,mqi->mq", e, e)

    return _integrated(space, density, degree)
