"""What an active set solve reports: its steps, its result, its failure.

:class:`SolveReport` is what both solvers, the primal-dual active set method for frictionless
contact (:class:`PDASResult`) and the semismooth Newton method for friction
(:class:`~.friction.result.FrictionResult`), report in the same words: counters, KKT
residuals as named relative numbers (``kkt.columns()``, ``kkt.max``), the iteration history,
the backend and the times. :class:`ConvergenceError` is the failure of either.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np

from .kkt import KKTResiduals

__all__ = [
    "PDASResult",
    "PDASStep",
    "SolveReport",
]


@dataclass(frozen=True)
class PDASStep:
    """One linear solve of the active set iteration.

    Attributes
    ----------
    iteration : int
        1-based solve counter within the call.
    method : str
        ``"pdas"`` or ``"primal-active-set"`` (the fallback).
    n_active : int
        Size of the active (working) set used for this solve.
    n_added, n_removed : int
        Constraints added to / removed from the set of the previous solve.
    """

    iteration: int
    method: str
    n_active: int
    n_added: int
    n_removed: int

    def __str__(self) -> str:
        return (
            f"{self.iteration:3d} {self.method}: |A| = {self.n_active}, "
            f"+{self.n_added} -{self.n_removed}"
        )

    @classmethod
    def between(
        cls, iteration: int, method: str, previous: np.ndarray, active: np.ndarray
    ) -> PDASStep:
        """The step that solves with ``active (m,) bool`` after a solve with ``previous``."""
        return cls(
            iteration=iteration,
            method=method,
            n_active=int(active.sum()),
            n_added=int((active & ~previous).sum()),
            n_removed=int((previous & ~active).sum()),
        )


@dataclass(kw_only=True)
class SolveReport:
    """What an active set solve reports, frictionless or frictional.

    Attributes
    ----------
    x : (n,) float array
        The solution (in the frame of ``K``).
    iterations : int
        Iterations of the active set loop(s) (one linear system each).
    n_solves, n_factorizations, n_analyses, n_updates : int
        Work done by the linear solver during this call: solves, numerical factorizations,
        symbolic analyses, and iterations solved with the previous factorization and a
        low-rank correction.
    history : list
        One step per iteration (:class:`PDASStep`, :class:`~.friction.result.FrictionStep`),
        each printable on one line.
    kkt : KKTResiduals or FrictionKKT
        The relative KKT residuals at ``x``: ``kkt.max`` and ``kkt.columns()``, the named
        history columns.
    backend : str
        Linear solver backend.
    c_scale : float
        The constant ``c`` of the active set rule.
    times : dict of str to float
        Seconds, e.g. ``analysis``, ``factorization``, ``solve``, ``total``.
    linear_iterations : tuple of int
        The iterations of each solve of an iterative linear solver (its ``iterations``,
        e.g. :attr:`AmgSolver.iterations <.backends.amg.AmgSolver.iterations>`) during this
        call; empty with a direct one.
    """

    x: np.ndarray
    iterations: int
    n_solves: int
    n_factorizations: int = 0
    n_analyses: int = 0
    n_updates: int = 0
    history: list
    kkt: KKTResiduals
    backend: str
    c_scale: float
    times: dict[str, float] = field(default_factory=dict)
    linear_iterations: tuple[int, ...] = ()

    #: the attributes that are forces (multiplied by :meth:`scaled`'s unit)
    FORCES: ClassVar[tuple[str, ...]] = ()

    def scaled(self, unit: float) -> SolveReport:
        """The report of a system that was solved divided by ``unit`` (the stiffness unit of
        :func:`signorini.contact.solution.stiffness_unit`), with its forces and ``c_scale``
        in the unit of the undivided system; ``self`` when ``unit`` is 1."""
        if unit == 1.0:
            return self
        forces = {name: getattr(self, name) * unit for name in self.FORCES}
        return replace(self, c_scale=self.c_scale * unit, **forces)


@dataclass(kw_only=True)
class PDASResult(SolveReport):
    """Solution of :func:`~.pdas.solve_pdas` and how it was obtained (:class:`SolveReport`).

    Attributes
    ----------
    multiplier : (m,) float array
        Multiplier Λ on the constrained DOFs, ``F_c - (K x)_c`` on the active set and 0 off it
        (the nodal contact force Λ_z of the paper, eqs. (3.5), (3.9), (3.17)).
    active : (m,) bool array
        Final active set over the constrained DOFs.
    method : str
        ``"pdas"``, or ``"primal-active-set"`` when the fallback finished the job.

    ``iterations`` counts the PDAS and the fallback's solves together; ``times`` holds
    ``analysis``, ``factorization``, ``solve``, ``elimination``, ``total``.
    """

    multiplier: np.ndarray
    active: np.ndarray
    method: str

    FORCES: ClassVar[tuple[str, ...]] = ("multiplier",)
