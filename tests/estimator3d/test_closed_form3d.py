"""The closed forms of the 3D estimator (estimator/residual3d.py, estimator/faces3d.py): on
affine cells σ(u_h) is linear, so the vertex stresses and η2's face integrals taken without
quadrature points equal the general path through the cells' maps and the triangle rule, on
distorted affine meshes and beside curved (isoparametric) cells."""

from __future__ import annotations

import numpy as np
import pytest
from fem3d_problems import MATERIAL, distorted_box

from signorini.estimator import residual3d as r3
from signorini.estimator.faces3d import TetStress, face_geometry
from signorini.fem.elasticity3d import cell_stress_3d
from signorini.fem.p2_tet import REFERENCE_NODES
from signorini.fem.quadrature import triangle_rule
from signorini.fem.space3d import P2TetSpace
from signorini.mesh.builders3d import eighth_ball


def _space(kind: str) -> P2TetSpace:
    if kind == "distorted":
        return P2TetSpace(distorted_box(4, amount=0.3, seed=7))
    return P2TetSpace(eighth_ball(2))


def _field(space: P2TetSpace, seed: int) -> np.ndarray:
    """A random P2 field (any field: the closed forms do not need a solution)."""
    return np.random.default_rng(seed).standard_normal((space.n_nodes, 3))


@pytest.mark.parametrize("kind", ["distorted", "curved"])
def test_vertex_stresses_equal_the_stress_through_the_maps(kind):
    space = _space(kind)
    u = _field(space, 1)
    stresses = TetStress(space, u, MATERIAL)
    through_maps = cell_stress_3d(space, MATERIAL, u, REFERENCE_NODES[:4]) / stresses.unit
    scale = np.abs(through_maps).max()
    assert np.abs(stresses.vertex_stress - through_maps).max() <= 1e-12 * scale


@pytest.mark.parametrize("kind", ["distorted", "curved"])
def test_closed_form_jumps_equal_the_triangle_rule(kind):
    space = _space(kind)
    stresses = TetStress(space, _field(space, 2), MATERIAL)
    mesh = space.mesh
    faces = r3._face_set(space, np.flatnonzero(mesh.facet2cell[:, 1] >= 0))
    s, w = triangle_rule(r3.FACE_DEGREE)
    closed = r3._jumps(space, stresses, faces, s, w)
    by_rule = np.zeros_like(closed)
    for rows, geometry in face_geometry(space, faces.nodes):
        by_rule[rows] = r3._jumps_by_rule(
            stresses, faces.cells[rows], faces.nodes[rows], geometry, s, w
        )
    assert by_rule.min() > 0.0  # a random field jumps on every face
    assert np.abs(closed - by_rule).max() <= 1e-12 * by_rule.max()
    if kind == "curved":  # both paths are taken
        affine = r3._affine(space, faces.cells).all(axis=1)
        assert affine.any() and not affine.all()


def test_linear_square_is_the_exact_integral_on_random_triangles():
    """Against a degree-2-exact rule written here (the three edge midpoints, weights 1/3)."""
    rng = np.random.default_rng(3)
    corners = rng.standard_normal((20, 3, 3))
    area = 0.5 * np.linalg.norm(
        np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1
    )
    values = rng.standard_normal((20, 3, 4))
    mid = 0.5 * (values + np.roll(values, -1, axis=1))
    exact = area / 3.0 * np.einsum("kjc,kjc->k", mid, mid)
    assert np.allclose(r3.linear_square(values, area), exact, rtol=1e-13, atol=0)
