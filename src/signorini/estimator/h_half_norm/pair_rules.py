r"""Quadrature rules for one block of pairs: same edge, far, touching (Duffy), zero run.

Each function integrates, for many pairs at once, one of the pieces of

.. math::

    |v|^2_{1/2} = \int_S\int_S \frac{(v(x) - v(y))^2}{|x - y|^2}
        + 2 \int_S v(x)^2 \int_{\Gamma_C \setminus S} |x - y|^{-2} \, ds_y \, ds_x

(module notes of :mod:`signorini.estimator.h_half_norm`), on panels ``u`` of pieces of S
(:mod:`.panels`). Which rule applies to which pair is decided in :mod:`.subdivision`.

References
----------
.. [1] M. G. Duffy, "Quadrature over a pyramid or cube of integrands with a
   singularity at a vertex", SIAM J. Numer. Anal. 19 (1982) 1260-1262.
"""

from __future__ import annotations

import numpy as np

from ...fem.quadrature import gauss_legendre
from . import parameters
from .panels import expansion, inverse_square_integral, panel_lengths, panel_nodes
from .pieces import PositivePartPieces

__all__ = [
    "duffy_pair_integral",
    "far_pair_integral",
    "same_edge_integral",
    "same_edge_pairs",
    "zero_run_integral",
]


def _chunked(fn, n_items: int, *arrays) -> np.ndarray:
    """Apply ``fn`` to slices of ``parameters.BLOCK`` rows of ``arrays`` and concatenate."""
    block = parameters.BLOCK
    if n_items <= block:
        return fn(*arrays)
    return np.concatenate(
        [fn(*(a[i : i + block] for a in arrays)) for i in range(0, n_items, block)]
    )


# --------------------------------------------------------------------------- same edge


def same_edge_pairs(pc: PositivePartPieces) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pairs ``(ii, jj)`` of pieces of one edge (a piece with itself included) and their
    multiplicity ``mult`` (2 for two different pieces, counted once)."""
    m = pc.n_pieces
    i = np.arange(m)
    nxt = np.flatnonzero(pc.edge[1:] == pc.edge[:-1])
    ii = np.concatenate([i, nxt])
    jj = np.concatenate([i, nxt + 1])
    mult = np.concatenate([np.ones(m), np.full(nxt.size, 2.0)])
    return ii, jj, mult


def same_edge_integral(pc: PositivePartPieces, ii: np.ndarray, jj: np.ndarray) -> np.ndarray:
    """``∫_P∫_Q (v(x)-v(y))^2/|x-y|^2`` for pieces ``P, Q`` of one edge, exactly.

    On one straight edge ``(w(s) - w(s'))/(s - s') = b + c (s + s')`` is a polynomial
    (the divided difference), so a 2 x 2 Gauss rule is exact; ``|x - y| = |e| |s - s'|``
    and the edge length cancels against the two line elements.
    """
    t, wt = gauss_legendre(2)
    si = pc.s[ii, :1] + (pc.s[ii, 1:] - pc.s[ii, :1]) * t
    sj = pc.s[jj, :1] + (pc.s[jj, 1:] - pc.s[jj, :1]) * t
    b = pc.edge_coef[ii, 1][:, None, None]
    c = pc.edge_coef[ii, 2][:, None, None]
    dd = b + c * (si[:, :, None] + sj[:, None, :])
    jac = (pc.s[ii, 1] - pc.s[ii, 0]) * (pc.s[jj, 1] - pc.s[jj, 0])
    return jac * np.einsum("nij,i,j->n", dd * dd, wt, wt)


# --------------------------------------------------------------------------- far pairs


def far_pair_integral(pc, p, up, q, uq, n: int) -> np.ndarray:
    """Tensor Gauss rule with ``n x n`` points on separated panel pairs.

    Parameters
    ----------
    pc : PositivePartPieces
    p, q : (N,) int arrays
        Pieces of the two panels of each pair.
    up, uq : (N, 2) float arrays
        The panels in their pieces.
    n : int
        Gauss points per direction (``parameters.FAR_TIERS``).

    Returns
    -------
    (N,) float array
    """
    return _chunked(lambda *a: _far_pair_kernel(pc, *a, n), p.size, p, up, q, uq)


def _far_pair_kernel(pc, p, up, q, uq, n: int) -> np.ndarray:
    t, wt = gauss_legendre(n)
    xp, yp, vp = panel_nodes(pc, p, up, t)
    xq, yq, vq = panel_nodes(pc, q, uq, t)
    diff = vp[:, :, None] - vq[:, None, :]
    d0 = xp[:, :, None] - xq[:, None, :]
    d1 = yp[:, :, None] - yq[:, None, :]
    f = diff * diff / (d0 * d0 + d1 * d1)
    return panel_lengths(pc, p, up) * panel_lengths(pc, q, uq) * ((f @ wt) @ wt)


# --------------------------------------------------------------------------- touching pairs


def duffy_angular_order(a: np.ndarray, b: np.ndarray, cos: np.ndarray) -> np.ndarray:
    """Gauss points in ``z`` for the Duffy rule, from the poles of its integrand.

    The denominators vanish at ``z = (a/b) e^{±iα}`` and ``z = (b/a) e^{±iα}``;
    with ``ρ`` the Bernstein-ellipse parameter of the nearer pole for [0, 1],
    the Gauss error decays like ``ρ^{-2n}`` (``parameters.DUFFY_DIGITS``).
    """
    alpha = np.arccos(np.clip(cos, -1.0, 1.0))
    rho = np.full(a.shape, np.inf)
    for r in (a / b, b / a):
        zeta = 2.0 * r * np.exp(1j * alpha) - 1.0
        root = np.sqrt(zeta * zeta - 1.0)
        rho = np.minimum(rho, np.maximum(np.abs(zeta + root), np.abs(zeta - root)))
    with np.errstate(divide="ignore"):
        n = np.ceil(parameters.DUFFY_DIGITS / (2.0 * np.log(rho)))
    nmin, nmax = parameters.DUFFY_ORDER[1], parameters.DUFFY_MAX_ORDER
    return np.clip(np.nan_to_num(n, nan=nmax, posinf=nmax), nmin, nmax).astype(np.int64)


def duffy_pair_integral(pc, p, up, p_end, q, uq, q_end) -> np.ndarray:
    """Duffy rule on panel pairs with a common end point.

    Parameters
    ----------
    pc : PositivePartPieces
    p, q : (N,) int arrays
        Pieces of the two panels.
    up, uq : (N, 2) float arrays
        The panels in their pieces.
    p_end, q_end : (N,) bool arrays
        Whether the common point is the end (``True``) or the start of each panel.

    Returns
    -------
    (N,) float array

    Raises
    ------
    ValueError
        If v differs on the two panels at the common point: edges that cross or overlap.
    """
    return _chunked(lambda *a: _duffy_pair_kernel(pc, *a), p.size, p, up, p_end, q, uq, q_end)


def _duffy_pair_kernel(pc, p, up, p_end, q, uq, q_end) -> np.ndarray:
    """Panels with a common end point ``c``: Duffy split of ``[0, a] x [0, b]``.

    With ``t = a ρ, s = b ρ z`` (and the mirror triangle) the factor ``ρ^2``
    of ``(v(t) - v(s))^2`` cancels that of ``|x - y|^2``; what remains is a
    cubic in ``ρ`` times a smooth rational function of ``z``.
    """
    a, vp, p1, p2, dp = expansion(pc, p, up, p_end)
    b, vq, q1, q2, dq = expansion(pc, q, uq, q_end)
    jump = np.abs(vp - vq)
    if np.any(jump > parameters.CONTINUITY_RTOL * pc.v_scale):
        # shared end points were checked on input: this is a point where edges cross
        raise ValueError(
            f"H^1/2 quadrature: v jumps by {jump.max():.3e} (the data's size is "
            f"{pc.v_scale:.3e}) where two edges meet away from a shared end point; the edges "
            "of Γ_C probably overlap or cross each other"
        )
    cos = np.einsum("ij,ij->i", dp, dq)
    order = duffy_angular_order(a, b, cos)
    out = np.empty(a.size)
    r, wr = gauss_legendre(parameters.DUFFY_ORDER[0])
    r = r[None, :, None]
    for nz in np.unique(order):
        sel = np.flatnonzero(order == nz)
        z, wz = gauss_legendre(int(nz))
        z = z[None, None, :]
        aa, bb, cc, pp1, pp2, qq1, qq2 = (v[sel, None, None] for v in (a, b, cos, p1, p2, q1, q2))
        num1 = aa * (pp1 + pp2 * aa * r) - bb * z * (qq1 + qq2 * bb * r * z)
        den1 = aa * aa + bb * bb * z * z - 2.0 * aa * bb * z * cc
        num2 = aa * z * (pp1 + pp2 * aa * r * z) - bb * (qq1 + qq2 * bb * r)
        den2 = aa * aa * z * z + bb * bb - 2.0 * aa * bb * z * cc
        f = r * (num1 * num1 / den1 + num2 * num2 / den2)
        out[sel] = a[sel] * b[sel] * np.einsum("nij,i,j->n", f, wr, wz)
    return out


# --------------------------------------------------------------------------- zero runs


def zero_run_integral(pc, p, u, za, zb, n: int) -> np.ndarray:
    """Gauss rule with ``n`` points for ``∫_P v(x)^2 ∫_Z |x - y|^{-2} ds_y ds_x``.

    Parameters
    ----------
    pc : PositivePartPieces
    p : (N,) int array
        Pieces of the panels.
    u : (N, 2) float array
        The panels in their pieces.
    za, zb : (N, 2) float arrays
        End points of the zero runs ``Z``.
    n : int
        Gauss points.

    Returns
    -------
    (N,) float array
    """
    return _chunked(lambda *a: _zero_run_kernel(pc, *a, n), p.size, p, u, za, zb)


def _zero_run_kernel(pc, p, u, za, zb, n: int) -> np.ndarray:
    t, wt = gauss_legendre(n)
    x, y, v = panel_nodes(pc, p, u, t)
    f = inverse_square_integral(np.stack([x, y], axis=-1), za[:, None, :], zb[:, None, :])
    return panel_lengths(pc, p, u) * ((v * v * f) @ wt)
