"""Benchmark: what each rank computes when it assembles the rows of its own nodes.

On Example 6.2's adaptive mesh within the budget, for 2 and 3 ranks (played one after the
other in this one process: the assembly needs no communication), the partition of
:func:`signorini.contact.partition.partition` and per rank: its nodes, its own cells, the
cells whose element matrices it computes (``row_cells``: its own and the ghost layer),
their share of all cells, the time of its stiffness rows
(:func:`~signorini.fem.stiffness.assemble_stiffness` with ``rows``) against the whole
matrix's, and of its whole ``assemble`` (with the partition, computed once per mesh)
against the serial one (best of ``--repeat``). The last lines: ``ghost_overhead_N=X``, the
cells computed by the N ranks together over all cells (1 would be no overlap).

    python benchmarks/rows.py                      # about 10^5 unknowns
    python benchmarks/rows.py --max-ndof 1000000
"""

from __future__ import annotations

import argparse
import time

from signorini import adaptive, example_6_2
from signorini.algebra.ranks import Ranks
from signorini.contact import assemble
from signorini.contact.partition import partition
from signorini.fem.space import space_of
from signorini.fem.stiffness import assemble_stiffness


class Rank(Ranks):
    """Rank ``rank`` of ``size``, played alone (the assembly sums nothing)."""

    def __init__(self, rank: int, size: int) -> None:
        self.rank, self.size = rank, size


def best(func, repeat: int) -> tuple[object, float]:
    """``func()`` and its fastest time of ``repeat`` runs."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = func()
        times.append(time.perf_counter() - t0)
    return out, min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-ndof", type=int, default=100_000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    problem = example_6_2()
    *_, last = adaptive(problem, max_ndof=args.max_ndof)
    mesh = last.result.mesh
    serial, t_serial = best(lambda: assemble(problem, mesh), args.repeat)
    n_cells = mesh.n_cells
    space = space_of(mesh)
    stiffness = (space.mapping, space.cell_dofs, space.n_dofs, problem.material_on(mesh))
    _, t_whole = best(lambda: assemble_stiffness(*stiffness, validate=False), args.repeat)
    print(
        f"Example 6.2, adaptive: {n_cells} cells, {serial.space.n_dofs} unknowns; serial: "
        f"stiffness {t_whole:.3f} s, assemble {t_serial:.3f} s"
    )
    print(f"{'ranks':>5} {'rank':>4} {'nodes':>8} {'own cells':>9} {'computed':>9} "
          f"{'share':>6} {'partition s':>11} {'rows s':>7} {'vs whole':>8} "
          f"{'assemble s':>10} {'vs serial':>9}")  # fmt: skip
    overhead = {}
    for size in (2, 3):
        computed = 0
        for r in range(size):
            ranks = Rank(r, size)
            part, t_part = best(lambda ranks=ranks: partition(space, ranks), args.repeat)
            own = part.owned_dofs
            _, t_rows = best(
                lambda own=own: assemble_stiffness(*stiffness, validate=False, rows=own),
                args.repeat,
            )
            _, t = best(lambda ranks=ranks: assemble(problem, mesh, ranks=ranks), args.repeat)
            rows = int(part.row_cells.sum())
            computed += rows
            print(
                f"{size:>5} {r:>4} {int(part.owned_nodes.sum()):>8} "
                f"{int(part.owned_cells.sum()):>9} {rows:>9} {rows / n_cells:>6.3f} "
                f"{t_part:>11.3f} {t_rows:>7.3f} {t_rows / t_whole:>8.3f} "
                f"{t:>10.3f} {t / t_serial:>9.3f}"
            )
        overhead[size] = computed / n_cells
    for size, value in overhead.items():
        print(f"ghost_overhead_{size}={value:.4f}")


if __name__ == "__main__":
    main()
