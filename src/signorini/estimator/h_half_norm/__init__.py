r"""The H^{1/2}(Γ_C) norm of the positive part of a piecewise quadratic (estimator term η7).

The last contribution of the residual estimator (Section 5, the definition of
η7 before (5.1); Section 6 for a non-zero gap) is

.. math::

    \eta_7^2 = \|v\|^2_{H^{1/2}(\Gamma_C)}, \qquad v = (u_h \cdot n - \psi)^+,

with the Sobolev-Slobodeckij norm

.. math::

    \|v\|^2_{H^{1/2}(\Gamma_C)} = \|v\|^2_{L^2(\Gamma_C)}
        + \int_{\Gamma_C}\int_{\Gamma_C} \frac{(v(x) - v(y))^2}{|x - y|^2}
          \, ds_x \, ds_y .

Γ_C is given as a list of straight edges ``x0 -> x1`` carrying a quadratic ``w`` (values
at ``[start, end, midpoint]``, the package's P2 edge-node order); ``v = max(w, 0)``.
Nothing else about the mesh is needed. The edges may lie on several straight segments,
connected or not, but must not cross or overlap (that is detected and reported).

The package keeps the edges' names here: this is the exact algorithm for a 1D curve Γ_C (a
2D problem's contact boundary, whose facets are edges), with panels, pair rules and
subdivision in one arc parameter. A 3D contact boundary is a surface and gets its own
algorithm; nothing here is a door for it.

Method (exact up to quadrature round-off, cost driven by the support of v):

* :mod:`.pieces`: every edge is cut at the real roots of its quadratic, so that v is a
  polynomial on each piece. ``S`` is the set of pieces where ``v = w > 0``; the rest of
  Γ_C is merged into maximal straight *zero runs*.
* The double integral splits into ``∫_S∫_S`` plus
  ``2 ∫_S v(x)^2 (∫_{Γ_C \ S} |x - y|^{-2} ds_y) ds_x``. The inner integral over a
  straight run ``[a, b]`` is analytic (:func:`.panels.segment_inverse_square_integral`):
  ``L θ / |(a - x) × (b - x)|`` with ``θ`` the angle the run subtends at ``x``.
* :mod:`.pair_rules`: pairs of pieces of the same edge use the divided difference
  ``(w(s) - w(s')) / (s - s') = b + c (s + s')``, a polynomial: a 2 x 2 Gauss rule is
  exact. Well separated panel pairs use tensor Gauss rules whose order depends on the
  separation; panels sharing an end point use a Duffy transformation that removes the
  non-smoothness at the common point (its angular order follows from the poles of the
  transformed integrand); a panel touching a zero run, once the run is long compared
  with it, uses a Gauss rule on ``v^2 ∫_Z |x - y|^{-2}``, ``t`` times an analytic
  function (``t`` = distance to the common point).
* :mod:`.subdivision`: all other pairs are subdivided, vectorized over all pairs of a
  level.
* :mod:`.norms`: the public functions, with the per-edge shares.
* :mod:`.parameters`: every tuning constant, with the reason for its value.
* :mod:`.localised`: a computable upper bound of η7 by facet norms, the replacement for
  surfaces (not part of the 2D estimator).

Cost: O(k) vectorized work to find S and the runs (k = number of edges), then
O(|S|^2 + |S| r) panel pairs (r = number of zero runs), processed in blocks.

References
----------
.. [1] R. Khandelwal, K. Porwal, T. Wadhawan, "Adaptive quadratic finite
   element method for the unilateral contact problem", Section 5 (η7).
.. [2] M. G. Duffy, "Quadrature over a pyramid or cube of integrands with a
   singularity at a vertex", SIAM J. Numer. Anal. 19 (1982) 1260-1262.
.. [3] E. Di Nezza, G. Palatucci, E. Valdinoci, "Hitchhiker's guide to the
   fractional Sobolev spaces", Bull. Sci. Math. 136 (2012) 521-573.
"""

from .localised import (
    FacetNorms,
    curve_weights,
    facet_norms2_positive_part,
    localised_bound2,
    localised_bound2_positive_part,
)
from .norms import hhalf_norm2_positive_part, hhalf_seminorm2_positive_part, l2_norm2_positive_part
from .panels import segment_inverse_square_integral
from .pieces import PositivePartPieces, positive_part_pieces

__all__ = [
    "FacetNorms",
    "PositivePartPieces",
    "curve_weights",
    "facet_norms2_positive_part",
    "hhalf_norm2_positive_part",
    "hhalf_seminorm2_positive_part",
    "l2_norm2_positive_part",
    "localised_bound2",
    "localised_bound2_positive_part",
    "positive_part_pieces",
    "segment_inverse_square_integral",
]
