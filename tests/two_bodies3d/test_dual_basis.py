"""The dual basis of the transformed quadratic face basis and the mortar matrices of a 3D
pair (docs/method.md, *Two bodies in three dimensions*): biorthogonality on distorted faces
by an independent rule, the weights, the partition of unity; D and M reproduce constants,
affine and quadratic fields across non-matching meshes, every P2 field across matching ones,
and the weighted gap is the gap."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from signorini.contact.mortar3d import (
    face_duals,
    face_transform,
    mortar_coupling_3d,
)
from signorini.fem.p2 import basis_barycentric
from signorini.fem.quadrature import triangle_rule
from signorini.fem.space import space_of
from signorini.mesh.bodies import union
from signorini.mesh.builders3d import box

ALPHA = 0.2


def distorted_faces(n: int = 20, seed: int = 7) -> np.ndarray:
    """Random triangles in space, from needle-like to near equilateral (fixed seed)."""
    rng = np.random.default_rng(seed)
    tri = rng.normal(size=(n, 3, 3)) * rng.uniform(0.01, 10.0, size=(n, 1, 1))
    return tri + rng.normal(size=(n, 1, 3)) * 100.0  # far from the origin too


def integrate(tri: np.ndarray, f) -> np.ndarray:
    """``∫_F f`` per face with the degree-8 rule (not the coupling's): ``f(λ (q, 3))``
    returns ``(q, ...)``."""
    s, w = triangle_rule(8)
    lam = np.column_stack([1 - s.sum(axis=1), s])
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    return np.einsum("f,q,q...->f...", 2 * area, w, f(lam))


@pytest.mark.parametrize("alpha", [0.1, ALPHA, 0.4])
def test_biorthogonal_on_distorted_faces(alpha):
    """∫_F ψ_a φ̃_b = δ_ab w̃_b to round-off on distorted faces; w̃ = |F| (2α/3 at the
    vertices, (1 − 2α)/3 at the midpoints), positive; Σ_a ψ_a = 1."""
    tri = distorted_faces()
    weight, coef = face_duals(tri, alpha)
    T = face_transform(alpha)
    area = integrate(tri, lambda lam: np.ones(len(lam)))
    share = np.array([2 * alpha / 3] * 3 + [(1 - 2 * alpha) / 3] * 3)
    assert np.allclose(weight, area[:, None] * share, rtol=1e-13, atol=0)
    gram = integrate(tri, lambda lam: np.einsum("qa,qb->qab", *(basis_barycentric(lam) @ T.T,) * 2))
    duals = np.einsum("fab,fbc->fac", coef, gram)  # ∫ ψ_a φ̃_c
    expected = weight[:, :, None] * np.eye(6)
    assert (np.abs(duals - expected).max(axis=(1, 2)) / area).max() < 1e-12
    assert np.allclose(coef.sum(axis=1) @ T, np.ones(6), atol=1e-12)  # Σ_a ψ_a = Σ φ = 1


def test_transformed_basis_is_a_partition_of_unity():
    """Every column of T_F sums to 1 (Σ φ̃ = Σ φ = 1); T_F maps P2 onto itself
    invertibly for α < 1/2."""
    T = face_transform(ALPHA)
    assert np.allclose(T.sum(axis=0), 1.0, atol=1e-15)
    assert abs(np.linalg.det(T)) == pytest.approx((1 - 2 * ALPHA) ** 3, rel=1e-14)


def coupling(counts_upper, counts_lower, gap=0.0, slave="upper.z0", master="lower.z1"):
    upper = box(*counts_upper, lower=(0, 0, 1 + gap), upper=(1, 1, 2))
    mesh = union({"upper": upper, "lower": box(*counts_lower)})
    space = space_of(mesh, "P2")
    return space, mortar_coupling_3d(space, slave, master, alpha=ALPHA)


def transformed(c, values: np.ndarray) -> np.ndarray:
    """``T^{-T}`` of nodal values on the slave: the coefficients of the φ̃."""
    out = np.array(values, dtype=np.float64)
    for e, a, b in ((3, 0, 1), (4, 1, 2), (5, 2, 0)):  # the three sides of a face
        f = c.slave_faces
        out[f[:, e]] = (values[f[:, e]] - ALPHA * (values[f[:, a]] + values[f[:, b]])) / (
            1 - 2 * ALPHA
        )
    return out


@pytest.mark.parametrize(("upper", "lower", "slave", "master"), [
    ((3, 3, 1), (4, 4, 1), "upper.z0", "lower.z1"),
    ((3, 3, 1), (4, 4, 1), "lower.z1", "upper.z0"),
    ((2, 5, 1), (5, 3, 1), "upper.z0", "lower.z1"),
])  # fmt: skip
def test_mortar_matrices_reproduce_p2_fields_across_nonmatching_meshes(upper, lower, slave, master):
    """Σ_k M_jk = D_jj (constants: coverage 1), and Σ_k M_jk f(x_k) = D_jj f̃_j for affine
    and quadratic f (f̃ the transformed coefficients of f on the slave), to 1e-14 of max D;
    the weighted gap over D is the gap 0.01 along the slave's normal."""
    space, c = coupling(upper, lower, gap=0.01, slave=slave, master=master)
    x = space.node_points
    scale = c.D.max()
    assert np.abs(c.M.sum(axis=1).A1 - c.D).max() < 1e-14 * scale
    for f in (x[:, 0] * 2 - x[:, 1] + 0.3, x[:, 0] ** 2 - 3 * x[:, 0] * x[:, 1] + x[:, 1] ** 2):
        assert np.abs(c.M @ f - c.D * transformed(c, f)[c.slave_nodes]).max() < 1e-14 * scale
    assert np.abs(c.weighted_gap / c.D - 0.01).max() < 1e-13
    assert np.abs(np.abs(c.normal[:, 2]) - 1).max() == 0.0


def test_mortar_matrices_on_matching_meshes_transfer_every_p2_field():
    """On matching meshes the master's space is the slave's: M f = D T^{-T} f for any P2
    nodal values f (random), read at the coinciding nodes."""
    space, c = coupling((3, 2, 1), (3, 2, 1))
    x = space.node_points
    rng = np.random.default_rng(3)
    f = rng.normal(size=space.n_nodes)
    # the slave node j and the master node at its point carry the same value
    master = np.unique(c.M.indices)
    distance, at = cKDTree(x[master]).query(x[c.slave_nodes])
    assert distance.max() < 1e-14
    partner = master[at]
    f[c.slave_nodes] = f[partner]
    assert np.abs(c.M @ f - c.D * transformed(c, f)[c.slave_nodes]).max() < 1e-14 * c.D.max()
