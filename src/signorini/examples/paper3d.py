"""The paper's numerical experiments carried to three dimensions (docs/method.md, *Three
dimensions: the paper's examples*).

- ``example-6.1-3d`` (:func:`example_6_1_3d`): the unit cube on the rigid plane z = 0, a
  manufactured solution (:mod:`.manufactured3d`) in contact on a disc of Γ_C = {z = 0} and
  lifted off around it; Dirichlet data on the top, σ(u) n on the sides, as the paper's
  Example 6.1 (whose Γ_C is in full contact).
- ``example-6.2-3d`` (:func:`example_6_2_3d`): the unit cube held at x = 0 by
  u = (0.1, 0, 0) and pushed onto the obstacle of its face x = 1 given by the pyramid
  ``w(y, z) = −0.2 + 0.5 max(|y − ½|, |z − ½|)``, E = 500, ν = 0.3, as the paper's
  Example 6.2 with ``w(y) = −0.2 + 0.5 |y − 0.5|``.

Initial meshes: the unit cube on 2 × 2 × 2 cubes of the mirrored Kuhn split
(:func:`~signorini.mesh.builders3d.mirrored_box`, 48 tetrahedra), symmetric about y = ½ and
z = ½ and under y ↔ z like the 2D "union jack"; on the face x = 1 the square's diagonals run
towards the centre, so the pyramid's four edges (its kinks, on the face's diagonals) lie on
mesh edges of every uniform refinement and the P2 interpolant ψ_h of the pyramid is ψ itself.
"""

from __future__ import annotations

import numpy as np

from ..fem.material import Material
from ..mesh.builders3d import mirrored_box
from ..problem import Contact, ContactProblem, Dirichlet, ExactSolution, Neumann
from .manufactured3d import CONTACT_CUBE, ContactCube
from .metrics import error_rate_metrics

__all__ = ["EXAMPLE_6_1_3D_METRICS", "example_6_1_3d", "example_6_2_3d", "pyramid"]

#: the side faces of the cube, Neumann in both examples (σ(u) n in 6.1-3d, zero in 6.2-3d)
SIDES_6_1 = ("x0", "x1", "y0", "y1")
SIDES_6_2 = ("y0", "y1", "z0", "z1")


def example_6_1_3d(
    n: int = 2, exact: ContactCube = CONTACT_CUBE, face_alpha: float | None = None
) -> ContactProblem:
    """Example 6.1 in 3D: a known solution in contact on a disc of the bottom, lifted off
    around it.

    Ω = (0, 1)³, Γ_D = {z = 1} (u = u_exact), Γ_N = the four sides with g = σ(u) n,
    Γ_C = {z = 0} with ψ = 0 along the body's normal n = (0, 0, −1) (the rigid plane z = 0),
    f = −div σ(u),
    λ = μ = 1; u of :mod:`.manufactured3d` (contact for r < 0.35 about (½, ½), a gap outside).

    Parameters
    ----------
    n : int, default 2
        The initial mesh: ``mirrored_box(n, n, n)`` (``6 n³`` tetrahedra), n even.
    exact : ContactCube
        The manufactured solution (default :data:`~.manufactured3d.CONTACT_CUBE`).
    face_alpha : float, optional
        The discrete contact condition: None for (b), 0 for (a) (:func:`example_6_2_3d`).

    Returns
    -------
    ContactProblem
        Named ``"example-6.1-3d"``, with its :class:`ExactSolution`.
    """
    return ContactProblem(
        mesh=mirrored_box(n, n, n),
        material=exact.material,
        conditions={
            "z1": Dirichlet(exact.displacement),
            **{side: Neumann(exact.traction) for side in SIDES_6_1},
            "z0": Contact(gap=0.0, face_alpha=face_alpha),
        },
        body_force=exact.body_force,
        exact=ExactSolution(exact.displacement, exact.gradient),
        name="example-6.1-3d",
    )


def pyramid(x: np.ndarray) -> np.ndarray:
    """The obstacle of Example 6.2 in 3D, ``w(y, z) = −0.2 + 0.5 max(|y − ½|, |z − ½|)`` at
    points ``x (..., 3)``: the gap along ``n = e_1`` on the face x = 1, so the constraint is
    ``u_1 ≤ w`` (negative in the middle: the face starts beyond the obstacle there)."""
    x = np.asarray(x, dtype=np.float64)
    return -0.2 + 0.5 * np.maximum(np.abs(x[..., 1] - 0.5), np.abs(x[..., 2] - 0.5))


def example_6_2_3d(n: int = 2, face_alpha: float | None = None) -> ContactProblem:
    """Example 6.2 in 3D: the unit cube pushed against the pyramid obstacle.

    Ω = (0, 1)³, Γ_D = {x = 0} with u = (0.1, 0, 0), Γ_N = the faces y = 0, 1 and z = 0, 1
    with g = 0, Γ_C = {x = 1} with the gap ψ = :func:`pyramid` along the body's normal
    n = e_1, i.e.
    ``u_1(1, y, z) ≤ −0.2 + 0.5 max(|y − ½|, |z − ½|)``, f = 0, E = 500, ν = 0.3. No exact
    solution is known; the contact zone is a neighbourhood of the face's centre. The problem
    is symmetric under y ↔ 1 − y, z ↔ 1 − z and y ↔ z, and so is its discrete solution on
    the default mesh and its uniform refinements.

    Parameters
    ----------
    n : int, default 2
        The initial mesh: ``mirrored_box(n, n, n)``, n even (the pyramid's edges on mesh
        edges).
    face_alpha : float, optional
        The discrete contact condition (:class:`~signorini.problem.Contact`): None for (b),
        the transformed face basis with α = 1/5; 0 for (a), nodal constraints at all P2 nodes.

    Returns
    -------
    ContactProblem
        Named ``"example-6.2-3d"``, without an exact solution.
    """
    return ContactProblem(
        mesh=mirrored_box(n, n, n),
        material=Material.from_young(500.0, 0.3),
        conditions={
            "x0": Dirichlet((0.1, 0.0, 0.0)),
            **{side: Neumann((0.0, 0.0, 0.0)) for side in SIDES_6_2},
            "x1": Contact(gap=pyramid, face_alpha=face_alpha),
        },
        name="example-6.2-3d",
    )


#: the L² error and the observed rates of the three errors (columns of the history)
EXAMPLE_6_1_3D_METRICS = error_rate_metrics()
