"""The node-pair pattern of P2 tetrahedra (:mod:`signorini.fem.pattern3d`) and the assembly
through it against a scalar COO assembly of the element matrices."""

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
