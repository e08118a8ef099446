"""The adaptive loop SOLVE → ESTIMATE → MARK → REFINE (paper, Section 6).

The only orchestrator of the package: it calls the solver, the estimator, the marking and
the refinement, warm-starts each solve from the previous level, and yields one
:class:`Level` at a time so that callers can write results as soon as a level is done.
A level also carries the mesh and warm start of the next one (:attr:`Level.next_mesh`,
:attr:`Level.next_u0`), so an interrupted run can be continued from its last finished level
with ``adaptive(..., mesh=level.next_mesh, u0=level.next_u0, first_level=k + 1)`` and gives
the same levels as an uninterrupted run.
"""

from __future__ import annotations

import logging
import numbers
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, fields, replace

import numpy as np

from ..algebra.ranks import solver_ranks
from ..contact.load_path import check_path, solve_path
from ..contact.partition import partition
from ..contact.solution import ContactResult, solve
from ..estimator.marking import mark_doerfler
from ..estimator.residual import Estimate, estimate
from ..estimator.roundoff import roundoff_level
from ..fem.space import space_of
from ..mesh.mesh import Mesh
from ..mesh.refine import refine_nvb, refine_uniform
from ..problem.problem import ContactProblem
from .options import AdaptiveOptions, OptionError, check_count
from .record import COLUMNS, LevelRecord, level_record

__all__ = [
    "COLUMNS",
    "AdaptiveOptions",
    "Level",
    "LevelRecord",
    "OptionError",
    "adaptive",
    "roundoff_text",
]

log = logging.getLogger(__name__)


@dataclass
class Level:
    """Everything known about one level of the loop.

    Attributes
    ----------
    record : LevelRecord
        The level's row of the convergence history.
    result : ContactResult
        The discrete solution on the level's mesh (``result.mesh``).
    estimate : Estimate or None
        The a posteriori estimator of that solution (in 3D :mod:`signorini.estimator.
        residual3d`).
    marked : (n_cells,) bool array or None
        Cells marked for refinement; None on the last level.
    next_mesh : Mesh or None
        The refined mesh the next level solves on; None on the last level.
    next_u0 : (n_nodes_next, 2) float array or None
        The next level's warm start: ``result.u`` prolongated to ``next_mesh`` (with a load
        path, the first step's solution; None on the last level or without warm start).
        With ``next_mesh`` it is all the loop needs to continue from this level
        (:func:`adaptive`, ``first_level``).
    """

    record: LevelRecord
    result: ContactResult
    estimate: Estimate | None
    marked: np.ndarray | None  # cells marked for refinement (None on the last level)
    next_mesh: Mesh | None = None
    next_u0: np.ndarray | None = None


def adaptive(
    problem: ContactProblem,
    options: AdaptiveOptions | None = None,
    *,
    mesh: Mesh | None = None,
    u0: np.ndarray | None = None,
    first_level: int = 0,
    metrics: Callable[[ContactResult], Mapping[str, float]] | None = None,
    path: Sequence[ContactProblem] | None = None,
    **changes: object,
) -> Iterator[Level]:
    """Run SOLVE → ESTIMATE → MARK → REFINE, yielding each finished level.

    Stops after the level whose refinement would exceed ``max_ndof`` free unknowns, when
    ``η_h ≤ tol``, when η_h reaches its round-off level (``η_h ≤``
    :func:`~signorini.estimator.roundoff.roundoff_level`: the problem is solved to
    round-off, and finer meshes would refine noise), or after ``max_levels`` levels
    (:class:`AdaptiveOptions`); the last level's :attr:`LevelRecord.stop` says which. The four
    steps stay in one function (:func:`_levels`, about 50 lines of code) so that the loop
    reads top to bottom as in docs/method.md, *Marking and refinement*. The arguments are
    checked when ``adaptive`` is called, before any work.

    Parameters
    ----------
    problem : ContactProblem
    options : AdaptiveOptions, optional
        How the loop runs: θ, the budgets, the tolerance, uniform refinement, the η5 variant,
        warm start, the fallback and the linear solver. Default ``AdaptiveOptions()``.
    mesh : Mesh, optional
        Mesh of the first level (default: the problem's).
    u0 : (n_nodes, 2) float array, optional
        Warm start of the first level's solve on ``mesh`` (nodal displacements of the
        element's space: for P2 vertices first, then edge midpoints; for P1 the vertices);
        its nodes in contact form the initial active set.
        Default: a cold start.
    first_level : int
        Index of the first level (default 0). To continue a run from its level ``k``, pass
        ``mesh=level.next_mesh, u0=level.next_u0, first_level=k + 1`` and the run's options:
        the levels are those an uninterrupted run yields.
    metrics : callable, optional
        ``metrics(result) -> {column: value}``: measurements of each level's solution beyond
        the record's own (e.g. the Hertz example's errors against the Hertz solution,
        :attr:`signorini.examples.Example.metrics`); they go into :attr:`LevelRecord.extra`,
        hence into the row of ``history.csv``. Names must be new columns, values real
        numbers.
    path : sequence of ContactProblem, optional
        The load steps before ``problem`` of a quasi-static load path (Coulomb friction is
        path-dependent; docs/method.md, *Load paths*), on the same initial mesh with the same
        contact parts. Each level then solves the whole path ``[*path, problem]`` on its mesh
        (:func:`~signorini.contact.load_path.solve_path`, each step from the previous one),
        and estimates, marks and measures the last step. ``u0`` and :attr:`Level.next_u0`
        are then the warm start of the first step (its solution on the previous level,
        prolongated); the record's iteration counts and solve timings are summed over the
        steps, its KKT residuals are the last step's. ``fallback`` does not apply to it.
    **changes
        Fields of :class:`AdaptiveOptions` that replace those of ``options``:
        ``adaptive(problem, theta=0.5, max_ndof=10**6)`` is
        ``adaptive(problem, AdaptiveOptions(theta=0.5, max_ndof=10**6))``.

    Yields
    ------
    Level
        The record, solution, estimate and marked cells of each level, as soon as it is
        done.

    Raises
    ------
    ValueError
        At the call, for an argument of the wrong type or out of range (naming it): an
        option (:class:`~.options.OptionError`, naming the field), ``first_level`` not in
        ``[0, max_levels)``, an initial mesh with more than ``max_ndof`` unknowns, or a
        ``path`` whose steps are not problems on ``problem``'s initial mesh with its contact
        parts.
    TypeError
        For a keyword that is no field of :class:`AdaptiveOptions`.
    """
    if not isinstance(problem, ContactProblem):
        raise ValueError(f"problem must be a ContactProblem, got {type(problem).__name__}")
    options = _changed(options, changes)
    first_level = check_count(first_level, "first_level", 0)
    if first_level >= options.max_levels:
        raise ValueError(
            f"first_level must be below max_levels={options.max_levels}, got {first_level}"
        )
    if metrics is not None and not callable(metrics):
        raise ValueError(f"metrics must be a function of a ContactResult, got {metrics!r}")
    if mesh is not None and not isinstance(mesh, Mesh):
        raise ValueError(f"mesh must be a Mesh, got {type(mesh).__name__}")
    if path is not None:
        if isinstance(path, ContactProblem) or not isinstance(path, Sequence):
            raise ValueError(
                f"path must be a sequence of ContactProblem (the load steps before problem), "
                f"got {type(path).__name__}"
            )
        path = check_path([*path, problem])[:-1]
    mesh = problem.mesh if mesh is None else mesh
    if problem.free_ndof(space_of(mesh, options.element)) > options.max_ndof:
        raise ValueError(
            f"the initial mesh already has {problem.free_ndof(space_of(mesh, options.element))} "
            "unknowns, "
            f"more than max_ndof={options.max_ndof}"
        )
    return _levels(problem, mesh, u0, options, first_level, metrics, path or None)


def _changed(options: AdaptiveOptions | None, changes: Mapping[str, object]) -> AdaptiveOptions:
    """``options`` (default ``AdaptiveOptions()``) with the fields in ``changes`` replaced,
    checked; a ``TypeError`` for a name that is no field."""
    if options is None:
        options = AdaptiveOptions()
    elif not isinstance(options, AdaptiveOptions):
        raise ValueError(f"options must be an AdaptiveOptions, got {type(options).__name__}")
    names = [f.name for f in fields(AdaptiveOptions)]
    unknown = sorted(set(changes) - set(names))
    if unknown:
        raise TypeError(
            f"adaptive() got unexpected keyword arguments {unknown}; the options are {names}"
        )
    return replace(options, **changes) if changes else options


def _levels(
    problem: ContactProblem,
    mesh: Mesh,
    u0: np.ndarray | None,
    options: AdaptiveOptions,
    first_level: int,
    metrics: Callable[[ContactResult], Mapping[str, float]] | None,
    path: Sequence[ContactProblem] | None,
) -> Iterator[Level]:
    """The loop of :func:`adaptive`, on checked arguments."""
    uniform, solver, element = options.uniform, options.solver, options.element
    for level in range(first_level, options.max_levels):
        if path:
            steps = solve_path([*path, problem], mesh, solver=solver, u0=u0, element=element)
            result, warm = steps[-1], steps[0]
        else:
            result = warm = solve(
                problem, mesh, u0=u0, solver=solver, fallback=options.fallback, element=element
            )
            steps = [result]
        u0 = None
        on_ranks = _estimator_ranks(result, solver)
        t0 = time.perf_counter()
        est = estimate(result, options.eta5_variant, **on_ranks)
        t_est = time.perf_counter() - t0
        record = level_record(level, result, est)
        record.t_estimate = t_est
        if path:
            _add_path_counts(record, steps)
        if metrics is not None:
            record.extra.update(_measured(metrics, result))
        record.eta_roundoff = roundoff_level(result)
        record.stop = _stop_reason(record, options)
        last = bool(record.stop)
        marked = next_mesh = None
        if not last:
            t0 = time.perf_counter()
            marked = (
                np.ones(mesh.n_cells, dtype=bool)
                if uniform
                else mark_doerfler(est.eta2, options.theta)
            )
            record.t_mark = time.perf_counter() - t0
            t0 = time.perf_counter()
            refinement = refine_uniform(mesh) if uniform else refine_nvb(mesh, marked)
            next_mesh = refinement.mesh
            last = problem.free_ndof(space_of(next_mesh, element)) > options.max_ndof
            if not last and options.warm_start:
                u0 = warm.space.prolongate(warm.u, refinement)
            record.t_refine = time.perf_counter() - t0
            if last:
                marked = next_mesh = None  # the budget ends the run: this marking is discarded
                record.stop = "max_ndof"
            else:
                record.n_marked = int(marked.sum())
        log.info(
            "level %d: ndof=%d eta=%.4e pdas=%d",
            level,
            record.ndof,
            record.eta,
            record.pdas_iterations,
        )
        if record.stop == "round-off":
            log.info("stopped: %s", roundoff_text(record))
        yield Level(record, result, est, marked, next_mesh, u0)
        if last:
            return
        # this level's solution, estimator and refinement maps are the caller's now: not held
        # here while the next level is solved (whose factorization is the run's memory peak)
        del result, warm, steps, est, marked, refinement
        mesh = next_mesh


def _stop_reason(record: LevelRecord, options: AdaptiveOptions) -> str:
    """Why the loop ends after this level, before refining (:attr:`LevelRecord.stop`): ``"tol"``
    for ``η_h ≤ tol``, ``"round-off"`` for η_h at its round-off level, ``"max_levels"``;
    ``""`` to go on (the budget, ``"max_ndof"``, is known only once the mesh is refined)."""
    if record.eta <= options.tol:
        return "tol"
    if record.eta <= record.eta_roundoff:  # False for a NaN level: no level known
        return "round-off"
    if record.level == options.max_levels - 1:
        return "max_levels"
    return ""


def roundoff_text(record: LevelRecord) -> str:
    """What a run says when it stops at round-off (its log and the command line)."""
    return (
        f"eta = {record.eta:.3e} is at the round-off level {record.eta_roundoff:.3e} of this "
        "problem (docs/method.md, *Round-off*): it is solved to round-off on this mesh, and "
        "a finer mesh would refine noise; no rate is fitted to noise"
    )


def _estimator_ranks(result: ContactResult, solver: object) -> dict[str, object]:
    """:func:`estimate`'s ``ranks`` and ``partition`` on a run of several MPI ranks (those of
    the solver, :func:`~signorini.algebra.ranks.solver_ranks`; docs/parallel.md): each rank
    integrates its own cells, of the partition its rows were assembled by; nothing on one
    process."""
    ranks = solver_ranks(solver)
    if not ranks.distributed:
        return {}
    own = result.partition if result.partition is not None else partition(result.space, ranks)
    return {"ranks": ranks, "partition": own}


def _add_path_counts(record: LevelRecord, steps: Sequence[ContactResult]) -> None:
    """A load path's level: the record's iteration counts and solve timings summed over the
    steps (:func:`level_record` wrote the last step's)."""
    for r in steps[:-1]:
        report = r.report
        record.pdas_iterations += report.iterations
        record.n_solves += report.n_solves
        record.n_factorizations += report.n_factorizations
        record.n_analyses += report.n_analyses
        record.n_updates += report.n_updates
        record.t_assemble += r.timings["assemble"]
        record.t_solve += r.timings["solve"]


def _measured(
    metrics: Callable[[ContactResult], Mapping[str, float]], result: ContactResult
) -> dict[str, float]:
    """``metrics(result)`` checked: new column names, real values (NaN where undefined)."""
    values = metrics(result)
    if not isinstance(values, Mapping):
        raise ValueError(f"metrics must return a mapping column -> value, got {values!r}")
    out = {}
    for name, value in values.items():
        if not isinstance(name, str) or name in COLUMNS or name == "extra":
            raise ValueError(f"metrics: {name!r} is not a new column name")
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise ValueError(f"metrics: the value of {name!r} must be a real number, got {value!r}")
        out[name] = float(value)
    return out
