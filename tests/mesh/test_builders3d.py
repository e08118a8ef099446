"""Built-in tetrahedral meshes: box, eighth ball, quarter cylinder; surfaces."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from signorini.mesh import MeshError
from signorini.mesh.builders3d import (
    MIN_DIHEDRAL_BALL,
    MIN_DIHEDRAL_CYLINDER,
    box,
    eighth_ball,
    kuhn_grid,
    kuhn_paths,
    quarter_cylinder,
    round_corner,
)
from signorini.mesh.quality3d import dihedral_angles, min_dihedral_angle
from signorini.mesh.surfaces import Cylinder, Sphere


def _on_part(mesh, part):
    """The vertices of a part and the curved midpoints of its faces' edges."""
    index = mesh.part_index(part)
    vertices = mesh.points[np.unique(mesh.boundary[mesh.boundary_part == index])]
    return vertices, mesh.curved_midpoints[mesh.part_edge_indices(index)]


def test_box_counts_and_errors():
    mesh = box(2, 3, 4, lower=(0.0, -1.0, 0.0), upper=(1.0, 2.0, 8.0))
    assert mesh.n_cells == 6 * 24 and mesh.n_points == 3 * 4 * 5
    assert np.isclose(mesh.volume.sum(), 24.0, rtol=1e-14)
    assert mesh.reoriented.size == 0
    with pytest.raises(MeshError, match="positive integers"):
        box(0, 1, 1)
    with pytest.raises(MeshError, match="lower < upper"):
        box(1, 1, 1, upper=(1.0, 0.0, 1.0))


def test_box_regions_by_centroid():
    mesh = box(2, 2, 2, regions={"low": lambda x: x[:, 2] < 0.5, "high": lambda x: x[:, 2] > 0.5})
    assert np.isclose(mesh.volume[mesh.region_cells("low")].sum(), 0.5)


def test_round_corner_keeps_planes_and_reaches_the_sphere():
    p = np.random.default_rng(0).random((200, 3))
    p[:50, 0] = 0.0
    p[50:100, 1] = 1.0
    q = round_corner(p)
    assert np.all(q[:50, 0] == 0.0)
    np.testing.assert_allclose(np.linalg.norm(q[50:100], axis=1), 1.0, rtol=1e-15)
    assert np.all(np.linalg.norm(q, axis=1) <= np.linalg.norm(p, axis=1) + 1e-15)
    assert np.array_equal(round_corner(np.zeros((1, 3))), np.zeros((1, 3)))


def test_eighth_ball_volume_converges_like_h2_and_sphere_nodes_are_on_it():
    radius, center = 2.0, np.array([1.0, -2.0, 0.5])
    exact = np.pi / 6 * radius**3
    errors = []
    for n in (2, 4, 8):
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # no slivers
            mesh = eighth_ball(n, radius=radius, center=tuple(center))
        assert mesh.part_names == ("x0", "y0", "z1", "sphere")
        assert mesh.reoriented.size == 0 and np.all(mesh.volume > 0)
        assert np.rad2deg(mesh.min_angle()) > 30.0
        assert mesh.points[:, 2].max() == center[2]
        assert np.isclose(mesh.points[:, 2].min(), center[2] - radius, rtol=1e-15)
        vertices, mid = _on_part(mesh, "sphere")
        np.testing.assert_allclose(np.linalg.norm(vertices - center, axis=1), radius, rtol=4e-16)
        np.testing.assert_allclose(np.linalg.norm(mid - center, axis=1), radius, rtol=4e-16)
        # the symmetry planes stay planes, their curved rim midpoints in them
        for axis, part in ((0, "x0"), (1, "y0"), (2, "z1")):
            vertices, mid = _on_part(mesh, part)
            assert np.all(vertices[:, axis] == center[axis])
            np.testing.assert_allclose(mid[:, axis], center[axis], atol=1e-15)
        errors.append(exact - mesh.volume.sum())
    errors = np.array(errors)
    assert np.all(errors > 0)
    rate = np.log2(errors[:-1] / errors[1:])
    assert np.all(rate > 1.9), f"volume error rate {rate}, expected 2"


def test_eighth_ball_cells_are_mirrored_kuhn_paths():
    n = 3
    mesh = eighth_ball(n)
    grid, cells = kuhn_grid(n, n, n)
    assert np.array_equal(kuhn_paths(mesh.cells, mirrored=True), kuhn_paths(cells))


def test_quarter_cylinder_volume_and_surface():
    radius, length = 0.5, 2.0
    errors = []
    for n in (2, 4, 8):
        mesh = quarter_cylinder(n, radius=radius, length=length, center=(0.0, 0.0, -1.0))
        assert mesh.part_names == ("x0", "y0", "z0", "z1", "cylinder")
        assert np.rad2deg(mesh.min_angle()) > 20.0
        assert np.isclose(mesh.part_measure("x0"), radius * length, rtol=1e-14)
        vertices, mid = _on_part(mesh, "cylinder")
        np.testing.assert_allclose(np.hypot(*vertices[:, :2].T), radius, rtol=4e-16)
        np.testing.assert_allclose(np.hypot(*mid[:, :2].T), radius, rtol=4e-16)
        assert mesh.points[:, 2].min() == -1.0 and np.isclose(mesh.points[:, 2].max(), 1.0)
        errors.append(np.pi / 4 * radius**2 * length - mesh.volume.sum())
    rate = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all(rate > 1.9), f"volume error rate {rate}, expected 2"


def test_surfaces_project_and_halfway():
    s = Sphere((1.0, 0.0, 0.0), 2.0)
    p = s.project(np.array([[3.0, 0.0, 0.0], [1.0, 2.0, 0.0]]))
    h = s.halfway(p[:1], p[1:])
    np.testing.assert_allclose(h, [[1 + np.sqrt(2), np.sqrt(2), 0.0]])
    np.testing.assert_allclose(s.normal(h), [[np.sqrt(0.5), np.sqrt(0.5), 0.0]])
    c = Cylinder((0.0, 0.0, 0.0), (0.0, 0.0, 2.0), 1.0)
    h = c.halfway(np.array([[1.0, 0.0, 0.0]]), np.array([[0.0, 1.0, 2.0]]))
    np.testing.assert_allclose(h, [[np.sqrt(0.5), np.sqrt(0.5), 1.0]])
    with pytest.raises(MeshError, match="radius must be a positive"):
        Sphere((0, 0, 0), -1.0)
    with pytest.raises(MeshError, match="three finite numbers"):
        Cylinder((0, 0), (0, 0, 1), 1.0)


def test_with_curve_in_3d_checks_the_surface():
    mesh = box(2, 2, 2)
    with pytest.raises(MeshError, match=r"part 'x1' lies .* from Sphere"):
        mesh.with_curve("x1", Sphere((0, 0, 0), 1.0))
    with pytest.raises(MeshError, match="must be a Surface"):
        mesh.with_curve("x1", object())


def _mapped_kuhn_limit(k: int, m: int) -> float:
    """The smallest dihedral angle (degrees) of the six Kuhn cells of the unit cube mapped by
    the Jacobian of ``round_corner`` on ``[0, 1]^k`` (central differences) at ``m^k`` points:
    the limit of large ``n`` of the builders' smallest angle (the identity along z for the
    cylinder)."""
    g = np.linspace(0.0, 1.0, m)
    x = np.stack(np.meshgrid(*[g] * k, indexing="ij"), axis=-1).reshape(-1, k)
    J = np.broadcast_to(np.eye(3), (len(x), 3, 3)).copy()
    for i in range(k):  # a loop over the axes
        step = np.zeros(k)
        step[i] = 1e-6
        J[:, :k, i] = (round_corner(x + step) - round_corner(x - step)) / 2e-6
    grid, cells = kuhn_grid(1, 1, 1)
    corners = np.einsum("xij,vj->xvi", J, grid.astype(float)).reshape(-1, 3)
    mapped = (8 * np.arange(len(x))[:, None, None] + cells[None]).reshape(-1, 4)
    return float(np.degrees(dihedral_angles(corners, mapped).min()))


def test_curved_builders_keep_their_documented_smallest_dihedral_angle():
    ball = [min_dihedral_angle(m.points, m.cells) for m in map(eighth_ball, (1, 2, 4, 8))]
    cylinder = [min_dihedral_angle(m.points, m.cells) for m in map(quarter_cylinder, (1, 2, 4, 8))]
    print(f"eighth ball n = 1, 2, 4, 8: {np.round(ball, 2)}; quarter cylinder: "
          f"{np.round(cylinder, 2)}")  # fmt: skip
    np.testing.assert_allclose(ball, [45.0, 39.48, 33.74, 30.90], atol=0.01)
    np.testing.assert_allclose(cylinder, [35.26, 28.18, 24.37, 22.55], atol=0.01)
    assert np.all(np.diff(ball) < 0) and np.all(np.diff(cylinder) < 0)  # falling with n
    assert min(ball) > MIN_DIHEDRAL_BALL and min(cylinder) > MIN_DIHEDRAL_CYLINDER


@pytest.mark.slow
def test_the_smallest_dihedral_angles_tend_to_the_mapped_kuhn_cells_limit():
    """For large n the cells are the Kuhn cells mapped by the Jacobian of round_corner: its
    smallest angle over the domain is the limit, above the documented bounds, and the
    meshes at n = 24 lie between it and n = 8's."""
    ball_limit, cylinder_limit = _mapped_kuhn_limit(3, 81), _mapped_kuhn_limit(2, 401)
    ball = min_dihedral_angle(*(lambda m: (m.points, m.cells))(eighth_ball(24)))
    cylinder = min_dihedral_angle(*(lambda m: (m.points, m.cells))(quarter_cylinder(24)))
    print(f"limits {ball_limit:.2f}, {cylinder_limit:.2f}; n = 24: {ball:.2f}, {cylinder:.2f}")
    assert ball_limit == pytest.approx(28.57, abs=0.05)
    assert cylinder_limit == pytest.approx(20.89, abs=0.05)
    assert MIN_DIHEDRAL_BALL < ball_limit < ball < 30.9
    assert MIN_DIHEDRAL_CYLINDER < cylinder_limit < cylinder < 22.55
