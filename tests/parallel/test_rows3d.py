"""Each rank assembles the stiffness rows of its own nodes in 3D as in 2D (docs/parallel.md,
*A stiffness matrix split by rows*): on rank r of N, ``assemble(..., ranks=)`` of a
tetrahedral mesh gives the serial system's ``K`` with the other ranks' rows emptied, bit for
bit, without contact and on contact faces after the change of unknowns ``Rᵀ K R``; the ranks'
rows cover every row once and F is the serial F.

Serial tests: the stand-in :class:`~.test_rows.Rank` plays rank r of N in turn (the
assembly needs no collective of it). They need neither MPI nor MKL and run in the MPI stage
as well.
"""

from __future__ import annotations

import numpy as np
import pytest

from signorini.contact.system import assemble
from signorini.examples import elasticity_3d, hertz_3d
from signorini.fem.material import Material
from signorini.fem.space import space_of
from signorini.fem.stiffness3d import assemble_stiffness_3d
from signorini.mesh.builders3d import box

from .test_rows import Rank

CASES = {
    "elasticity-3d": lambda: elasticity_3d(3),
    "hertz-3d": lambda: hertz_3d(h_contact=0.2),
    "hertz-3d (a)": lambda: hertz_3d(h_contact=0.2, face_alpha=0.0),
}


@pytest.mark.parametrize("name", CASES)
@pytest.mark.parametrize("size", [2, 3])
def test_each_rank_assembles_its_own_rows_of_the_serial_3d_system(name, size):
    problem = CASES[name]()
    serial = assemble(problem, problem.mesh)
    K = serial.K
    lengths = np.diff(K.indptr)
    covered = np.zeros(K.shape[0], dtype=np.int64)
    for rank in range(size):
        mine = assemble(problem, problem.mesh, ranks=Rank(rank, size))
        own = mine.partition.owned_dofs
        assert own.any() and mine.partition.size == size
        covered += own
        Kr = mine.K
        np.testing.assert_array_equal(np.diff(Kr.indptr), np.where(own, lengths, 0))
        kept = np.repeat(own, lengths)
        np.testing.assert_array_equal(Kr.indices, K.indices[kept])
        np.testing.assert_array_equal(Kr.data, K.data[kept])  # bit for bit
        np.testing.assert_array_equal(mine.F, serial.F)
        np.testing.assert_array_equal(mine.dirichlet, serial.dirichlet)
        # whole nodes: the three DOFs of a node on one rank (PETSc's block size 3)
        assert (own.reshape(-1, 3).all(axis=1) == own.reshape(-1, 3).any(axis=1)).all()
    np.testing.assert_array_equal(covered, 1)


def test_the_stiffness_rows_of_a_part_of_the_nodes_and_their_check():
    """``assemble_stiffness_3d(..., rows=)``: the kept rows bit for bit, the others empty, from
    the cells that touch them only; a mask that splits a node's DOFs is refused."""
    mesh = box(3, 2, 2)
    V = space_of(mesh)
    material = Material.from_young(2.0, 0.25)
    K = assemble_stiffness_3d(V.mapping, V.cell_dofs, V.n_dofs, material)
    node = np.random.default_rng(3).random(V.n_nodes) < 0.3
    rows = np.repeat(node, 3)
    Kr = assemble_stiffness_3d(V.mapping, V.cell_dofs, V.n_dofs, material, rows)
    assert Kr[np.flatnonzero(~rows)].nnz == 0
    A, B = K[np.flatnonzero(rows)], Kr[np.flatnonzero(rows)]
    np.testing.assert_array_equal(A.indices, B.indices)
    np.testing.assert_array_equal(A.data, B.data)
    none = assemble_stiffness_3d(V.mapping, V.cell_dofs, V.n_dofs, material, np.zeros_like(rows))
    assert none.nnz == 0 and none.shape == K.shape
    bad = rows.copy()
    bad[3 * np.flatnonzero(node)[0] + 1] = False
    with pytest.raises(ValueError, match="three DOFs of a node"):
        assemble_stiffness_3d(V.mapping, V.cell_dofs, V.n_dofs, material, bad)
    with pytest.raises(ValueError, match="rows must be a bool array"):
        assemble_stiffness_3d(V.mapping, V.cell_dofs, V.n_dofs, material, rows[:-3])
