"""The node-pair pattern of P2 tetrahedra (:mod:`signorini.fem.pattern3d`) against the pairs
of ``np.unique``, and the assembly through it against a scalar COO assembly of the element
matrices."""

import gc

import numpy as np
import scipy.sparse as sp
from fem3d_problems import MATERIAL, distorted_box

from signorini.fem import pattern3d
from signorini.fem.dofs import node_dofs
from signorini.fem.mapping3d import TetrahedronMap
from signorini.fem.material import CellMaterials, Material, on_cells
from signorini.fem.space import space_of
from signorini.fem.stiffness3d import assemble_stiffness_3d, element_stiffness_3d
from signorini.mesh.refine3d import bisect_mesh

RNG = np.random.default_rng(3)


def coo_reference(mapping, cell_dofs, n_dofs, material):
    """Every cell's 30 × 30 matrix summed by SciPy's COO -> CSR conversion."""
    rows, cols, vals = [], [], []
    for g in mapping.groups:
        K = element_stiffness_3d(g, on_cells(material, g.cells))
        dofs = cell_dofs[g.cells]
        rows.append(np.repeat(dofs, 30, axis=1).ravel())
        cols.append(np.tile(dofs, (1, 30)).ravel())
        vals.append(K.ravel())
    coo = (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols)))
    return sp.csr_matrix(coo, shape=(n_dofs, n_dofs))


def mixed_problem():
    """A distorted box with renumbered nodes, some isoparametric cells and two materials."""
    V = space_of(distorted_box(2))
    renumber = RNG.permutation(V.n_nodes)
    cell_dofs = node_dofs(renumber[V.cell_nodes], 3).reshape(-1, 30)
    curved = np.array([0, 5, 11, 30])
    nodes = V.node_points[V.cell_nodes[curved]]
    nodes[:, 4:] += 0.01 * RNG.normal(size=(len(curved), 6, 3))  # bent edges
    mapping = TetrahedronMap(V.vertices, (curved, nodes))
    soft, hard = Material(lam=1.0, mu=0.5), Material(lam=3.0, mu=2.0)
    material = CellMaterials([soft, hard], RNG.integers(0, 2, len(V.cell_nodes)))
    return mapping, cell_dofs, V.n_dofs, material


def test_pattern_assembly_equals_coo_assembly_and_is_exactly_symmetric():
    mapping, cell_dofs, n_dofs, material = mixed_problem()
    assert len(mapping.groups) == 2
    K = assemble_stiffness_3d(mapping, cell_dofs, n_dofs, material)
    K_ref = coo_reference(mapping, cell_dofs, n_dofs, material)
    assert isinstance(K, sp.csr_matrix) and K.has_sorted_indices
    assert abs(K - K_ref).max() < 1e-14 * abs(K_ref).max()
    # the pattern: every coupled node pair's full block, as the conversion's (no entry lost)
    assert np.array_equal(K.indptr, K_ref.indptr) and np.array_equal(K.indices, K_ref.indices)
    resorted = K.copy()
    resorted.has_sorted_indices = False
    resorted.sort_indices()
    assert np.array_equal(resorted.indices, K.indices)
    # symmetric bit for bit: the lower triangle is the mirror of the upper one
    KT = K.T.tocsr()
    KT.sort_indices()
    assert np.array_equal(KT.indices, K.indices) and np.array_equal(KT.data, K.data)


def test_pattern_kept_while_the_dof_array_lives_and_rebuilt_when_it_changes():
    V = space_of(distorted_box(1))
    nodes = V.cell_dofs[:, 0::3] // 3
    first = pattern3d.pattern_of(nodes, V.n_nodes, V.cell_dofs)
    assert pattern3d.pattern_of(nodes.copy(), V.n_nodes, V.cell_dofs) is first
    swapped = nodes[::-1].copy()
    assert pattern3d.pattern_of(swapped, V.n_nodes, V.cell_dofs) is not first
    K = assemble_stiffness_3d(V.mapping, V.cell_dofs, V.n_dofs, MATERIAL)
    K.indices[:] = 0  # the matrix owns its arrays: the kept pattern is untouched
    again = assemble_stiffness_3d(V.mapping, V.cell_dofs, V.n_dofs, MATERIAL)
    assert abs(again - coo_reference(V.mapping, V.cell_dofs, V.n_dofs, MATERIAL)).max() < 1e-13
    owner = V.cell_dofs.copy()
    pattern3d.pattern_of(owner[:, 0::3] // 3, V.n_nodes, owner)
    key = id(owner)
    assert key in pattern3d._PATTERNS
    del owner
    gc.collect()
    assert key not in pattern3d._PATTERNS


def unique_pairs_reference(cell_nodes):
    """Every coupled node pair ``(z, w)`` of both triangles, by ``np.unique`` of all cells'
    100 ordered local pairs (written without the pattern's construction)."""
    z = np.asarray(cell_nodes)
    rows = np.repeat(z, 10, axis=1).ravel()
    cols = np.tile(z, (1, 10)).ravel()
    return np.unique(np.column_stack([rows, cols]), axis=0)


def refined_space():
    """A box bisected twice where random cells were marked: varied node degrees."""
    mesh = distorted_box(2)
    for _ in range(2):
        marked = RNG.random(mesh.n_cells) < 0.3
        mesh = bisect_mesh(mesh, marked, 1)[0]
    return space_of(mesh)


def check_pattern(cell_nodes, n_nodes):
    p = pattern3d.node_pattern(cell_nodes, n_nodes)
    ref = unique_pairs_reference(cell_nodes)
    z_row = np.repeat(np.arange(n_nodes), np.diff(p.first))
    # the node-block CSR: exactly the coupled pairs, rows in order, columns sorted
    assert np.array_equal(np.column_stack([z_row, p.column]), ref)
    # each block is its unordered pair's, mirrored below the diagonal only
    assert np.array_equal(p.mirror, z_row > p.column)
    lo, hi = np.minimum(z_row, p.column), np.maximum(z_row, p.column)
    n_upper = p.sums.shape[0]
    assert np.array_equal(np.sort(p.pair[~p.mirror]), np.arange(n_upper))
    owner = np.full((n_upper, 2), -1)
    owner[p.pair[~p.mirror]] = np.column_stack([lo, hi])[~p.mirror]
    assert np.array_equal(owner[p.pair], np.column_stack([lo, hi]))
    # sums: row q lists, in cell order, every cell pair 55 c + k with the nodes of pair q
    a, b = np.divmod(p.select.astype(np.int64), 10)
    cells = np.asarray(cell_nodes)
    za = np.take_along_axis(cells, a, axis=1).ravel()
    zb = np.take_along_axis(cells, b, axis=1).ravel()
    assert np.all(za <= zb)
    coo = p.sums.tocoo()
    assert np.all(coo.data == 1.0) and coo.nnz == cells.shape[0] * 55
    assert np.array_equal(np.sort(coo.col), np.arange(coo.nnz))  # every cell pair once
    assert np.array_equal(owner[coo.row], np.column_stack([za, zb])[coo.col])
    step = np.diff(p.sums.indices)  # increasing within each row: cell order
    inside = np.ones(step.size, dtype=bool)
    inside[p.sums.indptr[1:-1] - 1] = False
    assert np.all(step[inside] > 0)
    # the scalar CSR: full 3 x 3 blocks, rows 3 z + i, sorted columns
    scalar = sp.csr_matrix((np.ones(len(ref)), (ref[:, 0], ref[:, 1])), shape=(n_nodes, n_nodes))
    expanded = sp.kron(scalar, np.ones((3, 3)), format="csr")
    expanded.sort_indices()
    assert np.array_equal(p.indptr, expanded.indptr)
    assert np.array_equal(p.scalar_indices(), expanded.indices)


def test_pattern_equals_unique_pairs_on_random_refined_and_curved_meshes():
    V = space_of(distorted_box(2))
    renumber = RNG.permutation(V.n_nodes)
    shuffled = renumber[V.cell_nodes][RNG.permutation(len(V.cell_nodes))]
    check_pattern(shuffled, V.n_nodes)  # random numbering and cell order
    W = refined_space()
    check_pattern(W.cell_nodes, W.n_nodes)
    mapping, cell_dofs, n_dofs, _ = mixed_problem()  # curved cells: the pattern of its nodes
    check_pattern(cell_dofs[:, 0::3] // 3, n_dofs // 3)
    sub = shuffled[: len(shuffled) // 3]  # some cells only: nodes no cell has are empty rows
    check_pattern(sub, V.n_nodes)


def test_laid_out_places_each_pair_block_and_its_transpose():
    W = refined_space()
    p = pattern3d.node_pattern(W.cell_nodes, W.n_nodes)
    summed = RNG.normal(size=(p.sums.shape[0], 9))
    data = p.laid_out(summed)
    K = sp.csr_matrix((data, p.scalar_indices(), p.indptr), shape=p.shape)
    # an independent layout: each upper pair's block at (lo, hi), transposed at (hi, lo)
    up = ~p.mirror
    z_row = np.repeat(np.arange(W.n_nodes), np.diff(p.first))
    lo, hi, q = z_row[up], p.column[up], p.pair[up]
    blocks = summed[q].reshape(-1, 3, 3)
    i, j = np.meshgrid(np.arange(3), np.arange(3), indexing="ij")
    rows = np.concatenate(
        [(3 * lo[:, None, None] + i).ravel(), (3 * hi[:, None, None] + j).ravel()]
    )
    cols = np.concatenate(
        [(3 * hi[:, None, None] + j).ravel(), (3 * lo[:, None, None] + i).ravel()]
    )
    strict = np.repeat(lo != hi, 9)
    vals = np.concatenate([blocks.ravel(), np.where(strict, blocks.ravel(), 0.0)])
    ref = sp.csr_matrix((vals, (rows, cols)), shape=p.shape)
    assert np.array_equal(K.toarray(), ref.toarray())
    diagonal = q[lo == hi]  # symmetric diagonal blocks (as a stiffness's): K is symmetric
    sym = summed.reshape(-1, 3, 3)[diagonal]
    summed.reshape(-1, 3, 3)[diagonal] = sym + sym.transpose(0, 2, 1)
    dense = sp.csr_matrix((p.laid_out(summed), p.scalar_indices(), p.indptr)).toarray()
    assert np.array_equal(dense, dense.T)
