"""The problem of a run: a built-in example by name, or ``problem()`` from a Python file.

A problem file is Python code: it runs with the rights of the user who runs the command,
like any script. A file that raises is reported with the traceback of its own frames only.
"""

from __future__ import annotations

import importlib.util
import os
import re
import sys
import traceback
import warnings
from dataclasses import dataclass
from pathlib import Path

from ..examples import EXAMPLES, Metrics
from ..mesh.mesh import Mesh
from ..output.run import file_digest
from ..problem.problem import ContactProblem

__all__ = [
    "ProblemFileError",
    "RunProblem",
    "label",
    "load",
    "load_problem",
    "problem_id",
    "with_curves_of",
]


class ProblemFileError(Exception):
    """A problem file that cannot be used; the message is ready to print."""


def label(name: str) -> str:
    """File-name friendly label of a problem: the example's name or the file's stem, without
    leading dots (``...py`` is ``problem``, not the parent folder ``..``)."""
    return name if name in EXAMPLES else (Path(name).stem.lstrip(".") or "problem")


def _user_traceback(exc: BaseException, folder: Path) -> str:
    """The traceback of ``exc`` restricted to frames in files under ``folder`` (the problem
    file and its helper modules), outside this package and installed packages."""
    package = Path(__file__).resolve().parent.parent  # signorini/, not only its cli

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


@dataclass(frozen=True)
class RunProblem:
    """What a run solves: the problem, its per-level measurements (built-in examples) and
    the load steps solved before it on every level (``partial-slip``, or a problem file's
    ``load_path()``)."""

    problem: ContactProblem
    metrics: Metrics | None = None
    path: list[ContactProblem] | None = None


def load_problem(name: str) -> ContactProblem:
    """A built-in example by name, or ``problem()`` from a Python file (:func:`load`)."""
    return load(name).problem


def load(name: str) -> RunProblem:
    """A built-in example by name, or ``problem()`` (and ``load_path()``, if the file
    defines it) from a Python file.

    The file is executed once, as a module registered in ``sys.modules`` (so that
    dataclasses and ``from __future__ import annotations`` work) with its folder on
    ``sys.path`` (so that a helper module beside it can be imported). A problem file is
    Python code and runs with the user's rights. ``load_path()``, if defined, returns the
    load steps solved before ``problem()`` on every level (a list of ContactProblem on the
    same initial mesh; ``adaptive(..., path=...)``, docs/method.md, *Load paths*).

    Raises
    ------
    ValueError
        For an unknown name, a missing file or a file that is not a problem file.
    ProblemFileError
        When the file's code raises: the message holds the traceback of its own frames.
    """
    if name in EXAMPLES:
        example = EXAMPLES[name]
        return RunProblem(example.problem(), example.metrics, example.steps_before())
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
        steps = getattr(module, "load_path", None)
        if steps is not None and not callable(steps):
            raise ValueError(
                f"load_path in {path} is a {type(steps).__name__}: define it as a function "
                "load_path() returning the list of ContactProblem solved before problem()"
            )
        try:
            problem = factory()
            path_steps = None if steps is None else steps()
        except Exception as exc:
            raise _problem_file_error(path, exc) from None
    finally:
        if folder in sys.path:
            sys.path.remove(folder)
    if not isinstance(problem, ContactProblem):
        raise ValueError(
            f"problem() in {path} returned {type(problem).__name__}, not a ContactProblem"
        )
    if path_steps is not None:
        path_steps = _checked_steps(path, path_steps)
    return RunProblem(problem, None, path_steps)


def _checked_steps(path: Path, steps: object) -> list[ContactProblem]:
    """``load_path()``'s value as a non-empty list of ContactProblem, or a clear error."""
    if isinstance(steps, ContactProblem) or not isinstance(steps, (list, tuple)):
        raise ValueError(
            f"load_path() in {path} returned {type(steps).__name__}, not a list of "
            "ContactProblem (the steps solved before problem())"
        )
    bad = [k for k, s in enumerate(steps) if not isinstance(s, ContactProblem)]
    if bad:
        raise ValueError(
            f"load_path() in {path}: step {bad[0]} is a {type(steps[bad[0]]).__name__}, not "
            "a ContactProblem"
        )
    if not steps:
        raise ValueError(
            f"load_path() in {path} returned no step: leave load_path out for a single step"
        )
    return list(steps)


def with_curves_of(mesh: Mesh, initial: Mesh) -> Mesh:
    """``mesh`` with the curves that ``initial`` attaches to the parts of the same name."""
    for name, curve in zip(initial.part_names, initial.curves, strict=True):
        if curve is not None:  # a loop over parts
            mesh = mesh.with_curve(name, curve)
    return mesh


def problem_id(name: str) -> dict:
    """How a run records its problem: the example's name, or the file with its digest."""
    if name in EXAMPLES:
        return {"name": name, "label": name, "file": None, "sha256": None}
    path = Path(name)
    return {
        "name": name,
        "label": label(name),
        "file": str(path.resolve()),
        "sha256": file_digest(path) if path.is_file() else None,
    }
