"""The command line's arguments: the parser, and which flag sets which option of the run."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..algebra.backends.selection import SOLVERS
from ..estimator.residual import ETA5_VARIANTS
from ..examples import EXAMPLES
from ..loop.options import AdaptiveOptions
from ..version import __version__

__all__ = ["FILE_FLAGS", "OPTION_FLAGS", "TRUST", "flag", "parser"]

TRUST = (
    "A problem file is Python code: signorini executes it with your rights, like any "
    "script you run, so run only files you trust."
)

#: The flags that set a field of :class:`~signorini.loop.AdaptiveOptions` (argparse
#: destination -> field), in the order a ``--resume`` reports the ones that differ.
OPTION_FLAGS: dict[str, str] = {
    "uniform": "uniform",
    "theta": "theta",
    "max_ndof": "max_ndof",
    "tol": "tol",
    "max_levels": "max_levels",
    "eta5": "eta5_variant",
    "backend": "solver",
    "fallback": "fallback",
    "element": "element",
}
#: The flags that decide a run's files (recorded with the options; default off).
FILE_FLAGS = ("no_vtu", "compare_uniform")


def flag(field: str) -> str:
    """The flag that sets ``field`` of the options (``eta5_variant`` -> ``--eta5``)."""
    dest = next((d for d, f in OPTION_FLAGS.items() if f == field), field)
    return "--" + dest.replace("_", "-")


def parser() -> argparse.ArgumentParser:
    """The parser of ``signorini run | figures``; the defaults shown are the options'."""
    default = AdaptiveOptions()
    p = argparse.ArgumentParser(
        prog="signorini",
        description="Adaptive P2 finite elements for the Signorini problem, with or without "
        "friction.",
    )
    p.add_argument("--version", action="version", version=f"signorini {__version__}")
    sub = p.add_subparsers(dest="command", required=True)
    run = sub.add_parser(
        "run",
        help="solve a problem on a sequence of meshes",
        description="Solve a problem on a sequence of adaptively (or uniformly) refined "
        "meshes, writing history.csv, one VTU file per level and figures into the output "
        "folder. A run owns its output folder: it refuses a non-empty one unless "
        "--overwrite is given, and --resume continues an interrupted run. "
        f"{TRUST}",
    )
    run.add_argument(
        "example",
        metavar="PROBLEM",
        nargs="?",
        help=f"one of {', '.join(sorted(EXAMPLES))}, or a Python file defining "
        "problem() -> ContactProblem and optionally load_path() -> the list of "
        "ContactProblem solved before it (Python code, executed with your rights); also "
        "with --resume (a results folder never names the code that runs)",
    )
    run.add_argument(
        "--uniform",
        action="store_true",
        help="uniform refinement instead of adaptive (Dörfler) refinement",
    )
    run.add_argument(
        "--theta", type=float, help=f"Dörfler parameter in (0, 1] (default {default.theta})"
    )
    run.add_argument(
        "--max-ndof",
        type=int,
        help=f"budget of free unknowns, Dirichlet ones excluded (default {default.max_ndof})",
    )
    run.add_argument("--tol", type=float, help=f"stop when eta <= tol (default {default.tol:g})")
    run.add_argument(
        "--max-levels",
        type=int,
        help="stop after this many levels, the initial mesh being the first "
        f"(default {default.max_levels})",
    )
    run.add_argument(
        "--eta5",
        choices=ETA5_VARIANTS,
        help=f"variant of the normal-stress term of the estimator (default {default.eta5_variant})",
    )
    run.add_argument(
        "--backend",
        choices=tuple(SOLVERS),
        help=f"sparse solver (default {default.to_record()['solver']}: pardiso if available, "
        "else scipy)",
    )
    run.add_argument(
        "--fallback",
        action="store_true",
        help="where the active set iteration cycles, finish that level with the primal "
        "active set method instead of stopping",
    )
    run.add_argument(
        "--element",
        type=str.upper,
        choices=("P1", "P2"),
        help="finite element: P2, the paper's, or P1 with its residual estimator (any case; "
        f"default {default.element})",
    )
    run.add_argument(
        "--out", type=Path, default=None, help="output folder (default results/<problem>)"
    )
    run.add_argument(
        "--overwrite",
        action="store_true",
        help="if the output folder is not empty, first remove the files of the run in it "
        "(only files a run writes; other files stay)",
    )
    run.add_argument(
        "--resume",
        type=Path,
        metavar="DIR",
        help="continue the interrupted run in DIR from its last finished level, with its "
        "options (options given again must agree); PROBLEM is named as for a new run and "
        "checked against the run's first level",
    )
    run.add_argument("--no-vtu", action="store_true", help="do not write VTU files")
    run.add_argument("--no-figures", action="store_true", help="do not draw figures")
    talk = run.add_mutually_exclusive_group()
    talk.add_argument("--quiet", action="store_true", help="no progress lines")
    talk.add_argument(
        "--verbose",
        action="store_true",
        help="also the library's log lines (INFO: each solve, factorization and file)",
    )
    run.add_argument(
        "--compare-uniform",
        action="store_true",
        help="also run uniform refinement to the same budget (into OUT/uniform) and plot both",
    )
    fig = sub.add_parser(
        "figures",
        help="redraw the figures of a finished run",
        description="Redraw the convergence figures of the run in DIR from its history.csv. "
        "PROBLEM is named as for run; it is rebuilt and its first level solved again, and "
        "refused unless it is the run's problem.",
    )
    fig.add_argument("example", metavar="PROBLEM", help="the problem's name, as for run")
    fig.add_argument("out", type=Path, help="the run's output folder (with history.csv)")
    return p
