"""The adaptive loop in 3D on a built-in problem, against uniform refinement (issue 39).

Per level of ``adaptive(problem)`` (θ = 0.4) it prints N, η and η1 … η7, the energy error and
the efficiency index where the exact solution is known, the active rows, the PDAS steps, and
where Dörfler's marking goes: ``c_zone`` = P(marked | cell touches the discrete contact zone's
boundary) / P(marked | it does not), ``c_DN`` the same for the Dirichlet–Neumann edges
(``tests/examples3d/adaptive_measures.py``; above 1: the marking gathers there), and on the
last level the median h_T of the cells at each set over that of the others. Then the uniform
run to the same budget, the slopes over the last four levels of both, and
N_adaptive / N_uniform at the uniform levels' η (log-log interpolation).

    python benchmarks/adaptive3d.py example-6.2-3d --max-ndof 40000
    python benchmarks/adaptive3d.py hertz-3d --max-ndof 40000 --uniform-max-ndof 40000
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from examples3d.adaptive_measures import (  # noqa: E402
    dirichlet_neumann_vertices,
    marking_concentration,
    ndof_ratio,
    near_cells,
    ridge_vertices,
    zone_boundary_vertices,
)

from signorini.examples import EXAMPLES  # noqa: E402
from signorini.loop import adaptive  # noqa: E402
from signorini.output import fitted_slope  # noqa: E402


def set_names(name: str) -> list[str]:
    """The vertex sets where the marking is measured: the contact zone's boundary, the
    Dirichlet–Neumann edges, and for example-6.2-3d the pyramid's ridges."""
    return ["zone", "DN", "ridge"] if name == "example-6.2-3d" else ["zone", "DN"]


def marked_sets(name: str, result) -> dict[str, np.ndarray]:
    """The vertices of each of :func:`set_names` on ``result``'s mesh."""
    of = {"zone": zone_boundary_vertices, "DN": dirichlet_neumann_vertices, "ridge": ridge_vertices}
    return {label: of[label](result) for label in set_names(name)}


def run(name: str, max_ndof: int, uniform: bool) -> dict:
    problem = EXAMPLES[name].problem()
    history: dict[str, list] = {"ndof": [], "eta": [], "error_energy": []}
    print(f"{name} {'uniform' if uniform else 'adaptive'}, max_ndof {max_ndof}")
    head = "level      N        eta " + " ".join(f"  eta_{k}   " for k in range(1, 8))
    print(head + "   error     eff  active pdas  c_" + "  c_".join(set_names(name)))
    t0 = time.perf_counter()
    last = None
    for lev in adaptive(problem, max_ndof=max_ndof, uniform=uniform):
        r = lev.record
        for key in history:
            history[key].append(getattr(r, key))
        terms = " ".join(f"{getattr(r, f'eta_{k}'):.3e}" for k in range(1, 8))
        shares = [math.nan] * len(set_names(name))
        if lev.marked is not None and not uniform:
            sets = marked_sets(name, lev.result).values()
            shares = [marking_concentration(lev.result.mesh, lev.marked, v) for v in sets]
        print(
            f"{r.level:5d} {r.ndof:7d} {r.eta:.4e} {terms} {r.error_energy:.3e} "
            f"{r.efficiency:7.2f} {r.n_active:6d} {r.pdas_iterations:4d} "
            + " ".join(f"{c:6.2f}" for c in shares),
            flush=True,
        )
        last = lev
    mesh = last.result.mesh
    for label, vertices in marked_sets(name, last.result).items():
        near = near_cells(mesh, vertices)
        if near.any() and not near.all():
            ratio = np.median(mesh.h[near]) / np.median(mesh.h[~near])
            print(f"last level: median h_T at the {label} set / elsewhere = {ratio:.3f}")
    for key in ("eta", "error_energy"):
        if np.isfinite(history[key]).all() and len(history[key]) >= 2:
            slope = fitted_slope(history["ndof"], history[key], 4)
            print(f"slope of {key} over the last 4 levels: {slope:.3f}")
    print(f"{len(history['ndof'])} levels in {time.perf_counter() - t0:.0f} s")
    return history


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("name")
    parser.add_argument("--max-ndof", type=int, default=40_000)
    parser.add_argument("--uniform-max-ndof", type=int, default=None)
    args = parser.parse_args()
    adapted = run(args.name, args.max_ndof, uniform=False)
    uniform = run(args.name, args.uniform_max_ndof or args.max_ndof, uniform=True)
    for n, eta in zip(uniform["ndof"], uniform["eta"], strict=True):
        ratio = ndof_ratio(adapted, uniform, eta)
        print(f"eta {eta:.4e}: N_uniform {n}, N_adaptive / N_uniform = {ratio:.3f}")


if __name__ == "__main__":
    main()
