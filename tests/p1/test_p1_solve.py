"""P1 elements through assembly and SOLVE: the element's stiffness, the space's numbering and
prolongation, patch tests with and without contact, KKT, and bad input refused."""

from __future__ import annotations

import numpy as np
import pytest
from contact_problems import Quadratic, patch_problem, random_quadratic, rotation

from signorini.contact.solution import solve
from signorini.contact.system import assemble
from signorini.examples import example_6_1, example_6_2
from signorini.fem.element import P1, P2, element_of
from signorini.fem.mapping import AffineCells
from signorini.fem.material import Material
from signorini.fem.norms import energy_error2
from signorini.fem.space import P1Space, P2Space, space_of
from signorini.fem.stiffness import element_blocks
from signorini.loop import adaptive
from signorini.loop.options import AdaptiveOptions, OptionError
from signorini.mesh.builders import rectangle
from signorini.mesh.refine import refine_nvb, refine_uniform
from tests.contact.test_solution import nvb_mesh, rotated_mesh, square_sides

MATERIAL = Material.from_young(7.0, 0.28)
KINDS = {"left": "D", "bottom": "N", "right": "N", "top": "N"}


def test_p1_element_stiffness_is_symmetric_with_three_rigid_modes():
    rng = np.random.default_rng(0)
    v = np.array([[0.0, 0.0], [1.0, 0.1], [0.2, 0.9]]) + 0.1 * rng.standard_normal((3, 2))
    K = element_blocks(AffineCells(v[None]), MATERIAL, dof_order=True, element=P1)
    K = K.reshape(6, 6)
    eig = np.linalg.eigvalsh(K)
    print("P1 element stiffness eigenvalues:", eig)
    assert np.abs(K - K.T).max() < 1e-14 * np.abs(K).max()
    assert np.sum(np.abs(eig) < 1e-12 * eig.max()) == 3
    assert eig.min() > -1e-12 * eig.max()


def test_p1_stiffness_is_the_p2_stiffness_on_p1_fields():
    """K1 = Eᵀ K2 E with E the embedding of P1 into P2 (midpoint = mean of the ends): the
    P1 assembly is the P2 bilinear form restricted to P1 functions."""
    mesh = nvb_mesh(rectangle(0, 2, 0, 1, nx=3, ny=2), 4)
    pb = patch_problem(mesh, MATERIAL, random_quadratic(np.random.default_rng(1)), KINDS)
    K1 = assemble(pb, mesh, element="P1").K.toarray()
    K2 = assemble(pb, mesh).K.toarray()
    n1, n2 = mesh.n_points, mesh.n_points + mesh.n_edges
    E = np.zeros((n2, n1))
    E[np.arange(n1), np.arange(n1)] = 1.0
    E[n1 + np.arange(mesh.n_edges)[:, None], mesh.edges] = 0.5
    E2 = np.kron(E, np.eye(2))
    err = np.abs(E2.T @ K2 @ E2 - K1).max() / np.abs(K1).max()
    print(f"max |E^T K2 E - K1| / max |K1| = {err:.1e}")
    assert err < 1e-13


def test_p1_space_numbers_the_vertices():
    mesh = nvb_mesh(rectangle(nx=3, ny=3), 2)
    space = space_of(mesh, "p1")
    assert isinstance(space, P1Space) and space.element is P1
    assert space.n_nodes == mesh.n_points and space.n_dofs == 2 * mesh.n_points
    assert np.array_equal(space.cell_nodes, mesh.cells)
    assert space.cell_dofs.shape == (mesh.n_cells, 6)
    assert np.array_equal(space.part_nodes(["bottom"]), np.flatnonzero(mesh.points[:, 1] == 0))
    assert isinstance(space_of(mesh), P2Space) and space_of(mesh).element is P2
    # a P1 field read as P2 coefficients: the midpoint values are the means of the ends
    u = np.random.default_rng(0).standard_normal((mesh.n_points, 2))
    c = space.field_coefficients(u).reshape(-1, 6, 2)
    assert np.allclose(c[:, 3], 0.5 * (u[mesh.cells[:, 0]] + u[mesh.cells[:, 1]]), atol=0)


def test_p1_prolongation_is_exact_interpolation():
    mesh = nvb_mesh(rectangle(nx=3, ny=2), 5)
    space = P1Space(mesh)
    rng = np.random.default_rng(3)
    marked = rng.random(mesh.n_cells) < 0.3
    ref = refine_nvb(mesh, marked)
    A = rng.standard_normal((2, 2))

    def affine(x):
        return x @ A.T + [0.3, -0.2]

    fine = P1Space(ref.mesh).interpolate(affine)
    err = np.abs(space.prolongate(space.interpolate(affine), ref) - fine).max()
    u = rng.standard_normal((mesh.n_points, 2))
    out = space.prolongate(u, ref)
    # every new vertex is the midpoint of a coarse edge: the field there is the mean
    split = np.flatnonzero(ref.edge_point >= 0)
    mean = 0.5 * u[mesh.edges[split]].sum(axis=1)
    print(f"affine field prolongated: max error {err:.1e}")
    assert err < 1e-14
    assert np.array_equal(out[: mesh.n_points], u)
    assert np.array_equal(out[ref.edge_point[split]], mean)
    with pytest.raises(ValueError, match="nodes"):
        space.prolongate(u[:-1], ref)


def _affine(q: Quadratic) -> Quadratic:
    return Quadratic(q.c, q.G, np.zeros((2, 2, 2)))


@pytest.mark.parametrize("seed", [0, 1])
def test_p1_patch_test_without_contact(seed):
    rng = np.random.default_rng(seed)
    mesh = nvb_mesh(rectangle(0, 2, 0, 1, nx=4, ny=2, pattern="right"), seed)
    u = _affine(random_quadratic(rng))
    pb = patch_problem(mesh, MATERIAL, u, {"left": "D", "bottom": "D", "top": "N", "right": "N"})
    r = solve(pb, element="P1")
    exact = u.value(r.space.node_points)
    err = np.abs(r.u - exact).max() / np.abs(exact).max()
    coef = r.space.field_coefficients(r.u)
    energy = np.sqrt(energy_error2(r.space.mapping, coef, u.gradient, MATERIAL).sum())
    print(f"seed {seed}: {r.ndof} unknowns, nodal error {err:.1e}, energy error {energy:.1e}")
    assert r.space.element is P1 and r.u.shape == (mesh.n_points, 2)
    assert err < 1e-12
    assert energy < 1e-11


def contact_patch(angle: float):
    """The P1 solution of an affine field with u·n = ψ, σ_t = 0 and σ_nn = −p < 0 on Γ_C
    (the bottom side, rotated by ``angle``), and p."""
    rng = np.random.default_rng(int(angle))
    R = rotation(angle)
    lam, mu = MATERIAL.lam, MATERIAL.mu
    q = random_quadratic(rng)
    G = q.G.copy()
    G[1, 0] = -G[0, 1]  # σ_12 = 0 on y = 0
    p = 1.0 + rng.uniform()
    G[1, 1] = (-p - lam * G[0, 0]) / (lam + 2 * mu)  # σ_22 = −p
    u = Quadratic(q.c, G, np.zeros((2, 2, 2))).rotated(R)
    base = nvb_mesh(refine_uniform(rectangle(0, 2, 0, 1, nx=4, ny=2)).mesh, int(angle) + 7)
    mesh = rotated_mesh(base, R, square_sides(x1=2.0))
    kinds = {"top": "D", "left": "N", "right": "N", "bottom": "C"}
    pb = patch_problem(mesh, MATERIAL, u, kinds, normal=R @ [0.0, -1.0])
    return solve(pb, element="P1"), p, u


@pytest.mark.parametrize("angle", [0.0, 30.0, 200.0])
def test_p1_contact_patch_test(angle):
    """An affine field with u·n = ψ, σ_t = 0 and σ_nn < 0 on Γ_C is the P1 solution: every
    node active, Λ_z = p |e|/2 summed (the P1 weights), the density s_z = p exactly."""
    r, p, u = contact_patch(angle)
    exact = u.value(r.space.node_points)
    err = np.abs(r.u - exact).max() / np.abs(exact).max()
    kkt = r.report.kkt.columns()
    density_err = np.abs(r.density - p).max() / p
    print(
        f"angle {angle}: {r.contact.size} constrained vertices, nodal error {err:.1e}, "
        f"density error {density_err:.1e}, total force {r.total_contact_force:.12g} = p L "
        f"{2 * p:.12g}; KKT {kkt}"
    )
    assert r.contact.size >= 9 and r.contact.is_vertex.all() and r.active.all()
    assert r.contact.facet_nodes.shape[1] == 2
    assert err < 1e-12
    assert density_err < 1e-10
    assert abs(r.total_contact_force - 2 * p) < 1e-10 * p
    assert max(kkt.values()) < 1e-12
    # the nodal stress (VTU) is the constant exact stress; the profile along Γ_C has p
    sigma = u.stress(r.space.node_points, MATERIAL)
    assert np.abs(r.nodal_stress[:, :2, :2] - sigma).max() < 1e-11 * p
    profile = r.contact_profile("bottom")
    assert np.array_equal(np.sort(profile.nodes), r.contact.nodes)  # every vertex, in order
    assert np.allclose(profile.s[-1], 2.0, rtol=1e-12)
    assert np.nanmax(np.abs(profile.pressure - p)) < 1e-10 * p


@pytest.mark.parametrize("example", [example_6_1, example_6_2])
def test_p1_kkt_residuals_on_the_paper_examples(example):
    pb = example()
    mesh = refine_uniform(refine_uniform(pb.mesh).mesh).mesh
    r = solve(pb, mesh, element="P1")
    kkt = r.report.kkt.columns()
    print(f"{pb.name} P1, {r.ndof} unknowns: {kkt}")
    assert r.ndof == 2 * mesh.n_points - 2 * r.dirichlet_nodes.size
    assert max(kkt.values()) < 1e-12
    assert r.active.any()


def test_an_unknown_element_is_refused_naming_the_argument():
    pb = example_6_2()
    for bad in ("P3", 2, None):
        with pytest.raises(ValueError, match=r"element must be one of \('P1', 'P2'\), got"):
            solve(pb, element=bad)
    with pytest.raises(ValueError, match="element must be one of"):
        assemble(pb, pb.mesh, element="Q1")
    with pytest.raises(ValueError, match="element must be one of"):
        element_of("P3")
    with pytest.raises(OptionError, match="element must be one of") as err:
        AdaptiveOptions(element="P3")
    assert err.value.field == "element"
    with pytest.raises(OptionError, match="element must be one of"):
        adaptive(pb, element="P3")  # refused at the call, before any work


def test_the_element_option_is_recorded_and_read_back():
    options = AdaptiveOptions(element="p1")
    assert options.element == "P1" and options.to_record()["element"] == "P1"
    assert AdaptiveOptions.from_record(options.to_record()).element == "P1"
    old = {k: v for k, v in AdaptiveOptions().to_record().items() if k != "element"}
    assert AdaptiveOptions.from_record(old).element == "P2"  # a manifest from before P1
