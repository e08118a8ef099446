"""``signorini run``: a run as named steps.

:func:`run` opens the interrupted run (``--resume``) or takes a new one's settings, loads the
problem the user names (never one a results folder names), claims and locks the output
folder, checks that a resumed run's problem is the one that produced its levels, then solves
and writes the levels, draws the figures and compares with uniform refinement
(``--compare-uniform``). Each level's files are written as soon as it is done
(:mod:`.levels`), so an interrupted run keeps what it finished.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

from ..algebra.backends.selection import solver_library, solver_name
from ..loop import COLUMNS, Level, adaptive
from ..loop.record import COLUMNS_3D, COLUMNS_3D_CONTACT, COLUMNS_3D_FRICTION, ElasticityRecord
from ..output import HistoryWriter, write_columns
from ..output.check import CHECK, write_check
from ..output.environment import environment
from ..output.run import MANIFEST, ResumeState, RunFolder
from ..output.vtu import write_fields
from .figures import compare_uniform, draw_figures
from .identity import check_problem, name_the_problem, problem_data
from .levels import Clock, Printer, Status, write_levels
from .problems import ProblemFileError, RunProblem, label, load, problem_id, with_curves_of
from .ranks import follow, launched_ranks
from .settings import RunSettings, new_settings, recorded_arguments, resumed_settings

__all__ = ["RunFailed", "run"]

#: errors whose message is written for the user as it is (others are named by their type)
_TOLD = (ValueError, RuntimeError, OSError, ProblemFileError)


@dataclass
class _Run:
    """What the steps of a run share once the problem is loaded."""

    name: str
    settings: RunSettings
    job: RunProblem
    folder: RunFolder
    state: ResumeState | None
    say: Callable[[str], None]

    @property
    def label(self) -> str:
        return label(self.name)


def run(args: argparse.Namespace, status: Status | None = None) -> int:
    """``signorini run``: returns the exit status (0); raises ``ValueError``,
    ``RuntimeError`` or ``OSError`` with a message for the user. The folder's lock is
    released by the caller (``status.folder.close()``) or when the process ends."""
    status = Status(say=Printer(quiet=args.quiet)) if status is None else status
    say = status.say
    if args.resume is not None:
        if launched_ranks() > 1:
            raise ValueError("--resume runs on one process: continue the run without mpiexec")
        folder = _open_resumed(args)
        status.folder = folder
        if args.example is None:
            raise name_the_problem(folder, f"run PROBLEM --resume {args.resume}")
        settings = resumed_settings(args, recorded_arguments(folder.manifest, folder.file))
        name = args.example  # checked by its data (_restart), never by the manifest's name
        if folder.manifest.get("status") == "finished":
            say(f"the run in {args.resume} is finished: nothing to resume")
            return 0
    else:
        if args.example is None:
            raise ValueError("give a PROBLEM (an example's name or a problem file)")
        folder, settings, name = None, new_settings(args), args.example
    status.problem = name
    job = load(name)
    if folder is None and follow(args, settings, job):  # a rank > 0 of an MPI run: no files
        return 0
    state = None
    if folder is None:
        folder = _create_folder(args, name, settings, say)
        status.folder = folder
    else:
        state = _restart(folder, name, job, settings, f"--resume {args.resume}")
    if state is not None:
        status.done = state.level
    work = _Run(name, settings, job, folder, state, say)
    try:
        last = _solve_levels(work, status)
        if last is not None and not args.no_figures:
            status.phase = "while drawing the figures"
            draw_figures(work.label, folder, last, job.metrics, say)
        options = settings.options
        if settings.compare_uniform and not options.uniform and last is not None:
            status.phase = "during the uniform comparison"
            compare_uniform(
                job.problem, options, args.no_figures, folder, say, job.metrics, job.path
            )
    except Exception as exc:
        raise _failed(work, status, exc, figures=not args.no_figures) from exc
    folder.set_status("finished")
    say(f"solver backend: {last.record.backend}" if last else "no level finished")
    return 0


class RunFailed(RuntimeError):
    """A run that stopped on an error once its folder was claimed; the message says where,
    what finished and the error."""


def _failed(work: _Run, status: Status, exc: Exception, figures: bool) -> RunFailed:
    """Record the failure ``exc`` of a run in its manifest (status ``failed``, with the error),
    after drawing the figures of the levels that finished (a failure in a level: a solver's,
    a problem's; a resumed run without a level solved here draws its history only); the
    error for the user."""
    error = str(exc) if isinstance(exc, _TOLD) else f"{type(exc).__name__}: {exc}"
    phase, drawn = status.phase, ""
    if figures and status.done >= 0 and phase.startswith("at level"):
        try:
            draw_figures(work.label, work.folder, status.last, work.job.metrics, work.say)
            drawn = ", their figures drawn"
        except Exception as again:
            drawn = f", their figures not drawn ({type(again).__name__}: {again})"
    try:
        work.folder.set_status("failed", error=f"{phase}: {error}")
        recorded = f"{MANIFEST} records the failure"
    except OSError as again:  # a full disk, a folder removed meanwhile
        recorded = f"{MANIFEST} could not record the failure: {again}"
    return RunFailed(f"the run failed {phase} ({status.finished()}{drawn}; {recorded}): {error}")


# ---------------------------------------------------------------------- the steps
def _open_resumed(args: argparse.Namespace) -> RunFolder:
    """The folder of the run ``--resume`` continues, locked."""
    if args.overwrite:
        raise ValueError("--resume and --overwrite exclude each other")
    if args.out is not None and args.out.resolve() != args.resume.resolve():
        raise ValueError(f"--out {args.out} differs from --resume {args.resume}")
    return RunFolder.open(args.resume)


def _restart(
    folder: RunFolder, name: str, job: RunProblem, settings: RunSettings, verb: str
) -> ResumeState:
    """Check that ``job`` is the run's problem (when the folder holds anything a level
    saved, whatever file is missing), then the saved state of the resumed run, its mesh
    with the problem's curves again (the state holds arrays only)."""
    if folder.saved_work():
        check_problem(folder, name, job, settings.options, verb)
    state = folder.restart(_environment(settings))
    if state.mesh is not None:
        state.mesh = with_curves_of(state.mesh, job.problem.mesh)
    return state


def _environment(settings: RunSettings) -> dict[str, str]:
    """Where the run runs, with the solver library its options name."""
    return environment(solver_library(solver_name(settings.options.solver)))


def _create_folder(
    args: argparse.Namespace, name: str, settings: RunSettings, say: Callable[[str], None]
) -> RunFolder:
    """Claim the output folder of a new run and record its problem and settings."""
    out: Path = args.out or Path("results") / label(name)
    folder, removed = RunFolder.create(
        out,
        problem_id(name),
        settings.record(),
        overwrite=args.overwrite,
        environment=_environment(settings),
    )
    if removed:
        say(f"removed {len(removed)} file(s) of the previous run in {folder.path}")
    return folder


def _checked_levels(levels, work: _Run):
    """The levels, the problem data of the first saved (:mod:`signorini.output.check`)
    before its files are written."""
    for level in levels:
        if level.record.level == 0:
            work.folder.add_files(CHECK)
            write_check(work.folder.path, problem_data(level.result, work.job.path))
        yield level


def _solve_levels(work: _Run, status: Status) -> Level | None:
    """Solve the levels still missing and write each as soon as it is done; with every level
    finished, solve the last one again (warm) for its figures only. Returns the last level."""
    out, state, options, say = work.folder.path, work.state, work.settings.options, work.say
    job = work.job
    work.folder.add_files("history.csv", "history.md")
    three = job.problem.mesh.dim == 3
    columns = COLUMNS_3D_CONTACT if job.problem.contact_parts else COLUMNS_3D
    conditions = job.problem.conditions
    if any(getattr(conditions[p], "friction", None) is not None for p in job.problem.contact_parts):
        columns = COLUMNS_3D_FRICTION
    if three and not job.problem.contact_parts:  # 3D elasticity: no contact columns
        columns = {k: v for k, v in columns.items() if k not in ElasticityRecord.LEFT_OUT}
    write_columns(
        out / "history.md",
        {
            **(columns if three else COLUMNS),
            **(job.metrics.columns if job.metrics else {}),
            "t_output": "seconds spent writing the level's VTU file and recording it",
        },
    )
    vtu = not work.settings.no_vtu
    if vtu:
        work.folder.add_files("fields.md")
        write_fields(out / "fields.md", job.problem.mesh)  # its regions' and bodies' names
    history = HistoryWriter(out / "history.csv", rows=state.history_rows if state else ())
    mode = "uniform" if options.uniform else f"adaptive, theta={options.theta}"
    eta5 = "" if three and not job.problem.contact_parts else f", eta5={options.eta5_variant}"
    say(f"{job.problem.name}: {mode}{eta5}, max_ndof={options.max_ndof} -> {out}")
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
    levels = _checked_levels(adaptive(job.problem, options, **start, **loop), work)
    return write_levels(
        levels,
        history,
        work.folder,
        vtu=vtu,
        save_state=True,
        say=say,
        status=status,
        clock=Clock(options),
    )
