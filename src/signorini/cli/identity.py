"""Is the problem the user names the one that produced a run folder's levels?

The problem is rebuilt from what the user names on the command line (never from a path read
in the folder), its first level is solved again, and its data are compared with those the
run saved after its first level (:mod:`signorini.output.check`): mesh, Dirichlet values,
contact data, loads, material and the first level's solution. An edited helper module, an
edited manifest or another problem file is caught by what it changes in these data.
"""

from __future__ import annotations

import shlex
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from ..contact.face_contact import FaceContactSet
from ..contact.mortar3d_set import MortarFaceSet
from ..contact.system import assemble
from ..loop import AdaptiveOptions, adaptive
from ..output.check import CHECK, MESH_ARRAYS, differences, read_check
from ..output.run import RunFolder, RunFolderError
from ..problem.problem import ContactProblem
from .problems import RunProblem

__all__ = ["check_problem", "name_the_problem", "problem_data"]


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


def _step_data(problem: ContactProblem, mesh, k: int) -> dict[str, np.ndarray]:
    """The assembled data of load step ``k`` on ``mesh``: the whole matrix (on one process),
    as rank 0 alone writes and checks them, on the first level's mesh, even on several."""
    system = assemble(problem, mesh)
    cs = system.contact
    probe = np.sin(1.0 + np.arange(system.K.shape[0]))  # no zero entry, no symmetry
    if isinstance(cs, FaceContactSet | MortarFaceSet):  # on faces (3D): no friction
        normal, nodes, friction = cs.direction, cs.node, np.zeros(0)
    else:
        normal, nodes = cs.normal, cs.nodes
        friction = np.concatenate([cs.friction.index, cs.friction.weight])
    return {
        f"dirichlet.{k}": system.dirichlet_values,
        f"contact.{k}.gap": cs.gap,
        f"contact.{k}.normal": normal,
        f"contact.{k}.nodes": nodes.astype(np.float64),
        f"contact.{k}.friction": friction.astype(np.float64),
        f"loads.{k}": system.F,
        f"material.{k}": system.K @ probe,
    }


def problem_data(result, path: Sequence[ContactProblem] | None = None) -> dict[str, np.ndarray]:
    """The data that identifies the problem of a run, from its first level's ``result``.

    Parameters
    ----------
    result : ContactResult
        The first level's solution (of the last load step with a load path).
    path : sequence of ContactProblem, optional
        The load steps solved before ``result.problem`` on every level.

    Returns
    -------
    dict of str to array
        Named arrays; the first part of a name (before a dot) is what they describe.
    """
    mesh = result.problem.mesh
    data: dict[str, np.ndarray] = {
        f"mesh.{name}": np.asarray(getattr(mesh, name)) for name in MESH_ARRAYS
    }
    data["mesh.part_names"] = np.array(mesh.part_names, dtype=str)
    steps = [*(path or ()), result.problem]
    data["steps.count"] = np.array([len(steps)], dtype=np.float64)
    for k, step in enumerate(steps):
        data.update(_step_data(step, result.space.mesh, k))
    data["solution.u"] = np.asarray(result.u, dtype=np.float64)
    data["solution.contact_force"] = np.asarray(result.contact_force, dtype=np.float64)
    if result.tangential_force is not None:
        data["solution.tangential_force"] = np.asarray(result.tangential_force, dtype=np.float64)
    return data
