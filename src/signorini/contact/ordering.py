"""The fill-reducing ordering of one mesh's unknowns (docs/method.md, *Ordering of the
unknowns*), and the solvers that use it.

PARDISO's own analysis runs METIS on the graph of the whole P2 stiffness matrix: 3.1 s of a
complete direct solve of 4.5 s at 1.2 M unknowns of Example 6.2. Here METIS orders the
mesh's *vertex* graph (an eighth of the unknowns, a fiftieth of the matrix's entries) and
:meth:`~signorini.fem.space.P2Space.dof_order` extends that order to the P2 DOFs; PARDISO
then only does its symbolic factorization. Measured there (``python benchmarks/ordering.py``):
ordering 0.37 s, analysis 0.98 s, a factor with 0.92 times the non-zeros and 0.81 times the
operations; the complete solve 0.57 times PARDISO's own.

:func:`ordered_solver` is where the contact layer turns the ``solver`` argument of
:func:`~signorini.contact.solve` into the solver of one mesh's systems: a factory is asked
for a new one, offered this ordering (computed only if the backend takes it); a solver
object is used as it is.
"""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager, nullcontext

import numpy as np
import scipy.sparse as sp

from ..algebra.backends import make_solver
from ..algebra.pardiso import metis_ordering
from ..algebra.solvers import SolverFactory, SPDSolver
from ..fem.space import LagrangeSpace
from ..mesh.mesh import Mesh

__all__ = ["dof_ordering", "ordered_solver", "vertex_graph"]


def vertex_graph(mesh: Mesh) -> sp.csr_matrix:
    """``(n_points, n_points)`` adjacency of the mesh's vertices: an entry per edge, both
    ways (no diagonal)."""
    e = mesh.edges
    n = mesh.n_points
    rows = np.concatenate([e[:, 0], e[:, 1]])
    cols = np.concatenate([e[:, 1], e[:, 0]])
    return sp.csr_matrix((np.ones(rows.size), (rows, cols)), shape=(n, n))


def _with_coupling(graph: sp.csr_matrix, mesh: Mesh, coupling: sp.spmatrix) -> sp.csr_matrix:
    """``graph`` with an edge between the vertices of every pair of P2 nodes that
    ``coupling`` (``n_nodes × n_nodes``, e.g. a mortar transfer) joins; an edge midpoint
    node stands for its edge's first vertex."""
    c = sp.coo_matrix(coupling)
    vertex = np.concatenate([np.arange(mesh.n_points), mesh.edges[:, 0]])
    rows, cols = vertex[c.row], vertex[c.col]
    extra = sp.csr_matrix(
        (np.ones(2 * rows.size), (np.concatenate([rows, cols]), np.concatenate([cols, rows]))),
        shape=graph.shape,
    )
    return (graph + extra).tocsr()


def dof_ordering(space: LagrangeSpace, coupling: sp.spmatrix | None = None) -> np.ndarray:
    """A nested dissection ordering of the space's DOFs: METIS on the vertex graph
    (:func:`~signorini.algebra.pardiso.metis_ordering`), with the node pairs ``coupling``
    joins (a contact pair's mortar transfer, docs/method.md, *Two bodies*), extended to the
    edge nodes by :meth:`~signorini.fem.space.P2Space.dof_order`.

    Raises
    ------
    signorini.algebra.BackendUnavailableError
        If MKL (which provides METIS here) cannot be loaded.
    """
    graph = vertex_graph(space.mesh)
    if coupling is not None:
        graph = _with_coupling(graph, space.mesh, coupling)
    return space.dof_order(metis_ordering(graph))


def ordered_solver(
    space: LagrangeSpace,
    solver: SPDSolver | SolverFactory | None = None,
    *,
    symmetric: bool = True,
    check_symmetry: bool = True,
    coupling: sp.spmatrix | None = None,
    rigid_modes: Callable[[], np.ndarray] | None = None,
) -> AbstractContextManager[SPDSolver]:
    """The solver of ``space``'s systems, as a context manager.

    Parameters
    ----------
    space : LagrangeSpace
    solver : SPDSolver or SolverFactory, optional
        A factory (default :func:`~signorini.algebra.auto_solver`) makes a new solver,
        offered :func:`dof_ordering` (PARDISO takes it; SuperLU keeps its own minimum degree
        ordering), and closed at the end of the ``with`` block. An :class:`SPDSolver` is used
        as it is and not closed: its owner closes it.
    symmetric, check_symmetry : bool
        What the factory is asked for (:class:`~signorini.algebra.SolverRequest`).
    coupling : (n_nodes, n_nodes) sparse matrix, optional
        Node pairs the system joins beyond the mesh's edges (a contact pair's mortar
        transfer), for the ordering.
    rigid_modes : callable () -> (n, k) float array, optional
        The rigid motions in the system's unknowns, offered to the factory
        (:attr:`~signorini.algebra.SolverRequest.rigid_modes`; an algebraic multigrid's
        near-nullspace, :func:`~.rigid_modes.system_rigid_modes`).
    """
    if isinstance(solver, SPDSolver):
        return nullcontext(solver)
    return make_solver(
        solver,
        symmetric=symmetric,
        check_symmetry=check_symmetry,
        ordering=lambda: dof_ordering(space, coupling),
        rigid_modes=rigid_modes,
    )
