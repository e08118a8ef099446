"""The structured cube [0, 1]³: n³ cubes, six Kuhn tetrahedra each, P2 (10-node) numbering.

Conventions (stated once): vertex (i, j, k) of the grid has number ``i + (n+1) j + (n+1)² k``;
a tetrahedron's local P2 order is its 4 vertices, then the midpoints of the local edges
:data:`TET_EDGES`; global P2 nodes are the vertices first, then one midpoint per edge; vector
DOFs are interleaved (DOF ``3 node + component``). A boundary face's local order is its three
vertices (a, b, c), then the midpoints of (a, b), (b, c), (c, a).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import permutations

import numpy as np

#: Local edges of a tetrahedron, in the order of its local nodes 4..9.
TET_EDGES = np.array([[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]])
#: Local faces of a tetrahedron (face k is opposite vertex k).
TET_FACES = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])


@dataclass(frozen=True)
class CubeMesh:
    """A P2 tetrahedral mesh of the unit cube.

    Attributes
    ----------
    n : int
        Cubes per direction, h = 1/n.
    points : ndarray, shape (n_nodes, 3)
        All P2 nodes: the (n+1)³ vertices, then the edge midpoints.
    tets : ndarray, shape (n_tets, 10)
        P2 connectivity (4 vertices, then the midpoints of :data:`TET_EDGES`).
    n_vertices : int
        Number of vertices; nodes ``>= n_vertices`` are midpoints.
    edges : ndarray, shape (n_edges, 2)
        Vertex pairs (sorted); edge e has the midpoint node ``n_vertices + e``.
    """

    n: int
    points: np.ndarray
    tets: np.ndarray
    n_vertices: int
    edges: np.ndarray

    @property
    def n_nodes(self) -> int:
        return self.points.shape[0]

    def edge_nodes(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Midpoint nodes of the edges joining vertices ``a`` and ``b`` (arrays of one shape)."""
        nv = self.n_vertices
        keys = self.edges[:, 0] * nv + self.edges[:, 1]
        query = np.minimum(a, b) * nv + np.maximum(a, b)
        e = np.searchsorted(keys, query)
        assert np.array_equal(keys[e], query), "not an edge of the mesh"
        return nv + e

    def boundary_faces(self, axis: int, value: float) -> np.ndarray:
        """The 6-node faces on the plane ``x_axis = value``, shape (n_faces, 6).

        Each face is oriented so that its normal (b − a) × (c − a) points out of the cube.
        """
        vert = self.tets[:, :4]
        on = np.isclose(self.points[vert, axis], value)  # (n_tets, 4)
        local = TET_FACES[None, :, :]
        hit = on[:, TET_FACES].all(axis=2)  # (n_tets, 4)
        t, k = np.nonzero(hit)
        tri = vert[t[:, None], local[0, k]]  # (n_faces, 3)
        x = self.points[tri]
        normal = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])[:, axis]
        outward = 1.0 if value > 0.5 else -1.0
        flip = normal * outward < 0
        tri[flip] = tri[flip][:, [0, 2, 1]]
        a, b, c = tri.T
        mids = np.stack(
            [self.edge_nodes(a, b), self.edge_nodes(b, c), self.edge_nodes(c, a)], axis=1
        )
        return np.hstack([tri, mids])


def cube_mesh(n: int) -> CubeMesh:
    """Mesh [0, 1]³ by n³ cubes, each split into the 6 Kuhn tetrahedra of its main diagonal.

    The Kuhn tetrahedron of a permutation σ of (x, y, z) is the path v0 = corner (0, 0, 0),
    v_{k+1} = v_k + e_{σ(k)}; the 6 paths share the diagonal and the split is conforming
    across cubes (every cube is cut the same way).

    Parameters
    ----------
    n : int
        Cubes per direction.

    Returns
    -------
    CubeMesh
    """
    m = n + 1
    g = np.arange(n)
    i, j, k = (a.ravel() for a in np.meshgrid(g, g, g, indexing="ij"))
    stride = np.array([1, m, m * m])
    base = i + m * j + m * m * k  # (n³,)
    tets = []
    for sigma in permutations(range(3)):
        steps = np.cumsum(stride[list(sigma)])
        tets.append(np.stack([base, *(base + s for s in steps)], axis=1))
    vert = np.concatenate(tets)  # (6 n³, 4)
    c = np.arange(m) / n
    X, Y, Z = np.meshgrid(c, c, c, indexing="ij")
    vertices = np.stack([X.ravel(order="F"), Y.ravel(order="F"), Z.ravel(order="F")], axis=1)
    pairs = np.sort(vert[:, TET_EDGES], axis=2).reshape(-1, 2)  # (6 n_tets, 2)
    edges, inverse = np.unique(pairs, axis=0, return_inverse=True)
    nv = vertices.shape[0]
    mid = nv + inverse.reshape(-1, 6)
    points = np.vstack([vertices, vertices[edges].mean(axis=1)])
    return CubeMesh(n, points, np.hstack([vert, mid]), nv, edges)
