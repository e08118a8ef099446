"""The frictional contact solver: semismooth Newton for Tresca and Coulomb friction.

Nothing is imported here (``problem`` imports :mod:`.laws` alone); the public names are
re-exported by :mod:`signorini.algebra`.

====================  ==========================================================================
``laws``              the friction-law protocol and per-node law groups
``kkt``               the frictional contact problem's data (tangent basis ``(m, d − 1)``),
                      checks and KKT residuals
``system``            one iteration's system: symmetric, or non-symmetric where s' ≠ 0
``result``            node states, steps and result of a frictional solve
``rule``              the update rule of the node states
``fixed_point``       Coulomb's fallback: the fixed point on the slip bound
``newton``            ``solve_friction``: semismooth Newton for Tresca and Coulomb friction
``disc``              3D: the disc law and ``solve_disc``, its semismooth Newton method
====================  ==========================================================================
"""
