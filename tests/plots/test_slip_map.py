"""The stick/slip map of Γ_C (plots.slip_map): the file is written and the drawn data are the
given states and the slip directions projected onto the obstacle plane."""

import numpy as np
import pytest

from signorini.plots.slip_map import plot_slip_map


def test_slip_map_draws_the_states_and_directions(tmp_path):
    rng = np.random.default_rng(3)
    # two six-node faces of the plane z = 0, normals +z
    vertices = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    tri = np.array([[0, 1, 2], [1, 3, 2]])
    edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    unique, index = np.unique(edges, axis=0, return_inverse=True)
    points = np.vstack([vertices, vertices[unique].mean(axis=1)])
    faces = np.hstack([tri, 4 + index.reshape(3, 2).T])
    m = points.shape[0]
    state = rng.integers(0, 3, m)
    state[:3] = [0, 1, 2]
    angle = rng.uniform(0, 2 * np.pi, m)
    direction = np.stack([np.cos(angle), np.sin(angle), np.zeros(m)], axis=1)
    normal = np.tile([0.0, 0.0, 1.0], (m, 1))
    written, drawn = plot_slip_map(
        points, faces, state, direction, normal, tmp_path / "map", circles={"c": 0.3, "a": 0.6}
    )
    assert {p.suffix for p in written} == {".png", ".pdf"} and all(p.is_file() for p in written)
    np.testing.assert_array_equal(drawn["state"], state)
    np.testing.assert_array_equal(drawn["uv"], points[:, :2])
    np.testing.assert_array_equal(drawn["slip"], np.flatnonzero(state == 2))
    np.testing.assert_allclose(drawn["arrows"], direction[state == 2, :2], atol=1e-15)
    with pytest.raises(ValueError, match="state"):
        plot_slip_map(points, faces, state[:-1], direction, normal, tmp_path / "bad")
