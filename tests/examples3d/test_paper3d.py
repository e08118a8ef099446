"""The 3D paper examples: the manufactured solution of example-6.1-3d meets the Signorini
conditions pointwise (checked by finite differences, independently of its closed-form
derivatives) and its error decays like N^{-2/3}; example-6.2-3d's obstacle is interpolated
exactly on its mirrored mesh, and its solution is invariant under the problem's symmetries
(docs/method.md, *Three dimensions: the paper's examples*)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from signorini.contact.solution import solve
from signorini.examples.manufactured3d import CONTACT_CUBE
from signorini.examples.paper3d import example_6_1_3d, example_6_2_3d, pyramid
from signorini.fem.space3d import P2TetSpace
from signorini.mesh.builders3d import box, mirrored_box
from signorini.mesh.mesh import Mesh
from signorini.mesh.refine import refine_uniform
from signorini.mesh.refine3d import matches, tags_of

RNG = np.random.default_rng(38)


def _fd(field, x, h=1e-5):
    """Central differences of ``field (n, ...)`` along the three axes: ``(n, ..., 3)``."""
    return np.stack([(field(x + h * e) - field(x - h * e)) / (2 * h) for e in np.eye(3)], -1)


# ------------------------------------------------------------------------- example-6.1-3d
def test_manufactured_solution_meets_the_signorini_conditions_pointwise():
    exact = CONTACT_CUBE
    lam, mu = exact.material.lam, exact.material.mu
    x = RNG.random((400, 3))
    # the closed-form derivatives against finite differences of u and of the stress
    grad = _fd(exact.displacement, x)
    scale = np.abs(grad).max()
    np.testing.assert_allclose(exact.gradient(x), grad, rtol=0, atol=1e-8 * scale)
    div = np.einsum("nijj->ni", _fd(exact.stress, x))
    np.testing.assert_allclose(exact.body_force(x), -div, rtol=0, atol=1e-6 * np.abs(div).max())
    # on Γ_C = {z = 0}: the gap, σ_nn = −p ≤ 0, complementarity, no shear (from the FD gradient)
    y = x.copy()
    y[:, 2] = 0.0
    g = _fd(exact.displacement, y)
    eps = 0.5 * (g + np.swapaxes(g, 1, 2))
    sigma = 2 * mu * eps + lam * np.einsum("nii->n", eps)[:, None, None] * np.eye(3)
    s_scale = np.abs(sigma).max()
    gap = exact.displacement(y)[:, 2]  # ψ − u·n with ψ = 0, n = −e_z
    pressure = -sigma[:, 2, 2]
    np.testing.assert_allclose(gap, exact.gap(y), rtol=0, atol=1e-15)
    np.testing.assert_allclose(pressure, exact.pressure(y), rtol=0, atol=1e-8 * s_scale)
    assert (gap >= 0).all() and (exact.pressure(y) >= 0).all()
    assert np.abs(gap * exact.pressure(y)).max() == 0.0
    np.testing.assert_allclose(sigma[:, :2, 2], 0.0, rtol=0, atol=1e-8 * s_scale)
    # both regimes occur: contact (p > 0) inside r < 0.35, a gap outside
    r = np.hypot(y[:, 0] - 0.5, y[:, 1] - 0.5)
    assert (exact.pressure(y)[r < 0.34] > 0).all() and (exact.gap(y)[r > 0.36] > 0).all()


def test_example_6_1_3d_total_force_and_contact_disc():
    """Σ Λ_z against ∫ p = P π R⁸ / 4 (the exact force on the plane: +51 % on this coarse
    mesh, +5.6 % on the next, the slow test), every row inside the disc r < R active, and
    rows beyond it inactive (the exact gap 5 φ⁴ is below 10⁻³ up to r ≈ 0.53, so the
    discrete zone reaches past R); on the 4³ mesh (1 944 unknowns)."""
    problem = example_6_1_3d()
    result = solve(problem, refine_uniform(problem.mesh).mesh)
    exact = CONTACT_CUBE
    total = exact.p_scale * math.pi * exact.radius**8 / 4
    assert result.total_contact_force == pytest.approx(total, rel=0.6)
    x = result.space.node_points[result.contact.node]
    r = np.hypot(x[:, 0] - 0.5, x[:, 1] - 0.5)
    assert result.active[r < exact.radius].all() and not result.active[r > 0.54].any()
    assert not result.active.all()


@pytest.mark.slow
def test_example_6_1_3d_error_decays_like_n_to_the_minus_two_thirds():
    """Uniform refinement 300 → 13 872 unknowns: the energy-error rate against N over the
    last step is about −0.70 (−2/3 optimal), the L² rate about −1; the total force within
    10 % of ∫ p, its error falling."""
    problem = example_6_1_3d()
    mesh, rows = problem.mesh, []
    for _ in range(3):
        result = solve(problem, mesh)
        rows.append((result.ndof, result.errors(), result.total_contact_force))
        mesh = refine_uniform(mesh).mesh
    total = CONTACT_CUBE.p_scale * math.pi * CONTACT_CUBE.radius**8 / 4
    force_error = [abs(row[2] / total - 1) for row in rows]
    assert force_error[2] < force_error[1] < force_error[0] and force_error[2] < 0.1
    (n1, e1, _), (n2, e2, _) = rows[-2:]
    rate = math.log(e2["error_energy"] / e1["error_energy"]) / math.log(n2 / n1)
    rate_l2 = math.log(e2["error_l2"] / e1["error_l2"]) / math.log(n2 / n1)
    print(f"energy rate {rate:.3f}, L2 rate {rate_l2:.3f}")
    assert rate < -0.6 and rate_l2 < -0.9


# ------------------------------------------------------------------------- example-6.2-3d
def _face_values(mesh: Mesh, part: str, bary: np.ndarray):
    """ψ and its P2 interpolant at the barycentric points ``bary (q, 3)`` of every face of
    ``part``: ``(f, q)`` each."""
    space = P2TetSpace(mesh)
    nodes = space.facet_nodes(mesh.part_facets(part))  # (f, 6): vertices, then midpoints
    x = space.node_points[nodes]
    b = bary
    # the P2 basis of the triangle: λ_i (2 λ_i − 1), then 4 λ_i λ_j on the edges 01, 12, 20
    phi = np.column_stack([b * (2 * b - 1), 4 * b[:, [0, 1, 2]] * b[:, [1, 2, 0]]])
    points = np.einsum("qk,fkc->fqc", b, x[:, :3])
    values = pyramid(x)  # (f, 6)
    return pyramid(points), values @ phi.T, space, nodes


def test_pyramid_is_interpolated_exactly_on_the_mirrored_mesh_only():
    """The pyramid's kinks lie on the diagonals of the face x = 1: on mesh edges of
    mirrored_box (ψ_h = ψ on every face), across the faces of the plain Kuhn box."""
    bary = np.array([[1 / 3, 1 / 3, 1 / 3], [0.6, 0.3, 0.1], [0.1, 0.2, 0.7], [0.45, 0.1, 0.45]])
    for n in (2, 4):
        psi, psi_h, space, nodes = _face_values(mirrored_box(n, n, n), "x1", bary)
        np.testing.assert_allclose(psi_h, psi, rtol=0, atol=1e-15)
        psi, psi_h, *_ = _face_values(box(n, n, n), "x1", bary)
        assert np.abs(psi_h - psi).max() > 1e-3


def test_mirrored_box_is_tagged_symmetric_and_refines_so():
    for mesh in (mirrored_box(2, 2, 2), refine_uniform(mirrored_box(2, 2, 2)).mesh):
        assert matches(mesh.points, tags_of(mesh))
        codes = _codes(mesh.points)
        cells = {tuple(sorted(c)) for c in codes[mesh.cells].tolist()}
        for mirror in _SYMMETRIES.values():
            image = _codes(mirror(mesh.points))[mesh.cells]
            assert {tuple(sorted(c)) for c in image.tolist()} == cells
    with pytest.raises(ValueError, match="even"):
        mirrored_box(3, 3, 3)


#: the symmetries of example-6.2-3d: y ↔ 1 − y, z ↔ 1 − z, y ↔ z (points or vectors)
_SYMMETRIES = {
    "y": lambda p: p * [1, -1, 1] + [0, 1, 0],
    "z": lambda p: p * [1, 1, -1] + [0, 0, 1],
    "yz": lambda p: p[:, [0, 2, 1]],
}
_LINEAR = {
    "y": lambda u: u * [1, -1, 1],
    "z": lambda u: u * [1, 1, -1],
    "yz": lambda u: u[:, [0, 2, 1]],
}


def _codes(points: np.ndarray) -> np.ndarray:
    """Integer codes of points on a grid of spacing 1/64 (exact for these meshes)."""
    k = np.round(points * 64).astype(np.int64)
    return (k[:, 0] * 4096 + k[:, 1]) * 4096 + k[:, 2]


def _matching(points: np.ndarray, images: np.ndarray) -> np.ndarray:
    """``(n,)`` the index in ``points`` of each image point."""
    codes, wanted = _codes(points), _codes(images)
    order = np.argsort(codes)
    pos = order[np.searchsorted(codes[order], wanted)]
    assert np.array_equal(codes[pos], wanted)
    return pos


def _mirrored(mesh: Mesh, mirror) -> Mesh:
    """The mesh mirrored by ``mirror`` (cells re-oriented by from_arrays), same part names."""
    parts = {name: mesh.boundary[mesh.boundary_part == i] for i, name in enumerate(mesh.part_names)}
    return Mesh.from_arrays(mirror(mesh.points), mesh.cells, parts)


@pytest.mark.parametrize("name", list(_SYMMETRIES))
def test_example_6_2_3d_solution_on_a_mirrored_mesh_is_the_mirrored_solution(name):
    """On the plain Kuhn box (not symmetric: its face diagonals run one way), the solution on
    the mirrored mesh equals the mirrored solution; on the symmetric default mesh refined
    once, the solution is itself symmetric. u, Λ and the active set, to round-off."""
    mirror, linear = _SYMMETRIES[name], _LINEAR[name]
    problem = example_6_2_3d()
    for mesh, image in ((box(2, 2, 2), None), (refine_uniform(problem.mesh).mesh, "self")):
        base = solve(problem, mesh)
        other = base if image == "self" else solve(problem, _mirrored(mesh, mirror))
        x = base.space.node_points
        pos = _matching(other.space.node_points, mirror(x))
        scale = np.abs(base.u).max()
        np.testing.assert_allclose(other.u[pos], linear(base.u), rtol=0, atol=1e-12 * scale)
        # one row per node (one contact part): the image of each row
        mapped = _matching(
            other.space.node_points[other.contact.node], mirror(x[base.contact.node])
        )
        assert np.array_equal(other.active[mapped], base.active)
        force = np.abs(base.contact_force).max()
        np.testing.assert_allclose(
            other.contact_force[mapped], base.contact_force, rtol=0, atol=1e-12 * force
        )
        assert 0 < base.active.sum() < base.contact.size
        if image is None and name != "yz":  # the Kuhn box is not symmetric: nor is its u
            self_pos = _matching(x, mirror(x))
            assert np.abs(base.u[self_pos] - linear(base.u)).max() > 1e-4 * scale
