"""Is the problem the user names the one that produced a run folder's levels?

The problem is rebuilt from what the user names on the command line (never from a path read
in the folder), its first level is solved again, and its data are compared with those the
run saved after its first level (:mod:`signorini.output.check`): mesh, Dirichlet values,
contact data, loads, material and the first level's solution. An edited helper module, an
edited manifest or another problem file is caught by what it changes in these data.
"""

from __future__ import annotations

import shlex
from dataclasses import replace

from ..loop import AdaptiveOptions, adaptive
from ..output.check import CHECK, differences, problem_data, read_check
from ..output.run import RunFolder, RunFolderError
from .problems import RunProblem

__all__ = ["check_problem", "name_the_problem"]


def name_the_problem(folder: RunFolder, command: str) -> RunFolderError:
    """The error for a command on a run folder that names no problem: how to write it, with
    the name the manifest records shown as text only."""
    recorded = folder.manifest.get("problem", {})
    name = recorded.get("name") if isinstance(recorded, dict) else None
    hint = ""
    if isinstance(name, str) and name:
        hint = (
            f" The run recorded its problem as {name!r}; if that is the problem you trust, "
            f"write: signorini {command.replace('PROBLEM', shlex.quote(name))}"
        )
    return RunFolderError(
        f"name the problem: signorini {command} (an example's name or your problem file, as "
        "for a new run). A run folder may come from anyone, so signorini never executes a "
        f"file that it names.{hint}"
    )


def check_problem(
    folder: RunFolder, name: str, job: RunProblem, options: AdaptiveOptions, verb: str
) -> None:
    """Refuse ``job`` unless its first level has the data the run in ``folder`` saved.

    Parameters
    ----------
    folder : RunFolder
    name : str
        The problem as the user named it (for the message).
    job : RunProblem
        The rebuilt problem, its load path and metrics.
    options : AdaptiveOptions
        The run's options (its solver solves the first level again).
    verb : str
        What is refused (``--resume DIR``, ``figures``), for the message.

    Raises
    ------
    RunFolderError
        Naming what differs, or saying the folder holds no problem data.
    """
    saved = read_check(folder.path)
    if saved is None:
        raise RunFolderError(
            f"{verb}: {folder.path} holds no readable {CHECK} (the data of the run's first "
            "level; runs written before this check have none), so its problem cannot be "
            "checked; start the run again with --overwrite"
        )
    once = replace(options, max_levels=1, tol=0.0)
    first = next(adaptive(job.problem, once, path=job.path))
    differ = differences(saved, problem_data(first.result, job.path))
    if differ:
        raise RunFolderError(
            f"{verb}: {name} is not the problem of the run in {folder.path}: rebuilt, it "
            f"differs from the run's first level in {_join(differ)}. Name the problem the "
            "run solved, or start a new run (another --out, or --overwrite)"
        )


def _join(items: list[str]) -> str:
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]
