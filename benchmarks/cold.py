"""Benchmark: a cold ``solve(problem, mesh)`` on a fine mesh against one direct solve.

The fine mesh is the last mesh of Example 6.2's adaptive loop (θ = 0.4) within the budget
of unknowns, made in a child process so that the peak memory printed is that of the solves
alone. Then, in this process: the floor (one complete analysis + factorization + solve of
the mesh's matrix with a fresh solver, :func:`adaptive.floor_seconds`, measured before and
after the solves, the smaller one kept), the cold solve with nested iteration (the default)
and, unless ``--no-baseline``, the cold solve from the empty active set
(``nested=False``). Assembly is outside every timing. It checks that both solves give the
same u and Λ (relative 1e-10) and prints as its last line ``cold_ratio=X``: the nested cold
solve over the floor.

    python benchmarks/cold.py                      # just above 10^6 unknowns
    python benchmarks/cold.py --max-ndof 200000
"""

from __future__ import annotations

import argparse
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from adaptive import floor_seconds

from signorini import adaptive, example_6_2
from signorini.contact import assemble, solve
from signorini.mesh.mesh import Mesh
from signorini.runtime import retain_freed_memory


def make_mesh(max_ndof: int, theta: float, path: Path) -> None:
    """Run the adaptive loop and save its last mesh's arrays to ``path`` (.npz)."""
    mesh = None
    for level in adaptive(example_6_2(), theta=theta, max_ndof=max_ndof):
        mesh = level.result.mesh
    np.savez(
        path,
        points=mesh.points,
        cells=mesh.cells,
        boundary=mesh.boundary,
        part=mesh.boundary_part,
        names=np.array(mesh.part_names),
    )


def load_mesh(path: Path) -> Mesh:
    data = np.load(path)
    names = tuple(str(n) for n in data["names"])
    return Mesh(data["points"], data["cells"], data["boundary"], data["part"], names)


def timed_solve(problem, mesh, assembled, nested: bool):
    t0 = time.perf_counter()
    result = solve(problem, mesh, assembled=assembled, nested=nested)
    return result, time.perf_counter() - t0


def describe(name: str, result, seconds: float, floor: float) -> None:
    p = result.report
    t = p.times
    print(
        f"{name}: {seconds:.3f} s = {seconds / floor:.3f} x floor; fine PDAS {p.iterations} "
        f"iterations, {p.n_factorizations} factorizations, {p.n_updates} low-rank updates; "
        f"analysis {t['analysis']:.2f} s, factorizations {t['factorization']:.2f} s, "
        f"solves {t['solve']:.2f} s, coarse stage {result.timings.get('nested', 0.0):.2f} s",
        flush=True,
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-ndof", type=int, default=1_300_000)
    parser.add_argument("--theta", type=float, default=0.4)
    parser.add_argument("--no-baseline", action="store_true", help="skip the nested=False solve")
    parser.add_argument("--make-mesh", type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args()
    retain_freed_memory()
    if args.make_mesh is not None:
        make_mesh(args.max_ndof, args.theta, args.make_mesh)
        return
    path = Path(tempfile.mkdtemp(prefix="signorini-cold-")) / "mesh.npz"
    command = [sys.executable, __file__, "--max-ndof", str(args.max_ndof)]
    subprocess.run([*command, "--theta", str(args.theta), "--make-mesh", str(path)], check=True)
    problem = example_6_2()
    mesh = load_mesh(path)
    floor_before = floor_seconds(problem, mesh, "auto")[0]
    assembled = assemble(problem, mesh)
    print(f"Example 6.2, adaptive mesh: {problem.free_ndof(mesh)} unknowns, {mesh.n_cells} cells")
    nested, t_nested = timed_solve(problem, mesh, assembled, nested=True)
    baseline = None
    if not args.no_baseline:
        baseline, t_baseline = timed_solve(problem, mesh, assembled, nested=False)
    del assembled
    floor_after = floor_seconds(problem, mesh, "auto")[0]
    floor = min(floor_before, floor_after)
    print(f"floor {floor:.3f} s (measured {floor_before:.3f} s and {floor_after:.3f} s)")
    describe("cold, nested iteration", nested, t_nested, floor)
    if baseline is not None:
        describe("cold, empty active set", baseline, t_baseline, floor)
        du = np.abs(nested.u - baseline.u).max() / np.abs(baseline.u).max()
        force = np.abs(baseline.contact_force).max()
        dl = np.abs(nested.contact_force - baseline.contact_force).max() / force
        print(f"agreement: u {du:.1e}, contact force {dl:.1e} (relative)")
        if max(du, dl) > 1e-10:
            raise SystemExit("the nested solve differs from the cold solve")
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    print(f"peak memory of the solves {peak / 2**20:.0f} MiB")
    print(f"cold_ratio={t_nested / floor:.3f}")


if __name__ == "__main__":
    main()
