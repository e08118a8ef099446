"""The geometry kernels by dimension: det J, J⁻ᵀ, J⁻¹ and facet normals, against NumPy's
linear algebra in 3D and bit for bit against the 2D closed forms the package always used."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.mesh import jacobians
from signorini.mesh.geometry import facet_normals, signed_area, spanned_normals


def _well_conditioned(d: int, m: int = 200, seed: int = 3) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.eye(d) + 0.3 * rng.standard_normal((m, d, d))


def _old_det(J):
    return J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0]


def _old_inverse_transpose(J, det):
    out = np.empty_like(J)
    out[..., 0, 0] = J[..., 1, 1]
    out[..., 0, 1] = -J[..., 1, 0]
    out[..., 1, 0] = -J[..., 0, 1]
    out[..., 1, 1] = J[..., 0, 0]
    out /= det[..., None, None]
    return out


def _old_affine_inverse_transpose(J, det):
    inv_det = 1.0 / det
    out = np.empty_like(J)
    out[:, 0, 0] = J[:, 1, 1] * inv_det
    out[:, 0, 1] = -J[:, 1, 0] * inv_det
    out[:, 1, 0] = -J[:, 0, 1] * inv_det
    out[:, 1, 1] = J[:, 0, 0] * inv_det
    return out


def _old_inverse(J, det):
    out = np.empty_like(J)
    out[..., 0, 0] = J[..., 1, 1]
    out[..., 0, 1] = -J[..., 0, 1]
    out[..., 1, 0] = -J[..., 1, 0]
    out[..., 1, 1] = J[..., 0, 0]
    out /= det[..., None, None]
    return out


def _same_bits(a, b):
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


def test_two_dimensional_branch_is_the_old_closed_form_bit_for_bit():
    J = _well_conditioned(2, m=500).reshape(50, 10, 2, 2)
    det = jacobians.determinant(J)
    assert _same_bits(det, _old_det(J))
    assert _same_bits(jacobians.inverse_transpose(J, det), _old_inverse_transpose(J, det))
    assert _same_bits(jacobians.inverse(J), _old_inverse(J, det))
    flat = J.reshape(-1, 2, 2)
    assert _same_bits(
        jacobians.inverse_transpose(flat, reciprocal=True),
        _old_affine_inverse_transpose(flat, _old_det(flat)),
    )


def test_inverse_keeps_the_memory_layout_of_a_transposed_view():
    J = np.swapaxes(_well_conditioned(2), -1, -2)
    assert _same_bits(jacobians.inverse(J), _old_inverse(J, _old_det(J)))
    assert jacobians.inverse(J).strides == np.empty_like(J).strides


def test_affine_jacobian_in_two_dimensions_is_the_old_one():
    v = np.random.default_rng(1).standard_normal((40, 3, 2))
    J, det = jacobians.affine_jacobian(v)
    old = np.stack([v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]], axis=2)
    assert _same_bits(J, old) and _same_bits(det, _old_det(old))


@pytest.mark.parametrize("d", [2, 3])
def test_kernels_match_numpy_linear_algebra(d):
    J = _well_conditioned(d)
    det = jacobians.determinant(J)
    np.testing.assert_allclose(det, np.linalg.det(J), rtol=1e-13)
    inv = np.linalg.inv(J)
    np.testing.assert_allclose(jacobians.inverse(J), inv, rtol=1e-13, atol=1e-13 * abs(inv).max())
    jit = np.swapaxes(inv, -1, -2)
    for reciprocal in (False, True):
        got = jacobians.inverse_transpose(J, det, reciprocal=reciprocal)
        np.testing.assert_allclose(got, jit, rtol=1e-13, atol=1e-13 * abs(jit).max())
    np.testing.assert_allclose(
        jacobians.cofactor(J), det[:, None, None] * jit, rtol=1e-13, atol=1e-13
    )


def test_affine_jacobian_of_a_tetrahedron_and_its_signed_volume():
    rng = np.random.default_rng(2)
    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]) + 0.1 * rng.random((30, 4, 3))
    J, det = jacobians.affine_jacobian(v)
    np.testing.assert_allclose(J, np.swapaxes(v[:, 1:] - v[:, :1], 1, 2), rtol=0, atol=0)
    np.testing.assert_allclose(det, np.linalg.det(J), rtol=1e-13)
    points, cells = v.reshape(-1, 3), np.arange(120).reshape(30, 4)
    np.testing.assert_allclose(signed_area(points, cells), det / 6, rtol=1e-15)


def test_triangle_facet_normal_and_measure():
    rng = np.random.default_rng(4)
    corners = rng.standard_normal((50, 3, 3))
    measure, normal = facet_normals(corners)
    n = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    norm = np.linalg.norm(n, axis=1)
    np.testing.assert_allclose(measure, 0.5 * norm, rtol=1e-14)
    np.testing.assert_allclose(normal, n / norm[:, None], rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(normal, axis=1), 1.0, rtol=1e-15)


def test_2d_facet_normals_are_the_old_closed_form_bit_for_bit():
    rng = np.random.default_rng(5)
    a, b = rng.standard_normal((2, 7, 9, 2))
    d = b - a
    length = np.hypot(d[..., 0], d[..., 1])
    normal = np.stack([d[..., 1], -d[..., 0]], axis=-1) / length[..., None]
    measure, facet_normal = facet_normals(np.stack([a, b], axis=-2))
    assert _same_bits(measure, length) and _same_bits(facet_normal, normal)
    element, tangent_normal = spanned_normals(d[..., None, :])
    assert _same_bits(element, length) and _same_bits(tangent_normal, normal)
