r"""A localised upper bound of η7 = ‖(u_h·n − ψ)⁺‖_{H^{1/2}(Γ_C)} (for three dimensions).

η7 of the paper (Section 5, before (5.1)) is the Sobolev-Slobodeckij norm of
``v = (u_h·n − ψ)⁺`` on Γ_C; :mod:`.norms` computes it exactly on curves. On a surface the
seminorm is a 4D singular integral (kernel ``|x − y|^{-3}``). The reliability proof
(Section 5, before (5.10)) uses η7 only as an *upper bound* of the norm, and the paper
proves no efficiency for it, so any computable upper bound keeps reliability. This module
computes, per facet ``F`` of Γ_C (measure ``h_F``),

.. math::

    B(v)^2 = \|v\|^2_{L^2(\Gamma_C)} + \sum_F \Big( h_F^{-1} \|v\|^2_{L^2(F)}
             + h_F \|\nabla_\Gamma v\|^2_{L^2(F)} \Big),

and, on curves, the weights ``α_F``, ``β_F`` of the guaranteed bound

.. math::

    \eta_7^2 \le G(v)^2 = \|v\|^2_{L^2(\Gamma_C)} + \sum_F \Big( \beta_F h_F^{-1}
             \|v\|^2_{L^2(F)} + \alpha_F h_F \|\partial_\tau v\|^2_{L^2(F)} \Big),

so that ``η7² ≤ max(1, max α, max β) B²``. The formula of ``B`` is the same in every
dimension (:func:`localised_bound2`); only the facet norms (:func:`facet_norms2_positive_part`,
on the same cut edges the exact η7 uses, :mod:`.pieces`) and the weights
(:func:`curve_weights`) are the curve's. docs/method.md, *η7 on surfaces: a localised
bound*, has the derivation, summed up here for a connected chain of straight edges,
``ℓ(x, y)`` the length along Γ_C and ``κ ≥ sup ℓ(x, y) / |x − y|`` over non-adjacent facets
(the chord-arc constant: 1 on a straight Γ_C).

* **Same facet.** For ``x, y`` on a straight facet, ``(v(x) − v(y))² ≤ |x − y| ∫_{[x,y]}
  |v'|²``; the measure of the pairs whose segment covers ``t`` is
  ``∫∫ |x − y|^{-1} = 2 J(a, h − a) ≤ 2 h ln 2``, ``a`` the distance of ``t`` to an end,
  with ``J(a, b) = a ln(1 + b/a) + b ln(1 + a/b)``. Hence ``∫_F∫_F ≤ 2 ln 2 · h_F
  ‖v'‖²_F``.
* **Adjacent facets** ``F, F'`` meeting at ``z`` at the interior angle ``θ``: along the
  path ``x → z → y`` (length ``p + q``), ``|x − y|² ≥ sin²(θ/2) (p + q)²``; both orders
  together give ``≤ 2 J(h_F, h_F') / sin²(θ/2) · (‖v'‖²_F + ‖v'‖²_F')``.
* **Far facets** (neither equal nor adjacent): ``(v(x) − v(y))² ≤ 2 v(x)² + 2 v(y)²`` and,
  for ``x ∈ F``, the far part beyond the neighbour ``F'`` lies at arc length ``≥ h_F'``, so
  ``∫_far |x − y|^{-2} ds_y ≤ κ² Σ_{F'} 1/h_F'``; both orders give
  ``≤ 4 κ² Σ_F (Σ_{F'∼F} 1/h_F') ‖v‖²_F``.

Whence ``α_F = 2 ln 2 + Σ_{F'∼F} 2 J(h_F, h_F') / (h_F sin²(θ/2))`` and
``β_F = 4 κ² Σ_{F'∼F} h_F / h_F'``: on a uniform straight mesh ``α = 10 ln 2 ≈ 6.93`` and
``β = 8`` inside, so ``η7² ≤ 8 B²`` there. The constants are elementary and computable;
they are not Faermann's (whose localisation is a sum of *double integrals over patches*,
equivalent to the norm only on functions orthogonal to the discrete space [2]_, [3]_, which
``v ≥ 0`` is not). On surfaces the same three steps hold with ``2 ln 2 · sup_z ∫_F |z −
y|^{-1} dy ≤ 2 ln 2 · 2 (π |F|)^{1/2}`` on one (convex) facet and a far field ``≤ 2π κ³ /
ρ_F`` (``ρ_F`` the distance to the far facets); facets sharing only a vertex need a path
argument whose constant depends on the shape regularity and is not computed here.

The bound is *not* robust under refinement of a fixed ``v``: halving every facet doubles
``Σ h_F^{-1} ‖v‖²_F`` and halves ``Σ h_F ‖v'‖²_F``, so ``B²`` changes by a factor in
``[1/2, 2]`` per bisection but grows like ``h^{-1}`` for a fixed ``v`` of large support
(the exact η7 does not). It is of the size of η7 when the support of ``v`` is a few facets
wide, as the penetration of a contact solution is; ``benchmarks/eta7_bound.py`` measures the
ratio ``B / η7`` on the paper's examples.

References
----------
.. [1] R. Khandelwal, K. Porwal, T. Wadhawan, "Adaptive quadratic finite element method for
   the unilateral contact problem", Section 5 (η7 and (5.10)).
.. [2] B. Faermann, "Localization of the Aronszajn-Slobodeckij norm and application to
   adaptive boundary element methods", Part I (curves) and Part II (surfaces).
.. [3] S. Bertoluzza, "Localization of trace norms in two and three dimensions",
   arXiv:2312.01101 (2023), Section 1 (what Faermann's localisation states).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ...fem.quadrature import gauss_legendre
from .norms import l2_shares_of_pieces
from .pieces import positive_part_pieces

__all__ = [
    "FacetNorms",
    "curve_weights",
    "facet_norms2_positive_part",
    "localised_bound2",
    "localised_bound2_positive_part",
]


class FacetNorms(NamedTuple):
    """The per-facet quantities of the localised bound, any dimension.

    Attributes
    ----------
    h : (k,) float array
        Facet size ``h_F`` (length of an edge; on surfaces ``|F|^{1/2}``).
    l2 : (k,) float array
        ``‖v‖²_{L²(F)}``.
    gradient : (k,) float array
        ``‖∇_Γ v‖²_{L²(F)}`` (on an edge, of the tangential derivative).
    """

    h: np.ndarray
    l2: np.ndarray
    gradient: np.ndarray


def facet_norms2_positive_part(
    x0, x1, w, *, validate: bool = True, scale: float | None = None
) -> FacetNorms:
    """``h_F``, ``‖v‖²_F`` and ``‖∂_τ v‖²_F`` of ``v = max(w, 0)`` on each edge of Γ_C.

    The edges are cut at the roots of ``w`` exactly as for the exact η7
    (:func:`.pieces.positive_part_pieces`); on each piece of ``{w > 0}``,
    ``v = c_0 + c_1 u + c_2 u²`` (``u ∈ [0, 1]``, piece length ``L``) and
    ``∫ |∂_τ v|² ds = L^{-1} ∫_0^1 (c_1 + 2 c_2 u)² du`` (2-point Gauss, exact); the L²
    part is :func:`.norms.l2_shares_of_pieces`' of the same pieces.

    Parameters
    ----------
    x0, x1 : array_like of float64, shape (k, 2)
        Edge end points.
    w : array_like of float64, shape (k, 3)
        Quadratic on each edge, values at ``[start, end, midpoint]``.
    validate, scale
        As for :func:`.norms.hhalf_norm2_positive_part`.

    Returns
    -------
    FacetNorms
        Arrays of shape (k,).
    """
    pc = positive_part_pieces(x0, x1, w, validate=validate, scale=scale)
    l2 = l2_shares_of_pieces(pc)
    t, wt = gauss_legendre(2)
    slope = pc.coef[:, 1:2] + 2.0 * pc.coef[:, 2:3] * t  # dv/du at the Gauss points, (m, 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        piece = np.where(pc.length > 0.0, ((slope * slope) @ wt) / pc.length, 0.0)
    gradient = np.bincount(pc.edge, weights=piece, minlength=pc.n_edges)
    h = np.hypot(*(np.asarray(x1, dtype=np.float64) - np.asarray(x0, dtype=np.float64)).T)
    return FacetNorms(h, l2, gradient)


def localised_bound2(
    norms: FacetNorms, near: np.ndarray | float = 1.0, far: np.ndarray | float = 1.0
) -> tuple[float, np.ndarray]:
    """``‖v‖² + Σ_F (far_F h_F^{-1} ‖v‖²_F + near_F h_F ‖∇_Γ v‖²_F)`` and its facet shares.

    With unit weights this is ``B(v)²`` of the module notes, the same formula on curves and
    surfaces; with the weights of :func:`curve_weights` it is the guaranteed upper bound
    ``G(v)² ≥ η7²`` on a chain of edges.

    Parameters
    ----------
    norms : FacetNorms
        The facet quantities, arrays of shape (k,).
    near, far : float or (k,) float array
        ``α_F`` and ``β_F`` (default 1).

    Returns
    -------
    total : float
        The squared bound.
    eta2_facet : (k,) float array
        Share of each facet; sums to ``total``, zero where ``v = 0``.
    """
    h, l2, gradient = norms
    eta2 = l2 + far * l2 / h + near * h * gradient
    return float(eta2.sum()), eta2


def localised_bound2_positive_part(
    x0, x1, w, *, validate: bool = True, scale: float | None = None
) -> tuple[float, np.ndarray]:
    """``B(v)²`` (unit weights) for ``v = max(w, 0)`` on the edges of Γ_C, with edge shares.

    Parameters
    ----------
    x0, x1 : array_like of float64, shape (k, 2)
        Edge end points.
    w : array_like of float64, shape (k, 3)
        Quadratic on each edge, values at ``[start, end, midpoint]``.
    validate, scale
        As for :func:`.norms.hhalf_norm2_positive_part`.

    Returns
    -------
    total : float
    eta2_edge : (k,) float array
    """
    return localised_bound2(facet_norms2_positive_part(x0, x1, w, validate=validate, scale=scale))


def _junctions(x0: np.ndarray, x1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The pairs of edges that share an end point ``(n, 2)`` and the end of each at it."""
    k = x0.shape[0]
    ends = np.concatenate([x0, x1])
    _, ids = np.unique(ends, axis=0, return_inverse=True)
    ids = ids.reshape(-1)
    if np.bincount(ids).max(initial=0) > 2:
        raise ValueError("curve_weights: Γ_C must be a chain (at most two edges at a point)")
    order = np.argsort(ids, kind="stable")
    same = np.flatnonzero(ids[order[:-1]] == ids[order[1:]])
    slot = np.stack([order[same], order[same + 1]], axis=1)  # rows of ``ends``
    if slot.shape[0] < k - 1:
        raise ValueError(
            f"curve_weights: Γ_C must be connected, got {k - slot.shape[0]} separate chains"
        )
    return slot % k, slot // k


def curve_weights(x0, x1, chord_arc: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """The weights ``α_F`` (near) and ``β_F`` (far) of the guaranteed bound on a chain.

    ``|v|²_{H^{1/2}(Γ_C)} ≤ Σ_F (β_F h_F^{-1} ‖v‖²_F + α_F h_F ‖∂_τ v‖²_F)`` for every
    ``v ∈ H¹(Γ_C)`` (the module notes' derivation): ``α_F = 2 ln 2 + Σ_{F'∼F}
    2 J(h_F, h_F') / (h_F sin²(θ/2))``, ``β_F = 4 κ² Σ_{F'∼F} h_F / h_F'``, over the edges
    ``F'`` sharing an end point with ``F`` at the interior angle ``θ``.

    Parameters
    ----------
    x0, x1 : array_like of float64, shape (k, 2)
        Edge end points of a connected chain of straight edges (shared end points equal).
    chord_arc : float
        ``κ ≥ ℓ(x, y) / |x − y|`` for ``x, y`` on non-adjacent edges (``ℓ`` the length
        along Γ_C): 1 when Γ_C is straight, the caller's bound otherwise.

    Returns
    -------
    near, far : (k,) float arrays

    Raises
    ------
    ValueError
        If the edges do not form one chain (a point of three edges, or several chains).
    """
    x0 = np.asarray(x0, dtype=np.float64)
    x1 = np.asarray(x1, dtype=np.float64)
    k = x0.shape[0]
    h = np.hypot(*(x1 - x0).T)
    edge, end = _junctions(x0, x1)
    ends = np.stack([x0, x1])  # (2, k, 2)
    z = ends[end[:, 0], edge[:, 0]]
    d = ends[1 - end, edge] - z[:, None, :]  # (n, 2, 2): from z along each edge
    ha, hb = h[edge[:, 0]], h[edge[:, 1]]
    cos_theta = np.einsum("ij,ij->i", d[:, 0], d[:, 1]) / (ha * hb)
    sin2_half = 0.5 * (1.0 - np.clip(cos_theta, -1.0, 1.0))  # sin²(θ/2), 1 when straight
    J = ha * np.log1p(hb / ha) + hb * np.log1p(ha / hb)
    pair = 2.0 * J / sin2_half
    near = 2.0 * np.log(2.0) + np.bincount(edge.ravel(), np.repeat(pair, 2), minlength=k) / h
    inverse = np.bincount(edge[:, 0], 1.0 / hb, minlength=k) + np.bincount(
        edge[:, 1], 1.0 / ha, minlength=k
    )
    far = 4.0 * chord_arc**2 * h * inverse
    return near, far
