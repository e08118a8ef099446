"""Benchmark: the element stiffness's BLAS-free product (``signorini.fem.fixed_order``) against
the BLAS product it replaced, and the whole stiffness assembly, measured in one run.

For Example 6.2 refined uniformly ``--refine`` times, the geometric factors of its cells times
the (10, 144) stiffness basis (affine cells) and ``(m, 70) @ (70, 144)`` (the per-point form
of curved cells) by ``rows_times`` and by ``@``, best of ``--repeat``; and
``assemble_stiffness`` whole. Prints the times and the ratios ``rows_times / matmul``.

    python benchmarks/fixed_order.py                # 526 338 unknowns
    python benchmarks/fixed_order.py --refine 7     # 2.1 million
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from signorini import example_6_2
from signorini.fem.fixed_order import rows_times
from signorini.fem.space import space_of
from signorini.fem.stiffness import _stiffness_basis, assemble_stiffness
from signorini.mesh.refine import refine_uniform


def best(func, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        func()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--refine", type=int, default=6)
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    problem = example_6_2()
    mesh = problem.mesh
    for _ in range(args.refine):
        mesh = refine_uniform(mesh).mesh
    space = space_of(mesh)
    material = problem.material_on(mesh)
    m = mesh.n_cells
    rng = np.random.default_rng(0)
    print(f"ndof={space.n_dofs} cells={m}")
    for per_point in (False, True):
        basis = _stiffness_basis(material.lam_eff, material.mu, False, 4 if per_point else 2,
                                 per_point)  # fmt: skip
        a = rng.random((m if not per_point else m // 10, basis.shape[0]))
        ours = best(lambda a=a, b=basis: rows_times(a, b), args.repeat)
        blas = best(lambda a=a, b=basis: a @ b, args.repeat)
        print(f"({a.shape[0]}, {a.shape[1]}) @ {basis.shape}: rows_times {ours:.4f} s, "
              f"matmul {blas:.4f} s, ratio={ours / blas:.2f}")  # fmt: skip
    K = best(lambda: assemble_stiffness(space.mapping, space.cell_dofs, space.n_dofs, material,
                                        validate=False), args.repeat)  # fmt: skip
    print(f"assemble_stiffness {K:.4f} s, {space.n_dofs / K / 1e6:.2f} M unknowns/s")


if __name__ == "__main__":
    main()
