"""Benchmark: the 3D estimator's rate (unknowns per second) on P2 tetrahedra
(docs/method.md, *Three dimensions: the estimator on tetrahedra and faces*).

Two problems, each solved once per size and estimated ``--repeat`` times (the best time is
printed, with the spread max/min):

- ``elasticity-3d`` (``signorini.examples.elasticity3d``): the Kuhn cube with ``n³`` cubes,
  affine cells, a body force (η1 with f at the 27 points of the cell rule), Dirichlet on every
  face (η2 on every interior face).
- ``hertz-3d``: the graded eighth ball (``hertz_3d(h_contact=...)``), isoparametric cells
  along the sphere (η1 through the quadratic maps, η2 on curved interior faces), rollers and
  a held component (η3), the contact faces (η4 … η7).

Printed per row: the free unknowns N, the cells, the contact faces, the best estimate time,
N / time, and η_h.

    python benchmarks/estimate3d.py                      # N ≈ 10⁵ for both
    python benchmarks/estimate3d.py --sizes 6 --h-contact 0.1 --repeat 1   # a quick look
"""

from __future__ import annotations

import argparse
import time

from signorini.contact.solution import solve
from signorini.estimator.residual import estimate
from signorini.examples.elasticity3d import elasticity_3d
from signorini.examples.hertz3d import hertz_3d


def _timed(result, repeat: int) -> tuple[float, float, float]:
    """The best and worst of ``repeat`` estimates of ``result``, and η_h."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        est = estimate(result)
        times.append(time.perf_counter() - t0)
    return min(times), max(times), est.eta


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[16], help="elasticity-3d n")
    parser.add_argument(
        "--h-contact", type=float, nargs="+", default=[0.018], help="hertz-3d h_contact"
    )
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    print(f"{'problem':>14} {'N':>8} {'cells':>7} {'faces_C':>7} {'best s':>7} {'spread':>6} "
          f"{'N/s':>9} {'eta':>10}")  # fmt: skip
    cases = [(f"elasticity n={n}", lambda n=n: elasticity_3d(n)) for n in args.sizes]
    cases += [(f"hertz h={h}", lambda h=h: hertz_3d(h_contact=h)) for h in args.h_contact]
    for name, build in cases:  # a loop over the benchmark's problems
        result = solve(build())
        best, worst, eta = _timed(result, args.repeat)
        faces = len(result.contact.faces) if result.contact.size else 0
        print(
            f"{name:>14} {result.ndof:8d} {result.mesh.n_cells:7d} {faces:7d} {best:7.2f} "
            f"{worst / best:6.2f} {result.ndof / best:9.3g} {eta:10.4e}",
            flush=True,
        )


if __name__ == "__main__":
    main()
