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
from .ranks import SERIAL, Ranks
from .sparse import abs_matvec

__all__ = [
    "KKTResiduals",
    "contact_scale",
    "force_scale",
    "ill_conditioned_message",
    "kkt_residuals",
    "round_off_scale",
]

#: Forces are round-off when they are at most this times ``|K| |x| + |F|``, the bound of the
#: round-off of ``F - K x`` (about eps times the number of entries in a row, 18 to 40 for P2).
_ROUNDOFF = 64 * float(np.finfo(np.float64).eps)


@dataclass(frozen=True)
class KKTResiduals:
    """Relative KKT residuals of a point ``x`` (see :func:`kkt_residuals`).

    Each residual is relative to the quantity it is about (docs/method.md, *Solver*): the
    contact conditions to the displacements and forces *at the contact*, not to a far-away gap
    nor to the largest row of ``|K| |x|`` (which grows with the stiffness: for ν → 1/2 or a
    sliver cell it is 10⁹ times the forces, and a scale built on it hid a tensile contact
    force of 5 % of the total).

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
        ``max(max |F|, max |K x|)``: the size of the forces acting on the body (loads,
        reactions, contact forces); ``round_off_scale`` where they are round-off of it (below
        ``64 eps`` of it).
    disp_scale : float
        ``max(max |x|, max |x_D|, max |g|`` over the constrained DOFs that touch or penetrate,
        ``x_c >= g)`` (1 if all vanish): the displacement of the body and the gap only where
        the contact is (a gap far from it does not count).
    contact_force : float
        The total contact force ``Σ max(Λ, 0)``.
    contact_force_scale : float
        ``contact_force``, or ``force_scale`` when the contact force is round-off (no contact):
        at most ``64 eps Σ_c (|K| |x| + |F|)_c``, a bound of the round-off of the multipliers.
    round_off_scale : float
        ``max(max |F|, max (|K| |x|))``: the size of the round-off of ``F - K x`` over eps.
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
    round_off_scale: float = 1.0

    @property
    def max(self) -> float:
        """The largest of the five relative residuals."""
        return max(self.primal, self.dual, self.complementarity, self.stationarity, self.dirichlet)

    def columns(self) -> dict[str, float]:
        """The five relative residuals as history columns: ``kkt_primal``, ``kkt_dual``,
        ``kkt_complementarity``, ``kkt_stationarity``, ``kkt_dirichlet``."""
        return normal_law_columns(self)


def normal_law_columns(kkt) -> dict[str, float]:
    """The history columns of the normal law's residuals of ``kkt`` (a
    :class:`KKTResiduals` or a :class:`~.friction.kkt.FrictionKKT`): ``kkt_primal``,
    ``kkt_dual``, ``kkt_complementarity``, ``kkt_stationarity``, ``kkt_dirichlet``."""
    return {
        "kkt_primal": kkt.primal,
        "kkt_dual": kkt.dual,
        "kkt_complementarity": kkt.complementarity,
        "kkt_stationarity": kkt.stationarity,
        "kkt_dirichlet": kkt.dirichlet,
    }


def kkt_residuals(
    K: sp.spmatrix,
    F: np.ndarray,
    x: np.ndarray,
    constrained: np.ndarray,
    gap: np.ndarray | float,
    dirichlet: np.ndarray | None = None,
    dirichlet_values: np.ndarray | float | None = None,
    *,
    ranks: Ranks = SERIAL,
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
    ranks : Ranks
        The processes that split ``K`` by rows (:attr:`~.qp.BoundQP.ranks`); default one.

    Returns
    -------
    KKTResiduals
    """
    qp = check_qp(K, F, constrained, gap, dirichlet, dirichlet_values, ranks=ranks)
    return qp_residuals(qp, check_vector(x, qp.n, "x"))


def force_scale(
    K: sp.csr_matrix,
    F: np.ndarray,
    x: np.ndarray,
    Kx: np.ndarray | None = None,
    round_off: float | None = None,
    ranks: Ranks = SERIAL,
) -> float:
    """The size of the forces at ``x``: ``max(max |F|, max |K x|)`` — loads, reactions and
    contact forces, not the entries of ``|K| |x|``, whose cancellation in ``K x`` is only
    round-off — against which the equilibrium residual is measured; :func:`round_off_scale`
    where the forces themselves are round-off (at most ``64 eps max |K| |x|``: a rigid
    motion, no load), and 1 where everything vanishes. ``Kx`` and ``round_off``: ``K @ x``
    and :func:`round_off_scale`, if known; ``ranks``: those that split ``K`` by rows."""
    Kx = ranks.sum(K @ x) if Kx is None else Kx
    force = max(np.abs(F).max(initial=0.0), np.abs(Kx).max(initial=0.0))
    round_off = round_off_scale(K, F, x, ranks) if round_off is None else round_off
    return float(force) if force > _ROUNDOFF * round_off else round_off


def round_off_scale(K: sp.csr_matrix, F: np.ndarray, x: np.ndarray, ranks: Ranks = SERIAL) -> float:
    """``max(max |F|, max |K| |x|)`` (1 where both vanish): the round-off of ``F - K x`` is
    about eps times it. ``ranks``: those that split ``K`` by rows."""
    rows = ranks.max(float(abs_matvec(K, x).max(initial=0.0)))
    scale = max(np.abs(F).max(initial=0.0), rows)
    return float(scale) if scale > 0 else 1.0


def contact_scale(
    K: sp.csr_matrix,
    F: np.ndarray,
    x: np.ndarray,
    rows: np.ndarray,
    total: float,
    force: float,
    ranks: Ranks = SERIAL,
) -> float:
    """The scale of the contact forces: their sum ``total``, or ``force`` when it is round-off,
    at most ``64 eps Σ (|K| |x| + |F|)`` over ``rows`` (the constrained DOFs).

    Parameters
    ----------
    K, F, x
        The system and the point.
    rows : (m,) int array
        The constrained DOFs.
    total : float
        ``Σ Λ⁺``.
    force : float
        :func:`force_scale`.
    ranks : Ranks
        Those that split ``K`` by rows.
    """
    if rows.size == 0:
        return force
    row_sums = ranks.sum(abs_matvec(K[rows], x))
    round_off = _ROUNDOFF * float((row_sums + np.abs(F[rows])).sum())
    return total if total > round_off else force


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
    Kx = qp.matvec(x)
    r = F - Kx
    round_off = round_off_scale(K, F, x, qp.ranks)
    force = force_scale(K, F, x, Kx, round_off)
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
    contact = contact_scale(K, F, x, c, contact_force, force, qp.ranks)
    other = np.ones(x.size, dtype=bool)
    other[c] = False
    other[d] = False
    return KKTResiduals(
        primal=float(np.maximum(slack, 0.0).max(initial=0.0) / disp),
        dual=float(np.maximum(-multiplier, 0.0).max(initial=0.0) / contact),
        complementarity=float(
            np.minimum(np.abs(multiplier) / contact, np.abs(slack) / disp).max(initial=0.0)
        ),
        stationarity=float(np.abs(r[other]).max(initial=0.0) / force),
        dirichlet=float(np.abs(x[d] - xd).max(initial=0.0) / disp),
        force_scale=float(force),
        disp_scale=float(disp),
        contact_force=contact_force,
        contact_force_scale=float(contact),
        round_off_scale=round_off,
    )


def ill_conditioned_message(kkt: KKTResiduals, bound: float, band: float) -> str:
    """What an :class:`~.errors.IllConditionedWarning` says of a solution whose KKT
    residuals ``kkt`` exceed ``bound``: each residual above it and, for a tensile contact
    force (``dual``), its size against the total contact force and against the active set's
    round-off band on the forces, ``band · max (|K| |x|)`` (the band of
    :func:`~.pdas.solve_pdas`, relative to ``round_off_scale``; docs/method.md, *Solver*)."""
    above = ", ".join(f"{k} {v:.1e}" for k, v in kkt.columns().items() if v > bound)
    text = f"the solution meets its KKT conditions only to {kkt.max:.1e} relative ({above})"
    if kkt.dual > bound:
        tensile = kkt.dual * kkt.contact_force_scale
        width = band * kkt.round_off_scale
        where = "within" if tensile <= width else "beyond"
        text += (
            f"; an active contact constraint carries a tensile force of {tensile:.3g}, "
            f"{kkt.dual:.1e} of the total contact force {kkt.contact_force:.6g}, {where} the "
            f"round-off band of the forces, {width:.3g} ({band:.1e} max |K||x|), inside which "
            "a force's sign does not decide whether its node is in contact: the contact "
            "forces are exact to about that size, no better"
        )
    return (
        text + ": the stiffness matrix is too ill-conditioned for double precision (a material "
        "close to incompressible, in any region, a contrast of stiffness between regions, "
        "sliver cells or a slender body)"
    )
