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
import math
import numbers
import time
from collections.abc import Callable, Iterator, Mapping
from dataclasses import asdict, dataclass, field

import numpy as np

from .algebra.backends import BACKENDS
from .algebra.friction_kkt import FrictionKKT
from .contact.contact_set import FULL_CONTACT, NO_CONTACT, SEMI_CONTACT
from .contact.solution import SLIP, STICK, ContactResult, solve
from .estimator.marking import check_theta, mark_doerfler
from .estimator.residual import ETA5_VARIANTS, Estimate, estimate
from .mesh.mesh import Mesh
from .mesh.refine import refine_nvb, refine_uniform
from .problem.problem import ContactProblem

__all__ = ["COLUMNS", "LevelRecord", "Level", "adaptive"]

log = logging.getLogger(__name__)

#: What each :class:`LevelRecord` field (= each column of a run's ``history.csv``) means,
#: with its unit. Units are those of the problem's data ("consistent units": if E is in MPa
#: and lengths in mm, forces are in N/mm of thickness and energies in N·mm/mm).
COLUMNS: dict[str, str] = {
    "level": "index of the level, 0 for the initial mesh",
    "ndof": "the paper's Ndof: free scalar unknowns, i.e. 2 × (vertices + edges) of the P2 "
    "space minus 2 per node on a Dirichlet part (both components of a Dirichlet node are "
    "excluded; contact unknowns are counted)",
    "ndof_total": "all scalar P2 unknowns, 2 × (vertices + edges), Dirichlet ones included",
    "n_cells": "triangles of the mesh",
    "eta": "the estimator η_h of (5.1), in units of energy norm (√energy)",
    **{
        f"eta_{k}": f"contribution η_{k} of the estimator, unsquared (η² = Σ η_k²), "
        "same unit as eta"
        for k in range(1, 8)
    },
    "eta_8": 'the friction work term η_8 (docs/method.md, *Estimator*, "With friction"), '
    "unsquared, same unit as eta; 0 without friction (with friction eta_4 is "
    "‖σ_t(u_h) + p_t,h‖ weighted as before)",
    "error_energy": "energy norm of u − u_h (only with an exact solution, else nan), "
    "same unit as eta",
    "error_h1": "H¹ seminorm of u − u_h (only with an exact solution, else nan), "
    "unit of displacement",
    "efficiency": "eta / error_energy (only with an exact solution, else nan), no unit",
    "pdas_iterations": "primal-dual active set iterations",
    "n_solves": "linear solves done by the active set method",
    "n_factorizations": "numerical factorizations of the stiffness matrix",
    "n_analyses": "symbolic analyses (orderings) of the stiffness matrix",
    "n_updates": "solves done with a low-rank update of an existing factor",
    "n_active": "contact nodes in the final active set (u·n = ψ imposed)",
    "n_constrained": "nodes on the contact parts (vertices and edge midpoints)",
    "n_full_contact": "contact nodes in full contact",
    "n_semi_contact": "contact nodes in semi contact",
    "n_no_contact": "contact nodes without contact",
    "n_stick": "contact nodes in contact that stick (u_t = 0 imposed; 0 without friction)",
    "n_slip": "contact nodes in contact that slip (friction force at its bound; without "
    "friction every node in contact)",
    "contact_force": "sum of the nodal contact forces Λ_z, unit of force per thickness",
    "n_marked": "cells marked for refinement on this level (0 on the last level)",
    "kkt_primal": "largest penetration u·n − ψ, relative to the contact's displacement scale "
    "(docs/method.md, *Solver*), no unit",
    "kkt_dual": "largest negative contact force, relative to the total contact force",
    "kkt_complementarity": "largest min(|Λ_z| / force scale, |u·n − ψ| / displacement scale)",
    "kkt_stationarity": "largest residual of the equilibrium equations at the free, "
    "unconstrained unknowns, relative to the largest force",
    "kkt_dirichlet": "largest misfit of the Dirichlet values, relative to the displacement scale",
    "kkt_tangential_bound": "largest friction force beyond its bound, max(abs(Λ_t) − s, 0), "
    "relative to the total contact force (only with friction, else nan)",
    "kkt_tangential_complementarity": "largest min(stick residual abs(u_t), slip residual) of "
    "the tangential law (docs/method.md, *Friction*; only with friction, else nan)",
    "backend": "sparse solver backend used (pardiso or scipy)",
    "t_assemble": "seconds spent assembling the linear system",
    "t_solve": "seconds spent in the active set solver",
    "t_estimate": "seconds spent computing the estimator",
    "t_mark": "seconds spent in Dörfler marking",
    "t_refine": "seconds spent refining the mesh (and prolongating the warm start)",
}


@dataclass
class LevelRecord:
    """One row of the convergence history: what the numerics measured on one level.

    Units are those of the problem's data (consistent units: if E is in MPa and lengths in
    mm, forces are in N/mm of thickness). :data:`COLUMNS` holds the same descriptions as
    text; the command line writes them beside ``history.csv`` as ``history.md``.

    Attributes
    ----------
    level : int
        Index of the level, 0 for the initial mesh.
    ndof : int
        The paper's Ndof, the number of **free** scalar unknowns: ``ndof_total`` minus 2
        for every node (vertex or edge midpoint) on a Dirichlet part. Contact unknowns are
        counted. Other codes that count all unknowns report ``ndof_total``.
    ndof_total : int
        All scalar P2 unknowns, ``2 × (n_vertices + n_edges)``.
    n_cells : int
        Triangles of the mesh.
    eta : float
        The estimator η_h of (5.1) (unit of the energy norm, √energy).
    eta_1, eta_2, eta_3, eta_4, eta_5, eta_6, eta_7, eta_8 : float
        Its contributions, unsquared, with ``eta² = eta_1² + … + eta_8²`` (docs/method.md,
        *Estimator*; the squared per-cell indicators are
        :attr:`Estimate.eta2 <signorini.Estimate.eta2>`); ``eta_8``, the friction work, is 0
        without friction.
    error_energy, error_h1 : float
        Energy norm and H¹ seminorm of ``u − u_h`` when the problem has an exact solution,
        else NaN.
    efficiency : float
        ``eta / error_energy`` (NaN without an exact solution).
    pdas_iterations, n_solves, n_factorizations, n_analyses, n_updates : int
        Active set iterations; linear solves; numerical factorizations; symbolic analyses;
        solves done by a low-rank update of an existing factor.
    n_active, n_constrained : int
        Contact nodes in the final active set; all nodes on the contact parts.
    n_full_contact, n_semi_contact, n_no_contact : int
        Contact nodes by class (paper Section 4; docs/method.md, *Estimator*).
    n_stick, n_slip : int
        Contact nodes in contact that stick or slip (``ContactResult.state``; without friction
        every node in contact slips).
    contact_force : float
        Sum of the nodal contact forces Λ_z (force per unit thickness).
    n_marked : int
        Cells marked for refinement (0 on the last level).
    kkt_primal, kkt_dual, kkt_complementarity, kkt_stationarity, kkt_dirichlet : float
        The KKT residuals of the discrete problem, each relative to the quantity it is about
        (:class:`signorini.algebra.kkt.KKTResiduals`; docs/method.md, *Solver*); with
        friction those of :class:`signorini.algebra.friction_kkt.FrictionKKT`.
    kkt_tangential_bound, kkt_tangential_complementarity : float
        With friction, the residuals of the tangential law (docs/method.md, *Friction*);
        NaN without.
    backend : str
        Sparse solver backend used.
    t_assemble, t_solve, t_estimate, t_mark, t_refine : float
        Seconds spent in each step of the loop.
    extra : dict
        Further columns; :meth:`row` merges them into the row. A caller writing the row
        adds its own columns to the dict :meth:`row` returns (the command line adds its
        output time ``t_output``).
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
    eta_8: float
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
    n_stick: int = 0
    n_slip: int = 0
    contact_force: float = 0.0
    n_marked: int = 0
    kkt_primal: float = math.nan
    kkt_dual: float = math.nan
    kkt_complementarity: float = math.nan
    kkt_stationarity: float = math.nan
    kkt_dirichlet: float = math.nan
    kkt_tangential_bound: float = math.nan
    kkt_tangential_complementarity: float = math.nan
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
    """Everything known about one level of the loop.

    Attributes
    ----------
    record : LevelRecord
        The level's row of the convergence history.
    result : ContactResult
        The discrete solution on the level's mesh (``result.mesh``).
    estimate : Estimate
        The a posteriori estimator of that solution.
    marked : (n_cells,) bool array or None
        Cells marked for refinement; None on the last level.
    next_mesh : Mesh or None
        The refined mesh the next level solves on; None on the last level.
    next_u0 : (n_nodes_next, 2) float array or None
        The next level's warm start: ``result.u`` prolongated to ``next_mesh`` (None on the
        last level or without warm start). With ``next_mesh`` it is all the loop needs to
        continue from this level (:func:`adaptive`, ``first_level``).
    """

    record: LevelRecord
    result: ContactResult
    estimate: Estimate
    marked: np.ndarray | None  # cells marked for refinement (None on the last level)
    next_mesh: Mesh | None = None
    next_u0: np.ndarray | None = None


def _check_count(value: object, name: str, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    if value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value}")
    return int(value)


def _check_real(value: object, name: str, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name} must be {what}, got {value!r}")
    value = float(value)
    if math.isnan(value):
        raise ValueError(f"{name} must be {what}, got nan")
    return value


def check_loop_arguments(
    *,
    theta: object = 0.4,
    max_ndof: object = 100_000,
    tol: object = 0.0,
    max_levels: object = 100,
    uniform: object = False,
    eta5: object = "consistent",
    backend: object = "auto",
    first_level: object = 0,
    prefix: str = "",
) -> dict:
    """The arguments of :func:`adaptive`, checked; a ``ValueError`` naming the first bad one.

    ``prefix`` is put before each name in the messages (the command line passes ``"--"``
    and spells the names with dashes).
    """

    def name(n: str) -> str:
        return prefix + (n.replace("_", "-") if prefix else n)

    if not isinstance(uniform, bool | np.bool_):
        raise ValueError(f"{name('uniform')} must be True or False, got {uniform!r}")
    theta = check_theta(theta, name("theta"))
    max_ndof = _check_real(max_ndof, name("max_ndof"), "a positive number")
    if max_ndof <= 0:
        raise ValueError(f"{name('max_ndof')} must be positive, got {max_ndof:g}")
    tol = _check_real(tol, name("tol"), "a number >= 0")
    if tol < 0:
        raise ValueError(f"{name('tol')} must be a number >= 0, got {tol:g}")
    max_levels = _check_count(max_levels, name("max_levels"), 1)
    if eta5 not in ETA5_VARIANTS:
        raise ValueError(f"{name('eta5')} must be one of {list(ETA5_VARIANTS)}, got {eta5!r}")
    backends = ("auto", *BACKENDS)
    if backend not in backends:
        raise ValueError(f"{name('backend')} must be one of {list(backends)}, got {backend!r}")
    first_level = _check_count(first_level, name("first_level"), 0)
    if first_level >= max_levels:
        raise ValueError(
            f"{name('first_level')} must be below {name('max_levels')}={max_levels}, "
            f"got {first_level}"
        )
    return {
        "theta": theta,
        "max_ndof": max_ndof,
        "tol": tol,
        "max_levels": max_levels,
        "uniform": bool(uniform),
        "eta5": eta5,
        "backend": backend,
        "first_level": first_level,
    }


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
    u0: np.ndarray | None = None,
    first_level: int = 0,
    fallback: bool = False,
    metrics: Callable[[ContactResult], Mapping[str, float]] | None = None,
) -> Iterator[Level]:
    """Run SOLVE → ESTIMATE → MARK → REFINE, yielding each finished level.

    Stops after the level whose refinement would exceed ``max_ndof`` free unknowns, when
    ``η_h ≤ tol``, or after ``max_levels`` levels. The four steps stay in one function
    (:func:`_levels`, about 50 lines of code) so that the loop reads top to bottom as in
    docs/method.md, *Marking and refinement*. The arguments are checked when ``adaptive``
    is called, before any work.

    Parameters
    ----------
    problem : ContactProblem
    theta : float
        Dörfler parameter in (0, 1] (ignored when ``uniform``).
    max_ndof : int
        Budget of free unknowns (:attr:`LevelRecord.ndof`): no level exceeds it.
    tol : float
        Stop once the estimator reaches this value (>= 0).
    max_levels : int
        Stop after the level with index ``max_levels - 1`` (at least 1).
    uniform : bool
        Refine every cell (NVB with all edges bisected) instead of Dörfler marking.
    eta5 : {"consistent", "paper"}
        Variant of the estimator's η5 (docs/method.md, *Estimator*).
    backend : {"auto", "pardiso", "scipy"}
        Sparse solver backend.
    warm_start : bool
        Start each PDAS from the previous level's prolongated solution and contact set (with
        friction, the semismooth Newton method from its update rule at that solution).
    mesh : Mesh, optional
        Mesh of the first level (default: the problem's).
    u0 : (n_nodes, 2) float array, optional
        Warm start of the first level's solve on ``mesh`` (P2 nodal displacements: vertices
        first, then edge midpoints); its nodes in contact form the initial active set.
        Default: a cold start.
    first_level : int
        Index of the first level (default 0). To continue a run from its level ``k``, pass
        ``mesh=level.next_mesh, u0=level.next_u0, first_level=k + 1`` and the run's other
        arguments: the levels are those an uninterrupted run yields.
    fallback : bool
        Where PDAS cycles or reaches its iteration bound, finish that level's solve with the
        primal active set method instead of raising (:func:`signorini.solve`); the record's
        ``n_solves`` counts both.
    metrics : callable, optional
        ``metrics(result) -> {column: value}``: measurements of each level's solution beyond
        the record's own (e.g. the Hertz example's errors against the Hertz solution,
        :data:`signorini.examples.METRICS`); they go into :attr:`LevelRecord.extra`, hence into
        the row of ``history.csv``. Names must be new columns, values real numbers.

    Yields
    ------
    Level
        The record, solution, estimate and marked cells of each level, as soon as it is
        done.

    Raises
    ------
    ValueError
        At the call, for an argument of the wrong type or out of range (naming it):
        ``theta`` outside (0, 1], ``max_ndof`` not a positive number, ``tol`` negative or
        NaN, ``max_levels`` < 1, an unknown ``eta5`` or ``backend``, ``first_level`` not
        in ``[0, max_levels)``, or an initial mesh with more than ``max_ndof`` unknowns.
    """
    if not isinstance(problem, ContactProblem):
        raise ValueError(f"problem must be a ContactProblem, got {type(problem).__name__}")
    args = check_loop_arguments(
        theta=theta,
        max_ndof=max_ndof,
        tol=tol,
        max_levels=max_levels,
        uniform=uniform,
        eta5=eta5,
        backend=backend,
        first_level=first_level,
    )
    if metrics is not None and not callable(metrics):
        raise ValueError(f"metrics must be a function of a ContactResult, got {metrics!r}")
    if mesh is not None and not isinstance(mesh, Mesh):
        raise ValueError(f"mesh must be a Mesh, got {type(mesh).__name__}")
    mesh = problem.mesh if mesh is None else mesh
    if problem.free_ndof(mesh) > args["max_ndof"]:
        raise ValueError(
            f"the initial mesh already has {problem.free_ndof(mesh)} unknowns, "
            f"more than max_ndof={max_ndof}"
        )
    return _levels(
        problem,
        mesh,
        u0,
        warm_start=bool(warm_start),
        fallback=bool(fallback),
        metrics=metrics,
        **args,
    )


def _levels(
    problem: ContactProblem,
    mesh: Mesh,
    u0: np.ndarray | None,
    *,
    theta: float,
    max_ndof: float,
    tol: float,
    max_levels: int,
    uniform: bool,
    eta5: str,
    backend: str,
    warm_start: bool,
    fallback: bool,
    first_level: int,
    metrics: Callable[[ContactResult], Mapping[str, float]] | None = None,
) -> Iterator[Level]:
    """The loop of :func:`adaptive`, on checked arguments."""
    for level in range(first_level, max_levels):
        result = solve(problem, mesh, u0=u0, backend=backend, fallback=fallback)
        u0 = None
        t0 = time.perf_counter()
        est = estimate(result, eta5=eta5)
        t_est = time.perf_counter() - t0
        record = _record(level, result, est)
        record.t_estimate = t_est
        if metrics is not None:
            record.extra.update(_measured(metrics, result))
        last = level == max_levels - 1 or est.eta <= tol
        marked = next_mesh = None
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
                marked = next_mesh = None  # the budget ends the run: this marking is discarded
            else:
                record.n_marked = int(marked.sum())
        log.info(
            "level %d: ndof=%d eta=%.4e pdas=%d",
            level,
            record.ndof,
            record.eta,
            record.pdas_iterations,
        )
        yield Level(record, result, est, marked, next_mesh, u0)
        if last:
            return
        mesh = next_mesh


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


def _record(level: int, result: ContactResult, est: Estimate) -> LevelRecord:
    terms = est.eta_terms
    classes = result.classes
    rec = LevelRecord(
        level=level,
        ndof=result.ndof,
        ndof_total=result.space.n_dofs,
        n_cells=result.mesh.n_cells,
        eta=est.eta,
        **{f"eta_{k + 1}": float(terms[k]) for k in range(8)},
        pdas_iterations=result.pdas.iterations,
        # the frictional solver does one linear solve per iteration and reports no updates
        n_solves=getattr(result.pdas, "n_solves", result.pdas.iterations),
        n_factorizations=result.pdas.n_factorizations,
        n_analyses=result.pdas.n_analyses,
        n_updates=getattr(result.pdas, "n_updates", 0),
        n_active=int(result.active.sum()),
        n_constrained=result.contact.size,
        n_full_contact=int((classes == FULL_CONTACT).sum()),
        n_semi_contact=int((classes == SEMI_CONTACT).sum()),
        n_no_contact=int((classes == NO_CONTACT).sum()),
        n_stick=int((result.state == STICK).sum()),
        n_slip=int((result.state == SLIP).sum()),
        contact_force=result.total_contact_force,
        **_kkt_columns(result.pdas),
        backend=result.pdas.backend,
        t_assemble=result.timings["assemble"],
        t_solve=result.timings["solve"],
    )
    if result.problem.exact is not None:
        err = result.errors()
        rec.error_energy, rec.error_h1 = err["error_energy"], err["error_h1"]
        rec.efficiency = est.eta / err["error_energy"] if err["error_energy"] > 0 else math.nan
    return rec


def _kkt_columns(report) -> dict[str, float]:
    """The KKT history columns of a solve: the five of the normal law, and with friction
    (a :class:`~signorini.algebra.friction_kkt.FrictionKKT`) the two of the tangential law."""
    kkt = report.kkt
    if not isinstance(kkt, FrictionKKT):
        return kkt.columns()
    return {
        "kkt_primal": kkt.primal,
        "kkt_dual": kkt.dual,
        "kkt_complementarity": kkt.complementarity,
        "kkt_stationarity": kkt.stationarity,
        "kkt_dirichlet": kkt.dirichlet,
        "kkt_tangential_bound": kkt.tangential_bound,
        "kkt_tangential_complementarity": kkt.tangential_complementarity,
    }
