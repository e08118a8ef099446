"""Command line: ``signorini run example-6.2 --out results/6.2``.

``run`` takes one of the paper's examples by name, or a Python file of your own that defines
``problem()`` returning a :class:`~signorini.problem.ContactProblem` (see
``examples/inclined_block.py``). A problem file is Python code: it runs with the rights of
the user who runs the command, like any script.

A run owns its output folder (:mod:`signorini.output.run`): it refuses a non-empty folder
unless ``--overwrite`` is given, and records its files in ``signorini-run.json``. Each
level's VTU file, history row and resume state are written (atomically) as soon as the level
is done, so an interrupted run keeps what it finished and ``--resume`` continues it; the
figures follow at the end. Ctrl-C stops a run with one line saying what finished and where
(exit status 130).
"""

from __future__ import annotations

import argparse
import importlib.util
import logging
import os
import re
import sys
import time
import traceback
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .algebra.backends import BACKENDS
from .estimator.residual import ETA5_VARIANTS
from .examples import EXAMPLES, METRICS, Metrics, get_example, get_load_path
from .loop import COLUMNS, Level, adaptive, check_loop_arguments
from .mesh.mesh import Mesh
from .output import HistoryWriter, write_columns, write_vtu
from .output.run import RunFolder, file_digest
from .problem.problem import ContactProblem
from .runtime import retain_freed_memory

__all__ = ["main", "load_problem"]

#: The options that decide a run's numbers and files, with their defaults; ``--resume``
#: takes them from the interrupted run and refuses different ones.
RUN_DEFAULTS: dict[str, object] = {
    "uniform": False,
    "theta": 0.4,
    "max_ndof": 100_000,
    "tol": 0.0,
    "max_levels": 100,
    "eta5": "consistent",
    "backend": "auto",
    "fallback": False,
    "no_vtu": False,
    "compare_uniform": False,
}

TRUST = (
    "A problem file is Python code: signorini executes it with your rights, like any "
    "script you run, so run only files you trust."
)


class ProblemFileError(Exception):
    """A problem file that cannot be used; the message is ready to print."""


def _parser() -> argparse.ArgumentParser:
    import signorini  # the package's version; the package is loaded before its modules

    p = argparse.ArgumentParser(
        prog="signorini",
        description="Adaptive P2 finite elements for the Signorini problem, with or without "
        "friction.",
    )
    p.add_argument("--version", action="version", version=f"signorini {signorini.__version__}")
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
        "problem() -> ContactProblem (Python code, executed with your rights); may be "
        "left out with --resume",
    )
    run.add_argument(
        "--uniform",
        action="store_true",
        help="uniform refinement instead of adaptive (Dörfler) refinement",
    )
    run.add_argument("--theta", type=float, help="Dörfler parameter in (0, 1] (default 0.4)")
    run.add_argument(
        "--max-ndof",
        type=int,
        help="budget of free unknowns, Dirichlet ones excluded (default 100000)",
    )
    run.add_argument("--tol", type=float, help="stop when eta <= tol (default 0)")
    run.add_argument(
        "--max-levels",
        type=int,
        help="stop after this many levels, the initial mesh being the first (default 100)",
    )
    run.add_argument(
        "--eta5",
        choices=ETA5_VARIANTS,
        help="variant of the normal-stress term of the estimator (default consistent)",
    )
    run.add_argument(
        "--backend",
        choices=("auto", *BACKENDS),
        help="sparse solver (default auto: pardiso if available, else scipy)",
    )
    run.add_argument(
        "--fallback",
        action="store_true",
        help="where the active set iteration cycles, finish that level with the primal "
        "active set method instead of stopping",
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
        "options (options given again must agree)",
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


# ---------------------------------------------------------------------- problem files
def _user_traceback(exc: BaseException, folder: Path) -> str:
    """The traceback of ``exc`` restricted to frames in files under ``folder`` (the problem
    file and its helper modules), outside this package and installed packages."""
    package = Path(__file__).resolve().parent

    def users(filename: str) -> bool:
        if not os.path.isfile(filename):
            return False
        path = Path(filename).resolve()
        installed = {"site-packages", "dist-packages"} & set(path.parts)
        return path.is_relative_to(folder) and not path.is_relative_to(package) and not installed

    frames = [f for f in traceback.extract_tb(exc.__traceback__) if users(f.filename)]
    lines = traceback.format_list(frames) + traceback.format_exception_only(type(exc), exc)
    return "".join(lines).rstrip("\n")


def _problem_file_error(path: Path, exc: BaseException) -> ProblemFileError:
    return ProblemFileError(
        f"the problem file {path} raised {type(exc).__name__}:\n"
        + _user_traceback(exc, path.resolve().parent)
    )


def load_problem(name: str) -> ContactProblem:
    """A built-in example by name, or ``problem()`` from a Python file.

    The file is executed once, as a module registered in ``sys.modules`` (so that
    dataclasses and ``from __future__ import annotations`` work) with its folder on
    ``sys.path`` (so that a helper module beside it can be imported). A problem file is
    Python code and runs with the user's rights.

    Raises
    ------
    ValueError
        For an unknown name, a missing file or a file that is not a problem file.
    ProblemFileError
        When the file's code raises: the message holds the traceback of its own frames.
    """
    if name in EXAMPLES:
        return get_example(name)
    path = Path(name)
    what = (
        "a problem file is a Python file (.py) that defines a function problem() taking "
        "no arguments and returning a ContactProblem (see examples/inclined_block.py)"
    )
    if path.suffix != ".py":
        if path.is_file():
            raise ValueError(f"{path} is not a problem file: {what}")
        raise ValueError(
            f"unknown problem {name!r}: give one of {sorted(EXAMPLES)} or a "
            "Python file defining problem()"
        )
    if not path.is_file():
        raise ValueError(f"no problem file at {path}")
    module_name = "signorini_problem_" + re.sub(r"\W", "_", path.stem)
    spec = importlib.util.spec_from_file_location(module_name, path)
    module = importlib.util.module_from_spec(spec)
    folder = str(path.resolve().parent)
    # Python shows DeprecationWarnings only for __main__: show those raised at the file's
    # own lines (a user function in an old form), which the file's author can act on
    warnings.filterwarnings("default", category=DeprecationWarning, module=module_name)
    sys.modules[module_name] = module
    sys.path.insert(0, folder)
    try:
        try:
            spec.loader.exec_module(module)
        except Exception as exc:
            del sys.modules[module_name]
            raise _problem_file_error(path, exc) from None
        factory = getattr(module, "problem", None)
        if not callable(factory):
            raise ValueError(
                f"{path} is not a problem file: it must define a function problem(); {what}"
            )
        try:
            problem = factory()
        except Exception as exc:
            raise _problem_file_error(path, exc) from None
    finally:
        if folder in sys.path:
            sys.path.remove(folder)
    if not isinstance(problem, ContactProblem):
        raise ValueError(
            f"problem() in {path} returned {type(problem).__name__}, not a ContactProblem"
        )
    return problem


def _with_curves_of(mesh: Mesh, initial: Mesh) -> Mesh:
    """``mesh`` with the curves that ``initial`` attaches to the parts of the same name."""
    for name, curve in zip(initial.part_names, initial.curves, strict=True):
        if curve is not None:  # a loop over parts
            mesh = mesh.with_curve(name, curve)
    return mesh


def _problem_id(name: str) -> dict:
    """How a run records its problem: the example's name, or the file with its digest."""
    if name in EXAMPLES:
        return {"name": name, "label": name, "file": None, "sha256": None}
    path = Path(name)
    return {
        "name": name,
        "label": _label(name),
        "file": str(path.resolve()),
        "sha256": file_digest(path) if path.is_file() else None,
    }


# ---------------------------------------------------------------------- the run
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


@dataclass
class _Status:
    """Where a run is, for the one line printed when it is interrupted."""

    problem: str = ""
    folder: RunFolder | None = None
    done: int = -1  # last level whose files are complete
    phase: str = "while starting"

    def interrupted(self) -> str:
        if self.folder is None:
            return "signorini: interrupted before the run started; nothing was written"
        out = self.folder.path
        if self.done < 0:
            finished = f"no level finished in {out}"
        else:
            levels = "level 0" if self.done == 0 else f"levels 0-{self.done}"
            finished = f"{levels} finished in {out}"
        return (
            f"signorini: interrupted {self.phase}; {finished}; continue with: "
            f"signorini run {self.problem} --resume {out}"
        )


def _write_levels(
    levels: Iterator[Level],
    history: HistoryWriter,
    folder: RunFolder,
    *,
    vtu: bool,
    save_state: bool,
    say: Callable[[str], None],
    status: _Status | None = None,
) -> Level | None:
    """Write each level as soon as it is done: its VTU file (if ``vtu``), then its history
    row with the seconds that file took as ``t_output``, then (if ``save_state``) the state
    to resume from. Returns the last level (None if there was none)."""
    last = None
    for level in levels:
        k = level.record.level
        t0 = time.perf_counter()
        if vtu:
            name = f"level_{k:03d}.vtu"
            folder.add_files(name)
            write_vtu(folder.path / name, level.result, level.estimate)
        history.append({**level.record.row(), "t_output": time.perf_counter() - t0})
        if save_state:
            if level.next_mesh is None:  # the last level: keep its own mesh and solution
                folder.save_state(k, level.result.mesh, level.result.u, final=True)
            else:
                folder.save_state(k, level.next_mesh, level.next_u0, final=False)
        if status is not None:
            status.done = k
            status.phase = f"at level {k + 1}"
        say(_progress(level))
        last = level
    return last


def _run_arguments(args: argparse.Namespace, stored: dict | None) -> dict:
    """The run's options: the given ones (defaults for the others), or with ``--resume``
    the interrupted run's, refusing given ones that differ."""
    out = {}
    conflicts = []
    for key, default in RUN_DEFAULTS.items():
        given = getattr(args, key)
        if stored is None:
            out[key] = default if given is None else given
            continue
        old = stored.get(key, default)
        out[key] = old
        if given is None or (isinstance(default, bool) and not given):
            continue
        if given != old:
            option = "--" + key.replace("_", "-")
            value = "" if isinstance(default, bool) else f" {given}"
            conflicts.append(f"{option}{value} (the run has {old})")
    if conflicts:
        raise ValueError(
            f"--resume {args.resume}: {', '.join(conflicts)}; leave these options out to "
            "continue the run, or start a new run with --overwrite"
        )
    return out


def run(args: argparse.Namespace, status: _Status | None = None) -> int:
    status = _Status() if status is None else status
    say = (lambda s: None) if args.quiet else (lambda s: print(s, flush=True))
    if args.resume is not None:
        if args.overwrite:
            raise ValueError("--resume and --overwrite exclude each other")
        if args.out is not None and args.out.resolve() != args.resume.resolve():
            raise ValueError(f"--out {args.out} differs from --resume {args.resume}")
        folder = RunFolder.open(args.resume)
        stored = folder.manifest
        opts = _run_arguments(args, stored.get("arguments", {}))
        recorded = stored.get("problem", {})
        name = args.example or recorded.get("file") or recorded.get("name")
        if not name:
            raise ValueError(f"--resume {args.resume}: the run does not name its problem")
        now = _problem_id(name)
        same = (
            now["sha256"] == recorded.get("sha256")  # a file: the same contents
            if now["file"] or recorded.get("file")
            else now["name"] == recorded.get("name")
        )
        if not same and (now["file"] or recorded.get("file")):
            raise ValueError(
                f"--resume {args.resume}: {name} is not the problem file the run solved "
                f"({recorded.get('name')}): another file, or its contents changed"
            )
        if not same:
            raise ValueError(
                f"--resume {args.resume}: the run solved {recorded.get('name')!r}, not {name!r}"
            )
        if stored.get("status") == "finished":
            say(f"the run in {args.resume} is finished: nothing to resume")
            return 0
    else:
        if args.example is None:
            raise ValueError("give a PROBLEM (an example's name or a problem file)")
        opts = _run_arguments(args, None)
        name = args.example
    check_loop_arguments(
        **{k: opts[k] for k in ("theta", "max_ndof", "tol", "max_levels", "uniform")},
        eta5=opts["eta5"],
        backend=opts["backend"],
        prefix="--",
    )
    status.problem = name
    problem = load_problem(name)
    label = _label(name)
    metrics = METRICS.get(name) if name in EXAMPLES else None
    path = get_load_path(name) if name in EXAMPLES else None
    if args.resume is not None:
        state = folder.restart()
        status.folder, status.done = folder, state.level
        if state.mesh is not None:
            # the saved state holds arrays only: the curves of the problem's parts come back
            # from the problem itself (the same problem, checked by restart)
            state.mesh = _with_curves_of(state.mesh, problem.mesh)
    else:
        out: Path = args.out or Path("results") / label
        folder, removed = RunFolder.create(out, _problem_id(name), opts, overwrite=args.overwrite)
        status.folder = folder
        if removed:
            say(f"removed {len(removed)} file(s) of the previous run in {out}")
        state = None
    out = folder.path
    folder.add_files("history.csv", "history.md")
    write_columns(
        out / "history.md",
        {
            **COLUMNS,
            **(metrics.columns if metrics else {}),
            "t_output": "seconds spent writing the level's VTU file and recording it",
        },
    )
    history = HistoryWriter(out / "history.csv", rows=state.history_rows if state else ())
    mode = "uniform" if opts["uniform"] else f"adaptive, theta={opts['theta']}"
    say(f"{problem.name}: {mode}, eta5={opts['eta5']}, max_ndof={opts['max_ndof']} -> {out}")
    loop = {
        "theta": opts["theta"],
        "max_ndof": opts["max_ndof"],
        "tol": opts["tol"],
        "max_levels": opts["max_levels"],
        "uniform": opts["uniform"],
        "eta5": opts["eta5"],
        "backend": opts["backend"],
        "fallback": opts["fallback"],
        "metrics": metrics,
        "path": path,
    }
    status.phase = "at level 0" if state is None else f"at level {state.level + 1}"
    last = None
    if state is not None and state.final:
        # every level finished: solve the last one again (warm) for its figures only
        say(f"levels 0-{state.level} were finished; drawing what is missing")
        last = next(
            adaptive(
                problem,
                **{**loop, "max_levels": state.level + 1},
                mesh=state.mesh,
                u0=state.u0,
                first_level=state.level,
            )
        )
    else:
        if state is not None and state.level >= 0:
            say(f"resuming after level {state.level}")
            levels = adaptive(
                problem, **loop, mesh=state.mesh, u0=state.u0, first_level=state.level + 1
            )
        else:
            levels = adaptive(problem, **loop)
        last = _write_levels(
            levels,
            history,
            folder,
            vtu=not opts["no_vtu"],
            save_state=True,
            say=say,
            status=status,
        )
    if last is not None and not args.no_figures:
        status.phase = "while drawing the figures"
        say(f"drawing the figures of {label} (convergence history, mesh, deformed body) ...")
        written = _figures(label, out, last)
        if metrics is not None and metrics.pressure is not None:
            written += _pressure_figure(label, out, last, metrics)
        folder.add_files(*(str(p.relative_to(out)) for p in written))
        say(f"figures: {', '.join(str(p.name) for p in written)}")
    if opts["compare_uniform"] and not opts["uniform"] and last is not None:
        status.phase = "during the uniform comparison"
        _compare_uniform(problem, opts, args.no_figures, folder, say, metrics, path)
    folder.set_status("finished")
    say(f"solver backend: {last.record.backend}" if last else "no level finished")
    return 0


def _compare_uniform(
    problem: ContactProblem,
    opts: dict,
    no_figures: bool,
    folder: RunFolder,
    say,
    metrics: Metrics | None = None,
    path: list[ContactProblem] | None = None,
) -> None:
    """Uniform refinement to the same budget, and one plot of both convergence histories."""
    from . import plots

    out = folder.path
    uni = out / "uniform"
    folder.add_files("uniform/history.csv")
    history = HistoryWriter(uni / "history.csv")
    say(f"{problem.name}: uniform refinement for comparison -> {uni}")
    levels = adaptive(
        problem,
        max_ndof=opts["max_ndof"],
        uniform=True,
        eta5=opts["eta5"],
        backend=opts["backend"],
        fallback=opts["fallback"],
        max_levels=opts["max_levels"],
        metrics=metrics,
        path=path,
    )
    _write_levels(levels, history, folder, vtu=False, save_state=False, say=say)
    if no_figures:
        return
    say("drawing adaptive against uniform refinement ...")
    histories = {"adaptive": out / "history.csv", "uniform": uni / "history.csv"}
    written = plots.plot_adaptive_vs_uniform(histories, out / "adaptive_vs_uniform", key="eta")
    if problem.exact is not None:
        written += plots.plot_adaptive_vs_uniform(
            histories, out / "adaptive_vs_uniform_error", key="error_energy"
        )
    folder.add_files(*(str(Path(p).relative_to(out)) for p in written))
    say(f"figures: {', '.join(str(p.name) for p in written)}")


def _figures(example: str, out: Path, last: Level | None = None) -> list[Path]:
    """The run's figures (:func:`signorini.plots.run_figures.run_figures`); matplotlib is
    imported only when figures are drawn."""
    from .plots.run_figures import run_figures

    return run_figures(example, out, last)


def _pressure_figure(example: str, out: Path, last: Level, metrics: Metrics) -> list[Path]:
    """The last level's pressure beside the known one the example's ``metrics`` give."""
    from .plots.run_figures import pressure_figure

    return pressure_figure(example, out, last, metrics)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``signorini`` command.

    Returns the exit status: 0 on success, 2 for an error (one message on stderr; for a
    problem file that raises, the traceback of its own frames), 130 when interrupted
    (Ctrl-C), with one line saying what finished and where.
    """
    args = _parser().parse_args(argv)
    retain_freed_memory()  # large meshes: reuse freed pages instead of faulting in new ones
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    status = _Status()
    try:
        if args.command == "run":
            return run(args, status)
        if args.command == "figures":
            written = _figures(_label(args.example), args.out)
            print("\n".join(str(p) for p in written))
            return 0
    except KeyboardInterrupt:
        if status.folder is not None:
            try:
                status.folder.set_status("interrupted")
            except OSError:
                pass
        print(status.interrupted(), file=sys.stderr, flush=True)
        return 130
    except ProblemFileError as exc:
        print(f"signorini: error: {exc}", file=sys.stderr)
        return 2
    except (ValueError, RuntimeError, OSError) as exc:
        print(f"signorini: error: {exc}", file=sys.stderr)
        return 2
    return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
