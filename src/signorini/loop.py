"""The adaptive loop SOLVE → ESTIMATE → MARK → REFINE (paper, Section 6).

The only orchestrator of the package: it calls the solver, the estimator, the marking and
the refinement, warm-starts each solve from the previous level, and yields one
:class:`Level` at a time so that callers can write results as soon as a level is done.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Iterator
from dataclasses import asdict, dataclass, field

import numpy as np

from .contact.contact_set import FULL_CONTACT, NO_CONTACT, SEMI_CONTACT
from .contact.solution import ContactResult, solve
from .estimator.marking import check_theta, mark_doerfler
from .estimator.residual import Estimate, estimate
from .mesh.mesh import Mesh
from .mesh.refine import refine_nvb, refine_uniform
from .problem.problem import ContactProblem

__all__ = ["LevelRecord", "Level", "adaptive"]

log = logging.getLogger(__name__)


@dataclass
class LevelRecord:
    """One row of the convergence history: what the numerics measured on one level.

    ``eta`` is the estimator η_h of (5.1) and ``eta_1`` … ``eta_7`` its contributions,
    unsquared, with ``eta² = eta_1² + … + eta_7²`` (docs/method.md, *Estimator*; the
    squared per-cell indicators are :attr:`Estimate.eta2 <signorini.Estimate.eta2>`).
    ``ndof`` is the paper's number of free unknowns, ``t_*`` are seconds spent in each
    step of the loop. A caller writing the row adds its own columns to the dict
    :meth:`row` returns (the command line adds its output time ``t_output``).
    """

    level: int
    ndof: int
    ndof_total: int
    n_cells: int
    eta: float
    eta_1: float
    eta_2: float
    eta_3: float
    eta_4: float
    eta_5: float
    eta_6: float
    eta_7: float
    error_energy: float = math.nan
    error_h1: float = math.nan
    efficiency: float = math.nan
    pdas_iterations: int = 0
    n_solves: int = 0
    n_factorizations: int = 0
    n_analyses: int = 0
    n_updates: int = 0
    n_active: int = 0
    n_constrained: int = 0
    n_full_contact: int = 0
    n_semi_contact: int = 0
    n_no_contact: int = 0
    contact_force: float = 0.0
    n_marked: int = 0
    backend: str = ""
    t_assemble: float = 0.0
    t_solve: float = 0.0
    t_estimate: float = 0.0
    t_mark: float = 0.0
    t_refine: float = 0.0
    extra: dict = field(default_factory=dict)

    def row(self) -> dict:
        """Flat dict for a CSV row."""
        d = asdict(self)
        extra = d.pop("extra")
        d.update(extra)
        return d


@dataclass
class Level:
    """Everything known about one level of the loop."""

    record: LevelRecord
    result: ContactResult
    estimate: Estimate
    marked: np.ndarray | None  # cells marked for refinement (None on the last level)


def adaptive(
    problem: ContactProblem,
    *,
    theta: float = 0.4,
    max_ndof: int = 100_000,
    tol: float = 0.0,
    max_levels: int = 100,
    uniform: bool = False,
    eta5: str = "consistent",
    backend: str = "auto",
    warm_start: bool = True,
    mesh: Mesh | None = None,
) -> Iterator[Level]:
    """Run SOLVE → ESTIMATE → MARK → REFINE, yielding each finished level.

    Stops after the level whose refinement would exceed ``max_ndof`` free unknowns, when
    ``η_h ≤ tol``, or after ``max_levels`` levels. The four steps stay in this one function
    (about 50 lines of code) so that the loop reads top to bottom as in docs/method.md,
    *Marking and refinement*.

    Parameters
    ----------
    problem : ContactProblem
    theta : float
        Dörfler parameter in (0, 1] (ignored when ``uniform``).
    max_ndof : int
        Budget of free unknowns: no level exceeds it.
    tol : float
        Stop once the estimator reaches this value.
    max_levels : int
        Stop after this many levels.
    uniform : bool
        Refine every cell (NVB with all edges bisected) instead of Dörfler marking.
    eta5 : {"consistent", "paper"}
        Variant of the estimator's η5 (docs/method.md, *Estimator*).
    backend : str
        Sparse solver backend.
    warm_start : bool
        Start each PDAS from the previous level's prolongated solution and contact set.
    mesh : Mesh, optional
        Initial mesh (default: the problem's).

    Yields
    ------
    Level
        The record, solution, estimate and marked cells of each level, as soon as it is
        done.

    Raises
    ------
    ValueError
        For ``theta`` outside (0, 1], a non-positive ``max_ndof`` or an initial mesh with
        more than ``max_ndof`` unknowns.
    """
    if not uniform:
        theta = check_theta(theta)
    if max_ndof <= 0:
        raise ValueError(f"max_ndof must be positive, got {max_ndof}")
    mesh = problem.mesh if mesh is None else mesh
    if problem.free_ndof(mesh) > max_ndof:
        raise ValueError(
            f"the initial mesh already has {problem.free_ndof(mesh)} unknowns, "
            f"more than max_ndof={max_ndof}"
        )
    u0 = None
    for level in range(max_levels):
        result = solve(problem, mesh, u0=u0, backend=backend)
        t0 = time.perf_counter()
        est = estimate(result, eta5=eta5)
        t_est = time.perf_counter() - t0
        record = _record(level, result, est)
        record.t_estimate = t_est
        last = level == max_levels - 1 or est.eta <= tol
        marked = None
        if not last:
            t0 = time.perf_counter()
            marked = (
                np.ones(mesh.n_cells, dtype=bool) if uniform else mark_doerfler(est.eta2, theta)
            )
            record.t_mark = time.perf_counter() - t0
            t0 = time.perf_counter()
            refinement = refine_uniform(mesh) if uniform else refine_nvb(mesh, marked)
            next_mesh = refinement.mesh
            last = problem.free_ndof(next_mesh) > max_ndof
            if not last and warm_start:
                u0 = result.space.prolongate(result.u, refinement)
            record.t_refine = time.perf_counter() - t0
            if last:
                marked = None  # the budget ends the run: this marking is discarded
            else:
                record.n_marked = int(marked.sum())
        log.info(
            "level %d: ndof=%d eta=%.4e pdas=%d",
            level,
            record.ndof,
            record.eta,
            record.pdas_iterations,
        )
        yield Level(record, result, est, marked)
        if last:
            return
        mesh = next_mesh


def _record(level: int, result: ContactResult, est: Estimate) -> LevelRecord:
    terms = est.eta_terms
    classes = result.classes
    rec = LevelRecord(
        level=level,
        ndof=result.ndof,
        ndof_total=result.space.n_dofs,
        n_cells=result.mesh.n_cells,
        eta=est.eta,
        **{f"eta_{k + 1}": float(terms[k]) for k in range(7)},
        pdas_iterations=result.pdas.iterations,
        n_solves=result.pdas.n_solves,
        n_factorizations=result.pdas.n_factorizations,
        n_analyses=result.pdas.n_analyses,
        n_updates=result.pdas.n_updates,
        n_active=int(result.active.sum()),
        n_constrained=result.contact.size,
        n_full_contact=int((classes == FULL_CONTACT).sum()),
        n_semi_contact=int((classes == SEMI_CONTACT).sum()),
        n_no_contact=int((classes == NO_CONTACT).sum()),
        contact_force=result.total_contact_force,
        backend=result.pdas.backend,
        t_assemble=result.timings["assemble"],
        t_solve=result.timings["solve"],
    )
    if result.problem.exact is not None:
        err = result.errors()
        rec.error_energy, rec.error_h1 = err["error_energy"], err["error_h1"]
        rec.efficiency = est.eta / err["error_energy"] if err["error_energy"] > 0 else math.nan
    return rec
