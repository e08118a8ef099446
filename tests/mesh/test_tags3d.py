"""The initial tagging of an arbitrary tetrahedral mesh (mesh/tags3d.py): the greedy vertex
colouring, Diening–Gehring–Storn's order, its equivalence with Maubach's tag 3, and local
refinement of a Gmsh mesh that stays conforming with bounded closure rounds and classes."""

from __future__ import annotations

import logging
import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial import Delaunay

from signorini.mesh import read_mesh
from signorini.mesh.bisect3d import bisect_tagged, boundary_of
from signorini.mesh.mesh import Mesh
from signorini.mesh.quality3d import similarity_forms
from signorini.mesh.refine3d import tags_of
from signorini.mesh.tags3d import (
    COLOURING_SEED,
    Tags,
    coloured_tags,
    greedy_colouring,
    mesh_cells,
)

from .test_bisect3d import assert_conforming
from .test_gmsh3d import gmsh_file

#: The bound of Maubach's rule on the similarity classes of one cell's descendants,
#: n! n 2^(n-2) for n = 3 (Diening, Gehring, Storn, Theorem 8).
CLASSES_PER_CELL = 36


def perturbed_box(n: int = 4, seed: int = 3) -> Mesh:
    """The Delaunay mesh of an n³ grid of the unit cube with every point moved by up to a
    third of the spacing (points in general position: an unstructured mesh of their convex
    hull, slivers included, no Kuhn paths), its boundary one part."""
    rng = np.random.default_rng(seed)
    g = np.linspace(0.0, 1.0, n + 1)
    points = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)
    points += rng.uniform(-1, 1, points.shape) / (3 * n)
    cells = Delaunay(points).simplices
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # slivers
        return Mesh.from_arrays(points, cells, {"boundary": lambda x: np.ones(len(x), bool)})


def test_the_colouring_is_the_sequential_greedy_one_in_its_order():
    mesh = perturbed_box()
    colour = greedy_colouring(mesh.edges, mesh.n_points)
    assert np.all(colour[mesh.edges[:, 0]] != colour[mesh.edges[:, 1]])  # proper
    degree = np.bincount(mesh.edges.ravel(), minlength=mesh.n_points)
    assert colour.max() + 1 <= degree.max() + 1
    # the reference: one vertex at a time, highest priority first (a small mesh)
    priority = np.random.default_rng(COLOURING_SEED).permutation(mesh.n_points)
    neighbours = [[] for _ in range(mesh.n_points)]
    for a, b in mesh.edges.tolist():
        neighbours[a].append(b)
        neighbours[b].append(a)
    expected = np.full(mesh.n_points, -1)
    for v in np.argsort(-priority):
        used = {expected[w] for w in neighbours[v]}
        expected[v] = min(set(range(len(used) + 1)) - used)
    np.testing.assert_array_equal(colour, expected)
    print(f"{mesh.n_points} points, largest degree {degree.max()}: {colour.max() + 1} colours")


def test_the_coloured_order_agrees_on_every_face_and_puts_the_top_colour_first():
    mesh = perturbed_box()
    colour = greedy_colouring(mesh.edges, mesh.n_points)
    order = coloured_tags(mesh.cells, colour)
    np.testing.assert_array_equal(np.sort(order, axis=1), np.sort(mesh.cells, axis=1))
    top = (colour[mesh.cells] == colour.max()).any(axis=1)
    np.testing.assert_array_equal(colour[order[top, 0]], colour.max())
    rest = colour[order[~top]]
    assert np.all(np.diff(rest, axis=1) > 0)
    assert np.all(np.diff(colour[order[top, 1:]], axis=1) > 0)
    # each face as the ordered triple its cell's order leaves: the same in both its cells
    keep = np.array([[k for k in range(4) if k != j] for j in range(4)])
    faces = order[:, keep].reshape(-1, 3)
    key = np.sort(faces, axis=1)
    by = np.lexsort(key.T[::-1])
    key, faces = key[by], faces[by]
    twin = np.all(key[1:] == key[:-1], axis=1)
    assert twin.sum() == np.sum(mesh.facet2cell[:, 1] >= 0)
    np.testing.assert_array_equal(faces[1:][twin], faces[:-1][twin])


def _maubach(cells: list[tuple[tuple[float, ...], ...]], tags: list[int]):
    """One bisection of every cell by Maubach's rule: ``[v0 .. v3]_g`` cut at the midpoint
    m of v0–v_g into ``v`` with v_g replaced by m and ``[v1 .. v_g, m, v_{g+1} .. v3]``, both
    of tag g - 1 (3 after 1)."""
    out, out_tags = [], []
    for v, g in zip(cells, tags, strict=True):  # a handful of cells of one tetrahedron
        m = tuple((np.array(v[0]) + np.array(v[g])) / 2)
        out += [(*v[:g], m, *v[g + 1 :]), (*v[1 : g + 1], m, *v[g + 1 :])]
        out_tags += [g - 1 if g > 1 else 3] * 2
    return out, out_tags


def test_maubach_tag_three_bisects_as_type_zero():
    """The initialisation's [y0, y1, y2, y3]_3 is the type-0 tagged cell (y0, y1, y2, y3)_0 of
    bisect3d: the same cells at each of six generations."""
    rng = np.random.default_rng(5)
    points = rng.random((4, 3))
    order = np.array([[2, 0, 3, 1]])
    tags = Tags(order, np.zeros(1, np.int8), np.ones(1, np.int8), np.full((1, 4), -1))
    reference = [tuple(map(tuple, points[order[0]]))], [3]
    for _ in range(6):
        result = bisect_tagged(points, tags, np.ones(tags.order.shape[0], dtype=bool))
        points, tags = result.points, result.tags
        reference = _maubach(*reference)
        ours = {frozenset(map(tuple, np.round(points[c], 12))) for c in tags.order}
        theirs = {frozenset(map(tuple, np.round(np.array(c), 12))) for c in reference[0]}
        assert ours == theirs


def test_local_refinement_of_a_gmsh_mesh_conforms_with_bounded_rounds_and_classes(tmp_path, caplog):
    """A Delaunay mesh written as a Gmsh file and read back, tagged by default (the
    colouring), refined 12 times towards a boundary region and 6 times towards a vertex:
    conforming, the closure estimate (cells added over cells marked) bounded and not
    growing, a few closure rounds per step, at most 36 classes per initial cell."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # slivers
        mesh = read_mesh(gmsh_file(perturbed_box(3), tmp_path / "box.msh"))
    with caplog.at_level(logging.INFO, logger="signorini.mesh.refine3d"):
        tags = tags_of(mesh)
    assert "greedy colouring" in caplog.text
    points, base = mesh.points, np.arange(mesh.n_cells)
    corner = np.argmin(points.sum(axis=1))  # the vertex nearest (0, 0, 0)
    rounds, ratio, n_marked = [], [], 0
    for level in range(18):
        if level < 12:  # the boundary faces within x, z < 0.3 (cells shrink towards them)
            near = (points[tags.order][..., [0, 2]] < 0.3).all(axis=(1, 2))
            marked = near & (tags.face_part >= 0).any(axis=1)
        else:  # the corner vertex
            marked = (tags.order == corner).any(axis=1)
        n_marked += int(marked.sum())
        result = bisect_tagged(points, tags, marked)
        points, tags, base = result.points, result.tags, base[result.parent]
        rounds.append(result.rounds)
        ratio.append((tags.order.shape[0] - mesh.n_cells) / n_marked)
        if level in (11, 17):
            cells = mesh_cells(tags)
            boundary, _ = boundary_of(cells, tags)
            assert_conforming(SimpleNamespace(points=points, cells=cells, boundary=boundary))
    deepest = np.argsort(np.bincount(base))[-12:]  # the 12 most refined initial cells
    mine = np.flatnonzero(np.isin(base, deepest))
    forms = similarity_forms(points, cells[mine])
    per_cell = np.unique(np.column_stack([base[mine], forms]), axis=0)[:, 0]
    per_cell = np.unique(per_cell, return_counts=True)[1]
    print(
        f"{mesh.n_cells} -> {cells.shape[0]} cells; rounds per step {rounds}; cells added "
        f"per cell marked {np.round(ratio, 2).tolist()}; classes per initial cell at most "
        f"{per_cell.max()}"
    )
    assert per_cell.max() <= CLASSES_PER_CELL
    assert max(rounds) <= 16 and max(rounds[12:]) <= 4
    assert max(ratio) <= 16 and ratio[-1] < 0.5 * max(ratio)
    volume = np.linalg.det(points[cells][:, 1:] - points[cells][:, :1]).sum() / 6
    assert volume == pytest.approx(mesh.volume.sum(), rel=1e-13)
