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

:class:`Ordering` computes the ordering once per system. :func:`~.system.assemble` starts it
in a background thread (``prefetch_ordering``) when the solver will take it
(:func:`~signorini.algebra.backends.selection.takes_ordering`): METIS runs in PARDISO's analysis
through ``ctypes``, which releases the interpreter, so it takes the second core while the
stiffness matrix is assembled on the first (docs/method.md, *Ordering of the unknowns*).
:class:`SolverAhead` makes the solver of the system as soon as the matrix's pattern is known
and starts its symbolic analysis there too, beside the rest of the assembly.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Future
from contextlib import AbstractContextManager, nullcontext

import numpy as np
import scipy.sparse as sp

from ..algebra.backends.beside import beside
from ..algebra.backends.pardiso import metis_ordering
from ..algebra.backends.selection import make_solver
from ..algebra.backends.solvers import SolverFactory, SolverRequest, SPDSolver
from ..fem.space import LagrangeSpace
from ..mesh.mesh import Mesh
from .contact_set import ContactSet

__all__ = ["Ordering", "SolverAhead", "dof_ordering", "ordered_solver", "vertex_graph"]


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


def ordering_graph(mesh: Mesh, coupling: sp.spmatrix | None = None) -> sp.csr_matrix:
    """The graph :func:`dof_ordering` orders: the mesh's vertex graph, joined along the node
    pairs of ``coupling``."""
    graph = vertex_graph(mesh)
    return graph if coupling is None else _with_coupling(graph, mesh, coupling)


def dof_ordering(space: LagrangeSpace, coupling: sp.spmatrix | None = None) -> np.ndarray:
    """A nested dissection ordering of the space's DOFs: METIS on the vertex graph
    (:func:`~signorini.algebra.backends.pardiso.metis_ordering`), with the node pairs ``coupling``
    joins (a contact pair's mortar transfer, docs/method.md, *Two bodies*), extended to the
    edge nodes by :meth:`~signorini.fem.space.P2Space.dof_order`.

    Raises
    ------
    signorini.algebra.BackendUnavailableError
        If MKL (which provides METIS here) cannot be loaded.
    """
    return space.dof_order(metis_ordering(ordering_graph(space.mesh, coupling)))


class Ordering:
    """The ordering :func:`dof_ordering` of one system's unknowns, computed once: when it is
    first asked for, or, with ``prefetch``, started at once in a background thread.

    With ``prefetch`` the graph is built here, in the caller's thread, and only METIS (in
    PARDISO's analysis, which releases the interpreter) runs in the background
    (:func:`~signorini.algebra.backends.beside.beside`) while the caller goes on (the stiffness
    matrix's assembly, :func:`~.system.assemble`); the first call waits for it and extends
    it to the DOFs. The result is the same either way, and an error of the background work
    (e.g. MKL missing) is raised by that call.

    Parameters
    ----------
    space : LagrangeSpace
    coupling : (n_nodes, n_nodes) sparse matrix, optional
        As in :func:`dof_ordering`.
    prefetch : bool
        Start METIS now, in the background.
    """

    def __init__(
        self, space: LagrangeSpace, coupling: sp.spmatrix | None = None, *, prefetch: bool = False
    ) -> None:
        self._space, self._coupling = space, coupling
        self._order: np.ndarray | None = None
        self._metis: Future | None = None
        if prefetch:
            graph = ordering_graph(space.mesh, coupling)
            self._metis = beside(metis_ordering, graph, one_thread=True)

    def __call__(self) -> np.ndarray:
        """``order[k]``: the DOF eliminated k-th."""
        if self._order is None:
            if self._metis is not None:
                vertices = self._metis.result()
            else:
                vertices = metis_ordering(ordering_graph(self._space.mesh, self._coupling))
            self._order = self._space.dof_order(vertices)
            self._metis = self._coupling = None
        return self._order


def ordered_solver(
    space: LagrangeSpace,
    solver: SPDSolver | SolverFactory | None = None,
    *,
    symmetric: bool = True,
    check_symmetry: bool = True,
    ordering: Callable[[], np.ndarray] | None = None,
    rigid_modes: Callable[[], np.ndarray] | None = None,
    coupled: bool = False,
) -> AbstractContextManager[SPDSolver]:
    """The solver of ``space``'s systems, as a context manager.

    Parameters
    ----------
    space : LagrangeSpace
    solver : SPDSolver or SolverFactory, optional
        A factory (default :func:`~signorini.algebra.auto_solver`) makes a new solver,
        offered ``ordering`` (PARDISO takes it; SuperLU keeps its own minimum degree
        ordering), and closed at the end of the ``with`` block. An :class:`SPDSolver` is used
        as it is and not closed: its owner closes it.
    symmetric, check_symmetry : bool
        What the factory is asked for (:class:`~signorini.algebra.SolverRequest`).
    ordering : callable () -> (n,) int array, optional
        The ordering offered: the system's :class:`Ordering` (the ``ordering`` of its
        :class:`~.system.Assembled`, which knows a contact pair's coupling). Default:
        :func:`dof_ordering` of ``space``.
    rigid_modes : callable () -> (n, k) float array, optional
        The rigid motions in the system's unknowns, offered to the factory
        (:attr:`~signorini.algebra.SolverRequest.rigid_modes`; an algebraic multigrid's
        near-nullspace, :func:`~.rigid_modes.system_rigid_modes`).
    coupled : bool
        Whether the system couples bodies through contact pairs (the automatic choice then
        stays direct, :attr:`~signorini.algebra.SolverRequest.coupled`).
    """
    if isinstance(solver, SPDSolver):
        return nullcontext(solver)
    return make_solver(
        solver,
        symmetric=symmetric,
        check_symmetry=check_symmetry,
        ordering=Ordering(space) if ordering is None else ordering,
        rigid_modes=rigid_modes,
        dimension=space.mesh.dim,
        size=space.n_dofs,
        coupled=coupled,
    )


class SolverAhead:
    """The factory of one mesh's solver whose symbolic analysis starts during the assembly.

    :meth:`start` (:func:`~.system.assemble`'s ``on_pattern``) makes the solver of the
    system from ``factory`` with the system's ordering as soon as ``K``'s pattern is known,
    and starts its analysis beside the rest of the assembly
    (:meth:`~signorini.algebra.SPDSolver.analyze`): a symmetric one, or an LU where a contact
    part's friction law is not symmetric (Coulomb, whose systems
    (:class:`~signorini.algebra.friction.system.CoupledSystem`) keep ``K``'s pattern where
    ``K`` is in node blocks). A request of that kind then gets that solver, any other request
    a new one from ``factory``. Where the LU's analysis would read the values (weighted
    matching), nothing starts. The solver does not check the symmetry of ``K``, symmetric by
    construction.
    """

    def __init__(self, factory: SolverFactory | None) -> None:
        self.factory = factory
        self.linear: SPDSolver | None = None
        self.symmetric = True

    def start(self, K: sp.csr_matrix, contact: ContactSet, ordering: Ordering) -> None:
        symmetric = not (contact.has_friction and not contact.friction.symmetric)
        linear = make_solver(
            self.factory, symmetric=symmetric, check_symmetry=False, ordering=ordering
        )
        if linear.analysis_reads_values:  # it would analyse K's values now, in this thread
            linear.close()
            return
        self.linear, self.symmetric = linear, symmetric
        linear.analyze(K, beside=True)

    def __call__(self, request: SolverRequest) -> SPDSolver:
        made, self.linear = self.linear, None
        if made is not None and request.symmetric == self.symmetric:
            return made
        if made is not None:
            made.close()
        return make_solver(
            self.factory,
            symmetric=request.symmetric,
            check_symmetry=request.check_symmetry,
            ordering=request.ordering,
            rigid_modes=request.rigid_modes,
            dimension=request.dimension,
            size=request.size,
            coupled=request.coupled,
        )
