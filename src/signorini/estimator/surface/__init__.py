"""The estimator's integrals on triangulated contact surfaces (three dimensions; docs/method.md,
*Three dimensions: positive parts on faces and η7 on surfaces*).

- ``face_quadratic``: the P2 function on a face as a quadratic in the reference coordinates.
- ``positive_part``: a quadrature of ``{v > 0}`` for a quadratic ``v`` on each face, by the
  triangles of the once-refined face (η6's ``∫ v⁺ φ_p`` and η7's norms), and the P1 hats of
  the once-refined face.
- ``penetration``: η7 on a surface, the guaranteed localised bound of ``‖v⁺‖_{H^{1/2}}``.
"""

from .penetration import face_norms2_positive_part, surface_penetration, surface_weights
from .positive_part import PositiveRule, face_monomials, positive_region_rule, refined_face_hats

__all__ = [
    "PositiveRule",
    "face_monomials",
    "face_norms2_positive_part",
    "positive_region_rule",
    "refined_face_hats",
    "surface_penetration",
    "surface_weights",
]
