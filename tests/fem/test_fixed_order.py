"""A row's product and a cell's stiffness block are the same bit for bit whatever rows are
computed beside them (``signorini.fem.fixed_order``): the ground of a rank's rows of K being
the serial rows on any CPU, whatever kernel its BLAS picks (tests/parallel/test_rows.py)."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.examples.hertz import hertz
from signorini.fem.element import P1, P2
from signorini.fem.fixed_order import rows_times
from signorini.fem.space import space_of
from signorini.fem.stiffness import _stiffness_basis, element_blocks

#: batch sizes around the tiles of BLAS kernels (4, 8, 16, 32 … rows) and a single row
SIZES = [*range(1, 34), 47, 63, 64, 65, 127, 128, 129, 255, 257, 1000]


@pytest.mark.parametrize("element", ["P2", "P1"])
@pytest.mark.parametrize("per_point", [False, True])
def test_each_row_of_the_product_is_the_same_in_a_batch_of_any_size(element, per_point):
    basis = _stiffness_basis(1.7, 0.9, False, 4 if per_point else 2, per_point, element)
    rng = np.random.default_rng(7)
    a = rng.random((1500, basis.shape[0])) * 10.0 ** rng.uniform(-6, 6, (1500, 1))
    whole = rows_times(a, basis)
    # it is the product: both within the dot products' bound s u (|a| |b|) of the exact one
    bound = 2 * basis.shape[0] * np.finfo(float).eps * (np.abs(a) @ np.abs(basis))
    assert np.all(np.abs(whole - a @ basis) <= bound)
    for size in SIZES:
        rows = np.sort(rng.choice(len(a), size, replace=False))
        assert np.array_equal(rows_times(a[rows], basis), whole[rows]), size
        out = np.empty((size, basis.shape[1]))
        assert rows_times(a[rows], basis, out=out) is out
        assert np.array_equal(out, whole[rows]), size


@pytest.mark.parametrize("element", [P2, P1], ids=["P2", "P1"])
def test_a_cells_block_is_the_same_computed_alone_or_among_others(element):
    """On the curved Hertz mesh: straight cells (one Jacobian per cell) and isoparametric
    ones (a Jacobian per point), each alone, in pairs and in every batch size."""
    problem = hertz()
    space = space_of(problem.mesh)
    material = problem.material_on(problem.mesh)
    groups = space.mapping.groups
    assert len(groups) == 2  # the affine cells and the curved ones
    rng = np.random.default_rng(3)
    for group in groups:
        whole = element_blocks(group, material, element=element)
        assert len(group) >= 9
        for size in sorted({1, 2, 3, 5, 8, 17, len(group) - 1} & set(range(1, len(group)))):
            slot = np.sort(rng.choice(len(group), size, replace=False))
            part = element_blocks(group.rows(slot), material, element=element)
            assert np.array_equal(part, whole[slot]), (type(group).__name__, size)
