"""``signorini run``: a run as named steps.

:func:`run` opens the interrupted run (``--resume``) or takes a new one's settings, loads the
problem, claims the output folder, then solves and writes the levels, draws the figures and
compares with uniform refinement (``--compare-uniform``). Each level's files are written as
soon as it is done (:mod:`.levels`), so an interrupted run keeps what it finished.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

from ..examples import EXAMPLES, Metrics
from ..loop import COLUMNS, Level, adaptive
from ..output import HistoryWriter, write_columns
from ..output.run import ResumeState, RunFolder
from ..problem.problem import ContactProblem
from .figures import compare_uniform, draw_figures
from .levels import Status, write_levels
from .problems import label, load_problem, problem_id, with_curves_of
from .settings import RunSettings, new_settings, resumed_settings

__all__ = ["run"]


@dataclass
class _Run:
    """What the steps of a run share once the problem is loaded."""

    name: str
    settings: RunSettings
    problem: ContactProblem
    metrics: Metrics | None
    path: list[ContactProblem] | None
    folder: RunFolder
    state: ResumeState | None
    say: Callable[[str], None]

    @property
    def label(self) -> str:
        return label(self.name)


def run(args: argparse.Namespace, status: Status | None = None) -> int:
    """``signorini run``: returns the exit status (0); raises ``ValueError``,
    ``RuntimeError`` or ``OSError`` with a message for the user."""
    status = Status() if status is None else status
    say = (lambda s: None) if args.quiet else (lambda s: print(s, flush=True))
    if args.resume is not None:
        folder = _open_resumed(args)
        settings = resumed_settings(args, folder.manifest.get("arguments", {}))
        name = _resumed_problem(args, folder.manifest.get("problem", {}))
        if folder.manifest.get("status") == "finished":
            say(f"the run in {args.resume} is finished: nothing to resume")
            return 0
    else:
        if args.example is None:
            raise ValueError("give a PROBLEM (an example's name or a problem file)")
        folder, settings, name = None, new_settings(args), args.example
    status.problem = name
    problem = load_problem(name)
    example = EXAMPLES.get(name)
    state = None
    if folder is None:
        folder = _create_folder(args, name, settings, say)
    else:
        state = _restart(folder, problem)
    status.folder = folder
    if state is not None:
        status.done = state.level
    job = _Run(
        name,
        settings,
        problem,
        example.metrics if example else None,
        example.steps_before() if example else None,
        folder,
        state,
        say,
    )
    last = _solve_levels(job, status)
    if last is not None and not args.no_figures:
        status.phase = "while drawing the figures"
        draw_figures(job.label, folder, last, job.metrics, say)
    options = settings.options
    if settings.compare_uniform and not options.uniform and last is not None:
        status.phase = "during the uniform comparison"
        compare_uniform(problem, options, args.no_figures, folder, say, job.metrics, job.path)
    folder.set_status("finished")
    say(f"solver backend: {last.record.backend}" if last else "no level finished")
    return 0


# ---------------------------------------------------------------------- the steps
def _open_resumed(args: argparse.Namespace) -> RunFolder:
    """The folder of the run ``--resume`` continues, read only."""
    if args.overwrite:
        raise ValueError("--resume and --overwrite exclude each other")
    if args.out is not None and args.out.resolve() != args.resume.resolve():
        raise ValueError(f"--out {args.out} differs from --resume {args.resume}")
    return RunFolder.open(args.resume)


def _resumed_problem(args: argparse.Namespace, recorded: dict) -> str:
    """The problem of the resumed run: PROBLEM if given (it must be the run's: the same
    example, or a file with the same contents), else the one the run recorded."""
    name = args.example or recorded.get("file") or recorded.get("name")
    if not name:
        raise ValueError(f"--resume {args.resume}: the run does not name its problem")
    now = problem_id(name)
    is_file = now["file"] or recorded.get("file")
    same = (
        now["sha256"] == recorded.get("sha256")  # a file: the same contents
        if is_file
        else now["name"] == recorded.get("name")
    )
    if not same and is_file:
        raise ValueError(
            f"--resume {args.resume}: {name} is not the problem file the run solved "
            f"({recorded.get('name')}): another file, or its contents changed"
        )
    if not same:
        raise ValueError(
            f"--resume {args.resume}: the run solved {recorded.get('name')!r}, not {name!r}"
        )
    return name


def _restart(folder: RunFolder, problem: ContactProblem) -> ResumeState:
    """The saved state of the resumed run, its mesh with the problem's curves again (the
    state holds arrays only; the problem is the same, checked by restart)."""
    state = folder.restart()
    if state.mesh is not None:
        state.mesh = with_curves_of(state.mesh, problem.mesh)
    return state


def _create_folder(
    args: argparse.Namespace, name: str, settings: RunSettings, say: Callable[[str], None]
) -> RunFolder:
    """Claim the output folder of a new run and record its problem and settings."""
    out: Path = args.out or Path("results") / label(name)
    folder, removed = RunFolder.create(
        out, problem_id(name), settings.record(), overwrite=args.overwrite
    )
    if removed:
        say(f"removed {len(removed)} file(s) of the previous run in {out}")
    return folder


def _solve_levels(job: _Run, status: Status) -> Level | None:
    """Solve the levels still missing and write each as soon as it is done; with every level
    finished, solve the last one again (warm) for its figures only. Returns the last level."""
    out, state, options, say = job.folder.path, job.state, job.settings.options, job.say
    job.folder.add_files("history.csv", "history.md")
    write_columns(
        out / "history.md",
        {
            **COLUMNS,
            **(job.metrics.columns if job.metrics else {}),
            "t_output": "seconds spent writing the level's VTU file and recording it",
        },
    )
    history = HistoryWriter(out / "history.csv", rows=state.history_rows if state else ())
    mode = "uniform" if options.uniform else f"adaptive, theta={options.theta}"
    say(
        f"{job.problem.name}: {mode}, eta5={options.eta5_variant}, "
        f"max_ndof={options.max_ndof} -> {out}"
    )
    loop = {"metrics": job.metrics, "path": job.path}
    status.phase = "at level 0" if state is None else f"at level {state.level + 1}"
    if state is not None and state.final:
        say(f"levels 0-{state.level} were finished; drawing what is missing")
        again = replace(options, max_levels=state.level + 1)
        return next(
            adaptive(
                job.problem, again, mesh=state.mesh, u0=state.u0, first_level=state.level, **loop
            )
        )
    if state is not None and state.level >= 0:
        say(f"resuming after level {state.level}")
        start = {"mesh": state.mesh, "u0": state.u0, "first_level": state.level + 1}
    else:
        start = {}
    levels = adaptive(job.problem, options, **start, **loop)
    return write_levels(
        levels,
        history,
        job.folder,
        vtu=not job.settings.no_vtu,
        save_state=True,
        say=say,
        status=status,
    )
