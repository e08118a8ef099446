"""The round-off level of the estimator: the η_h that floating point alone gives a solution.

Below it η_h measures the rounding of the discrete solution, not its discretization error,
and refining cannot lower it: the adaptive loop stops there (:func:`signorini.adaptive`;
docs/method.md, *Marking and refinement*, "Round-off").
"""

from __future__ import annotations

import math

import numpy as np

from ..contact.solution import ContactResult
from ..fem.material import Material
from ..problem.problem import ContactProblem

__all__ = ["ROUNDOFF_FACTOR", "hooke_norm", "roundoff_level"]

#: The factor of :func:`roundoff_level`: about 10² from the second derivatives of the P2
#: basis in η1 (and the first derivatives in the jumps η2 … η5) times 10² for the linear
#: solve, which makes the nodal errors a small multiple of ε times the condition's growth.
#: Measured: η_h of the contact patch test (``stacked-blocks``, exact in P2) is 2·10² to
#: 1.2·10³ times ``ε ‖C‖ max|u_h| sqrt(n_cells)`` over 55 adaptive levels (640 to 90 000
#: unknowns); the other examples' η_h lie 10⁶ times above the level or more. In 3D, with the 3D
#: ``‖C‖``: η_h of the contact patch test on the cube is 5.3 to 8.0 times ``ε ‖C‖ max|u_h|
#: sqrt(n_cells)`` (375 to 107 811 unknowns, uniform and graded; docs/method.md, *Round-off in
#: three dimensions*), so the same factor holds with a wider margin.
ROUNDOFF_FACTOR = 1e4


def hooke_norm(problem: ContactProblem) -> float:
    """``‖C‖`` of the problem's stiffest material: the largest eigenvalue of its Hooke's law
    in the mesh's dimension (:attr:`Material.hooke_norm
    <signorini.fem.material.Material.hooke_norm>` in 2D, :attr:`~signorini.fem.material.
    Material.hooke_norm_3d` in 3D)."""
    material = problem.material
    materials = [material] if isinstance(material, Material) else list(material.values())
    if problem.mesh.dim == 3:
        return max(m.hooke_norm_3d for m in materials)
    return max(m.hooke_norm for m in materials)


def roundoff_level(result: ContactResult) -> float:
    """η_h of ``result``'s mesh that round-off alone gives: ``ROUNDOFF_FACTOR ε ‖C‖ U √n``.

    The terms of η_h are derivatives of u_h: rounding each nodal value of u_h by ``ε U``
    (``U = max |u_h|``, the displacement's own scale; ε the machine epsilon) changes σ(u_h)
    on a cell of size h by about ``‖C‖ ε U / h`` (:func:`hooke_norm`) and div σ(u_h) by
    ``‖C‖ ε U / h²``; the weights of η1 (``h_T ‖·‖_{L²(T)}``, ~h²) and of the jumps
    (``h_e^{1/2} ‖·‖_{L²(e)}``, ~h) turn both into ``‖C‖ ε U`` per cell whatever its size, and
    the squares of ``n`` cells add up to ``‖C‖ ε U √n``. :data:`ROUNDOFF_FACTOR` is the
    constant of the basis' derivatives and of the linear solve, which rounds with the
    condition of the stiffness matrix. In 3D the rounding of the nodal values alone would
    leave a factor h_T in each cell's square (``(Σ_T h_T)^{1/2}`` in place of ``√n``), but the
    solve's nodal errors grow as the mesh is refined and make up for it: measured on the 3D
    contact patch test, η_h / (ε ‖C‖ U √n) stays between 5.3 and 8.0 from 375 to 107 811
    unknowns, uniform or graded, while η_h / (ε ‖C‖ U (Σ_T h_T)^{1/2}) grows from 8 to 19 like
    h^{-1/2} (docs/method.md, *Round-off in three dimensions*); the formula is the 2D one
    with the 3D ``‖C‖`` (:func:`hooke_norm`). The level is therefore a property of the problem's
    scale (its stiffness and its displacement) and of the mesh's size, not of the mesh's
    grading; an η_h at or below it is noise: a rate fitted to it, or a marking of it, means
    nothing.

    Parameters
    ----------
    result : ContactResult
        A discrete solution.

    Returns
    -------
    float
        The level in the unit of η_h's stress terms (stress × length); 0 for ``u_h = 0``
        and NaN where the product overflows (no level known: the loop does not stop on it).

    References
    ----------
    N. J. Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., SIAM 2002,
    Chapter 3 (rounding of sums and products) and Section 7.2 (a linear solve's forward error
    as ε times the condition number).
    """
    u = np.asarray(result.u, dtype=np.float64)
    scale = float(np.abs(u).max(initial=0.0))
    if scale == 0.0:
        return 0.0
    n_cells = result.mesh.n_cells
    eps = float(np.finfo(np.float64).eps)
    level = ROUNDOFF_FACTOR * eps * hooke_norm(result.problem) * scale * math.sqrt(n_cells)
    return float(level) if math.isfinite(level) else math.nan
