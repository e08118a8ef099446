"""Command line: ``signorini run example-6.2 --out results/6.2``.

``run`` takes one of the paper's examples by name, or a Python file of your own that defines
``problem()`` returning a :class:`~signorini.problem.ContactProblem` (see
``examples/inclined_block.py``).

Each level's history row and VTU file are written (atomically) as soon as the level is done,
so an interrupted run keeps what it finished; the figures follow at the end.
"""

from __future__ import annotations

import argparse
import importlib.util
import logging
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from .estimator.marking import check_theta
from .estimator.residual import ETA5_VARIANTS
from .examples import EXAMPLES, get_example
from .loop import Level, adaptive
from .output import HistoryWriter, write_vtu
from .problem.problem import ContactProblem
from .runtime import retain_freed_memory

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="signorini",
        description="Adaptive P2 finite elements for the frictionless Signorini problem.",
    )
    sub = p.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="solve a problem on a sequence of meshes")
    run.add_argument(
        "example",
        metavar="PROBLEM",
        help=f"one of {', '.join(sorted(EXAMPLES))}, or a Python file defining "
        "problem() -> ContactProblem",
    )
    run.add_argument(
        "--uniform",
        action="store_true",
        help="uniform refinement instead of adaptive (Dörfler) refinement",
    )
    run.add_argument("--theta", type=float, default=0.4, help="Dörfler parameter (default 0.4)")
    run.add_argument(
        "--max-ndof", type=int, default=100_000, help="budget of free unknowns (default 100000)"
    )
    run.add_argument("--tol", type=float, default=0.0, help="stop when eta <= tol")
    run.add_argument("--max-levels", type=int, default=100)
    run.add_argument(
        "--eta5",
        choices=ETA5_VARIANTS,
        default="consistent",
        help="variant of the normal-stress term of the estimator",
    )
    run.add_argument("--backend", default="auto", help="sparse solver: auto, pardiso, scipy")
    run.add_argument(
        "--out", type=Path, default=None, help="output folder (default results/<example>)"
    )
    run.add_argument("--no-vtu", action="store_true", help="do not write VTU files")
    run.add_argument("--no-figures", action="store_true", help="do not draw figures")
    run.add_argument("--quiet", action="store_true", help="no progress lines")
    run.add_argument(
        "--compare-uniform",
        action="store_true",
        help="also run uniform refinement to the same budget (into OUT/uniform) and plot both",
    )
    fig = sub.add_parser("figures", help="redraw the figures of a finished run")
    fig.add_argument("example", metavar="PROBLEM", help="the problem's name, as for run")
    fig.add_argument("out", type=Path, help="the run's output folder (with history.csv)")
    return p


def _label(name: str) -> str:
    """File-name friendly label of a problem: the example's name or the file's stem."""
    return name if name in EXAMPLES else Path(name).stem


def load_problem(name: str) -> ContactProblem:
    """A built-in example by name, or ``problem()`` from a Python file."""
    if name in EXAMPLES:
        return get_example(name)
    path = Path(name)
    if path.suffix != ".py":
        raise ValueError(
            f"unknown problem {name!r}: give one of {sorted(EXAMPLES)} or a "
            "Python file defining problem()"
        )
    if not path.is_file():
        raise ValueError(f"no problem file at {path}")
    spec = importlib.util.spec_from_file_location(f"signorini_user_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    factory = getattr(module, "problem", None)
    if not callable(factory):
        raise ValueError(f"{path} must define a function problem() returning a ContactProblem")
    problem = factory()
    if not isinstance(problem, ContactProblem):
        raise ValueError(
            f"problem() in {path} returned {type(problem).__name__}, not a ContactProblem"
        )
    return problem


def _progress(level: Level) -> str:
    r = level.record
    line = f"level {r.level:3d}  ndof {r.ndof:9d}  cells {r.n_cells:8d}  eta {r.eta:.4e}"
    if not np.isnan(r.error_energy):
        line += f"  error {r.error_energy:.4e}  eff {r.efficiency:.3f}"
    line += (
        f"  pdas {r.pdas_iterations:2d}  active {r.n_active:5d}"
        f"  [{r.t_assemble + r.t_solve + r.t_estimate + r.t_mark + r.t_refine:.2f}s]"
    )
    return line


def _write_levels(
    levels: Iterator[Level], history: HistoryWriter, vtu_dir: Path | None, say
) -> Level | None:
    """Write each level as soon as it is done: its VTU file (into ``vtu_dir``, unless None),
    then its history row with the seconds that file took as ``t_output``. Returns the last
    level (None if there was none)."""
    last = None
    for level in levels:
        t0 = time.perf_counter()
        if vtu_dir is not None:
            write_vtu(vtu_dir / f"level_{level.record.level:03d}.vtu", level.result, level.estimate)
        history.append({**level.record.row(), "t_output": time.perf_counter() - t0})
        say(_progress(level))
        last = level
    return last


def run(args: argparse.Namespace) -> int:
    if not args.uniform:
        check_theta(args.theta, "--theta")
    if args.max_ndof <= 0:
        raise ValueError(f"--max-ndof must be positive, got {args.max_ndof}")
    problem = load_problem(args.example)
    label = _label(args.example)
    out: Path = args.out or Path("results") / label
    out.mkdir(parents=True, exist_ok=True)
    history = HistoryWriter(out / "history.csv")
    say = (lambda s: None) if args.quiet else (lambda s: print(s, flush=True))
    mode = "uniform" if args.uniform else f"adaptive, theta={args.theta}"
    say(f"{problem.name}: {mode}, eta5={args.eta5}, max_ndof={args.max_ndof} -> {out}")
    levels = adaptive(
        problem,
        theta=args.theta,
        max_ndof=args.max_ndof,
        tol=args.tol,
        max_levels=args.max_levels,
        uniform=args.uniform,
        eta5=args.eta5,
        backend=args.backend,
    )
    last = _write_levels(levels, history, None if args.no_vtu else out, say)
    if last is not None and not args.no_figures:
        written = _figures(label, out, last)
        say(f"figures: {', '.join(str(p.name) for p in written)}")
    if args.compare_uniform and not args.uniform and last is not None:
        _compare_uniform(args, out, say)
    say(f"solver backend: {last.record.backend}" if last else "no level finished")
    return 0


def _compare_uniform(args: argparse.Namespace, out: Path, say) -> None:
    """Uniform refinement to the same budget, and one plot of both convergence histories."""
    from . import plots

    problem = load_problem(args.example)
    uni = out / "uniform"
    history = HistoryWriter(uni / "history.csv")
    say(f"{problem.name}: uniform refinement for comparison -> {uni}")
    levels = adaptive(
        problem,
        max_ndof=args.max_ndof,
        uniform=True,
        eta5=args.eta5,
        backend=args.backend,
        max_levels=args.max_levels,
    )
    _write_levels(levels, history, None, say)
    if args.no_figures:
        return
    histories = {"adaptive": out / "history.csv", "uniform": uni / "history.csv"}
    written = plots.plot_adaptive_vs_uniform(histories, out / "adaptive_vs_uniform", key="eta")
    if problem.exact is not None:
        written += plots.plot_adaptive_vs_uniform(
            histories, out / "adaptive_vs_uniform_error", key="error_energy"
        )
    say(f"figures: {', '.join(str(p.name) for p in written)}")


def _figures(example: str, out: Path, last: Level | None = None) -> list[Path]:
    """The run's convergence figures; with its last level also the mesh and the deformed body.

    The mesh figure shows the finest level of at most ``plots.READABLE_CELLS`` cells (read back
    from its ``level_NNN.vtu``; the last level when that file is missing or holds another
    mesh), with Γ_D, Γ_N and Γ_C marked. The deformed body is drawn with a stated displacement
    scale, the obstacle at its gap with the same scale.
    """
    from . import plots
    from .output import read_history
    from .plots.deformed import free_boundary_ends

    written = list(plots.make_figures(out / "history.csv", out, example))
    if last is None:
        return written
    res = last.result
    mesh = res.mesh
    # the level the mesh figure shows
    history = read_history(out / "history.csv")
    k = plots.readable_level(history["n_cells"])
    level, points, cells = last.record.level, mesh.points, mesh.cells
    if k != level and (out / f"level_{k:03d}.vtu").is_file():
        p, c = plots.read_level_mesh(out / f"level_{k:03d}.vtu")
        if c.shape[0] == int(history["n_cells"][k]):
            level, points, cells = k, p, c
    problem = res.problem
    initial = problem.mesh
    kinds = {
        r"Dirichlet $\Gamma_D$": problem.dirichlet_parts,
        r"Neumann $\Gamma_N$": problem.neumann_parts,
        r"contact $\Gamma_C$": problem.contact_parts,
    }
    segments = {
        label: np.concatenate(
            [initial.points[initial.edges[initial.part_edges(n)]] for n in parts]
            or [np.zeros((0, 2, 2))]
        )
        for label, parts in kinds.items()
    }
    # a zoom on the first end of the contact zone, if it ends inside Γ_C
    cs = res.contact
    ends = free_boundary_ends(res.space.node_points[cs.nodes], res.active)
    zoom = {}
    if len(ends):
        half = 0.06 * float(np.ptp(points, axis=0).max())
        # the window inside the body's bounding box, so it shows mesh, not empty space
        centre = np.clip(ends[0], points.min(axis=0) + 0.9 * half, points.max(axis=0) - 0.9 * half)
        zoom = {"zoom": (*centre, half), "zoom_title": "end of the contact zone"}
    written += plots.plot_mesh(
        points,
        cells,
        out / "mesh",
        title=f"{example}: mesh, level {level}, {cells.shape[0]} cells",
        highlight=plots.boundary_groups(points, cells, segments),
        colors=("#1f77b4", "#2ca02c", "#d62728"),
        **zoom,
    )
    written += plots.plot_deformed(
        mesh.points,
        mesh.cells,
        res.u[: mesh.n_points],
        out / "deformed",
        contact_points=res.space.node_points[cs.nodes],
        pressure=res.pressure,
        gap=cs.gap,
        normal=cs.normal,
        title=f"{example}: deformed body",
    )
    return written


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``signorini`` command."""
    args = _parser().parse_args(argv)
    retain_freed_memory()  # large meshes: reuse freed pages instead of faulting in new ones
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    try:
        if args.command == "run":
            return run(args)
        if args.command == "figures":
            written = _figures(_label(args.example), args.out)
            print("\n".join(str(p) for p in written))
            return 0
    except (ValueError, RuntimeError, OSError) as exc:
        print(f"signorini: error: {exc}", file=sys.stderr)
        return 2
    return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
