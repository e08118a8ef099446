"""The estimator on several ranks (:mod:`signorini.estimator.owned`), in one process.

Rank r of N is played by a stand-in :class:`~signorini.algebra.ranks.Ranks` whose ``sum``
keeps the array it is given and returns it unchanged: its estimate is then made of rank r's
own integrals only. Summed over the N ranks, the per-cell and per-node indicators are the
serial ones; the integrals the ranks hand to ``sum`` are nonzero on disjoint sets and add up
to the one-rank integrals bit for bit (each integral computed on exactly one rank). Example
6.2 (frictionless, both η5 variants, P1), its Coulomb variant (η8), Example 6.1 (a body
force), the curved Hertz half-disc, its quarter with a roller (η3 on a held part) and two
cylinders (a contact pair: η3 on the master, two materials) on N = 2 and 3; in 3D Hertz
(contact faces, rollers, a Neumann top) and the manufactured body-force block.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

from signorini.algebra.ranks import SERIAL, Ranks
from signorini.contact.partition import partition
from signorini.estimator.residual import estimate
from signorini.examples import (
    elasticity_3d,
    example_6_1,
    example_6_2,
    example_6_2_coulomb,
    hertz,
    hertz_3d,
    two_cylinders,
)
from signorini.examples.hertz_half import hertz_quarter
from signorini.fem.material import Material
from signorini.loop import adaptive
from signorini.mesh import rectangle
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann


def held_block() -> ContactProblem:
    """A block pressed on a plane, its left side holding u_x only (one-component Dirichlet: η3
    on the free component there)."""
    return ContactProblem(
        rectangle(0.0, 1.0, 0.0, 1.0, 4, 4),
        Material.from_young(1.0, 0.3),
        {
            "top": Dirichlet((0.01, -0.02)),
            "left": Dirichlet((0.0, None)),
            "right": Neumann((0.0, 0.0)),
            "bottom": Contact(gap=0.0, normal=(0.0, -1.0)),
        },
    )


class StandIn(Ranks):
    """Rank ``rank`` of ``size``, alone: ``sum`` records its argument and returns it."""

    def __init__(self, rank: int, size: int) -> None:
        self.rank, self.size = rank, size
        self.summed: list[np.ndarray] = []

    def sum(self, a: np.ndarray) -> np.ndarray:
        self.summed.append(np.array(a, copy=True))
        return a


PROBLEMS = {  # the problem, its element, its levels: 130 to 760 cells
    "example-6.2": (example_6_2, "P2", 14),
    "example-6.2-p1": (example_6_2, "P1", 12),
    "example-6.2-coulomb": (example_6_2_coulomb, "P2", 14),
    "example-6.1": (example_6_1, "P2", 10),
    "hertz": (hertz, "P2", 10),
    "hertz-quarter": (hertz_quarter, "P2", 10),
    "two-cylinders": (two_cylinders, "P2", 6),
    "held-block": (held_block, "P2", 8),
    "hertz-3d": (lambda: hertz_3d(h_contact=0.2), "P2", 3),  # tetrahedra: 486 to ~2000 cells
    "elasticity-3d": (lambda: elasticity_3d(2), "P2", 2),
}
PROBLEMS_3D = ("hertz-3d", "elasticity-3d")


@cache
def solved(name: str):
    """A few adaptive levels of the problem; the last level's solution."""
    problem, element, levels = PROBLEMS[name]
    return list(adaptive(problem(), max_levels=levels, element=element))[-1].result


def on_ranks(result, size: int, variant: str):
    """Each stand-in rank's estimate and the arrays it handed to ``sum``."""
    out = []
    for rank in range(size):
        ranks = StandIn(rank, size)
        est = estimate(result, variant, ranks=ranks, partition=partition(result.space, ranks))
        assert len(ranks.summed) == 1  # one reduction of all the integrals
        out.append((est, ranks.summed[0]))
    return out


CASES = [(name, "consistent") for name in PROBLEMS if name not in PROBLEMS_3D]
CASES += [("example-6.2", "paper")]


@pytest.mark.parametrize("size", [2, 3])
@pytest.mark.parametrize("name,variant", CASES)
def test_the_ranks_indicators_sum_to_the_serial_ones(name, variant, size):
    result = solved(name)
    serial = estimate(result, variant)
    parts = on_ranks(result, size, variant)
    assert all(est.unit == serial.unit == 1.0 for est, _ in parts)
    for field in ("eta2_cell", "eta2_node"):
        total = sum(getattr(est, field) for est, _ in parts)
        want = getattr(serial, field)
        scale = np.abs(want).max(axis=1, keepdims=True)
        assert (np.abs(total - want) <= 1e-13 * np.maximum(np.abs(want), 1e-3 * scale)).all()
    # every contribution computed once: the ranks' integrals are nonzero on disjoint sets,
    # every rank has some, and they add up to one rank's integrals bit for bit
    flats = [flat for _, flat in parts]
    assert (sum((flat != 0).astype(int) for flat in flats) <= 1).all()
    assert all(np.count_nonzero(flat) > 0 for flat in flats)
    (_, whole), = on_ranks(result, 1, variant)  # fmt: skip
    np.testing.assert_array_equal(sum(flats), whole)


@pytest.mark.parametrize("size", [2, 3])
@pytest.mark.parametrize("name", PROBLEMS_3D)
def test_the_ranks_3d_indicators_sum_to_the_serial_ones(name, size):
    """As in 2D, on tetrahedra: each rank integrates η1 on its cells, η2 and η3 on the faces
    whose first cell is its own, η4 … η7 on its own contact faces (estimator/residual3d.py)."""
    result = solved(name)
    serial = estimate(result)
    parts = on_ranks(result, size, "consistent")
    assert all(est.unit == serial.unit for est, _ in parts)
    for field in ("eta2_cell", "eta2_node"):
        total = sum(getattr(est, field) for est, _ in parts)
        want = getattr(serial, field)
        scale = np.abs(want).max(axis=1, keepdims=True)
        assert (np.abs(total - want) <= 1e-13 * np.maximum(np.abs(want), 1e-3 * scale)).all()
    flats = [flat for _, flat in parts]
    assert (sum((flat != 0).astype(int) for flat in flats) <= 1).all()
    assert all(np.count_nonzero(flat) > 0 for flat in flats)
    (_, whole), = on_ranks(result, 1, "consistent")  # fmt: skip
    np.testing.assert_array_equal(sum(flats), whole)
    (one, _), = on_ranks(result, 1, "consistent")  # fmt: skip
    np.testing.assert_array_equal(one.eta2_cell, serial.eta2_cell)
    np.testing.assert_array_equal(one.eta2_node, serial.eta2_node)


@pytest.mark.parametrize("name", ["example-6.2", "example-6.2-coulomb", "hertz", "two-cylinders"])
def test_one_rank_of_a_partition_is_the_serial_estimate_bit_for_bit(name):
    """Rank 0 of 1 integrates every cell and edge through the partitioned path: the same
    numbers as the serial path, so that on several ranks (where the sum over the ranks adds
    zeros to each integral) every rank holds the serial estimate exactly."""
    result = solved(name)
    serial = estimate(result)
    (one, _), = on_ranks(result, 1, "consistent")  # fmt: skip
    np.testing.assert_array_equal(one.eta2_cell, serial.eta2_cell)
    np.testing.assert_array_equal(one.eta2_node, serial.eta2_node)
    assert one.eta == serial.eta


def test_a_partition_that_does_not_fit_is_refused():
    result = solved("example-6.2")
    other = solved("hertz")
    with pytest.raises(ValueError, match="ranks must be"):
        estimate(result, ranks=2)
    with pytest.raises(ValueError, match="partition must be"):
        estimate(result, ranks=StandIn(0, 2), partition="rows")
    with pytest.raises(ValueError, match="partition is rank 0 of 2, but ranks is rank 1 of 2"):
        estimate(result, ranks=StandIn(1, 2), partition=partition(result.space, StandIn(0, 2)))
    with pytest.raises(ValueError, match="cell owners"):
        estimate(result, ranks=StandIn(0, 2), partition=partition(other.space, StandIn(0, 2)))


def test_several_ranks_without_a_partition_use_the_spaces_own():
    result = solved("example-6.2")
    ranks = StandIn(1, 2)
    implicit = estimate(result, ranks=ranks)
    explicit = estimate(result, ranks=ranks, partition=partition(result.space, ranks))
    np.testing.assert_array_equal(implicit.eta2_cell, explicit.eta2_cell)
    assert estimate(result, ranks=SERIAL).eta == estimate(result).eta
