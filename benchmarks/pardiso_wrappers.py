"""Benchmark: our ctypes PARDISO solver against pydiso's ``MKLPardisoSolver``.

Both call the same MKL PARDISO (real SPD, ``mtype = 2``) with the same settings: parallel
nested dissection (``iparm[1] = 3``), no matrix checker, no iterative refinement. The matrix
is the one PDAS factorizes: the rotated P2 stiffness of Example 6.2 on a uniformly refined
mesh, with the Dirichlet DOFs and a changing set of contact DOFs eliminated in place (same
pattern, refactorized ``--refactorizations`` times). Ours factorizes through the keep-mask of
the elimination (:meth:`SPDSolver.factorize` with ``keep``); pydiso is given the eliminated
matrix (its ``refactor`` takes the upper triangle of it every time). Times are the minimum
over ``--repeat`` rounds, the two wrappers alternating within one process; the peak memory
of each (resident set above the process's before the first analysis) is measured in a child
process of its own.

pydiso is installed for this benchmark only (it builds from source against MKL's headers:
``pip install mkl-devel`` then ``PKG_CONFIG_PATH=<venv>/lib/pkgconfig pip install pydiso``).

Measured (pydiso 0.2.0, MKL 2026.2, 2 cores, machine otherwise idle; 4 factorizations per
round, min of 3 rounds; both wrappers give the same solutions to 5e-14):

=============================  ==============  ==============
                               206 082 unkn.   1 016 738 unkn.
=============================  ==============  ==============
first factorization, ctypes    0.38 + 0.18 s   1.95 + 1.43 s
  pydiso / ctypes: analysis    1.38            2.04
  refactorization              1.12            1.11
  solve                        1.01            0.96
peak memory, ctypes            219 MiB         1148 MiB
  pydiso                       320 MiB         1630 MiB
=============================  ==============  ==============

pydiso's analysis includes its constructor, which analyses with its own settings (serial
METIS) before ours can be set; every refactorization builds the eliminated matrix and its
upper triangle (``sp.triu``), where ours gathers the upper triangle's values through positions
found once. Later runs with other jobs on the machine gave refactorization ratios of 1.07-1.9,
none below 1. pydiso is therefore not used.

    python benchmarks/pardiso_wrappers.py                       # 200k and 1M unknowns
    python benchmarks/pardiso_wrappers.py --sizes 200000 --repeat 5
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import time

import numpy as np

from signorini import example_6_2, refine_uniform
from signorini.algebra.backends.pardiso import PardisoSolver
from signorini.algebra.elimination import SymmetricEliminator
from signorini.contact import assemble
from signorini.runtime import retain_freed_memory


def pdas_systems(size: int, n_systems: int):
    """The stiffness ``K`` and ``n_systems`` fixed masks (Dirichlet and a growing contact set)."""
    n = max(2, int(round((np.sqrt(size / 2) - 1) / 4)))
    n += n % 2
    problem = example_6_2(nx=n)
    mesh = refine_uniform(problem.mesh).mesh
    a = assemble(problem, mesh)
    normal_dofs = 2 * a.contact.nodes
    masks = []
    for k in range(n_systems):
        fixed = np.zeros(a.K.shape[0], dtype=bool)
        fixed[a.dirichlet] = True
        fixed[normal_dofs[: (k + 1) * normal_dofs.size // (n_systems + 1)]] = True
        masks.append(fixed)
    rng = np.random.default_rng(0)
    return a.K, masks, rng.standard_normal(a.K.shape[0])


class Ours:
    name = "ctypes"

    def __init__(self, K):
        self.K = K
        self.solver = PardisoSolver(check_symmetry=False)

    def analyze(self, keep):
        self.solver.factorize(self.K, keep=keep)  # analysis + first factorization

    def factorize(self, keep):
        self.solver.factorize(self.K, keep=keep)

    def solve(self, b):
        return self.solver.solve(b)

    def close(self):
        self.solver.close()


class Pydiso:
    name = "pydiso"

    def __init__(self, K):
        self.K = K
        self.A = K.copy()  # the eliminated matrix, overwritten in place for every system

    def analyze(self, keep):
        from pydiso.mkl_solver import MKLPardisoSolver

        np.multiply(self.K.data, keep, out=self.A.data)
        # the constructor analyses with its own defaults (serial METIS); the settings are only
        # reachable afterwards, so the analysis is repeated with ours (not counted as analysis)
        t0 = time.perf_counter()
        self.solver = MKLPardisoSolver(
            self.A, matrix_type="real_symmetric_positive_definite", factor=False
        )
        self.default_analysis = time.perf_counter() - t0
        self.solver.set_iparm(1, 3)  # parallel nested dissection, as ours
        self.solver.set_iparm(26, 0)  # no matrix checker, as ours
        self.solver.set_iparm(7, 0)
        self.solver._analyze()
        self.solver.refactor(self.A)

    def factorize(self, keep):
        np.multiply(self.K.data, keep, out=self.A.data)
        self.solver.refactor(self.A)

    def solve(self, b):
        return self.solver.solve(b)

    def close(self):
        del self.solver


def run(wrapper, K, masks, b):
    """Seconds of analysis with our settings (the first factorization subtracted), mean
    factorization, mean solve, the solutions, and the seconds of pydiso's constructor."""
    keeps = [SymmetricEliminator(K).keep_mask(fixed) for fixed in masks]
    t0 = time.perf_counter()
    wrapper.analyze(keeps[0])
    t_first = time.perf_counter() - t0
    xs, t_fact, t_solve = [], [], []
    for keep, fixed in zip(keeps, masks, strict=True):
        t0 = time.perf_counter()
        wrapper.factorize(keep)
        t_fact.append(time.perf_counter() - t0)
        rhs = np.where(fixed, 0.0, b)
        t0 = time.perf_counter()
        xs.append(wrapper.solve(rhs))
        t_solve.append(time.perf_counter() - t0)
    wrapper.close()
    extra = getattr(wrapper, "default_analysis", 0.0)
    analysis = t_first - min(t_fact) - extra
    return analysis, float(np.mean(t_fact)), float(np.mean(t_solve)), xs, extra


def resident_bytes(field: str) -> int:
    """``VmRSS`` (now) or ``VmHWM`` (peak since the last reset) of this process, in bytes."""
    with open("/proc/self/status") as f:
        line = next(line for line in f if line.startswith(field + ":"))
    return int(line.split()[1]) * 1024


def peak_memory(kind: str, size: int, n_systems: int, queue) -> None:
    """Peak resident memory of analysis, factorizations and solves above the assembled
    problem (the peak is reset first: the assembly's own peak does not count)."""
    retain_freed_memory()
    K, masks, b = pdas_systems(size, n_systems)
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")  # resets VmHWM to the current resident set
    base = resident_bytes("VmRSS")
    run((Ours if kind == "ctypes" else Pydiso)(K), K, masks, b)
    queue.put(resident_bytes("VmHWM") - base)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[200_000, 1_000_000])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--refactorizations", type=int, default=4)
    parser.add_argument("--no-memory", action="store_true")
    args = parser.parse_args()
    retain_freed_memory()
    for size in args.sizes:
        K, masks, b = pdas_systems(size, args.refactorizations)
        best = {"ctypes": [np.inf] * 3, "pydiso": [np.inf] * 3}
        solutions = {}
        constructor = np.inf
        for _ in range(args.repeat):
            for kind in (Ours, Pydiso):
                *times, xs, extra = run(kind(K), K, masks, b)
                best[kind.name] = [min(t, s) for t, s in zip(best[kind.name], times, strict=True)]
                solutions[kind.name] = xs
                if extra:
                    constructor = min(constructor, extra)
        diff = max(
            np.abs(x - y).max() / np.abs(x).max()
            for x, y in zip(solutions["ctypes"], solutions["pydiso"], strict=True)
        )
        print(
            f"n = {K.shape[0]}, nnz = {K.nnz}, {args.refactorizations} factorizations per "
            f"round, min of {args.repeat} rounds; solutions agree to {diff:.1e} relative"
        )
        print(f"{'':8s} {'analysis':>9s} {'factorize':>10s} {'solve':>8s}  (seconds)")
        for name, (ta, tf, ts) in best.items():
            print(f"{name:8s} {ta:9.3f} {tf:10.3f} {ts:8.4f}")
        ratios = [p / c for p, c in zip(best["pydiso"], best["ctypes"], strict=True)]
        print(f"{'pydiso/ctypes':14s} " + " ".join(f"{r:8.2f}" for r in ratios))
        print(
            f"pydiso's constructor (analysis with its default settings, needed before ours can "
            f"be set) adds {constructor:.3f} s",
            flush=True,
        )
        del K, masks
        if args.no_memory:
            continue
        ctx = mp.get_context("spawn")
        for kind in ("ctypes", "pydiso"):
            queue = ctx.Queue()
            proc = ctx.Process(target=peak_memory, args=(kind, size, 2, queue))
            proc.start()
            extra = queue.get()
            proc.join()
            print(f"{kind:8s} peak memory above the assembled problem: {extra / 2**20:7.0f} MiB")


if __name__ == "__main__":
    main()
