"""Stresses of a discrete field (:mod:`signorini.fem.postprocess`): ``div sigma(u_h)``,
tractions in cells and on edges, and the traction jump across an interior edge."""

import numpy as np
from contact_problems import random_quadratic
from fem_problems import SquareMesh

from signorini.fem import p2
from signorini.fem.material import Material
from signorini.fem.postprocess import cell_stress, div_stress, facet_traction, traction

RNG = np.random.default_rng(5)
MAT = Material.from_lame(1.3, 0.8)


def test_div_stress_traction_and_facet_traction_for_quadratic_field():
    mesh = SquareMesh(3, RNG, perturb=0.3)
    u = random_quadratic(RNG)
    u_cell = mesh.interpolate(u.value)[mesh.cell_dofs]
    m = len(mesh.cells)
    assert np.allclose(div_stress(mesh.vertices, u_cell, MAT), u.div_stress(MAT), atol=1e-10)
    xi = np.array([[0.2, 0.3], [0.6, 0.1]])
    x = p2.physical_points(mesh.vertices, xi)
    assert np.allclose(cell_stress(mesh.vertices, u_cell, MAT, xi), u.stress(x, MAT), atol=1e-11)
    nrm = RNG.standard_normal((m, 2))
    tr = traction(mesh.vertices, u_cell, MAT, xi, nrm)
    assert np.allclose(tr, np.einsum("mqij,mj->mqi", u.stress(x, MAT), nrm), atol=1e-11)
    # one normal for all cells, and one per point
    one = traction(mesh.vertices, u_cell, MAT, xi, nrm[0])
    assert np.allclose(one, np.einsum("mqij,j->mqi", u.stress(x, MAT), nrm[0]), atol=1e-11)
    per_point = np.broadcast_to(nrm[:, None, :], (m, 2, 2))
    assert np.allclose(traction(mesh.vertices, u_cell, MAT, xi, per_point), tr, atol=1e-14)
    # along every local edge: outward normal and sigma n at the right points
    t = np.array([0.0, 0.3, 1.0])
    for k in range(3):
        le = np.full(m, k)
        trac, normal = facet_traction(mesh.vertices, u_cell, MAT, le, t)
        start, end = mesh.vertices[:, k], mesh.vertices[:, (k + 1) % 3]
        centroid = mesh.vertices.mean(axis=1)
        assert np.all(np.einsum("mi,mi->m", normal, 0.5 * (start + end) - centroid) > 0)
        assert np.allclose(np.linalg.norm(normal, axis=1), 1.0)
        assert np.allclose(np.einsum("mi,mi->m", normal, end - start), 0.0, atol=1e-14)
        xs = start[:, None, :] + t[None, :, None] * (end - start)[:, None, :]
        expect = np.einsum("mqij,mj->mqi", u.stress(xs, MAT), normal)
        assert np.allclose(trac, expect, atol=1e-10)


def test_stress_jump_vanishes_for_quadratic_and_not_for_cubic():
    mesh = SquareMesh(2)
    # cell 0 = (a, b, c) and cell 4 = (a, c, d) of the first square share the diagonal a-c:
    # it is local edge 2 (c -> a) of cell 0 and local edge 0 (a -> c) of cell 4
    lower, upper = 0, 4
    assert mesh.cells[lower, 2] == mesh.cells[upper, 1]
    assert mesh.cells[lower, 0] == mesh.cells[upper, 0]
    t = np.array([0.1, 0.5, 0.8])

    def jump(field):
        u_cell = mesh.interpolate(field)[mesh.cell_dofs]
        ta, na = facet_traction(mesh.vertices[[lower]], u_cell[[lower]], MAT, np.array([2]), t)
        tb, nb = facet_traction(mesh.vertices[[upper]], u_cell[[upper]], MAT, np.array([0]), 1 - t)
        assert np.allclose(na, -nb)
        return np.abs(ta + tb).max()

    assert jump(random_quadratic(RNG).value) < 1e-12
    assert jump(lambda x: np.stack([x[..., 0] ** 3 * x[..., 1], x[..., 1] ** 3], -1)) > 1e-3
