"""The fill-reducing ordering of a mesh's unknowns (signorini.contact.ordering) and the
solvers' ``ordering`` argument (signorini.algebra)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from linalg_problems import p2_elasticity

import signorini.algebra.backends.beside as background
from signorini import adaptive, example_6_2, solve
from signorini.algebra import (
    SOLVERS,
    SymmetricEliminator,
    available_backends,
    make_solver,
    pardiso_solver,
    superlu_solver,
)
from signorini.algebra.backends.pardiso import PardisoSolver, metis_ordering
from signorini.algebra.backends.selection import takes_ordering
from signorini.contact import assemble
from signorini.contact.ordering import Ordering, dof_ordering, ordered_solver, vertex_graph
from signorini.examples import example_6_2_coulomb, example_6_2_tresca, two_cylinders
from signorini.fem.space import P2Space
from signorini.mesh.builders import rectangle

HAS_PARDISO = "pardiso" in available_backends()
needs_pardiso = pytest.mark.skipif(not HAS_PARDISO, reason="MKL PARDISO is not available")


@pytest.fixture(scope="module")
def adaptive_mesh():
    """Example 6.2's adaptive mesh near 40 000 unknowns (graded towards the contact)."""
    for level in adaptive(example_6_2(), max_ndof=45_000):
        mesh = level.result.mesh
    return mesh


def factor_size(K, keep, ordering=None):
    """(non-zeros of the Cholesky factor, Mflop of one factorization) reported by PARDISO."""
    with PardisoSolver(check_symmetry=False, ordering=ordering) as solver:
        solver.factorize(K, keep=keep)
        return solver.factor_nnz, solver.factor_mflop


def eliminated(problem, mesh):
    a = assemble(problem, mesh)
    fixed = np.zeros(a.K.shape[0], dtype=bool)
    fixed[a.dirichlet] = True
    return a, SymmetricEliminator(a.K).keep_mask(fixed)


def test_dof_order_puts_each_edge_node_after_its_earlier_vertex():
    mesh = rectangle(nx=5, ny=3)
    space = P2Space(mesh)
    vertex_order = np.random.default_rng(2).permutation(mesh.n_points)
    order = space.dof_order(vertex_order)
    assert np.array_equal(np.sort(order), np.arange(space.n_dofs))
    assert np.array_equal(order[1::2], order[0::2] + 1)  # the two DOFs of a node together
    node_position = np.empty(space.n_nodes, dtype=np.int64)
    node_position[order[0::2] // 2] = np.arange(space.n_nodes)
    vertex_position = node_position[: mesh.n_points]
    # the vertices keep their relative order
    assert np.array_equal(np.argsort(vertex_position), vertex_order)
    earlier = vertex_position[mesh.edges].min(axis=1)
    edge_position = node_position[mesh.n_points :]
    assert (edge_position > earlier).all()
    # ... before the vertex that follows the earlier one
    following = np.sort(vertex_position)
    nxt = following[np.searchsorted(following, earlier, side="right").clip(max=following.size - 1)]
    last = earlier == following[-1]
    assert (edge_position[~last] < nxt[~last]).all()


@needs_pardiso
def test_metis_ordering_is_a_permutation_and_pardiso_uses_a_given_one():
    """A nested dissection of the vertex graph; handed to PARDISO it changes the factor,
    and the natural (row by row) order of a 16 x 16 grid fills in far more than it (19
    times; the band's fill grows like n^1.5, so a larger grid only costs time: 140 s in
    natural order at 40 x 40)."""
    K, _ = p2_elasticity(16, 16)
    graph = sp.csr_matrix(K != 0)
    order = metis_ordering(graph)
    assert np.array_equal(np.sort(order), np.arange(K.shape[0]))
    keep = None
    K = K + sp.eye(K.shape[0])  # positive definite without boundary conditions
    nnz_metis, _ = factor_size(K, keep, ordering=order)
    nnz_natural, _ = factor_size(K, keep, ordering=np.arange(K.shape[0]))
    nnz_own, _ = factor_size(K, keep)
    assert nnz_natural > 2 * nnz_metis
    assert nnz_metis < 1.3 * nnz_own


@pytest.mark.slow
@needs_pardiso
def test_vertex_graph_ordering_is_no_worse_than_pardisos_own(adaptive_mesh):
    """Measured on Example 6.2's graded adaptive mesh and on a uniform one: the P2 order
    from METIS on the vertex graph gives a factorization no costlier than PARDISO's METIS
    on the whole matrix, and a Cholesky factor at most 10 % larger (docs/method.md,
    *Ordering of the unknowns*; measured here 0.95 / 0.79 adaptive, 1.08 / 1.02 uniform)."""
    problem = example_6_2()
    for mesh in (adaptive_mesh, rectangle(nx=60, ny=60)):
        a, keep = eliminated(problem, mesh)
        own = factor_size(a.K, keep)
        ours = factor_size(a.K, keep, ordering=dof_ordering(a.space))
        print(f"{a.K.shape[0]} unknowns: factor nnz {ours[0] / own[0]:.3f}, Mflop "
              f"{ours[1] / max(own[1], 1):.3f} of PARDISO's own ordering")  # fmt: skip
        assert ours[0] <= 1.10 * own[0]
        assert ours[1] <= 1.05 * own[1]


@pytest.mark.parametrize("backend", available_backends())
def test_solution_does_not_depend_on_the_ordering(backend):
    """The backend's own ordering, a random one and the vertex-graph one (``solve``'s with
    PARDISO) on Example 6.2's mesh of about 3000 unknowns: the same solution to round-off."""
    problem = example_6_2()
    for level in adaptive(problem, max_ndof=3000):
        mesh = level.result.mesh
    a, keep = eliminated(problem, mesh)
    fixed = np.zeros(a.K.shape[0], dtype=bool)
    fixed[a.dirichlet] = True
    b = SymmetricEliminator(a.K).rhs(a.K, a.F, fixed, np.zeros(a.K.shape[0]))
    orderings = [None, np.random.default_rng(0).permutation(a.K.shape[0])]
    if HAS_PARDISO:
        orderings.append(dof_ordering(a.space))
    solutions = []
    for ordering in orderings:
        with make_solver(SOLVERS[backend], check_symmetry=False) as solver:
            solver.ordering = ordering
            solver.factorize(a.K, keep=keep)
            solutions.append(solver.solve(b))
    scale = np.abs(solutions[0]).max()
    for x in solutions[1:]:
        assert np.abs(x - solutions[0]).max() <= 1e-10 * scale
    with ordered_solver(a.space, SOLVERS[backend]) as solver:
        assert (solver.ordering is not None) == (solver.backend == "pardiso")


@pytest.mark.slow
@needs_pardiso
def test_solve_uses_the_ordering_and_agrees_with_pardisos_own(adaptive_mesh):
    problem = example_6_2()
    ordered = solve(problem, adaptive_mesh, solver=pardiso_solver, nested=False)
    with PardisoSolver(check_symmetry=False) as linear:  # a solver object: no ordering set
        own = solve(problem, adaptive_mesh, solver=linear, nested=False)
        assert linear.ordering is None and linear.n_analyses == 1
    assert ordered.report.iterations == own.report.iterations
    assert np.abs(ordered.u - own.u).max() <= 1e-10 * np.abs(own.u).max()
    assert (
        np.abs(ordered.contact_force - own.contact_force).max()
        <= 1e-10 * np.abs(own.contact_force).max()
    )


@pytest.mark.parametrize(
    ("ordering", "message"),
    [
        (np.arange(5), r"shape \(6,\)"),
        (np.arange(6.0), "integer array"),
        (np.array([0, 1, 2, 3, 4, 6]), "outside 0..5"),
        (np.array([0, 1, 2, 3, 4, 4]), "not a permutation: unknowns 5"),
    ],
)
@pytest.mark.parametrize("backend", available_backends())
def test_a_bad_ordering_is_refused_naming_it(ordering, message, backend):
    K = sp.csr_matrix(np.eye(6) * 2 + np.eye(6, k=1) * 0.5 + np.eye(6, k=-1) * 0.5)
    with make_solver(SOLVERS[backend]) as solver:
        solver.ordering = ordering
        with pytest.raises(ValueError, match="ordering") as info:
            solver.factorize(K)
    assert info.match(message)


def test_vertex_graph_has_an_entry_per_edge_both_ways():
    mesh = rectangle(nx=3, ny=2)
    G = vertex_graph(mesh)
    assert G.nnz == 2 * mesh.n_edges and (G != G.T).nnz == 0 and G.diagonal().sum() == 0


@pytest.mark.slow
@needs_pardiso
def test_an_ordering_started_in_the_background_is_the_ordering(adaptive_mesh):
    """:class:`Ordering` with ``prefetch`` (METIS beside the caller, on one MKL thread) gives
    :func:`dof_ordering` exactly, with and without a contact pair's coupling; it is computed
    once."""
    space = P2Space(adaptive_mesh)
    ahead = Ordering(space, prefetch=True)
    first = ahead()
    assert np.array_equal(first, dof_ordering(space)) and ahead() is first
    assert np.array_equal(Ordering(space)(), first)
    pair = assemble(two_cylinders(), two_cylinders().mesh)
    coupling = pair.contact.transfer.nodes
    assert np.array_equal(
        Ordering(pair.space, coupling, prefetch=True)(), dof_ordering(pair.space, coupling)
    )
    assert np.array_equal(pair.ordering(), dof_ordering(pair.space, coupling))


@pytest.mark.slow
@needs_pardiso
@pytest.mark.parametrize("make", [example_6_2, example_6_2_tresca, example_6_2_coulomb])
def test_solve_with_its_analysis_beside_the_assembly_is_the_solve_without(
    adaptive_mesh, make, monkeypatch
):
    """``solve`` with the PARDISO factory orders the unknowns and analyses the matrix beside
    the assembly (:class:`Ordering`, :meth:`SPDSolver.analyze`): by its Cholesky, or, for
    Coulomb's systems (on ``K``'s pattern), by its LU. With an assembly passed in, it does
    both in turn. The solutions are the same bit for bit, with the same counts (one
    analysis)."""
    problem = make()
    u0 = solve(problem, adaptive_mesh, solver=pardiso_solver).u  # a warm start: no nested solve
    submitted = []
    work_beside = background.beside

    def spy(work, *args, **kwargs):
        submitted.append(getattr(work, "__self__", None))
        return work_beside(work, *args, **kwargs)

    monkeypatch.setattr(background, "beside", spy)
    beside = solve(problem, adaptive_mesh, u0=u0, solver=pardiso_solver)
    monkeypatch.setattr(background, "beside", work_beside)
    analysed = [type(s).__name__ for s in submitted if s is not None]
    coulomb = make is example_6_2_coulomb
    assert analysed == ["PardisoLUSolver" if coulomb else "PardisoSolver"]
    in_turn = solve(
        problem, adaptive_mesh, u0=u0, solver=pardiso_solver,
        assembled=assemble(problem, adaptive_mesh),
    )  # fmt: skip
    assert np.array_equal(beside.u, in_turn.u)
    assert np.array_equal(beside.contact_force, in_turn.contact_force)
    for key in ("iterations", "n_solves", "n_factorizations", "n_analyses", "n_updates"):
        assert getattr(beside.report, key) == getattr(in_turn.report, key), key
    assert beside.report.n_analyses == 1


def test_takes_ordering_names_the_factories_that_use_an_offered_ordering():
    assert takes_ordering(pardiso_solver) is True
    assert takes_ordering(superlu_solver) is False
    assert takes_ordering(None) is HAS_PARDISO  # auto: PARDISO where it works
    with make_solver(superlu_solver) as solver:
        assert takes_ordering(solver) is False  # a solver object is used as it is
