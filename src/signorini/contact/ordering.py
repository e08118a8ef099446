"""The fill-reducing ordering of one mesh's unknowns (docs/method.md, *Ordering of the
unknowns*), and the solvers that use it.

PARDISO's own analysis runs METIS on the graph of the whole P2 stiffness matrix: 3.1 s of a
complete direct solve of 4.5 s at 1.2 M unknowns of Example 6.2. Here METIS orders the
mesh's *vertex* graph (an eighth of the unknowns, a fiftieth of the matrix's entries) and
:meth:`~signorini.fem.space.P2Space.dof_order` extends that order to the P2 DOFs; PARDISO
then only does its symbolic factorization. Measured there (``python benchmarks/ordering.py``):
ordering 0.37 s, analysis 0.98 s, a factor with 0.92 times the non-zeros and 0.81 times the
operations; the complete solve 0.57 times PARDISO's own.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..algebra.backends import make_lu_solver, make_solver
from ..algebra.pardiso import metis_ordering
from ..algebra.solvers import SPDSolver
from ..fem.space import P2Space
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


def dof_ordering(space: P2Space) -> np.ndarray:
    """A nested dissection ordering of the space's DOFs: METIS on the vertex graph
    (:func:`~signorini.algebra.pardiso.metis_ordering`), extended to the edge nodes by
    :meth:`~signorini.fem.space.P2Space.dof_order`.

    Raises
    ------
    signorini.algebra.BackendUnavailableError
        If MKL (which provides METIS here) cannot be loaded.
    """
    return space.dof_order(metis_ordering(vertex_graph(space.mesh)))


def ordered_solver(space: P2Space, backend: str, *, lu: bool = False, **options) -> SPDSolver:
    """A solver for the systems of ``space`` (``make_solver``, or ``make_lu_solver`` with
    ``lu``) that analyses them with :func:`dof_ordering` when it is PARDISO; SuperLU keeps its
    own minimum degree ordering (without MKL there is no METIS to compute ours)."""
    solver = make_lu_solver(backend) if lu else make_solver(backend, **options)
    if solver.backend == "pardiso":
        solver.ordering = dof_ordering(space)
    return solver
