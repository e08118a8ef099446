"""Example-6.2-3d's slope against its singular lines (docs/method.md, *Three dimensions:
example-6.2-3d's slope and the Dirichlet–Neumann edges*).

Prints the exponent λ of the Dirichlet–Neumann edges (Williams' clamped–free equation at
the dihedral angle π/2), then per level of ``adaptive(example-6.2-3d, theta=...)``: N, η_h,
the slope over the last four levels, the share of η² on the cells with a vertex on the D–N
edges, the pyramid's ridges, the contact zone's boundary and the face x = 1, the share of
cells at the D–N edges and their smallest size h_min = |T|^{1/3}.

    python benchmarks/edges3d.py --max-ndof 220000
    python benchmarks/edges3d.py --theta 0.2 --max-ndof 120000
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from examples3d.adaptive_measures import (  # noqa: E402
    dirichlet_neumann_vertices,
    near_cells,
    ridge_vertices,
    zone_boundary_vertices,
)

from signorini.examples import get_example  # noqa: E402
from signorini.loop import adaptive  # noqa: E402


def clamped_free_exponent(omega: float, nu: float) -> float:
    """The smallest real root λ in (0, 1.5) of (3 − 4ν) sin²(λω) = 4(1 − ν)² − λ² sin²ω."""

    def f(lam: float) -> float:
        return (
            (3 - 4 * nu) * np.sin(lam * omega) ** 2 - 4 * (1 - nu) ** 2 + (lam * np.sin(omega)) ** 2
        )

    grid = np.linspace(0.05, 1.5, 2901)
    values = f(grid)
    k = np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:]))[0]
    return brentq(f, grid[k], grid[k + 1])


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--theta", type=float, default=0.4)
    parser.add_argument("--max-ndof", type=float, default=60_000)
    args = parser.parse_args(argv)
    print(
        f"D-N edge (omega = pi/2, nu = 0.3): lambda = {clamped_free_exponent(np.pi / 2, 0.3):.4f}"
    )
    print(f"{'level':>5} {'N':>8} {'eta':>9} {'slope4':>7}  share: {'DN':>5} {'ridge':>5} "
          f"{'zone':>5} {'x=1':>5}  cells@DN {'h_min@DN':>8}")  # fmt: skip
    ns, etas = [], []
    for level in adaptive(get_example("example-6.2-3d"), theta=args.theta, max_ndof=args.max_ndof):
        res, e2 = level.result, level.estimate.eta2  # a loop over levels
        mesh = res.mesh
        sets = {
            "DN": dirichlet_neumann_vertices(res),
            "ridge": ridge_vertices(res),
            "zone": zone_boundary_vertices(res),
            "x1": np.flatnonzero(mesh.points[:, 0] > 1 - 1e-12),
        }
        near = {name: near_cells(mesh, v) for name, v in sets.items()}
        edges = mesh.points[mesh.cells[:, 1:]] - mesh.points[mesh.cells[:, :1]]
        h = np.cbrt(np.abs(np.linalg.det(edges)) / 6)
        ns.append(level.record.ndof)
        etas.append(level.record.eta)
        slope = np.polyfit(np.log(ns[-4:]), np.log(etas[-4:]), 1)[0] if len(ns) >= 4 else np.nan
        shares = " ".join(f"{e2[near[n]].sum() / e2.sum():5.3f}" for n in sets)
        print(
            f"{level.record.level:>5} {ns[-1]:>8} {etas[-1]:>9.4g} {slope:>7.3f}         "
            f"{shares}  {near['DN'].mean():8.3f} {h[near['DN']].min():8.3g}",
            flush=True,
        )


if __name__ == "__main__":
    main()
