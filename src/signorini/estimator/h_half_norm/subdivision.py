r"""Hierarchical subdivision: which rule of :mod:`.pair_rules` integrates which panel pair.

Pairs of pieces of different edges (:func:`cross_edge_integral`): a well separated panel
pair takes a tensor Gauss rule whose order depends on the separation
(``parameters.FAR_TIERS``); panels with a common end point of equal length take the Duffy
rule; a touching pair of unequal lengths has its longer panel cut at the length of the
shorter; any other pair has its longer panel halved. A piece and a zero run
(:func:`zero_run_pair_integral`): the panel is halved until it is far from the run, or
touches it and is short compared with it (``parameters.TOUCH_RUN_RATIO``).

All pairs of one level are processed together (vectorized); a level that still has pairs
closer than the point tolerance after ``parameters.MAX_LEVEL`` bisections, or more than
``parameters.MAX_ACTIVE`` pairs, means edges that cross or overlap: a ``ValueError``.
"""

from __future__ import annotations

import numpy as np

from . import parameters
from .pair_rules import duffy_pair_integral, far_pair_integral, zero_run_integral
from .panels import (
    cut_at_touch,
    far_order,
    panel_lengths,
    panel_points,
    segment_distance,
    split_half,
    touching_ends,
)
from .pieces import PositivePartPieces

__all__ = ["cross_edge_integral", "zero_run_pair_integral"]


def _unresolved(count: int) -> None:
    """Pairs still closer than the point tolerance after ``MAX_LEVEL`` bisections."""
    if count:
        raise ValueError(
            f"H^1/2 quadrature: {count} panel pairs meet away from their end points; "
            "the edges of Γ_C probably overlap or cross each other"
        )


def _check_growth(n_active: int) -> None:
    """Stop a subdivision that no longer localises (overlapping or crossing edges)."""
    if n_active > parameters.MAX_ACTIVE:
        raise ValueError(
            f"H^1/2 quadrature: {n_active} panel pairs still unresolved; the edges of "
            "Γ_C probably overlap or cross each other"
        )


def _children(owner, p, up, q, uq, lp, lq, touching, p_end, q_end, equal, order):
    """The panel pairs of the next level, in the order ``(owner, p, up, q, uq)``.

    A touching pair of unequal lengths has its longer panel cut at the length of the
    shorter; a separated pair too close for a Gauss rule has its longer panel halved.
    """
    new = []
    uneq = np.flatnonzero(touching & ~equal)
    if uneq.size:
        p_long = lp[uneq] > lq[uneq]
        s = uneq[p_long]  # P is longer: cut P
        for child in cut_at_touch(up[s], p_end[s], lq[s] / lp[s]):
            new.append((owner[s], p[s], child, q[s], uq[s]))
        s = uneq[~p_long]  # Q is longer: cut Q
        for child in cut_at_touch(uq[s], q_end[s], lp[s] / lq[s]):
            new.append((owner[s], p[s], up[s], q[s], child))
    near = np.flatnonzero(~touching & (order == 0))
    if near.size:
        p_long = lp[near] >= lq[near]
        s = near[p_long]
        for child in split_half(up[s]):
            new.append((owner[s], p[s], child, q[s], uq[s]))
        s = near[~p_long]
        for child in split_half(uq[s]):
            new.append((owner[s], p[s], up[s], q[s], child))
    if not new:
        return ()
    return tuple(np.concatenate(col) for col in zip(*new, strict=True))


def cross_edge_integral(pc: PositivePartPieces, p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """``∫_P∫_Q (v(x)-v(y))^2/|x-y|^2`` for pairs of pieces ``p, q (N,)`` of different edges.

    Returns
    -------
    (N,) float array
    """
    out = np.zeros(p.size)
    owner = np.arange(p.size)
    up = np.tile([0.0, 1.0], (p.size, 1))
    uq = up.copy()
    for level in range(parameters.MAX_LEVEL + 1):
        if owner.size == 0:
            break
        last = level == parameters.MAX_LEVEL
        ap, bp = panel_points(pc, p, up)
        aq, bq = panel_points(pc, q, uq)
        lp, lq = panel_lengths(pc, p, up), panel_lengths(pc, q, uq)
        touching, p_end, q_end = touching_ends(ap, bp, aq, bq, pc.tol)
        lmax = np.maximum(lp, lq)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(touching, 0.0, segment_distance(ap, bp, aq, bq) / lmax)
        order = far_order(ratio)
        if last:
            _unresolved(np.count_nonzero((order == 0) & ~touching))
        for n in np.unique(order[order > 0]):
            sel = np.flatnonzero(order == n)
            np.add.at(out, owner[sel], far_pair_integral(pc, p[sel], up[sel], q[sel], uq[sel], n))
        equal = touching & (last | (lmax <= parameters.DUFFY_RATIO * np.minimum(lp, lq)))
        sel = np.flatnonzero(equal)
        if sel.size:
            val = duffy_pair_integral(pc, p[sel], up[sel], p_end[sel], q[sel], uq[sel], q_end[sel])
            np.add.at(out, owner[sel], val)
        if last:
            break
        children = _children(owner, p, up, q, uq, lp, lq, touching, p_end, q_end, equal, order)
        if not children:
            break
        owner, p, up, q, uq = children
        _check_growth(owner.size)
    return out


def zero_run_pair_integral(pc: PositivePartPieces, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """``∫_P v(x)^2 ∫_Z |x - y|^{-2} ds_y ds_x`` for pairs of a piece ``p (N,)`` of S and
    a zero run ``z (N,)``.

    Returns
    -------
    (N,) float array
    """
    out = np.zeros(p.size)
    owner = np.arange(p.size)
    u = np.tile([0.0, 1.0], (p.size, 1))
    for level in range(parameters.MAX_LEVEL + 1):
        if owner.size == 0:
            break
        a, b = panel_points(pc, p, u)
        za, zb = pc.run_start[z], pc.run_end[z]
        lp = panel_lengths(pc, p, u)
        lz = np.hypot(*(zb - za).T)
        touching, _, _ = touching_ends(a, b, za, zb, pc.tol)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(touching, 0.0, segment_distance(a, b, za, zb) / lp)
        order = far_order(ratio)
        order[touching & (lz >= parameters.TOUCH_RUN_RATIO * lp)] = parameters.TOUCH_RUN_ORDER
        if level == parameters.MAX_LEVEL:
            _unresolved(np.count_nonzero(order == 0))
        for n in np.unique(order[order > 0]):
            sel = np.flatnonzero(order == n)
            val = zero_run_integral(pc, p[sel], u[sel], za[sel], zb[sel], int(n))
            np.add.at(out, owner[sel], val)
        split = np.flatnonzero(order == 0)
        if split.size == 0:
            break
        _check_growth(2 * split.size)
        lo, hi = split_half(u[split])
        owner = np.concatenate([owner[split], owner[split]])
        p = np.concatenate([p[split], p[split]])
        z = np.concatenate([z[split], z[split]])
        u = np.concatenate([lo, hi])
    return out
