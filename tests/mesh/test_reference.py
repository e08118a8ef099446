"""The reference cells: the triangle's table is today's convention, the tetrahedron's is
consistent with it and with itself."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.fem import p2
from signorini.fem.mapping import EDGE_NODES
from signorini.mesh.reference import INTERVAL, TETRAHEDRON, TRIANGLE


def test_the_triangle_states_the_package_convention():
    """Local edge k joins vertices k and k + 1 mod 3; its facets are its edges, intervals;
    the P2 node of edge k is 3 + k, as in meshio's triangle6."""
    k = np.arange(3)
    assert TRIANGLE.edges.tolist() == np.column_stack([k, (k + 1) % 3]).tolist()
    assert TRIANGLE.facets.tolist() == TRIANGLE.edges.tolist()
    assert TRIANGLE.facet_cell is INTERVAL and INTERVAL.facet_cell is None
    assert TRIANGLE.edge_nodes.tolist() == [[0, 1, 3], [1, 2, 4], [2, 0, 5]]
    assert np.array_equal(EDGE_NODES, TRIANGLE.edge_nodes)
    assert np.array_equal(p2.REFERENCE_NODES[:3], TRIANGLE.vertices)
    assert (TRIANGLE.vtk_name, TRIANGLE.vtk_p2_name) == ("triangle", "triangle6")
    assert (INTERVAL.vtk_p2_name, INTERVAL.edge_nodes.tolist()) == ("line3", [[0, 1, 2]])


@pytest.mark.parametrize("cell", [INTERVAL, TRIANGLE, TETRAHEDRON], ids=repr)
def test_a_table_is_read_only_and_of_its_dimension(cell):
    assert cell.vertices.shape == (cell.n_vertices, cell.dim)
    assert cell.facets.shape == (cell.n_facets, cell.dim) and cell.n_facets == cell.dim + 1
    assert cell.n_edges == cell.n_vertices * (cell.n_vertices - 1) // 2
    assert {tuple(sorted(e)) for e in cell.edges.tolist()} == {
        (a, b) for a in range(cell.n_vertices) for b in range(a + 1, cell.n_vertices)
    }
    for table in (cell.vertices, cell.edges, cell.facets, cell.edge_nodes):
        with pytest.raises(ValueError):
            table[0] = 0
    if cell.facet_cell is not None:
        assert cell.facet_cell.dim == cell.dim - 1


def test_the_tetrahedron_faces_are_opposite_their_vertex_and_outward():
    """Face k leaves out vertex k, and its right-hand normal points away from that vertex;
    its edges are edges of the cell, and the first three edges are the triangle's."""
    v = TETRAHEDRON.vertices
    for k, face in enumerate(TETRAHEDRON.facets.tolist()):
        assert sorted(face) == sorted(set(range(4)) - {k})
        a, b, c = v[face]
        normal = np.cross(b - a, c - a)
        assert normal @ (a - v[k]) > 0, k
    edges = {tuple(sorted(e)) for e in TETRAHEDRON.edges.tolist()}
    for face in TETRAHEDRON.facets.tolist():
        for i in range(3):
            assert tuple(sorted((face[i], face[(i + 1) % 3]))) in edges
    assert TETRAHEDRON.edges[:3].tolist() == TRIANGLE.edges.tolist()
    assert TETRAHEDRON.facet_cell is TRIANGLE
    assert (TETRAHEDRON.vtk_name, TETRAHEDRON.vtk_p2_name) == ("tetra", "tetra10")
    assert TETRAHEDRON.edge_nodes[:, 2].tolist() == list(range(4, 10))
