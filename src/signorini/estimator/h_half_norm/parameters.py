r"""Tuning parameters of the H^{1/2}(Γ_C) norm, each with the reason for its value.

The other modules read them as ``parameters.NAME`` at call time, so a test can tighten
them all in one place (``monkeypatch.setattr(parameters, ...)``) and check that the
result does not move. Errors are quoted relative to the integrand's scale.

Quadrature orders follow one rule: a Gauss rule with ``n`` points on a panel whose
integrand is analytic inside the Bernstein ellipse with parameter ``ρ`` errs by about
``ρ^{-2n}``. A singularity at distance ``r·L`` beyond the end of a panel of length ``L``
gives ``z = 1 + 2r`` on the reference interval [−1, 1] and ``ρ = z + (z² − 1)^{1/2}``.
"""

from __future__ import annotations

# ---- far pairs (pair_rules.far_pair_integral)

#: ``(min separation / longer panel length, Gauss points per direction)``, tried in order.
#: With ``r`` the separation ratio the nearest singularity of ``|x − y|^{-2}`` gives
#: ``ρ = 5.8, 17.9, 66, 258`` for ``r = 1, 4, 16, 64``; with 12, 8, 6, 4 points the
#: bound ``ρ^{-2n}`` is 4e-19, 9e-21, 1e-22, 5e-20: every tier is below double round-off,
#: and the cheaper tiers take the many well separated pairs. Pairs closer than ``r = 1``
#: are subdivided.
FAR_TIERS: tuple[tuple[float, int], ...] = ((64.0, 4), (16.0, 6), (4.0, 8), (1.0, 12))

# ---- a piece of S touching a zero run (subdivision.zero_run_pair_integral)

#: a panel touching a zero run at its end point is integrated once the run is this many
#: times longer than the panel. There ``v² · ∫_Z |x − y|^{-2}`` equals ``t`` times an
#: analytic function whose nearest singularity lies at distance ``|Z|`` from the common
#: point (for collinear runs and at any angle), so ``r ≥ 2`` gives ``ρ ≥ 9.9``.
TOUCH_RUN_RATIO = 2.0
#: Gauss points for such a panel: ``9.9^{-24} ≈ 1e-24``.
TOUCH_RUN_ORDER = 12

# ---- touching pairs of pieces: the Duffy rule (pair_rules.duffy_pair_integral)

#: touching panel pairs go to the Duffy rule once their lengths agree to this factor;
#: otherwise the longer one is cut at the length of the shorter. Equal lengths keep the
#: poles of the angular integrand, at ``(a/b) e^{±iα}`` and ``(b/a) e^{±iα}``, on the unit
#: circle and away from [0, 1]. The cut makes the lengths equal up to round-off; the
#: tolerance only absorbs that round-off (any value from 1e-12 to 1e-3 would do, the
#: angular order follows the actual ratio).
DUFFY_RATIO = 1.0 + 1e-6
#: ``(radial, minimum angular)`` Gauss points of the Duffy rule. The radial integrand is a
#: cubic in ``ρ``: 2 points would be exact, 3 (exact to degree 5) keep a margin. The pole
#: estimate below asks 12 points for collinear and 14 for perpendicular pairs; the floor
#: of 20 keeps a margin where the estimate is asymptotic.
DUFFY_ORDER = (3, 20)
#: the angular order is raised until the Gauss error bound ``ρ^{-2n}`` is below
#: ``exp(−DUFFY_DIGITS) ≈ 4e-18``, below double round-off.
DUFFY_DIGITS = 40.0
#: cap of the angular order: reached only for edges folding back onto each other at an
#: angle below about 0.07° (``ρ → 1`` as the poles approach [0, 1]).
DUFFY_MAX_ORDER = 400

# ---- subdivision (subdivision.py)

#: bisections of a panel before a pair is declared unresolved. A separated pair resolves
#: once its panels are shorter than their distance, which is at least the point
#: tolerance ``POINT_TOL``: after ``log2(1 / POINT_TOL) ≈ 40`` levels. Only pairs that meet
#: away from their end points (crossing or overlapping edges) reach 60.
MAX_LEVEL = 60
#: panel pairs per vectorized block: bounds the temporaries (4096 pairs x 12 x 12 points
#: is 4.7 MB per array; a Duffy block at the maximal order 3 x 400 is 39 MB).
BLOCK = 4096
#: panel pairs alive in one subdivision level beyond which the subdivision is declared
#: non-localising (crossing or overlapping edges). A valid Γ_C keeps few pairs alive (the
#: adaptive run of Example 6.2 to 55 000 unknowns never more than 4); the bound stops a
#: runaway subdivision before it exhausts memory.
MAX_ACTIVE = 200_000

# ---- geometry and roots (pieces.py)

#: points closer than ``POINT_TOL`` times the extent of Γ_C (largest coordinate plus
#: diameter) are the same point. Input coordinates carry round-off of ~1e-16 relative;
#: four orders of magnitude above that, yet far below any mesh size.
POINT_TOL = 1e-12
#: roots of ``w`` closer than this to an end point (in the edge parameter) are dropped: a
#: root at a node computed with round-off would otherwise cut a sliver piece on which
#: ``|v| ≤ 1e-13 · max|w'|``, far below what the norm resolves.
ROOT_SNAP = 1e-13
#: relative tolerance for the continuity of ``v = max(w, 0)`` at shared end points (relative
#: to ``max|w|``). Values from one nodal value are exactly equal; values of one quadratic
#: evaluated on both sides of a split agree to round-off. A true jump (an infinite norm)
#: is larger by many orders.
CONTINUITY_RTOL = 1e-8
#: two zero pieces meeting at a point are merged into one straight run when ``|sin|`` of
#: their angle is below this. The merged run is the chord of the two, an error of the
#: order of the angle in the inner integral; edges of a straight contact part meet at
#: round-off angles (~1e-16). Not merging is always exact, merging only saves work.
PARALLEL_TOL = 1e-9

# ---- closed form of ∫ |x − y|^{-2} over a segment (panels.inverse_square_integral)

#: below this ratio ``|cross| / dot`` the closed form ``arctan(r) / r`` is replaced by its
#: series to ``r^6``: the truncation ``r^8 / 9 ≈ 1e-25`` is below round-off, and the series
#: avoids the cancellation of ``arctan2(cr, dt) / cr`` for nearly collinear points.
SERIES_SWITCH = 1e-3
