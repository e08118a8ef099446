"""The P2 space (signorini.fem.space): node numbering, DOF maps, interpolation, prolongation."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from signorini.fem.space import P2Space
from signorini.mesh.builders import rectangle
from signorini.mesh.refine import refine_nvb, refine_uniform

REFERENCE_NODES = np.array([[0, 0], [1, 0], [0, 1], [0.5, 0], [0.5, 0.5], [0, 0.5]])


def local_monomials(x: np.ndarray, centre: np.ndarray, h: np.ndarray) -> np.ndarray:
    """``[1, s, t, s², st, t²]`` at ``x (m, q, 2)`` in the scaled coordinates of each cell."""
    s = (x - centre[:, None, :]) / h[:, None, None]
    a, b = s[..., 0], s[..., 1]
    return np.stack([np.ones_like(a), a, b, a * a, a * b, b * b], axis=-1)


def evaluate_on_cells(
    space: P2Space, u: np.ndarray, cells: np.ndarray, x: np.ndarray
) -> np.ndarray:
    """Values of the P2 field ``u (n_nodes, ...)`` of ``space`` at points ``x (m, q, 2)`` lying
    in ``cells (m,)``.

    Independent of the package's basis functions: on each cell the quadratic is recovered
    from its six nodal values by solving the 6 x 6 monomial (Vandermonde) system.
    """
    nodes = space.cell_nodes[cells]  # (m, 6)
    xn = space.node_points[nodes]  # (m, 6, 2)
    centre = xn[:, :3].mean(axis=1)
    h = np.ptp(xn[:, :3], axis=1).max(axis=1)
    V = local_monomials(xn, centre, h)  # (m, 6, 6)
    vals = u[nodes].reshape(len(cells), 6, -1)  # (m, 6, k)
    coef = np.linalg.solve(V, vals)  # (m, 6, k)
    out = np.einsum("mqa,mak->mqk", local_monomials(x, centre, h), coef)
    return out.reshape(x.shape[:2] + u.shape[1:])


def random_nvb(mesh, rng, steps, fraction=0.3):
    """Several random NVB refinements (at least one cell marked in each); returns the
    refinements and each fine cell's ancestor."""
    ancestor = np.arange(mesh.n_cells)
    refinements = []
    for _ in range(steps):
        marked = rng.random(mesh.n_cells) < fraction
        marked[rng.integers(mesh.n_cells)] = True
        ref = refine_nvb(mesh, marked)
        refinements.append(ref)
        ancestor = ancestor[ref.parent]
        mesh = ref.mesh
    return refinements, ancestor


# ------------------------------------------------------------------------------- numbering
def test_node_points_vertices_then_midpoints():
    rng = np.random.default_rng(2)
    (ref,), _ = random_nvb(rectangle(0, 2, 0, 1, nx=3, ny=2), rng, 1, 0.5)
    mesh = ref.mesh
    space = P2Space(mesh)
    assert space.n_nodes == mesh.n_points + mesh.n_edges
    assert space.n_dofs == 2 * space.n_nodes
    assert np.array_equal(space.node_points[: mesh.n_points], mesh.points)
    mid = 0.5 * (mesh.points[mesh.edges[:, 0]] + mesh.points[mesh.edges[:, 1]])
    assert np.allclose(space.node_points[mesh.n_points :], mid, atol=1e-15)
    # per cell: local node 3 + k is the midpoint of local vertices k and k + 1
    v = mesh.points[mesh.cells]
    x = space.node_points[space.cell_nodes]
    assert np.array_equal(space.cell_nodes[:, :3], mesh.cells)
    for k in range(3):
        assert np.allclose(x[:, 3 + k], 0.5 * (v[:, k] + v[:, (k + 1) % 3]), atol=1e-15)


def test_cell_dofs_are_interleaved():
    space = P2Space(rectangle(nx=2, ny=3, pattern="crossed"))
    dofs = space.cell_dofs
    assert dofs.shape == (space.mesh.n_cells, 12)
    for a in range(6):
        for c in range(2):
            assert np.array_equal(dofs[:, 2 * a + c], 2 * space.cell_nodes[:, a] + c)
    # the identity field x -> x: local DOF 2a + c holds coordinate c of local node a
    u = space.interpolate(lambda x: x)
    cell_u = space.cell_values(u).reshape(-1, 6, 2)
    assert np.array_equal(cell_u, space.node_points[space.cell_nodes])
    # every DOF is used, and each appears in both components
    assert np.array_equal(np.unique(dofs), np.arange(space.n_dofs))


def test_edge_nodes_counter_clockwise_with_outward_normals():
    mesh = rectangle(0, 3, 0, 2, nx=3, ny=2)
    space = P2Space(mesh)
    outward = {"bottom": (0, -1), "right": (1, 0), "top": (0, 1), "left": (-1, 0)}
    for name, n in outward.items():
        edges = mesh.part_facets(name)
        en = space.facet_nodes(edges)
        a, b = space.node_points[en[:, 0]], space.node_points[en[:, 1]]
        d = b - a
        normal = np.column_stack([d[:, 1], -d[:, 0]]) / np.hypot(d[:, 0], d[:, 1])[:, None]
        assert np.allclose(normal, n, atol=1e-15), name
        assert np.array_equal(en[:, 2], mesh.n_points + edges)
        assert np.allclose(space.node_points[en[:, 2]], 0.5 * (a + b), atol=1e-15)
        nodes = space.part_nodes([name])
        assert nodes.size == 2 * edges.size + 1  # a straight open segment
        assert np.array_equal(nodes, np.unique(en))
    both = space.part_nodes(["bottom", "right"])
    assert both.size == 2 * (3 + 2) + 1  # the shared corner counted once
    assert space.part_nodes([]).size == 0


# ------------------------------------------------------------------------------ interpolation
def test_interpolate_reproduces_quadratics_inside_cells():
    space = P2Space(rectangle(0, 1, 0, 2, nx=2, ny=3, pattern="left"))

    def q(x):
        return np.stack(
            [1 + x[..., 0] ** 2 - 3 * x[..., 0] * x[..., 1], x[..., 1] ** 2 - 2 * x[..., 0]],
            axis=-1,
        )

    u = space.interpolate(q)
    assert u.shape == (space.n_nodes, 2)
    rng = np.random.default_rng(3)
    bary = rng.dirichlet(np.ones(3), size=(space.mesh.n_cells, 7))
    x = np.einsum("mqa,mac->mqc", bary, space.vertices)
    vals = evaluate_on_cells(space, u, np.arange(space.mesh.n_cells), x)
    err = np.abs(vals - q(x)).max()
    print(f"interpolant of a quadratic, max error inside cells: {err:.2e}")
    assert err < 1e-12


@pytest.mark.parametrize(
    "bad",
    [
        lambda x: x[:, 0],  # scalar field
        lambda x: np.zeros((len(x), 3)),  # three components
        lambda x: np.array([1.0, 2.0]),  # one vector for all points
        lambda x: x[:-1],  # one value short
    ],
)
def test_interpolate_rejects_wrong_shapes(bad):
    space = P2Space(rectangle(nx=1, ny=1))
    with pytest.raises(ValueError, match=r"must return shape \(9, 2\)"):
        space.interpolate(bad)


# ------------------------------------------------------------------------------- prolongation
@settings(max_examples=12, deadline=None)
@given(
    pattern=st.sampled_from(("unionjack", "right", "left", "crossed")),
    steps=st.integers(1, 4),
    fraction=st.floats(0.1, 0.6),
    seed=st.integers(0, 2**32 - 1),
)
def test_prolongation_exact_over_random_nvb_refinements(pattern, steps, fraction, seed):
    """A random (piecewise quadratic) P2 field keeps its values under prolongation."""
    rng = np.random.default_rng(seed)
    coarse = rectangle(0, 2, 0, 1, nx=2, ny=2, pattern=pattern)
    refinements, ancestor = random_nvb(coarse, rng, steps, fraction)
    space0 = P2Space(coarse)
    u0 = rng.standard_normal((space0.n_nodes, 2))
    s0 = rng.standard_normal(space0.n_nodes)
    u, s, space = u0, s0, space0
    for ref in refinements:
        u, s = space.prolongate(u, ref), space.prolongate(s, ref)
        space = P2Space(ref.mesh)
    assert u.shape == (space.n_nodes, 2) and s.shape == (space.n_nodes,)
    # fine nodal values = coarse field at the fine nodes (through the ancestor cell)
    x = space.node_points[space.cell_nodes]  # (m, 6, 2)
    expect_u = evaluate_on_cells(space0, u0, ancestor, x)
    expect_s = evaluate_on_cells(space0, s0, ancestor, x)
    err_u = np.abs(u[space.cell_nodes] - expect_u).max()
    err_s = np.abs(s[space.cell_nodes] - expect_s).max()
    # and at random points inside the fine cells
    bary = rng.dirichlet(np.ones(3), size=(space.mesh.n_cells, 4))
    y = np.einsum("mqa,mac->mqc", bary, space.vertices)
    cells = np.arange(space.mesh.n_cells)
    err_in = np.abs(
        evaluate_on_cells(space, u, cells, y) - evaluate_on_cells(space0, u0, ancestor, y)
    ).max()
    assert max(err_u, err_s, err_in) < 1e-11, (
        f"{coarse.n_cells} -> {space.mesh.n_cells} cells, prolongation errors "
        f"nodes {err_u:.1e} (vector) {err_s:.1e} (scalar), inside cells {err_in:.1e}"
    )
    # the data changed: a non-trivial refinement of a non-trivial field
    assert space.mesh.n_cells > coarse.n_cells


def test_prolongation_exact_under_uniform_refinement():
    mesh = rectangle(nx=3, ny=2, pattern="crossed")
    space = P2Space(mesh)

    def q(x):
        return np.stack(
            [x[..., 0] * x[..., 1] - 0.5 * x[..., 1] ** 2 + 2, 3 * x[..., 0] ** 2 + x[..., 1]],
            axis=-1,
        )

    u = space.interpolate(q)
    for _ in range(2):
        ref = refine_uniform(space.mesh)
        u = space.prolongate(u, ref)
        space = P2Space(ref.mesh)
    err = np.abs(u - q(space.node_points)).max()
    print(f"uniform x2: {space.n_nodes} nodes, prolongation error {err:.1e}")
    assert err < 1e-13


def test_prolongation_is_not_interpolation_of_a_cubic():
    """Control: prolongating the interpolant of a cubic differs from interpolating it."""
    mesh = rectangle(nx=2, ny=2)
    space = P2Space(mesh)

    def cubic(x):
        return np.stack([x[..., 0] ** 3, x[..., 1] ** 3], axis=-1)

    ref = refine_uniform(mesh)
    diff = np.abs(
        space.prolongate(space.interpolate(cubic), ref) - P2Space(ref.mesh).interpolate(cubic)
    ).max()
    # the P2 interpolation error of x³ at quarter points of an edge of length h = 0.5 is
    # |x³ − I x³| = h³ |t (t − 1/2)(t − 1)| = h³ · 3/64 at t = 1/4
    assert diff == pytest.approx(0.5**3 * 3 / 64, rel=1e-12)


def test_prolongate_rejects_wrong_size():
    mesh = rectangle(nx=1, ny=1)
    space = P2Space(mesh)
    ref = refine_uniform(mesh)
    with pytest.raises(ValueError, match="u has 8 nodes, the space has 9"):
        space.prolongate(np.zeros((8, 2)), ref)


def test_prolongate_rejects_a_refinement_of_another_mesh():
    space = P2Space(rectangle(nx=2, ny=2))
    u = np.zeros((space.n_nodes, 2))
    with pytest.raises(ValueError, match="not a refinement of this space's mesh"):
        space.prolongate(u, refine_uniform(rectangle(nx=4, ny=4)))  # more cells
    # same points and cell count, other diagonals: caught geometrically
    with pytest.raises(ValueError, match="not inside its parent cell"):
        space.prolongate(u, refine_uniform(rectangle(nx=2, ny=2, pattern="right")))
