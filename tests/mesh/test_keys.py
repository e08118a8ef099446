"""Keys of vertex sets (:func:`signorini.mesh.topology.common_keys`): equal exactly for equal
sets and ordered as the sorted rows, on both sides of the int64 limit of base-``n`` digits
(faces: ``n = 2**21``; cells: ``n = 55108``), and meshes beyond it."""

from __future__ import annotations

import numpy as np
import pytest
from contact3d_problems import mirrored

from signorini.mesh import MeshError
from signorini.mesh.builders3d import box, eighth_ball, quarter_cylinder
from signorini.mesh.reference import TETRAHEDRON
from signorini.mesh.topology import (
    KEY_LIMIT,
    common_keys,
    entity_keys,
    entity_topology,
    find_rows,
)


def _sets(n_points: int, k: int, rows: int, seed: int) -> np.ndarray:
    """``(rows, k)`` distinct vertices each, most near the top of ``[0, n_points)`` (where
    base-n digits overflow first), with repeated sets in shuffled vertex order."""
    rng = np.random.default_rng(seed)
    top = n_points - 1 - rng.choice(40, size=(rows, k), replace=True)
    low = rng.integers(0, n_points, size=(rows, k))
    s = np.where(rng.random((rows, 1)) < 0.7, top, low)
    s = s[np.array([len(set(r)) == k for r in s.tolist()])]
    repeat = rng.permuted(s[rng.integers(0, len(s), len(s) // 3)], axis=1)
    return np.concatenate([s, repeat])


@pytest.mark.parametrize(
    ("n_points", "k"),
    [(2**21, 3), (2**21 + 1, 3), (10**7, 3), (55108, 4), (55109, 4), (10**7, 4), (2**40, 2)],
)
def test_keys_are_equal_for_equal_sets_and_ordered_as_the_sorted_rows(n_points, k):
    """Against Python's tuples: the keys' equalities are the sets' and ``argsort`` of the
    keys sorts the sorted rows lexicographically; two arrays keyed together compare."""
    sets = _sets(n_points, k, 3000, seed=k)
    keys = entity_keys(sets, n_points)
    assert keys.dtype == np.int64
    rows = [tuple(sorted(r)) for r in sets.tolist()]
    ranks = {t: i for i, t in enumerate(sorted(set(rows)))}
    rank = np.array([ranks[t] for t in rows])
    assert np.array_equal(keys[:, None] == keys[None, :], rank[:, None] == rank[None, :])
    order = np.argsort(keys, kind="stable")
    assert np.array_equal(rank[order], np.sort(rank))
    a, b = sets[:1800], sets[1800:]
    ka, kb = common_keys([a, b], n_points)
    want = {t: i for i, t in reversed(list(enumerate(rows[:1800])))}  # the first row of a set
    row, found = find_rows(a, b, n_points)
    assert np.array_equal(found, [t in want for t in rows[1800:]])
    assert np.array_equal(row[found], [want[t] for t in rows[1800:] if t in want])
    assert np.array_equal(ka[row[found]], kb[found])


@pytest.mark.parametrize(("n_points", "k"), [(2**21, 3), (55108, 4), (3037000499, 2)])
def test_keys_below_the_limit_are_base_n_digits(n_points, k):
    """At the largest ``n`` whose ``n**k`` fits, the keys are the sorted vertices read in
    base ``n`` (the same in every call), the largest set's key just below 2**63."""
    top = np.arange(n_points - k, n_points)[::-1][None, :]  # the largest set, reversed
    small = np.arange(k)[None, :]
    key = entity_keys(np.concatenate([top, small]), n_points)
    expect = sum(
        int(v) * n_points ** (k - 1 - j) for j, v in enumerate(range(n_points - k, n_points))
    )
    assert int(key[0]) == expect < KEY_LIMIT
    assert int(key[1]) == sum(j * n_points ** (k - 1 - j) for j in range(k))
    assert np.array_equal(entity_keys(top, n_points), key[:1])


def test_a_mesh_beyond_the_cells_limit_has_its_faces_and_duplicates_found():
    """56 004 points (cells' base-n keys overflow above 55 108): the box validates, its faces
    are those of a lexicographic sort of the cells' faces, and a duplicated cell is refused
    naming both."""
    mesh = box(1, 1, 14000, upper=(1.0, 1.0, 14000.0))
    assert mesh.n_points == 56004
    tuples = np.sort(mesh.cells[:, TETRAHEDRON.facets].reshape(-1, 3), axis=1)
    faces, inverse = np.unique(tuples, axis=0, return_inverse=True)
    assert np.array_equal(mesh.facets, faces)
    assert np.array_equal(mesh.cell2facet.ravel(), inverse.ravel())
    assert len(mesh.boundary) == 4 * 2 * 14000 + 2 * 2
    cells = np.concatenate([mesh.cells, mesh.cells[-1:, [1, 0, 3, 2]]])
    with pytest.raises(MeshError, match=f"duplicate cells {len(cells) - 2} and {len(cells) - 1}"):
        type(mesh).from_arrays(mesh.points, cells, {})


def test_face_topology_beyond_the_faces_limit():
    """Faces of cells numbered up to 10**7 (base-n face keys overflow above 2**21 points):
    the entity lists of :func:`entity_topology` are those of a lexicographic sort."""
    rng = np.random.default_rng(7)
    cells = np.sort(rng.choice(10**7, size=(2000, 4), replace=False), axis=1)
    cells = np.concatenate([cells, cells[:500, [0, 1, 2]][:, [0, 1, 2, 2]]])
    cells[2000:, 3] = 10**7 - 1 - np.arange(500)  # cells sharing a face with the first 500
    faces, cell2face, face2cell = entity_topology(cells, 10**7, TETRAHEDRON.facets)
    tuples = np.sort(cells[:, TETRAHEDRON.facets].reshape(-1, 3), axis=1)
    ref, first, inverse = np.unique(tuples, axis=0, return_index=True, return_inverse=True)
    assert np.array_equal(faces, ref)
    assert np.array_equal(cell2face.ravel(), inverse.ravel())
    assert np.array_equal(face2cell[:, 0], first // 4)
    assert (face2cell[:, 1] >= 0).sum() == 500


@pytest.mark.slow
def test_curved_builders_beyond_the_cells_limit():
    """``quarter_cylinder(32, length=2)`` (70 785 points) and ``eighth_ball(40)`` (68 921)
    were refused for int64 keys; now their volumes converge to the exact ones."""
    cylinder = quarter_cylinder(32, length=2.0)
    ball = eighth_ball(40)
    assert cylinder.n_points == 33 * 33 * 65 and ball.n_points == 41**3
    assert abs(cylinder.volume.sum() / (np.pi / 2) - 1) < 2e-3
    assert abs(ball.volume.sum() / (np.pi / 6) - 1) < 2e-3


@pytest.mark.slow
def test_the_half_ball_mirrored_from_eighth_ball_32():
    """``eighth_ball(32)`` (35 937 points) and the lower half ball made of it and its mirror
    images in x = 0 and y = 0 (139 425 points, 786 432 cells, beyond the cells' limit):
    valid, the volume four times the eighth's, the boundary parts' areas those of the
    sphere's lower half and the equatorial disc within the mesh's O(h²)."""
    eighth = eighth_ball(32)
    quarter, _ = mirrored(eighth, 0)
    half, _ = mirrored(quarter, 1)
    assert half.n_points == 65 * 65 * 33 and half.n_cells == 4 * eighth.n_cells
    assert set(half.part_names) == {"z1", "sphere"}
    assert np.isclose(half.volume.sum(), 4 * eighth.volume.sum(), rtol=1e-12)
    assert abs(half.volume.sum() / (2 * np.pi / 3) - 1) < 2e-3
    assert abs(half.part_measure("sphere") / (2 * np.pi) - 1) < 2e-3
    assert abs(half.part_measure("z1") / np.pi - 1) < 2e-3
