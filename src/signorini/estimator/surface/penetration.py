r"""η7 on a triangulated contact surface: a computable upper bound of
``‖v⁺‖_{H^{1/2}(Γ_C)}``, ``v = u_h·n − ψ_h`` (docs/method.md, *Three dimensions: positive
parts on faces and η7 on surfaces*).

The paper's η7 (Section 5, before (5.1)) is the Sobolev–Slobodeckij norm; its reliability
proof (Section 5, the step before (5.10)) uses it only as an upper bound, and no efficiency
is proved for it. On a surface the seminorm ``∫∫ (v(x) − v(y))² |x − y|⁻³`` is a 4D singular
integral; this module computes the localised bound

.. math::

    \eta_7^2 \le G(v)^2 = \|v^+\|^2_{L^2(\Gamma_C)} + \sum_F \Big(
        \frac{8\pi}{\varepsilon_F} \|v^+\|^2_{L^2(F)}
        + 2\pi \Delta_F \|\nabla_\Gamma v^+\|^2_{L^2(F)} \Big),

with face radii ``δ_F = c h_F`` (``h_F = |F|^{1/2}``, ``c`` = :data:`DELTA_FACTOR`),
``ε_F = min{δ_F' : dist(F, F') < δ_F}`` and ``Δ_F = max{δ_F' : dist(F, F') < δ_F'}``
(``F' = F`` included). Derivation (docs/method.md): split the pairs ``(x, y)`` into *near*
ones, ``|x − y| < min(δ(x), δ(y))``, and the rest. Near pairs: ``(v(x) − v(y))² ≤ |x − y|
∫_{[x,y]} |∇v|²``, and the pairs whose segment passes through ``z ∈ F`` weigh at most
``∫_{S¹} ∫_0^{Δ} ∫_ρ^{Δ} r⁻¹ dr dρ dω = 2π Δ_F``; the others: ``(v(x) − v(y))² ≤ 2 v(x)² +
2 v(y)²`` and for ``x ∈ F`` they have ``|x − y| ≥ ε_F``, where ``∫_{|x−y|≥ε} |x − y|⁻³ dy ≤
2π/ε`` on a plane. The argument needs the near segments ``[x, y]`` inside Γ_C: it is a proof
for a plane, convex Γ_C (faces sharing an edge, a vertex or nothing are all covered, without
a constant per kind); on a bent or non-convex Γ_C it is applied as it stands (marked so in
docs/method.md). The face pairs closer than the radii are found through their centroids
(``|c_F − c_F'| < δ + R_F + R_F'``, ``R`` the distance of a face's nodes from its
centroid), a superset: it can only decrease ``ε_F`` and increase ``Δ_F``.

Every integral of ``v⁺`` is on ``{v > 0}`` by :func:`.positive_part.positive_region_rule`,
through the face's map ``x(s) = Σ x_a ψ_a(s)`` (flat or quadratic faces; ``∇_Γ v`` by the
metric ``JᵀJ``).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ...fem.p2 import basis, grad_basis
from ...mesh.geometry import facet_normals
from ..h_half_norm.localised import FacetNorms, localised_bound2
from .positive_part import positive_region_rule

__all__ = [
    "DELTA_FACTOR",
    "face_norms2_positive_part",
    "face_reach",
    "surface_penetration",
    "surface_weights",
]

#: the face radius ``δ_F = c h_F``: with ``c = 2`` the weights of a uniform mesh are ``4π``
#: on both ``h_F⁻¹‖v‖²_F`` and ``h_F ‖∇v‖²_F`` (the balance of the two terms)
DELTA_FACTOR = 2.0

#: the rule's degree: ``(v⁺)²`` on a flat face is of degree 4
_DEGREE = 4


def _checked(points: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``points (k, 6, 3)`` and ``v (k, 6)`` as float arrays, or ``ValueError``."""
    points = np.asarray(points, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    if points.ndim != 3 or points.shape[1:] != (6, 3):
        raise ValueError(
            f"surface_penetration: points must have shape (k, 6, 3), got {points.shape}"
        )
    if v.shape != points.shape[:2]:
        raise ValueError(
            f"surface_penetration: v must have shape {points.shape[:2]}, got {v.shape}"
        )
    if not (np.isfinite(points).all() and np.isfinite(v).all()):
        raise ValueError("surface_penetration: points and v must be finite")
    return points, v


def face_norms2_positive_part(points: np.ndarray, v: np.ndarray) -> FacetNorms:
    """``h_F = |F|^{1/2}``, ``‖v⁺‖²_F`` and ``‖∇_Γ v⁺‖²_F`` on each face.

    Parameters
    ----------
    points : (k, 6, 3) float array
        The faces' P2 nodes (vertices, then side midpoints; on a flat face the midpoints are
        those of the sides).
    v : (k, 6) float array
        The P2 nodal values of ``v`` on each face.

    Returns
    -------
    FacetNorms
        Arrays of shape (k,).
    """
    points, v = _checked(points, v)
    rule = positive_region_rule(v, _DEGREE)
    g = grad_basis(rule.s)  # (m, 6, 2)
    jac = np.swapaxes(points[rule.face], 1, 2) @ g  # (m, 3, 2): one 3 × 6 × 2 product a point
    metric = np.swapaxes(jac, 1, 2) @ jac
    det = metric[:, 0, 0] * metric[:, 1, 1] - metric[:, 0, 1] ** 2
    dv = (v[rule.face][:, None, :] @ g)[:, 0]  # (m, 2)
    # ∇_Γ v · ∇_Γ v = dvᵀ (JᵀJ)⁻¹ dv with the adjugate of the 2 × 2 metric
    grad2 = (
        metric[:, 1, 1] * dv[:, 0] ** 2
        - 2.0 * metric[:, 0, 1] * dv[:, 0] * dv[:, 1]
        + metric[:, 0, 0] * dv[:, 1] ** 2
    ) / det
    weight = rule.w * np.sqrt(det)
    value = np.einsum("ma,ma->m", basis(rule.s), v[rule.face])
    k = len(v)
    l2 = np.bincount(rule.face, weight * value**2, minlength=k)
    gradient = np.bincount(rule.face, weight * grad2, minlength=k)
    h = np.sqrt(facet_normals(points[:, :3])[0])
    return FacetNorms(h, l2, gradient)


def face_reach(
    points: np.ndarray, delta: np.ndarray, faces: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """``ε_F = min{δ_F' : dist(F, F') < δ_F}`` and ``Δ_F = max{δ_F' : dist(F, F') < δ_F'}``
    over the faces ``F'`` whose centroids are close enough (a superset of the pairs, module
    notes).

    Parameters
    ----------
    points : (k, 6, 3) float array
    delta : (k,) float array
        The face radii ``δ_F > 0``.
    faces : (p,) int array, optional
        The faces ``F`` whose ``ε_F`` and ``Δ_F`` are wanted (the others keep ``δ_F``); all
        by default. The pairs are those of these faces with every face, so their values are
        those of the whole set exactly (minima and maxima of the same numbers).

    Returns
    -------
    eps, reach : (k,) float arrays
    """
    eps, reach = delta.copy(), delta.copy()
    if faces is not None and len(faces) == 0:
        return eps, reach
    centre = points.mean(axis=1)
    radius = np.linalg.norm(points - centre[:, None], axis=2).max(axis=1)
    near = float(delta.max() + 2.0 * radius.max())
    tree = cKDTree(centre)
    if faces is None:
        pairs = tree.query_pairs(near, output_type="ndarray")
        i, j = np.concatenate([pairs, pairs[:, ::-1]]).T  # each pair both ways
    else:
        faces = np.asarray(faces)
        close = cKDTree(centre[faces]).sparse_distance_matrix(tree, near, output_type="ndarray")
        i, j = faces[close["i"]], close["j"]
        i, j = i[i != j], j[i != j]
    gap = np.linalg.norm(centre[i] - centre[j], axis=1) - radius[i] - radius[j]
    np.minimum.at(eps, i[gap < delta[i]], delta[j[gap < delta[i]]])  # F' = j within δ_F of F
    np.maximum.at(reach, i[gap < delta[j]], delta[j[gap < delta[j]]])  # F within δ_F' of F'
    return eps, reach


def surface_weights(
    points: np.ndarray, delta_factor: float = DELTA_FACTOR, faces: np.ndarray | None = None
) -> tuple:
    """The weights ``near_F = 2π Δ_F / h_F`` and ``far_F = 8π h_F / ε_F`` of the guaranteed
    bound, in the form of :func:`~signorini.estimator.h_half_norm.localised.localised_bound2`.

    Parameters
    ----------
    points : (k, 6, 3) float array
    delta_factor : float
        ``c`` in ``δ_F = c h_F``.
    faces : (p,) int array, optional
        Only these faces' weights are wanted (:func:`face_reach`); all by default.

    Returns
    -------
    near, far : (k,) float arrays
    """
    h = np.sqrt(facet_normals(np.asarray(points, dtype=np.float64)[:, :3])[0])
    eps, reach = face_reach(np.asarray(points, dtype=np.float64), delta_factor * h, faces)
    return 2.0 * np.pi * reach / h, 8.0 * np.pi * h / eps


def surface_penetration(
    points: np.ndarray, v: np.ndarray, *, delta_factor: float = DELTA_FACTOR
) -> np.ndarray:
    """η7² on a triangulated Γ_C as per-face shares of the guaranteed bound ``G(v⁺)²``
    (module notes), the 3D replacement of the exact η7 of the 2D estimator.

    Parameters
    ----------
    points : (k, 6, 3) float array
        The P2 nodes of the contact faces (vertices, then side midpoints).
    v : (k, 6) float array
        ``u_h·n − ψ_h`` at the faces' P2 nodes.
    delta_factor : float
        ``c`` in ``δ_F = c h_F`` (any ``c > 0`` gives an upper bound).

    Returns
    -------
    (k,) float array
        ``‖v⁺‖²_F + far_F h_F⁻¹ ‖v⁺‖²_F + near_F h_F ‖∇_Γ v⁺‖²_F``; they sum to ``G²`` and
        vanish on faces where ``v ≤ 0``.

    Raises
    ------
    ValueError
        On arrays of the wrong shape, non-finite values or ``delta_factor ≤ 0``.
    """
    points, v = _checked(points, v)
    if not delta_factor > 0.0:
        raise ValueError(f"surface_penetration: delta_factor must be > 0, got {delta_factor!r}")
    norms = face_norms2_positive_part(points, v)
    # the weights only where v⁺ ≠ 0: the other faces' shares are zero whatever theirs
    positive = np.flatnonzero((norms.l2 > 0.0) | (norms.gradient > 0.0))
    near, far = surface_weights(points, delta_factor, positive)
    return localised_bound2(norms, near, far)[1]
