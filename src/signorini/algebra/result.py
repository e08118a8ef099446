"""What an active set solve reports: its steps, its result, its failure."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .kkt import KKTResiduals

__all__ = ["PDASConvergenceError", "PDASResult", "PDASStep", "with_history"]


def with_history(message: str, history: list) -> str:
    """An error message followed by the last 20 steps of an iteration's history."""
    lines = "\n".join(str(step) for step in history[-20:])
    skipped = f"\n  ({len(history) - 20} earlier steps not shown)" if len(history) > 20 else ""
    return f"{message}\niteration history:{skipped}\n{lines}"


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


@dataclass
class PDASResult:
    """Solution of :func:`~.pdas.solve_pdas` and how it was obtained.

    Attributes
    ----------
    x : (n,) float array
        The minimizer (in the frame of ``K``).
    multiplier : (m,) float array
        Multiplier Λ on the constrained DOFs, ``F_c - (K x)_c`` on the active set and 0 off it
        (the nodal contact force Λ_z of the paper, eqs. (3.5), (3.9), (3.17)).
    active : (m,) bool array
        Final active set over the constrained DOFs.
    iterations : int
        Linear solves of the active set loop(s), PDAS and fallback together.
    n_solves, n_factorizations, n_analyses : int
        Work done by the linear solver during this call.
    history : list of PDASStep
    kkt : KKTResiduals
    backend : str
        Linear solver backend.
    method : str
        ``"pdas"``, or ``"primal-active-set"`` when the fallback finished the job.
    c_scale : float
        The constant ``c`` of the active set rule.
    times : dict of str to float
        Seconds: ``analysis``, ``factorization``, ``solve``, ``elimination``, ``total``.
    n_updates : int
        Iterations solved with the previous factorization and a low-rank correction.
    """

    x: np.ndarray
    multiplier: np.ndarray
    active: np.ndarray
    iterations: int
    n_solves: int
    n_factorizations: int
    n_analyses: int
    history: list[PDASStep]
    kkt: KKTResiduals
    backend: str
    method: str
    c_scale: float
    times: dict[str, float] = field(default_factory=dict)
    n_updates: int = 0


class PDASConvergenceError(RuntimeError):
    """The active set iteration cycled or hit its bound.

    Attributes
    ----------
    history : list of PDASStep
    reason : str
        ``"cycling"`` or ``"max_iter"``.
    x, active : numpy arrays
        The last iterate and its active set.
    """

    def __init__(
        self,
        message: str,
        history: list[PDASStep],
        reason: str,
        x: np.ndarray | None = None,
        active: np.ndarray | None = None,
    ) -> None:
        super().__init__(with_history(message, history))
        self.history = history
        self.reason = reason
        self.x = x
        self.active = active
