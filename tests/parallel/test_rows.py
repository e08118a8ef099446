"""Each rank assembles the stiffness rows of its own nodes (docs/parallel.md, *What is
distributed*): on rank r of N, ``assemble(..., ranks=)`` gives the serial ``K`` with the other
ranks' rows emptied, bit for bit, after the change of basis of two bodies and the rotation
into frames; the ranks' matrices sum to the serial one and F is the serial F.

Serial tests: a stand-in :class:`~signorini.algebra.ranks.Ranks` plays rank r of N in turn
(its collectives are not needed by the assembly, or are played in lockstep by
:class:`Lockstep`). They need neither MPI nor MKL and run in the MPI stage as well.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from signorini import Contact, ContactProblem, HalfPlane, Material, Neumann, Roller
from signorini.algebra.backends.selection import SOLVERS
from signorini.algebra.friction.kkt import FrictionProblem
from signorini.algebra.ranks import SERIAL, Ranks
from signorini.contact import solution
from signorini.contact.partition import partition
from signorini.contact.solution import solve
from signorini.contact.system import assemble
from signorini.examples.hertz import hertz
from signorini.examples.hertz_half import hertz_quarter, quarter_disc
from signorini.examples.paper import example_6_2
from signorini.examples.two_bodies import two_cylinders
from signorini.fem.material import CellMaterials
from signorini.fem.space import space_of
from signorini.fem.stiffness import assemble_stiffness
from signorini.mesh import with_regions
from signorini.mesh.refine import refine_uniform
from signorini.problem import Tresca

from ..problem.test_roller_frames import _rotated


class Rank(Ranks):
    """Rank ``rank`` of ``size``, alone: its sums and gathers must not be needed."""

    def __init__(self, rank: int, size: int) -> None:
        self.rank, self.size = rank, size

    def sum(self, a):
        raise AssertionError("the assembly sums nothing over the ranks")

    def gather(self, a):
        raise AssertionError("the assembly gathers nothing over the ranks")


class Lockstep(Ranks):
    """Rank ``rank`` of ``size`` in a run played twice: the first time each rank's arrays
    to sum are recorded (and returned as they are), the second time their sums over the
    ranks (``totals``) are returned in the same order."""

    def __init__(self, rank: int, size: int, totals: list | None = None) -> None:
        self.rank, self.size, self.totals, self.seen = rank, size, totals, []

    def sum(self, a):
        self.seen.append(np.array(a))
        return a if self.totals is None else self.totals[len(self.seen) - 1]


def lockstep(size: int, func) -> list:
    """``func(ranks)`` on every rank of ``size``, its sums over the ranks played in lockstep:
    the values of the second round, one per rank."""
    first = [Lockstep(r, size) for r in range(size)]
    for ranks in first:
        func(ranks)
    totals = [sum(arrays) for arrays in zip(*(ranks.seen for ranks in first), strict=True)]
    return [func(Lockstep(r, size, totals)) for r in range(size)]


def region_model() -> ContactProblem:
    """A quarter disc of two materials on a roller (tests/mesh/test_with_regions.py)."""

    def core(x):
        return np.hypot(x[:, 0], x[:, 1] - 1.0) < 0.5

    mesh = with_regions(quarter_disc(1.0), {"core": core, "shell": lambda x: ~core(x)})
    return ContactProblem(
        mesh=mesh,
        material={"core": Material.from_young(10.0, 0.3), "shell": Material.from_young(1.0, 0.3)},
        conditions={
            "top": Neumann((0.0, -0.0042)),
            "axis": Roller(),
            "arc": Contact(obstacle=HalfPlane((0.0, 0.0), (0.0, 1.0))),
        },
    )


CASES = {
    "example-6.2": (example_6_2, "P2", 1),
    "example-6.2-P1": (example_6_2, "P1", 2),
    "hertz-curved": (hertz, "P2", 1),
    "regions": (region_model, "P2", 1),
    "oblique-roller": (lambda: _rotated(hertz_quarter(rings=4, h_bottom=0.05)), "P2", 0),
    "two-cylinders": (two_cylinders, "P2", 0),
    "two-cylinders-tresca": (lambda: two_cylinders(friction=Tresca(0.01)), "P2", 0),
}


def case(name: str):
    build, element, refinements = CASES[name]
    problem = build()
    mesh = problem.mesh
    for _ in range(refinements):
        mesh = refine_uniform(mesh).mesh
    return problem, mesh, element


def assert_same_rows(Kr: sp.csr_matrix, K: sp.csr_matrix, rows: np.ndarray) -> None:
    """``Kr`` is ``K`` with the rows outside ``rows`` emptied: same stored entries, bit for
    bit, explicit zeros included."""
    Kr, K = Kr.copy(), K.copy()
    Kr.sort_indices()
    K.sort_indices()
    length = np.diff(K.indptr)
    expected = np.zeros_like(K.indptr)
    np.cumsum(np.where(rows, length, 0), out=expected[1:])
    kept = np.repeat(rows, length)
    assert np.array_equal(Kr.indptr, expected)
    assert np.array_equal(Kr.indices, K.indices[kept])
    assert np.array_equal(Kr.data, K.data[kept])  # bit for bit: no tolerance


@pytest.mark.parametrize("name", list(CASES))
@pytest.mark.parametrize("size", [2, 3])
def test_each_rank_assembles_its_own_rows_of_the_serial_system(name, size):
    problem, mesh, element = case(name)
    serial = assemble(problem, mesh, element=element)
    assert serial.partition is None and serial.ranks is SERIAL
    total = None
    owners = np.zeros(serial.space.n_nodes, dtype=np.int64)
    for r in range(size):
        mine = assemble(problem, mesh, element=element, ranks=Rank(r, size))
        part = mine.partition
        assert (part.rank, part.size) == (r, size)
        own = part.owned_dofs
        assert_same_rows(mine.K, serial.K, own)
        # the rows stored are exactly the rank's own: every own row has its diagonal block
        assert np.array_equal(np.diff(mine.K.indptr) > 0, own)
        assert np.array_equal(mine.F, serial.F)
        assert np.array_equal(mine.dirichlet, serial.dirichlet)
        assert np.array_equal(mine.dirichlet_values, serial.dirichlet_values)
        assert np.array_equal(mine.frames, serial.frames)
        owners[part.owned_nodes] += 1
        total = mine.K if total is None else total + mine.K
    assert np.array_equal(owners, np.ones_like(owners))  # every row on one rank
    difference = total - serial.K
    difference.eliminate_zeros()
    assert difference.nnz == 0  # the ranks' matrices sum to the serial one exactly
    assert serial.K.nnz == sum(np.diff(serial.K.indptr))


@pytest.mark.parametrize("size", [2, 3])
def test_the_ranks_products_sum_to_the_serial_products(size):
    """``ranks.sum(K @ x)`` over the ranks is ``K @ x`` bit for bit, and so is the roller
    force ``Λ_z = F_z − (K y)_z`` summed over the ranks, on the oblique rollers."""
    problem, mesh, element = case("oblique-roller")
    serial = assemble(problem, mesh)
    y = np.sin(1.0 + np.arange(serial.space.n_dofs))
    assert serial.rollers.dofs.size > 0
    force = serial.rollers.force(serial.K, serial.F, y)
    rank_systems = [assemble(problem, mesh, ranks=Rank(r, size)) for r in range(size)]

    def on_rank(ranks):
        mine = rank_systems[ranks.rank]
        return ranks.sum(mine.K @ y), mine.rollers.force(mine.K, mine.F, y, ranks)

    for product, roller in lockstep(size, on_rank):
        assert np.array_equal(product, serial.K @ y)
        assert np.array_equal(roller, force)
        assert np.array_equal(
            roller, serial.rollers.sign * (serial.F - serial.K @ y)[serial.rollers.dofs]
        )


def test_the_ranks_diagonals_give_the_serial_stiffness_unit():
    problem, mesh, _ = case("example-6.2")
    serial = assemble(problem, mesh)
    systems = [assemble(problem, mesh, ranks=Rank(r, 3)) for r in range(3)]
    for diagonal in lockstep(3, lambda ranks: ranks.sum(systems[ranks.rank].K.diagonal())):
        assert np.array_equal(diagonal, serial.K.diagonal())


@pytest.mark.parametrize("size", [2, 3])
def test_partition_gives_every_node_and_cell_one_owner_the_same_on_every_call(size):
    problem, mesh, _ = case("two-cylinders")
    space = space_of(mesh)
    coupling = assemble(problem, mesh).contact.transfer.nodes
    parts = [partition(space, Rank(r, size), coupling) for r in range(size)]
    again = partition(space_of(mesh), Rank(0, size), coupling)
    for p in parts:
        # the same owners on every rank and on every call (replicated, deterministic)
        assert np.array_equal(p.node_owner, parts[0].node_owner)
        assert np.array_equal(p.cell_owner, parts[0].cell_owner)
    assert np.array_equal(again.node_owner, parts[0].node_owner)
    assert np.array_equal(again.cell_owner, parts[0].cell_owner)
    owner = parts[0].node_owner
    assert owner.shape == (space.n_nodes,) and parts[0].cell_owner.shape == (mesh.n_cells,)
    assert set(np.unique(owner)) == set(range(size))  # every rank owns nodes
    assert set(np.unique(parts[0].cell_owner)) == set(range(size))
    # one owner each: the owned masks of the ranks partition the nodes and the cells
    assert np.array_equal(sum(p.owned_nodes.astype(int) for p in parts), np.ones(space.n_nodes))
    assert np.array_equal(sum(p.owned_cells.astype(int) for p in parts), np.ones(mesh.n_cells))
    # a cell's owner owns one of its vertices; the row cells are those with an owned node
    assert (owner[mesh.cells] == parts[0].cell_owner[:, None]).any(axis=1).all()
    for p in parts:
        assert np.array_equal(p.row_cells, p.owned_nodes[space.cell_nodes].any(axis=1))
        assert not (p.owned_cells & ~p.row_cells).any()
    # the coupling's nodes (a slave node and its master nodes) are on one rank
    c = coupling.tocoo()
    assert c.nnz > 0
    assert np.array_equal(owner[c.row], owner[c.col])
    # and without the coupling they would not all be: the coupling moved them together
    free = partition(space, Rank(0, size)).node_owner
    assert not np.array_equal(free[c.row], free[c.col])


def test_partition_refuses_ranks_that_disagree():
    class Disagreeing(Rank):
        def max(self, value):
            return value + self.rank + 1.0  # as if another rank's checksum were larger

    space = space_of(case("example-6.2")[1])
    with pytest.raises(RuntimeError, match="the ranks computed different partitions"):
        partition(space, Disagreeing(0, 2))


def test_partition_balances_the_nodes():
    problem, mesh, _ = case("example-6.2")
    mesh = refine_uniform(refine_uniform(mesh).mesh).mesh
    space = space_of(mesh)
    for size in (2, 3):
        count = np.bincount(partition(space, Rank(0, size)).node_owner, minlength=size)
        assert count.max() <= 1.25 * space.n_nodes / size, count


def test_a_lone_cell_of_a_material_gives_the_serial_rows():
    """A rank whose own node touches a single cell of a material (or of the curved cells)
    computes it beside another of its kind: NumPy rounds a one-row product differently."""
    problem, mesh, _ = case("two-cylinders")
    space = space_of(mesh)
    material = problem.material_on(mesh)
    assert isinstance(material, CellMaterials) and len(space.mapping.groups) == 2
    args = (space.mapping, space.cell_dofs, space.n_dofs, material)
    K = assemble_stiffness(*args, validate=False)
    # nodes with a single cell: corner vertices of each body, a lone curved cell's nodes
    count = np.bincount(space.cell_nodes.ravel(), minlength=space.n_nodes)
    lone = np.flatnonzero(count == 1)
    assert lone.size >= 2
    for z in lone:
        rows = np.zeros(space.n_dofs, dtype=bool)
        rows[[2 * z, 2 * z + 1]] = True
        assert_same_rows(assemble_stiffness(*args, rows=rows), K, rows)


def test_assemble_stiffness_of_no_rows_and_of_all_rows():
    problem, mesh, _ = case("hertz-curved")
    space = space_of(mesh)
    args = (space.mapping, space.cell_dofs, space.n_dofs, problem.material_on(mesh))
    K = assemble_stiffness(*args)
    none = assemble_stiffness(*args, rows=np.zeros(space.n_dofs, dtype=bool))
    assert none.shape == K.shape and none.nnz == 0
    every = np.ones(space.n_dofs, dtype=bool)
    assert_same_rows(assemble_stiffness(*args, rows=every), K, every)


def test_assemble_stiffness_rows_are_checked():
    problem, mesh, _ = case("example-6.2")
    space = space_of(mesh)
    args = (space.mapping, space.cell_dofs, space.n_dofs, problem.material_on(mesh))
    with pytest.raises(ValueError, match=r"rows must be a bool array of shape \("):
        assemble_stiffness(*args, rows=np.ones(space.n_dofs - 2, dtype=bool))
    with pytest.raises(ValueError, match="rows must be a bool array"):
        assemble_stiffness(*args, rows=np.ones(space.n_dofs))
    half = np.zeros(space.n_dofs, dtype=bool)
    half[6] = True
    with pytest.raises(ValueError, match="both DOFs of a node or neither; node 3"):
        assemble_stiffness(*args, rows=half)
    with pytest.raises(ValueError, match="ranks must be a signorini.algebra.ranks.Ranks"):
        assemble(problem, mesh, ranks=2)


class Stop(Exception):
    """Raised by a stand-in solver call once it has seen its arguments."""


@pytest.mark.parametrize("name", ["regions", "two-cylinders-tresca"])
def test_solve_takes_the_ranks_from_its_solver_and_hands_them_to_the_qp(name, monkeypatch):
    """``solve`` assembles the rows of the solver's rank and passes its ranks to the QP (to
    ``solve_pdas``, or to the frictional problem's ``on_ranks`` with friction)."""
    problem, mesh, element = case(name)
    ranks = Rank(1, 3)
    ranks.sum = lambda a: a  # the stiffness unit's diagonal: this rank's part is enough here
    seen = {}

    def record(K, *args, ranks, **kwargs):
        seen.update(K=K, ranks=ranks)
        raise Stop

    def record_problem(problem, ranks):
        record(problem.qp.K, ranks=ranks)

    if "tresca" in name:
        monkeypatch.setattr(FrictionProblem, "on_ranks", record_problem)
    else:
        monkeypatch.setattr(f"{solution.__name__}.solve_pdas", record)

    def factory(request):
        return SOLVERS["scipy"](request)

    factory.ranks = lambda: ranks
    with pytest.raises(Stop):
        solve(problem, mesh, solver=factory, element=element, nested=False)
    assert seen["ranks"] is ranks
    mine = assemble(problem, mesh, element=element, ranks=Rank(1, 3))
    assert_same_rows(seen["K"], mine.K, mine.partition.owned_dofs)


def test_solve_refuses_rows_of_other_ranks():
    problem, mesh, _ = case("example-6.2")
    rows = assemble(problem, mesh, ranks=Rank(0, 2))
    with pytest.raises(ValueError, match="rank 0 of 2, but the solver runs as rank 0 of 1"):
        solve(problem, mesh, assembled=rows)


def test_a_serial_solve_has_no_partition():
    problem, mesh, _ = case("regions")
    result = solve(problem, mesh)
    assert result.partition is None
    assert abs(2 * result.total_contact_force - 0.0084) <= 1e-9 * 0.0084


def mpi_launcher() -> tuple[list[str] | None, str | None]:
    """``mpiexec`` (beside this Python, or on PATH; with Open MPI's flags for root and
    oversubscription) and None, or None and why the MPI run cannot be made."""
    try:
        from signorini.algebra.backends.petsc import petsc_module

        petsc_module()
    except Exception as err:  # BackendUnavailableError: no petsc4py here
        return None, str(err)
    here = Path(sys.executable).parent / "mpiexec"
    found = str(here) if here.exists() else shutil.which("mpiexec")
    if found is None:
        return None, "no mpiexec found"
    version = subprocess.run([found, "--version"], capture_output=True, text=True).stdout
    if "Open MPI" in version or "OpenRTE" in version:
        return [found, "--allow-run-as-root", "--oversubscribe"], None
    return [found], None


@pytest.mark.slow
@pytest.mark.parametrize("size", [2, 3])
def test_the_rows_of_mpi_ranks_are_the_serial_rows(size):
    """The same checks with real ranks (``world_ranks``, MPI's collectives): each rank's rows
    are the serial ones, and its products summed by MPI are the serial products."""
    launcher, why = mpi_launcher()
    if launcher is None:
        if os.environ.get("SIGNORINI_REQUIRE_PETSC") == "1":
            pytest.fail(f"SIGNORINI_REQUIRE_PETSC=1 but the MPI run cannot be made: {why}")
        pytest.skip(f"MPI run: {why}")
    script = Path(__file__).with_name("mpi_rows.py")
    done = subprocess.run(
        [*launcher, "-n", str(size), sys.executable, str(script)],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-3000:]
    assert f"rows: {size} ranks same" in done.stdout
