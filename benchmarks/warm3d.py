"""Benchmark: PDAS steps per level of a 3D contact run under uniform refinement, with and
without the warm start (docs/method.md, *Three dimensions: warm starts*).

Each problem is run twice by ``signorini.adaptive(problem, uniform=True, ...)``: with
``warm_start=True`` (each level starts PDAS from the active set rule at the previous level's
solution prolongated to the refined mesh, in the solver's variables: docs/method.md, *Three
dimensions: warm starts by the active set rule*) and with
``warm_start=False`` (the empty active set; 3D has no nested iteration yet). Printed per
level: the free unknowns, the rows in contact, and per run the PDAS steps (``pdas``), the
linear solves (``solves``: factorizations and bordered updates, or the iterative path's
loose and confirming solves) and the solve time; then the mean solves per level after the
first level. ``hertz-3d-coarse`` is ``hertz_3d(h_contact=0.2)``: a level more within the
budget.

    python benchmarks/warm3d.py                                 # the table of docs/method.md
    python benchmarks/warm3d.py --problems hertz-3d --max-ndof 60000  # a quick look
    python benchmarks/warm3d.py --adaptive --problems hertz-3d --max-ndof 40000

With ``--adaptive`` it runs ``adaptive(problem)`` once (warm started) and prints per level the
solves and, for ``--sweeps`` projected ℓ1-Jacobi sweeps before the active set rule
(docs/method.md, *Three dimensions: warm starts smoothed before the rule*), the rows of the
converged active set the prediction misses (``-``) and the rows it adds (``+``).
"""

from __future__ import annotations

import argparse

import numpy as np

import signorini.contact.nested as nested
from signorini.algebra.sparse import stiffness_unit
from signorini.contact.system import assemble
from signorini.examples import get_example
from signorini.examples.hertz3d import hertz_3d
from signorini.loop import adaptive

#: the problems by name: the built-in ones, and hertz-3d from a coarser mesh (more levels)
PROBLEMS = {
    "hertz-3d": lambda: get_example("hertz-3d"),
    "hertz-3d-coarse": lambda: hertz_3d(h_contact=0.2),
    "example-6.2-3d": lambda: get_example("example-6.2-3d"),
}


def _levels(problem, max_ndof: float, warm: bool) -> list:
    """The records of one uniform run."""
    return [
        level.record
        for level in adaptive(problem, uniform=True, max_ndof=max_ndof, warm_start=warm)
    ]


def predictions(problem, max_ndof: float, sweeps: list[int]) -> None:
    """Per adaptive level: the solves, and each sweep count's missed / added rows."""
    u0, default = None, nested.WARM_SMOOTHING_SWEEPS
    try:
        for level in adaptive(problem, max_ndof=max_ndof):  # a loop over levels
            r, res = level.record, level.result
            line = f"{r.level:>5} {r.ndof:>8} {r.n_active:>7} {r.n_solves:>6}"
            if u0 is not None:
                a = assemble(problem, res.mesh)
                unit = stiffness_unit(a.K)
                system = (a.K / unit, a.F / unit)
                final = np.asarray(res.active)
                for k in sweeps:  # a loop over sweep counts
                    nested.WARM_SMOOTHING_SWEEPS = k
                    p = nested.warm_active_set(a.contact, u0, a, system)
                    line += f"   {k:>3}: -{int((~p & final).sum())} +{int((p & ~final).sum())}"
                nested.WARM_SMOOTHING_SWEEPS = default
            print(line, flush=True)
            u0 = level.next_u0
    finally:
        nested.WARM_SMOOTHING_SWEEPS = default


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--problems", nargs="+", choices=sorted(PROBLEMS), default=list(PROBLEMS))
    parser.add_argument("--max-ndof", type=float, default=200_000)
    parser.add_argument("--adaptive", action="store_true", help="the adaptive run's predictions")
    parser.add_argument("--sweeps", nargs="+", type=int, default=[0, 10, 20, 40, 80])
    args = parser.parse_args(argv)
    if args.adaptive:
        for name in args.problems:  # a loop over problems
            print(f"{name} adaptive: level ndof active solves   sweeps: -missed +extra")
            predictions(PROBLEMS[name](), args.max_ndof, args.sweeps)
        return
    for name in args.problems:  # a loop over problems
        problem = PROBLEMS[name]()
        runs = {warm: _levels(problem, args.max_ndof, warm) for warm in (True, False)}
        print(f"{name}:")
        print(
            f"{'level':>5} {'ndof':>8} {'active':>7}   {'pdas':>4} {'solves':>6} {'t_solve':>8}"
            f"   {'pdas':>4} {'solves':>6} {'t_solve':>8}    (warm | cold)"
        )
        for w, c in zip(runs[True], runs[False], strict=True):  # a loop over levels
            print(
                f"{w.level:>5} {w.ndof:>8} {w.n_active:>7}   {w.pdas_iterations:>4} "
                f"{w.n_solves:>6} {w.t_solve:>8.2f}   {c.pdas_iterations:>4} {c.n_solves:>6} "
                f"{c.t_solve:>8.2f}"
            )
        for warm, records in runs.items():  # a loop over the two runs
            later = [r.n_solves for r in records[1:]]
            mean = float(np.mean(later)) if later else float("nan")
            print(f"  {'warm' if warm else 'cold'}: {mean:.2f} solves per level after the first")
        print()


if __name__ == "__main__":
    main()
