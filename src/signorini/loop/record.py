"""One level's row of the convergence history: :data:`COLUMNS` (what each column means,
with its unit) and :class:`LevelRecord`, filled from a level's solution and estimate by
:func:`level_record`."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import ClassVar

import numpy as np

from ..contact.contact_set import FULL_CONTACT, NO_CONTACT, SEMI_CONTACT
from ..contact.solution import SLIP, STICK, ContactResult
from ..estimator.names import TERM_TABLE, TERMS
from ..estimator.residual import Estimate

__all__ = [
    "COLUMNS",
    "COLUMNS_3D",
    "COLUMNS_3D_CONTACT",
    "COLUMNS_3D_FRICTION",
    "ElasticityRecord",
    "FaceContactRecord",
    "FrictionalFaceContactRecord",
    "LevelRecord",
    "level_record",
]

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
    **{term.name: term.description for term in TERM_TABLE},
    "error_energy": "energy norm of u − u_h (only with an exact solution, else nan), "
    "same unit as eta",
    "error_h1": "H¹ seminorm of u − u_h (only with an exact solution, else nan), "
    "unit of displacement",
    "efficiency": "eta / error_energy (only with an exact solution, else nan), no unit",
    "eta_roundoff": "the round-off level of eta on this mesh (docs/method.md, *Round-off*): "
    "an eta at or below it is noise, and the loop stops there; same unit as eta",
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
    "stop": "why the run ends after this level, empty on the others: tol (eta <= tol), "
    "round-off (eta at eta_roundoff), max_ndof (the next mesh would exceed the budget), "
    "max_levels",
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
    eta_roundoff : float
        The round-off level of η_h on this mesh
        (:func:`~signorini.estimator.roundoff.roundoff_level`): an η_h at or below it is
        noise, and the loop stops there.
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
    stop : str
        Why the loop ends after this level (``""`` on the others): ``"tol"``,
        ``"round-off"``, ``"max_ndof"`` or ``"max_levels"``.
    kkt_primal, kkt_dual, kkt_complementarity, kkt_stationarity, kkt_dirichlet : float
        The KKT residuals of the discrete problem, each relative to the quantity it is about
        (:class:`signorini.algebra.kkt.KKTResiduals`; docs/method.md, *Solver*); with
        friction those of :class:`signorini.algebra.friction.kkt.FrictionKKT`.
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
    eta_roundoff: float = math.nan
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
    stop: str = ""
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

    #: the fields a row leaves out (none here; :class:`ElasticityRecord`)
    LEFT_OUT: ClassVar[tuple[str, ...]] = ()

    def row(self) -> dict:
        """Flat dict for a CSV row (without the fields of :attr:`LEFT_OUT`)."""
        d = asdict(self)
        extra = d.pop("extra")
        d.update(extra)
        for name in self.LEFT_OUT:
            del d[name]
        return d


#: The columns of a level without an estimator (the estimator's, NaN there) and without
#: contact (the contact's, zero or NaN there).
NO_ESTIMATE_COLUMNS = ("eta", *TERMS, "efficiency", "eta_roundoff")
NO_CONTACT_COLUMNS = (
    "n_active", "n_constrained", "n_full_contact", "n_semi_contact", "n_no_contact",
    "n_stick", "n_slip", "contact_force", "kkt_primal", "kkt_dual", "kkt_complementarity",
    "kkt_tangential_bound", "kkt_tangential_complementarity",
)  # fmt: skip


@dataclass
class ElasticityRecord(LevelRecord):
    """The record of a level of 3D elasticity without contact (docs/method.md, *Three
    dimensions: solving elasticity*): its row leaves out the contact's columns, which hold
    nothing there (zero, NaN), and without an estimate the estimator's as well (NaN); the
    attributes stay, so code reading a record reads either kind. An
    iterative solve adds ``linear_iterations`` to :attr:`extra`."""

    LEFT_OUT: ClassVar[tuple[str, ...]] = NO_CONTACT_COLUMNS

    def row(self) -> dict:
        """Flat dict for a CSV row, without the contact's columns (and the estimator's where
        there is no estimate)."""
        d = super().row()
        if math.isnan(self.eta):
            for name in NO_ESTIMATE_COLUMNS:
                del d[name]
        return d


#: The columns of a 3D run's history, with their meaning in 3D (an
#: :class:`ElasticityRecord`'s row has those but the contact's).
COLUMNS_3D: dict[str, str] = {
    **COLUMNS,
    "ndof": "free scalar unknowns, 3 × (vertices + edges) of the P2 tetrahedra minus 3 per "
    "node on a Dirichlet part (one per fixed component on a roller)",
    "ndof_total": "all scalar P2 unknowns, 3 × (vertices + edges), Dirichlet ones included",
    "n_cells": "tetrahedra of the mesh",
    "error_energy": "energy norm of u − u_h (only with an exact solution, else nan), unit √energy",
    "pdas_iterations": "iterations of the solve, one linear system each (without contact the "
    "active set is empty: one, or a second with an iterative solver's tightened tolerance)",
    "linear_iterations": "CG iterations of an iterative solver (amg), summed over the level's "
    "solves; absent with a direct solver",
    "backend": "sparse solver backend used (pardiso, scipy or amg)",
    "osc_obstacle": "the obstacle's interpolation term beside eta, (Σ_F |∫_F λ̃_h (ψ − ψ_h)|)^(1/2) "
    "(docs/method.md, *Three dimensions: the estimator on tetrahedra and faces*); not a part "
    "of eta, unit of eta_6; 3D contact runs only",
}


#: The columns a frictionless 3D contact level's row leaves out: the friction's
#: (:class:`FrictionalFaceContactRecord` keeps them).
FACE_CONTACT_LEFT_OUT = (
    "n_stick", "n_slip", "kkt_tangential_bound", "kkt_tangential_complementarity",
)  # fmt: skip


@dataclass
class FaceContactRecord(LevelRecord):
    """The record of a 3D contact level (docs/method.md, *Three dimensions: contact on
    faces*): its row leaves out :data:`FACE_CONTACT_LEFT_OUT` and, on a level without an
    estimate (η NaN), the estimator's columns; an iterative solve adds
    ``linear_iterations`` to :attr:`extra`."""

    LEFT_OUT: ClassVar[tuple[str, ...]] = FACE_CONTACT_LEFT_OUT

    def row(self) -> dict:
        """Flat dict for a CSV row (without :attr:`LEFT_OUT`, and without the estimator's
        columns where there is no estimate)."""
        d = super().row()
        if math.isnan(self.eta):
            for name in NO_ESTIMATE_COLUMNS:
                del d[name]
        return d


#: The columns of a 3D contact run's history (:class:`FaceContactRecord`), with their
#: meaning in 3D.
_IN_3D_CONTACT = {
    "pdas_iterations": "primal-dual active set iterations",
    "n_active": "constraint rows in the final active set: the P2 nodes of Γ_C in contact (one "
    "row per node and contact part; for condition (b) the transformed coefficient at its "
    "bound)",
    "n_full_contact": "rows in full contact (Section 4 on faces: every node of every contact "
    "face at the row in contact)",
    "n_semi_contact": "rows in contact but not in full contact (where η6 lives)",
    "n_no_contact": "rows not in contact",
    "n_constrained": "constraint rows: the P2 nodes (vertices and edge midpoints) of the "
    "contact parts' faces whose normal component is not held, one per node and part",
    "contact_force": "Σ Λ_z (3.17) over the rows, force units: the resultant normal force on "
    "Γ_C where all n_z agree",
    "kkt_primal": "largest penetration of the solver's bounds (for condition (b) those of the "
    "transformed coefficients, ỹ ≤ ψ̃), relative to the contact's displacement scale "
    "(docs/method.md, *Solver*), no unit",
    "kkt_dual": "largest negative multiplier (for condition (b) the transformed force "
    "Λ̃ = T Λ), relative to the total contact force",
    "kkt_complementarity": "largest min(|multiplier| / force scale, |bound − variable| / "
    "displacement scale) over the rows, in the solver's variables",
    "linear_iterations": "CG iterations of an iterative solver (amg), summed over the level's "
    "PDAS solves; absent with a direct solver",
}
COLUMNS_3D_CONTACT: dict[str, str] = {
    name: _IN_3D_CONTACT.get(name) or COLUMNS_3D.get(name) or COLUMNS[name]
    for name in [*COLUMNS, "osc_obstacle", "linear_iterations"]
    if name not in FACE_CONTACT_LEFT_OUT
}
#: The friction's columns of a 3D frictional run's history, with their meaning on faces
#: (docs/method.md, *Friction in three dimensions: the disc law*).
_FRICTION_3D = {
    "n_stick": "contact rows in contact that stick (‖ξ‖ < s: the slip increment is 0)",
    "n_slip": "contact rows in contact that slip (‖Λ_t‖ = s, the slip along Λ_t); a "
    "frictionless row in contact counts here",
    "kkt_tangential_bound": "largest friction force beyond its bound, max(‖Λ_t‖ − s, 0), "
    "relative to the contact force scale (‖·‖ of the node frame's [t_1 t_2] components)",
    "kkt_tangential_complementarity": "largest min(stick residual ‖x_t − x_ref‖, slip "
    "residual) over the rows: the slip residual is the larger of | ‖Λ_t‖ − s | and the "
    "wrong way ‖Λ_t‖ ‖x_t − x_ref‖ − Λ_t·(x_t − x_ref), each scaled (docs/method.md)",
}
#: The columns of a 3D frictional contact run's history
#: (:class:`FrictionalFaceContactRecord`).
COLUMNS_3D_FRICTION: dict[str, str] = {
    name: _FRICTION_3D.get(name) or COLUMNS_3D_CONTACT[name]
    for name in [*COLUMNS, "osc_obstacle", "linear_iterations"]
    if name in COLUMNS_3D_CONTACT or name in _FRICTION_3D
}


@dataclass
class FrictionalFaceContactRecord(FaceContactRecord):
    """The record of a 3D contact level with friction: a :class:`FaceContactRecord` whose
    row keeps the friction's columns (the counts of the node states and the tangential KKT
    residuals of :func:`~signorini.algebra.friction.disc.disc_kkt`, as the 2D columns are
    named)."""

    LEFT_OUT: ClassVar[tuple[str, ...]] = ()


@dataclass(frozen=True)
class _NoEstimate:
    """What a record reads of an estimate where there is none (3D): NaN."""

    eta: float = math.nan
    eta_terms: tuple[float, ...] = (math.nan,) * len(TERMS)


_NO_ESTIMATE = _NoEstimate()


def level_record(level: int, result: ContactResult, est: Estimate | None) -> LevelRecord:
    """The record of one level; without an estimate η and its terms are NaN; a 3D level
    without contact is an :class:`ElasticityRecord`, whose row leaves the contact's columns
    out (and the estimator's without an estimate), a 3D level with contact a
    :class:`FaceContactRecord`."""
    if est is None:
        est = _NO_ESTIMATE
    classes = result.classes if result.contact.size else np.zeros(0, dtype=np.int64)
    report = result.report
    elasticity = result.mesh.dim == 3 and not result.contact.size
    three = result.mesh.dim == 3
    kind = ElasticityRecord if elasticity else FaceContactRecord if three else LevelRecord
    if three and not elasticity and result.contact.has_friction:
        kind = FrictionalFaceContactRecord
    rec = kind(
        level=level,
        ndof=result.ndof,
        ndof_total=result.space.n_dofs,
        n_cells=result.mesh.n_cells,
        eta=est.eta,
        **{name: float(value) for name, value in zip(TERMS, est.eta_terms, strict=True)},
        pdas_iterations=report.iterations,
        n_solves=report.n_solves,
        n_factorizations=report.n_factorizations,
        n_analyses=report.n_analyses,
        n_updates=report.n_updates,
        n_active=int(result.active.sum()),
        n_constrained=result.contact.size,
        n_full_contact=int((classes == FULL_CONTACT).sum()),
        n_semi_contact=int((classes == SEMI_CONTACT).sum()),
        n_no_contact=int((classes == NO_CONTACT).sum()),
        n_stick=int((result.state == STICK).sum()),
        n_slip=int((result.state == SLIP).sum()),
        contact_force=result.total_contact_force,
        **report.kkt.columns(),  # without friction no tangential columns: they stay NaN
        backend=report.backend,
        t_assemble=result.timings["assemble"],
        t_solve=result.timings["solve"],
    )
    oscillation = getattr(est, "obstacle_oscillation", None)  # a 3D estimate with contact
    if oscillation is not None and result.contact.size:
        rec.extra["osc_obstacle"] = oscillation
    if three and report.linear_iterations:
        rec.extra["linear_iterations"] = int(sum(report.linear_iterations))
    if result.problem.exact is not None:
        err = result.errors()
        rec.error_energy, rec.error_h1 = err["error_energy"], err["error_h1"]
        rec.efficiency = est.eta / err["error_energy"] if err["error_energy"] > 0 else math.nan
    return rec
