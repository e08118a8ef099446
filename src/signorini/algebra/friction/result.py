"""What a frictional contact solve reports: node states, steps, result and failure."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..result import SolveReport
from .kkt import FrictionKKT

__all__ = [
    "INACTIVE",
    "SLIP",
    "STICK",
    "FrictionResult",
    "FrictionStep",
]

#: Node state: not in contact (``Λ_n = 0``).
INACTIVE = 0
#: Node state: in contact and sticking (``x_n = g``, ``x_t = x_ref``).
STICK = 1
#: Node state: in contact and slipping (``x_n = g``, ``|Λ_t| = s``).
SLIP = 2


@dataclass(frozen=True)
class FrictionStep:
    """One linear solve of the frictional active set iteration.

    Attributes
    ----------
    iteration : int
        1-based solve counter within the call.
    n_inactive, n_stick, n_slip : int
        Node counts of the states used for this solve.
    n_changed : int
        Nodes whose state or slip direction differs from the previous solve's.
    """

    iteration: int
    n_inactive: int
    n_stick: int
    n_slip: int
    n_changed: int

    def __str__(self) -> str:
        return (
            f"{self.iteration:3d}: inactive {self.n_inactive}, stick {self.n_stick}, "
            f"slip {self.n_slip}, changed {self.n_changed}"
        )


@dataclass(kw_only=True)
class FrictionResult(SolveReport):
    """Solution of :func:`~.newton.solve_friction` and how it was obtained
    (:class:`~.result.SolveReport`; ``n_solves`` counts one linear solve per iteration and
    ``n_updates`` is 0, as the history has always recorded them, although both kinds of
    system solve some iterations by a low-rank update of the previous factor, which only
    ``n_factorizations`` below the iterations shows; ``times`` holds ``analysis``,
    ``factorization``, ``solve``, ``assembly`` (forming the systems), ``total``; ``kkt`` is a
    :class:`~.friction.kkt.FrictionKKT`, the residuals of both laws).

    Attributes
    ----------
    multiplier_n, multiplier_t : (m,) float arrays
        The nodal contact forces ``Λ_n = F_n − (K x)_n`` (0 off contact) and
        ``Λ_t = F_t − (K x)_t`` (its imposed value ``±s`` on slipping nodes, 0 where no
        friction acts); force units. The obstacle acts on the body with ``−Λ``.
    state : (m,) int8 array
        :data:`INACTIVE`, :data:`STICK` or :data:`SLIP` per node.
    direction : (m,) int8 array
        ``sign Λ_t`` on nodes whose friction force is at a positive bound (slipping), 0
        elsewhere. Where a law acts everywhere (classical Tresca) a node out of contact also
        obeys the tangential law: its state is INACTIVE, its direction 0 where it sticks and
        ±1 where it slips.
    symmetric : bool
        Whether the systems were symmetric (every law with ``s' = 0``: Cholesky) or not (LU).
    method : str
        ``"semismooth-newton"``, or ``"fixed-point"`` where Coulomb's node states cycled and
        the fixed point on its slip bound finished the solve (:mod:`.friction.fixed_point`;
        ``iterations`` counts the solves of both).
    """

    kkt: FrictionKKT
    multiplier_n: np.ndarray
    multiplier_t: np.ndarray
    state: np.ndarray
    direction: np.ndarray
    symmetric: bool
    method: str = "semismooth-newton"

    FORCES: ClassVar[tuple[str, ...]] = ("multiplier_n", "multiplier_t")
