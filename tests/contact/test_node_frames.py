"""Rotation of node DOFs into (normal, tangential) frames (signorini.contact.node_frames)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given, settings
from hypothesis import strategies as st
from linalg_problems import block_spd, p2_elasticity

from signorini.contact.node_frames import rotate_frames, to_cartesian, to_frames


def dense_Q(n_dofs, nodes, normals):
    """Reference: the full block-diagonal rotation matrix with columns [n t] at each node."""
    Q = np.eye(n_dofs)
    for z, (n1, n2) in zip(nodes, normals, strict=True):
        Q[2 * z : 2 * z + 2, 2 * z : 2 * z + 2] = [[n1, -n2], [n2, n1]]
    return Q


def random_normals(rng, k):
    angle = rng.uniform(0, 2 * np.pi, k)
    return np.column_stack([np.cos(angle), np.sin(angle)])


@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    nx=st.integers(1, 6),
    ny=st.integers(1, 6),
    frac=st.floats(0.0, 1.0),
)
def test_rotation_equals_dense_product(seed, nx, ny, frac):
    rng = np.random.default_rng(seed)
    K = block_spd(nx, ny, rng)
    n_nodes = nx * ny
    nodes = rng.permutation(n_nodes)[: int(frac * n_nodes)]
    normals = random_normals(rng, nodes.size)
    F = rng.standard_normal(2 * n_nodes)
    K_rot, F_rot = rotate_frames(K, F, nodes, normals)
    Q = dense_Q(2 * n_nodes, nodes, normals)
    assert np.abs(K_rot.toarray() - Q.T @ K.toarray() @ Q).max() < 1e-13 * np.abs(K.data).max()
    assert np.abs(F_rot - Q.T @ F).max() < 1e-14 * np.abs(F).max()
    assert np.array_equal(K_rot.indptr, K.indptr) and np.array_equal(K_rot.indices, K.indices)
    # trusting the input changes nothing on a valid system
    K_trust, F_trust = rotate_frames(K, F, nodes, normals, validate=False)
    assert np.array_equal(K_trust.data, K_rot.data) and np.array_equal(F_trust, F_rot)
    x = rng.standard_normal((2 * n_nodes, 2))
    assert np.allclose(to_frames(x, nodes, normals), Q.T @ x, rtol=0, atol=1e-14)
    assert np.allclose(to_cartesian(x, nodes, normals), Q @ x, rtol=0, atol=1e-14)


def test_rotation_on_p2_elasticity_keeps_energy():
    K, xy = p2_elasticity(3, 3)
    rng = np.random.default_rng(0)
    nodes = np.flatnonzero(xy[:, 1] < 1e-12)
    normals = np.tile([0.6, -0.8], (nodes.size, 1))
    F = rng.standard_normal(K.shape[0])
    K_rot, F_rot = rotate_frames(K, F, nodes, normals)
    u = rng.standard_normal(K.shape[0])
    y = to_frames(u, nodes, normals)
    # the energy and the work are frame invariant: y^T K_rot y = u^T K u, F_rot.y = F.u
    assert np.isclose(y @ K_rot @ y, u @ K @ u, rtol=1e-13)
    assert np.isclose(F_rot @ y, F @ u, rtol=1e-13)
    # the normal DOF is u.n
    assert np.allclose(y[2 * nodes], u[2 * nodes] * 0.6 - 0.8 * u[2 * nodes + 1], atol=1e-15)
    assert np.allclose(to_cartesian(y, nodes, normals), u, atol=1e-15)


def test_in_place():
    rng = np.random.default_rng(1)
    K = block_spd(3, 3, rng)
    F = rng.standard_normal(18)
    K0, F0 = K.copy(), F.copy()
    nodes, normals = np.array([4, 0]), random_normals(rng, 2)
    K_copy, F_copy = rotate_frames(K0, F0, nodes, normals)
    K_rot, F_rot = rotate_frames(K, F, nodes, normals, copy=False)
    assert K_rot is K and F_rot is F
    assert np.array_equal(K.data, K_copy.data) and np.array_equal(F, F_copy)
    assert not np.array_equal(K0.data, K.data)


def test_not_block_pattern_raises():
    # column 2 stored without column 3 in row 0 (and symmetric): node 1 is not node-blocked
    A = sp.csr_matrix(
        np.array(
            [
                [4.0, 1.0, 1.0, 0.0],
                [1.0, 4.0, 1.0, 1.0],
                [1.0, 1.0, 4.0, 1.0],
                [0.0, 1.0, 1.0, 4.0],
            ]
        )
    )
    with pytest.raises(ValueError, match="2x2 node-block pattern"):
        rotate_frames(A, np.zeros(4), [1], [[0.0, 1.0]])
    # node 0: rows 0 and 1 store different columns
    with pytest.raises(ValueError, match="rows 2z, 2z\\+1 of node 0"):
        rotate_frames(A, np.zeros(4), [0], [[0.0, 1.0]])
    # rows 2 and 3 match, but row 0 stores column 2 without column 3
    B = np.ones((4, 4)) + 3 * np.eye(4)
    B[0, 3] = 0.0
    with pytest.raises(ValueError, match="columns 2z and 2z\\+1"):
        rotate_frames(sp.csr_matrix(B), np.zeros(4), [1], [[0.0, 1.0]])
    full = sp.csr_matrix(np.ones((4, 4)) + 3 * np.eye(4))
    K_rot, _ = rotate_frames(full, np.zeros(4), [0, 1], [[0.0, 1.0], [1.0, 0.0]])
    Q = dense_Q(4, [0, 1], [[0.0, 1.0], [1.0, 0.0]])
    assert np.allclose(K_rot.toarray(), Q.T @ full.toarray() @ Q, atol=1e-15)


@pytest.mark.parametrize(
    "nodes,normals,message",
    [
        ([0], [[1.0, 1.0]], "unit vectors"),
        ([0], [[0.0, 0.0]], "unit vectors"),
        ([0, 0], [[1.0, 0.0], [1.0, 0.0]], "repeated"),
        ([5], [[1.0, 0.0]], r"nodes must lie in \[0, 2\)"),
        ([0, 1], [[1.0, 0.0]], r"normals must have shape \(2, 2\)"),
        ([0.5], [[1.0, 0.0]], "integer"),
        ([0], [[np.nan, 1.0]], "non-finite"),
    ],
)
def test_bad_frames_raise(nodes, normals, message):
    K = sp.identity(4, format="csr")
    with pytest.raises(ValueError, match=message):
        rotate_frames(K, np.zeros(4), nodes, normals)


def test_bad_system_raises():
    with pytest.raises(ValueError, match="F must have shape"):
        rotate_frames(sp.identity(4, format="csr"), np.zeros(3), [0], [[1.0, 0.0]])
    with pytest.raises(ValueError, match="even size"):
        rotate_frames(sp.identity(3, format="csr"), np.zeros(3), [0], [[1.0, 0.0]])


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), nx=st.integers(1, 5), ny=st.integers(1, 5))
def test_general_frames_equal_dense_product(seed, nx, ny):
    """Corner frames Q_z = A_z⁻¹ (rows of A_z: two constraint directions) mixed with
    rotations: K_rot = Qᵀ K Q, y = Q⁻¹ x, and the frame unknowns are (u·n, u·m)."""
    rng = np.random.default_rng(seed)
    K = block_spd(nx, ny, rng)
    n_nodes = nx * ny
    nodes = rng.permutation(n_nodes)[: max(1, n_nodes // 2)]
    n, m = random_normals(rng, nodes.size), random_normals(rng, nodes.size)
    # directions at least 0.2 rad apart, so that A_z is well conditioned
    cross = np.abs(n[:, 0] * m[:, 1] - n[:, 1] * m[:, 0])
    m[cross < np.sin(0.2)] = n[cross < np.sin(0.2)] @ [[0.0, 1.0], [-1.0, 0.0]]
    frames = np.linalg.inv(np.stack([n, m], axis=1))
    F = rng.standard_normal(2 * n_nodes)
    K_rot, F_rot = rotate_frames(K, F, nodes, frames)
    Q = np.eye(2 * n_nodes)
    for z, Qz in zip(nodes, frames, strict=True):
        Q[2 * z : 2 * z + 2, 2 * z : 2 * z + 2] = Qz
    scale = np.abs(K.data).max() * np.abs(frames).max() ** 2
    assert np.abs(K_rot.toarray() - Q.T @ K.toarray() @ Q).max() < 1e-13 * scale
    assert np.abs(F_rot - Q.T @ F).max() < 1e-13 * np.abs(F).max() * np.abs(frames).max()
    u = rng.standard_normal(2 * n_nodes)
    y = to_frames(u, nodes, frames)
    un = np.einsum("kc,kc->k", u.reshape(-1, 2)[nodes], n)
    um = np.einsum("kc,kc->k", u.reshape(-1, 2)[nodes], m)
    assert np.allclose(y[2 * nodes], un, atol=1e-13) and np.allclose(
        y[2 * nodes + 1], um, atol=1e-13
    )
    assert np.allclose(to_cartesian(y, nodes, frames), u, atol=1e-13)


def test_singular_frame_is_refused():
    K = sp.identity(4, format="csr")
    with pytest.raises(ValueError, match=r"the frame normals\[0\] is singular"):
        rotate_frames(K, np.zeros(4), [0], [[[1.0, 1.0], [1.0, 1.0]]])


@pytest.mark.parametrize("which", ["example-6.2", "two-cylinders"])
def test_the_assemblys_rotation_reads_only_the_rows_near_the_frames(which):
    """Without validation, on a whole matrix (its pattern symmetric, no row empty), the
    columns of the frame nodes are looked for only in the rows those nodes couple with; the
    rotated matrix is the one of the scan of every entry, bit for bit."""
    from signorini import example_6_2
    from signorini.contact import assemble
    from signorini.contact.node_frames import rotate_frames
    from signorini.examples import two_cylinders

    problem = example_6_2() if which == "example-6.2" else two_cylinders()
    a = assemble(problem, problem.mesh)
    rng = np.random.default_rng(7)
    nodes = np.union1d(a.frame_nodes, rng.choice(a.space.n_nodes, 40, replace=False))
    normals = random_normals(rng, nodes.size)
    F = np.arange(a.K.shape[0], dtype=float)
    near, F_near = rotate_frames(a.K, F, nodes, normals, validate=False)
    every, F_every = rotate_frames(a.K, F, nodes, normals, validate=True)
    assert np.array_equal(near.data, every.data) and np.array_equal(F_near, F_every)
    assert not np.array_equal(near.data, a.K.data)
    Q = sp.csr_matrix(dense_Q(a.K.shape[0], nodes, normals))
    reference = (Q.T @ a.K @ Q).toarray()
    assert np.abs(near.toarray() - reference).max() <= 1e-12 * np.abs(reference).max()
