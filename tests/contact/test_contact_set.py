"""The discrete contact boundary (:mod:`signorini.contact.contact_set`).

Constrained nodes, the integrals ``m_z = ∫ φ_z`` of the half-edge hats and ``w_z = ∫ ψ_z`` of
the P2 basis, the contact force density ``s_z`` (4.1) and the consistent pressure ``p_z``
(docs/method.md, *Discrete problem*), node classes (Section 4), and contact data that cannot be
discretised (corners, gaps that disagree or are not numbers).
"""

from __future__ import annotations

import numpy as np
import pytest
from contact_problems import contact_patch_field, patch_problem, problem_contact_set

from signorini.contact.contact_set import (
    FULL_CONTACT,
    NO_CONTACT,
    SEMI_CONTACT,
    node_classes,
)
from signorini.contact.solution import solve
from signorini.examples import example_6_1, example_6_2
from signorini.fem.material import Material
from signorini.fem.space import P2Space
from signorini.mesh.builders import rectangle
from signorini.mesh.mesh import Mesh
from signorini.mesh.refine import refine_nvb, refine_uniform
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann, ProblemError

MATERIAL = Material.from_young(10.0, 0.3)


def graded_mesh(seed: int, steps: int = 6, x1: float = 2.0) -> Mesh:
    """A rectangle refined by NVB towards a random point of the bottom edge."""
    rng = np.random.default_rng(seed)
    mesh = rectangle(0, x1, 0, 1, nx=4, ny=2)
    target = np.array([rng.uniform(0, x1), 0.0])
    for step in range(steps):
        centroid = mesh.points[mesh.cells].mean(axis=1)
        near = np.hypot(*(centroid - target).T) < 0.6 * 0.75**step
        mesh = refine_nvb(mesh, near | (rng.random(mesh.n_cells) < 0.1)).mesh
    return mesh


def block_problem(mesh: Mesh, gap=0.0) -> ContactProblem:
    """Contact on the bottom, Dirichlet on top, free sides."""
    return ContactProblem(
        mesh=mesh,
        material=MATERIAL,
        conditions={
            "top": Dirichlet((0.0, -0.1)),
            "left": Neumann(),
            "right": Neumann(),
            "bottom": Contact(gap=gap),
        },
    )


# ------------------------------------------------------------------------- constrained nodes
def test_weights_on_a_uniform_mesh():
    mesh = rectangle(0, 1, 0, 1, nx=4, ny=4)
    space = P2Space(mesh)
    cs = problem_contact_set(block_problem(mesh, gap=lambda x: x[..., 0] ** 2), space)
    x = space.node_points[cs.nodes]
    assert cs.size == 9 and np.allclose(x[:, 1], 0.0)
    assert np.array_equal(cs.is_vertex, cs.nodes < mesh.n_points)
    assert np.allclose(cs.normal, [0.0, -1.0])
    assert np.allclose(cs.gap, x[:, 0] ** 2, atol=1e-15)
    h = 0.25
    end = np.isclose(x[:, 0], 0) | np.isclose(x[:, 0], 1)
    expect_m = np.where(cs.is_vertex, np.where(end, h / 4, h / 2), h / 2)
    expect_w = np.where(cs.is_vertex, np.where(end, h / 6, h / 3), 2 * h / 3)
    assert np.allclose(cs.hat_integral, expect_m, rtol=1e-14)
    assert np.allclose(cs.basis_integral, expect_w, rtol=1e-14)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_weights_sum_to_the_contact_length(seed):
    mesh = graded_mesh(seed)
    cs = problem_contact_set(block_problem(mesh), P2Space(mesh))
    lengths = mesh.edge_length[mesh.part_facets("bottom")]
    print(
        f"seed {seed}: {cs.size} constrained nodes, edge lengths "
        f"{lengths.min():.4f}..{lengths.max():.4f}, Σm = {cs.hat_integral.sum():.15f}, "
        f"Σw = {cs.basis_integral.sum():.15f}"
    )
    assert lengths.min() < lengths.max() / 3  # a graded contact boundary
    assert cs.hat_integral.sum() == pytest.approx(2.0, rel=1e-14)
    assert cs.basis_integral.sum() == pytest.approx(2.0, rel=1e-14)
    # ∫ψ_z of the P2 basis is |e|/6 per edge at a vertex, 2|e|/3 at a midpoint
    mid = ~cs.is_vertex
    assert np.allclose(cs.basis_integral[mid], 4 / 3 * cs.hat_integral[mid], rtol=1e-14)
    assert np.allclose(cs.basis_integral[~mid], 2 / 3 * cs.hat_integral[~mid], rtol=1e-14)


def test_dirichlet_nodes_are_not_constrained():
    mesh = rectangle(0, 1, 0, 1, nx=4, ny=4)
    space = P2Space(mesh)
    pb = ContactProblem(
        mesh=mesh,
        material=MATERIAL,
        conditions={
            "left": Dirichlet(),
            "top": Neumann(),
            "right": Neumann(),
            "bottom": Contact(gap=0.01),
        },
    )
    cs = problem_contact_set(pb, space)
    x = space.node_points[cs.nodes]
    assert cs.size == 8  # 9 nodes on the bottom minus the corner (0, 0)
    assert np.all(x[:, 0] > 0.1) and np.allclose(x[:, 1], 0)
    # the corner's share of the first edge is missing from m_z
    assert cs.hat_integral.sum() == pytest.approx(1 - 0.25 / 4, rel=1e-14)
    assert cs.facet_gap.shape == (4, 3) and np.allclose(cs.facet_gap, 0.01)


# --------------------------------------------------------------------------- s_z and p_z
@pytest.mark.parametrize("seed", [3, 4])
def test_uniform_pressure_density_and_pressure(seed):
    """Uniform pressure p: p_z = p, s_z = 2p/3 at vertices and 4p/3 at midpoints, ΣΛ = p|Γ_C|."""
    rng = np.random.default_rng(seed)
    mesh = graded_mesh(seed, x1=1.5)
    u = contact_patch_field(rng, MATERIAL, uniform=True)
    pb = patch_problem(
        mesh,
        MATERIAL,
        u,
        {"top": "D", "left": "N", "right": "N", "bottom": "C"},
        normal=np.array([0.0, -1.0]),
    )
    r = solve(pb)
    p = -u.stress(np.array([0.7, 0.0]), MATERIAL)[1, 1]
    v = r.contact.is_vertex
    print(
        f"seed {seed}: p = {p:.6f}, p_z in [{r.pressure.min():.12f}, {r.pressure.max():.12f}],"
        f" max |s_z/p − 2/3| at vertices {np.abs(r.density[v] / p - 2 / 3).max():.1e}, "
        f"max |s_z/p − 4/3| at midpoints {np.abs(r.density[~v] / p - 4 / 3).max():.1e}, "
        f"ΣΛ = {r.total_contact_force:.12f}"
    )
    assert p > 1.0 and r.active.all()
    assert np.allclose(r.pressure, p, rtol=1e-10)
    assert np.allclose(r.density[v], 2 * p / 3, rtol=1e-10)
    assert np.allclose(r.density[~v], 4 * p / 3, rtol=1e-10)
    assert r.total_contact_force == pytest.approx(p * 1.5, rel=1e-10)
    assert r.contact.hat_integral.sum() == pytest.approx(1.5, rel=1e-14)


@pytest.mark.parametrize("seed", [5, 6])
def test_pressure_exact_for_linear_pressures(seed):
    rng = np.random.default_rng(seed)
    mesh = graded_mesh(seed)
    u = contact_patch_field(rng, MATERIAL)
    pb = patch_problem(
        mesh,
        MATERIAL,
        u,
        {"top": "D", "left": "N", "right": "N", "bottom": "C"},
        normal=np.array([0.0, -1.0]),
    )
    r = solve(pb)
    x = r.space.node_points[r.contact.nodes]
    p = -u.stress(x, MATERIAL)[:, 1, 1]
    err = np.abs(r.pressure - p).max() / np.abs(p).max()
    total = 0.5 * (p[np.argmin(x[:, 0])] + p[np.argmax(x[:, 0])]) * 2.0  # ∫ of a linear p
    print(
        f"seed {seed}: p from {p.min():.4f} to {p.max():.4f}, max |p_z − p(z)|/max p = "
        f"{err:.1e}, ΣΛ = {r.total_contact_force:.12f} vs ∫p = {total:.12f}"
    )
    assert np.ptp(p) > 0.05 * np.abs(p).max()  # really non-uniform
    assert err < 1e-10
    assert r.total_contact_force == pytest.approx(total, rel=1e-10)
    # s_z is only right in the weak sense: off by 2/3 or 4/3 pointwise
    assert np.abs(r.density - p).max() > 0.3 * p.min()


# ----------------------------------------------------------------------------- node classes
def classes_by_definition(cs, in_contact):
    """Paper, Section 4, written out edge by edge (plain loops; small meshes only)."""
    where = {int(z): k for k, z in enumerate(cs.nodes)}
    full_edge = [
        all(z in where and in_contact[where[z]] for z in map(int, e)) for e in cs.facet_nodes
    ]
    out = np.full(cs.size, NO_CONTACT)
    for k, z in enumerate(cs.nodes):
        if in_contact[k]:
            edges = [i for i, e in enumerate(cs.facet_nodes) if z in e]
            out[k] = FULL_CONTACT if all(full_edge[i] for i in edges) else SEMI_CONTACT
    return out


@pytest.mark.parametrize("seed", range(4))
def test_node_classes_follow_the_definition(seed):
    rng = np.random.default_rng(seed)
    mesh = graded_mesh(seed)
    cs = problem_contact_set(block_problem(mesh), P2Space(mesh))
    # random intervals of contact nodes plus isolated ones
    x = P2Space(mesh).node_points[cs.nodes, 0]
    a, b = np.sort(rng.uniform(0, 2, 2))
    in_contact = ((x >= a) & (x <= b)) | (rng.random(cs.size) < 0.15)
    edge_in = np.isin(cs.facet_nodes, cs.nodes[in_contact])
    got = node_classes(cs, in_contact, edge_in)
    expect = classes_by_definition(cs, in_contact)
    print(f"seed {seed}: {np.bincount(got, minlength=3)} (no, semi, full)")
    assert np.array_equal(got, expect)
    assert np.array_equal(
        node_classes(cs, np.ones(cs.size, bool), np.ones_like(edge_in)),
        np.full(cs.size, FULL_CONTACT),
    )
    assert np.all(node_classes(cs, np.zeros(cs.size, bool), np.zeros_like(edge_in)) == NO_CONTACT)


def test_example_6_1_every_node_full_contact():
    pb = example_6_1()
    r = solve(pb)
    assert r.active.all()
    assert np.all(r.classes == FULL_CONTACT)


def test_example_6_2_semi_contact_only_at_the_ends():
    pb = example_6_2()
    mesh = pb.mesh
    for level in range(3):
        if level:
            mesh = refine_uniform(mesh).mesh
        r = solve(pb, mesh)
        cs = r.contact
        order = np.argsort(r.space.node_points[cs.nodes, 1])
        active, cls = r.active[order], r.classes[order]
        ends = np.flatnonzero(active)[[0, -1]]
        is_vertex = cs.is_vertex[order]
        print(f"level {level}: classes along x = 1 (bottom to top) {''.join(map(str, cls))}")
        assert np.all(cls[ends] == SEMI_CONTACT)
        semi = np.flatnonzero(cls == SEMI_CONTACT)
        # an end at a midpoint makes the next vertex inwards semi as well (its other edge is
        # not fully in contact); every other node is full or no contact
        expect = set(ends.tolist())
        if not is_vertex[ends[0]]:
            expect.add(ends[0] + 1)
        if not is_vertex[ends[1]]:
            expect.add(ends[1] - 1)
        assert set(semi.tolist()) == expect
        assert np.all(cls[active & (cls != SEMI_CONTACT)] == FULL_CONTACT)
        assert np.all(cls[~active] == NO_CONTACT)
        assert np.array_equal(r.classes, classes_by_definition(cs, r.active))


# ------------------------------------------------------------------------------ bad input
def _square():
    return rectangle(nx=2, ny=2)


def test_gap_returning_nan():
    pb = ContactProblem(
        _square(),
        MATERIAL,
        {
            "left": Dirichlet(),
            "top": Neumann(),
            "bottom": Neumann(),
            "right": Contact(gap=lambda x: np.where(x[..., 1] > 0.5, np.nan, 0.0)),
        },
    )
    with pytest.raises(ProblemError, match="gap function of contact part 'right' returned NaN"):
        solve(pb)


def test_gap_of_wrong_shape():
    pb = ContactProblem(
        _square(),
        MATERIAL,
        {
            "left": Dirichlet(),
            "top": Neumann(),
            "bottom": Neumann(),
            "right": Contact(gap=lambda x: x),
        },
    )
    with pytest.raises(ProblemError, match="gap function of contact part 'right' must return"):
        solve(pb)


def test_contact_parts_meeting_at_a_corner_give_two_constraints():
    pb = ContactProblem(
        _square(),
        MATERIAL,
        {"left": Dirichlet(), "top": Neumann(), "bottom": Contact(), "right": Contact()},
    )
    cs = problem_contact_set(pb, P2Space(pb.mesh))
    corner = np.flatnonzero(cs.nodes == 2)  # the vertex (1, 0)
    assert corner.size == 2 and cs.second[corner].tolist() == [False, True]
    assert {tuple(n) for n in cs.normal[corner]} == {(0.0, -1.0), (1.0, 0.0)}
    assert cs.constrained_dofs[corner].tolist() == [4, 5]
    # each constraint's weights count its own part's edge only: |e| / 6 with |e| = 1/2
    assert np.allclose(cs.basis_integral[corner], 1 / 12, rtol=0, atol=1e-15)


def _split_right_side():
    base = rectangle(nx=4, ny=4)
    tol = 1e-12
    return Mesh.from_arrays(
        base.points,
        base.cells,
        {
            "left": lambda x: np.abs(x[:, 0]) < tol,
            "top": lambda x: np.abs(x[:, 1] - 1) < tol,
            "bottom": lambda x: np.abs(x[:, 1]) < tol,
            "right_low": lambda x: (np.abs(x[:, 0] - 1) < tol) & (x[:, 1] < 0.5),
            "right_high": lambda x: (np.abs(x[:, 0] - 1) < tol) & (x[:, 1] > 0.5),
        },
    )


def test_collinear_contact_parts_with_disagreeing_gaps():
    conditions = {"left": Dirichlet((0.1, 0.0)), "top": Neumann(), "bottom": Neumann()}
    pb = ContactProblem(
        _split_right_side(),
        MATERIAL,
        {**conditions, "right_low": Contact(gap=0.0), "right_high": Contact(gap=0.05)},
    )
    with pytest.raises(
        ProblemError,
        match=r"node \d+ at \[1\.0, 0\.5\] lies on contact parts "
        "whose gap functions disagree",
    ):
        solve(pb)
    # a continuous obstacle split over two parts gives the solution of the unsplit problem
    gap = lambda x: -0.2 + 0.5 * np.abs(x[..., 1] - 0.5)  # noqa: E731
    split = solve(
        ContactProblem(
            _split_right_side(),
            MATERIAL,
            {**conditions, "right_low": Contact(gap=gap), "right_high": Contact(gap=gap)},
        )
    )
    whole = solve(
        ContactProblem(rectangle(nx=4, ny=4), MATERIAL, {**conditions, "right": Contact(gap=gap)})
    )
    assert np.abs(split.u - whole.u).max() <= 1e-13 * np.abs(whole.u).max()
