"""The estimator's integrals on triangulated contact surfaces (three dimensions; docs/method.md,
*Three dimensions: positive parts on faces and η7 on surfaces*).

- ``positive_part``: a quadrature of ``{v > 0}`` for a quadratic ``v`` on each face, by the
  triangles of the once-refined face (η6's ``∫ v⁺ φ_p`` and η7's norms), and the P1 hats of
  the once-refined face.
"""

from .positive_part import PositiveRule, face_monomials, positive_region_rule, refined_face_hats

__all__ = ["PositiveRule", "face_monomials", "positive_region_rule", "refined_face_hats"]
