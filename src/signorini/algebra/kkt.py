"""KKT residuals of the bound-constrained QP (docs/method.md, *Solver*).

The multiplier of the bound ``x_c <= g`` is the residual of the constrained rows,
``Λ = F_c - (K x)_c``: the nodal contact force Λ_z of the paper, eqs. (3.5), (3.9) and (3.17).
A point ``x`` solves the QP when

.. math::

    x_c \\le g,\\qquad Λ \\ge 0,\\qquad Λ (x_c - g) = 0,\\qquad x_d = x_D,\\qquad
    (F - K x)_i = 0 \\text{ on every other DOF } i.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .qp import BoundQP, check_qp, check_vector
from .sparse import abs_matvec

__all__ = ["KKTResiduals", "force_scale", "kkt_residuals"]

_SQRT_EPS = float(np.sqrt(np.finfo(np.float64).eps))


@dataclass(frozen=True)
class KKTResiduals:
    """Relative KKT residuals of a point ``x`` (see :func:`kkt_residuals`).

    Each residual is relative to the quantity it is about (docs/method.md, *Solver*): the
    contact conditions to the displacements and forces *at the contact*, not to a far-away gap
    nor to the largest row of ``|K| |x|``.

    Attributes
    ----------
    primal : float
        ``max (x_c - g)^+ / disp_scale``: the largest penetration.
    dual : float
        ``max (-Λ)^+ / contact_force_scale``: the largest contact force of the wrong sign.
    complementarity : float
        ``max min(|Λ| / contact_force_scale, |x_c - g| / disp_scale)``: at every constrained DOF
        the force or the gap must vanish (the round-off multiplier of a DOF far from the
        obstacle is not multiplied by its large gap).
    stationarity : float
        ``max |F - K x|`` over the free unconstrained rows, over ``force_scale``.
    dirichlet : float
        ``max |x_d - x_D| / disp_scale``.
    force_scale : float
        ``max(max |F|, max (|K| |x|))`` (1 if both vanish): the size of the forces, which also
        bounds the round-off in ``F - K x``.
    disp_scale : float
        ``max(max |x|, max |x_D|, max |g|`` over the constrained DOFs that touch or penetrate,
        ``x_c >= g)`` (1 if all vanish): the displacement of the body and the gap only where
        the contact is (a gap far from it does not count).
    contact_force : float
        The total contact force ``Σ max(Λ, 0)``.
    contact_force_scale : float
        ``contact_force``, or ``force_scale`` when the contact force is below ``√eps`` of it
        (no contact: the multipliers are round-off).
    """

    primal: float
    dual: float
    complementarity: float
    stationarity: float
    dirichlet: float
    force_scale: float
    disp_scale: float
    contact_force: float = 0.0
    contact_force_scale: float = 1.0

    @property
    def max(self) -> float:
        """The largest of the five relative residuals."""
        return max(self.primal, self.dual, self.complementarity, self.stationarity, self.dirichlet)

    def columns(self) -> dict[str, float]:
        """The five relative residuals as history columns: ``kkt_primal``, ``kkt_dual``,
        ``kkt_complementarity``, ``kkt_stationarity``, ``kkt_dirichlet``."""
        return {
            "kkt_primal": self.primal,
            "kkt_dual": self.dual,
            "kkt_complementarity": self.complementarity,
            "kkt_stationarity": self.stationarity,
            "kkt_dirichlet": self.dirichlet,
        }


def kkt_residuals(
    K: sp.spmatrix,
    F: np.ndarray,
    x: np.ndarray,
    constrained: np.ndarray,
    gap: np.ndarray | float,
    dirichlet: np.ndarray | None = None,
    dirichlet_values: np.ndarray | float | None = None,
) -> KKTResiduals:
    """Relative KKT residuals of ``x`` for ``min 1/2 x^T K x - F^T x``, ``x_c <= g``, ``x_d = x_D``.

    The multiplier is the residual of the constrained rows, ``Λ = F_c - (K x)_c``
    (paper's (3.5)/(3.9)/(3.17)); see :class:`KKTResiduals` for the five measures and their
    scales.

    Parameters
    ----------
    K : scipy sparse matrix, shape (n, n)
    F : (n,) float array
    x : (n,) float array
    constrained : (m,) int array or (n,) bool mask
    gap : float or (m,) float array
    dirichlet : (n_d,) int array or (n,) bool mask, optional
    dirichlet_values : float, (n_d,) or (n,) float array, optional
        Default 0.

    Returns
    -------
    KKTResiduals
    """
    qp = check_qp(K, F, constrained, gap, dirichlet, dirichlet_values)
    return qp_residuals(qp, check_vector(x, qp.n, "x"))


def force_scale(K: sp.csr_matrix, F: np.ndarray, x: np.ndarray) -> float:
    """The scale of the forces at ``x``: ``max(max |F|, max |K| |x|)`` (1 where both vanish),
    against which the equilibrium and force residuals are measured."""
    force = max(np.abs(F).max(initial=0.0), abs_matvec(K, x).max(initial=0.0))
    return float(force) if force > 0 else 1.0


def qp_residuals(qp: BoundQP, x: np.ndarray) -> KKTResiduals:
    """:func:`kkt_residuals` on checked data (no checks).

    Parameters
    ----------
    qp : BoundQP
    x : (n,) float array

    Returns
    -------
    KKTResiduals
    """
    K, F, c, g = qp.K, qp.F, qp.constrained, qp.gap
    d, xd = qp.dirichlet, qp.dirichlet_values
    r = F - K @ x
    force = force_scale(K, F, x)
    multiplier = r[c]
    slack = x[c] - g
    touching = slack >= 0
    disp = max(
        np.abs(x).max(initial=0.0),
        np.abs(xd).max(initial=0.0),
        np.abs(g[touching]).max(initial=0.0),
    )
    disp = disp if disp > 0 else 1.0
    contact_force = float(np.maximum(multiplier, 0.0).sum())
    contact_scale = contact_force if contact_force > _SQRT_EPS * force else force
    other = np.ones(x.size, dtype=bool)
    other[c] = False
    other[d] = False
    return KKTResiduals(
        primal=float(np.maximum(slack, 0.0).max(initial=0.0) / disp),
        dual=float(np.maximum(-multiplier, 0.0).max(initial=0.0) / contact_scale),
        complementarity=float(
            np.minimum(np.abs(multiplier) / contact_scale, np.abs(slack) / disp).max(initial=0.0)
        ),
        stationarity=float(np.abs(r[other]).max(initial=0.0) / force),
        dirichlet=float(np.abs(x[d] - xd).max(initial=0.0) / disp),
        force_scale=float(force),
        disp_scale=float(disp),
        contact_force=contact_force,
        contact_force_scale=float(contact_scale),
    )
