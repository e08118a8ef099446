"""Boundary conditions on named boundary parts, and a known exact solution.

The strong form (paper, Section 2; docs/method.md, *The continuous problem*)::

    u = u_D on Γ_D   (Dirichlet),
    σ(u) n = g on Γ_N   (Neumann),
    u·n ≤ ψ,  σ_nn ≤ 0,  (u·n − ψ) σ_nn = 0,  σ_t = 0 on Γ_C   (Contact),

the obstacle of a contact part given by a gap function or as a shape (``obstacles``).

Each condition holds its data as given (numbers, or a function of the points ``x``) and checks
them when it is built: numbers must be finite and as many as the condition needs, a function
must accept the calling convention of docs/method.md, *User functions* (points ``x (n, 2)``,
the normal by name). The data are handed out as functions through ``field`` / ``gap_field``;
they are called and their values checked by :func:`signorini.problem.fields.evaluate_field`.

Units are the user's, and must be consistent: if E is in MPa (N/mm²) and lengths in mm,
displacements and gaps are in mm, tractions in MPa, body forces in N/mm³, and forces along the
boundary (per unit thickness, plane strain) in N/mm.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .fields import (
    CALL_NAMED,
    CALL_POSITIONAL,
    CALL_X,
    ProblemError,
    VectorField,
    check_function,
    check_numbers,
    constant_field,
)
from .friction_laws import LAW_MEMBERS, Friction
from .obstacles import Obstacle

__all__ = ["Condition", "Contact", "Dirichlet", "ExactSolution", "Neumann", "Roller"]

_DIRICHLET = "two finite numbers (u_x, u_y) or a function u_D(x) of points x (n, 2)"
_COMPONENT = (
    "two finite numbers (u_x, u_y), one of them possibly None (that component free), or a "
    "function u_D(x) of points x (n, 2)"
)
_TRACTION = (
    "two finite numbers (g_x, g_y) or a function g(x) or g(x, normal) of points x (n, 2) "
    "and outward unit normals normal (n, 2)"
)
_GAP = "a finite number or a function gap(x) of points x (n, 2)"
_NORMAL = "None or two finite numbers, not both zero"
_NORMAL_3D = (
    "None, three finite numbers, not all zero, or a function n(x) of points x (n, 3) "
    "returning unit vectors (n, 3) (on a 3D mesh)"
)


def _components(value: object) -> int:
    """How many components constant data give: 3 for a tuple or list of three (a 3D
    problem, docs/method.md, *Three dimensions: solving elasticity*), else 2 (the 2D
    count every message states)."""
    return 3 if isinstance(value, tuple | list) and len(value) == 3 else 2


@dataclass(frozen=True)
class Dirichlet:
    """Prescribed displacement ``u = u_D`` on a boundary part, or one component of it.

    Parameters
    ----------
    value : two floats (one may be None), or callable, default (0, 0)
        The displacement ``(u_x, u_y)`` on the whole part, or a function ``u_D(x)`` of the
        points ``x``, a float array of shape ``(n, 2)``, returning ``(n, 2)`` (or one
        ``(2,)`` vector for all points). Length units (docs/method.md, *User functions*).
        A component given as ``None`` is free: ``Dirichlet((0.0, None))`` holds ``u_x = 0``
        and leaves ``u_y`` and the traction ``σ_yx n_x + σ_yy n_y`` free (zero), as
        FEniCS's ``DirichletBC(V.sub(0), 0, ...)`` does (docs/method.md, *Rollers and
        components*). For the normal component of a part see :class:`Roller`.

    Raises
    ------
    ProblemError
        If ``value`` is neither two finite numbers (one of them possibly ``None``, not both)
        nor a function of one argument ``x``.
    """

    value: VectorField | tuple[float | None, float | None] = (0.0, 0.0)

    def __post_init__(self) -> None:
        if callable(self.value):
            check_function(self.value, "Dirichlet(value=...)", _DIRICHLET)
            return
        value = self.value
        n = _components(value)
        if isinstance(value, tuple | list) and len(value) == n and any(v is None for v in value):
            given = [v for v in value if v is not None]
            if not given:
                raise ProblemError(
                    f"Dirichlet(value=...) must be {_COMPONENT}; got {value!r} (a part with "
                    "no component held needs Neumann((0, 0)))"
                )
            check_numbers(
                given, len(given), "Dirichlet(value=...)", _COMPONENT, shown=value, bounded=True
            )
        else:
            check_numbers(value, n, "Dirichlet(value=...)", _DIRICHLET, bounded=True)

    @property
    def components(self) -> tuple[bool, ...]:
        """Which of ``(u_x, u_y)`` (3D: ``(u_x, u_y, u_z)``) the condition holds; a function
        holds all (:func:`~.rollers.held_nodes` takes as many as the mesh has)."""
        if callable(self.value):
            return (True, True)
        held = tuple(v is not None for v in self.value)
        return held  # type: ignore[return-value]

    def field(self) -> VectorField:
        """``u_D`` as a function of ``x (n, 2)`` (a free component reads 0)."""
        if callable(self.value):
            return self.value
        value = tuple(0.0 if v is None else v for v in self.value)
        return constant_field(value, shape=(len(value),))


@dataclass(frozen=True)
class Roller:
    """A roller (symmetry) condition: ``u(z)·n_z = value`` at each node, ``σ_t = 0``.

    The normal component of the displacement is prescribed and the body slides freely along
    the part (no tangential traction): the symmetry plane of a half-model, deal.II's "no
    normal flux" constraint, a body in a frictionless socket. ``n_z`` is the outward unit
    normal at the node, so ``value > 0`` moves the part outwards: the part's normal on a
    straight part, the exact normal of the part's curve where the mesh carries one, else the
    normalised mean of the part's edges' normals at a vertex
    (:func:`signorini.problem.normals.node_normals`). On a part along an axis the roller
    holds one Cartesian component (``Roller()`` on ``x = 0`` is ``Dirichlet((0.0, None))``);
    elsewhere the node's DOFs are solved in the frame ``[n_z t_z]`` (docs/method.md,
    *Rollers and components*). A part with a corner (turning by more than 30° at a vertex
    where no curve gives the normal) is refused by
    :class:`~signorini.problem.problem.ContactProblem`: split it into two rollers.

    Parameters
    ----------
    value : float, default 0
        The normal displacement ``u·n`` (length units).

    Raises
    ------
    ProblemError
        If ``value`` is not a finite number.
    """

    value: float = 0.0

    def __post_init__(self) -> None:
        check_numbers(self.value, 1, "Roller(value=...)", "a finite number", bounded=True)


@dataclass(frozen=True)
class Neumann:
    """Prescribed traction ``σ(u) n = g`` on a boundary part.

    Parameters
    ----------
    traction : two floats, or callable, default (0, 0)
        The traction ``(g_x, g_y)`` (force per unit length of boundary, in stress units: MPa
        if E is in MPa) on the whole part, or a function of the points ``x``, a float array of
        shape ``(n, 2)``, returning ``(n, 2)`` (or one ``(2,)`` vector). A function whose
        signature has a parameter ``normal`` is called ``g(x, normal=n)`` with the outward unit
        normals ``n (n, 2)`` at the points; a function of one argument is called ``g(x)``. The
        older ``g(x, n)``, with the normal as a second positional argument, still works and
        issues a :class:`DeprecationWarning` (docs/method.md, *User functions*).

    Raises
    ------
    ProblemError
        If ``traction`` is neither two finite numbers nor a function callable as ``g(x)``,
        ``g(x, normal=n)`` or ``g(x, n)``.
    """

    traction: Callable[..., np.ndarray] | tuple[float, float] = (0.0, 0.0)
    _call: str = field(default=CALL_X, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if callable(self.traction):
            call = check_function(self.traction, "Neumann(traction=...)", _TRACTION, normal=True)
            object.__setattr__(self, "_call", call)
        else:
            n = _components(self.traction)
            check_numbers(self.traction, n, "Neumann(traction=...)", _TRACTION)

    def field(self) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
        """``g`` as a function ``(x (n, 2), normal (n, 2))``, whatever form the user wrote."""
        g = self.traction
        if not callable(g):
            const = constant_field(g, shape=(np.size(g),))
            return lambda x, normal: const(x)
        if self._call == CALL_NAMED:
            return lambda x, normal: g(x, normal=normal)
        if self._call == CALL_POSITIONAL:
            return g
        return lambda x, normal: g(x)

    @property
    def is_zero(self) -> bool:
        """A zero constant traction (the part adds nothing to the load)."""
        return not callable(self.traction) and not np.any(np.asarray(self.traction))


@dataclass(frozen=True)
class Contact:
    """Frictionless unilateral contact ``u(z)·n_z ≤ ψ(z)`` on a boundary part.

    The obstacle is given either as a gap function along the body's outward normal (the
    paper's form) or as a rigid shape (docs/method.md, *Contact directions*):

    - ``gap``: ψ is measured along the body's outward normal n_z at each constrained node:
      the exact normal of the part's curve where the mesh carries one
      (:meth:`~signorini.mesh.mesh.Mesh.with_curve`), the part's normal on a straight part,
      otherwise the normalised mean of the outward normals of the part's edges at the node;
    - ``obstacle``: n_z is the obstacle's normal at its point closest to z, pointing into the
      obstacle, and ψ(z) the signed distance from z to the obstacle
      (:mod:`signorini.problem.obstacles`).

    Parameters
    ----------
    gap : float or callable, default 0
        The gap ψ between the part and the obstacle, measured along the outward normal (length
        units): a constant, or a function ``ψ(x)`` of the points ``x``, a float array of shape
        ``(n, 2)``, returning ``(n,)`` (or one value for all points); docs/method.md, *User
        functions*. Not with ``obstacle``.
    normal : two floats, three floats, a function or None
        The outward normal of a straight part (normalised here); ``None`` takes it from the
        geometry. A given normal must agree with the geometry (checked by
        :class:`~signorini.problem.problem.ContactProblem`). Not with ``obstacle``. On a 3D
        mesh: three numbers, or a direction field ``n(x)`` of points ``(n, 3)`` returning unit
        vectors ``(n, 3)``, the constraint directions instead of the body's normal, each
        pointing out of the body (docs/method.md, *Three dimensions: rollers, force control,
        regions*).
    obstacle : Obstacle or None
        A rigid obstacle given as a shape: :class:`~signorini.problem.obstacles.HalfPlane`,
        :class:`~signorini.problem.obstacles.Disc`,
        :class:`~signorini.problem.obstacles.Polyline` or
        :class:`~signorini.problem.obstacles.SignedDistance`.
    friction : Tresca, Coulomb, another friction law, or None
        The friction law on the part (:mod:`signorini.problem.friction_laws`, or any object of the
        protocol :class:`signorini.algebra.friction.laws.FrictionLaw`); ``None`` for frictionless
        contact.
    master : str or None
        Contact with a second deformable body: the boundary part of the other body (the
        master; this part is the slave) that this part may touch (docs/method.md, *Two
        bodies*). The constraint is the dual mortar one, the gap and the direction come from
        the two surfaces; the master part takes no condition of its own. Not with ``gap``,
        ``normal`` or ``obstacle``.
    face_alpha : float or None
        On a 3D mesh, the α of the transformed face basis, in [0, 1/2): None for the default
        1/5 (condition (b)), 0 for the nodal constraints at all P2 nodes (condition (a));
        docs/method.md, *Three dimensions: contact on faces*. Not on a 2D mesh.

    Raises
    ------
    ProblemError
        If ``gap`` is neither a finite number nor a function of one argument ``x``,
        ``normal`` is not ``None`` nor two finite numbers, not both zero, ``obstacle`` is not
        an obstacle, ``obstacle`` comes with a ``gap`` or a ``normal``, or ``friction`` is not
        a friction law.
    """

    gap: Callable[[np.ndarray], np.ndarray] | float = 0.0
    normal: tuple[float, ...] | Callable[[np.ndarray], np.ndarray] | None = None
    obstacle: Obstacle | None = None
    friction: Friction | None = None
    master: str | None = None
    face_alpha: float | None = None

    def __post_init__(self) -> None:
        friction = self.friction
        alpha = self.face_alpha
        if alpha is not None and not (isinstance(alpha, int | float) and 0 <= alpha < 0.5):
            raise ProblemError(f"Contact(face_alpha=...) must be in [0, 1/2), got {alpha!r}")
        if self.master is not None:
            if not isinstance(self.master, str) or not self.master:
                raise ProblemError(
                    "Contact(master=...) must be the name of the other body's boundary part, "
                    f"got {self.master!r}"
                )
            given = [
                f"{key}=..."
                for key, v in (
                    ("gap", self.gap),
                    ("normal", self.normal),
                    ("obstacle", self.obstacle),
                )
                if v is not None and (callable(v) or key != "gap" or np.any(np.asarray(v, float)))
            ]
            if given:
                raise ProblemError(
                    f"Contact(master={self.master!r}) takes its gap and direction from the two "
                    f"surfaces; do not give {', '.join(given)} with it"
                )
        if friction is not None and not all(hasattr(friction, a) for a in LAW_MEMBERS):
            raise ProblemError(
                "Contact(friction=...) must be None, Tresca(bound) or Coulomb(coefficient) "
                "from signorini.problem.friction_laws, or a friction law with "
                f"{', '.join(LAW_MEMBERS)}, got {self.friction!r}"
            )
        if callable(self.gap):
            check_function(self.gap, "Contact(gap=...)", _GAP)
        else:
            check_numbers(self.gap, 1, "Contact(gap=...)", _GAP, bounded=True)
        if callable(self.normal):  # a direction field n(x): 3D only (problem3d)
            check_function(self.normal, "Contact(normal=...)", _NORMAL_3D)
        elif self.normal is not None:
            size = 3 if np.size(self.normal) == 3 else 2  # three numbers: 3D only (problem3d)
            check_numbers(self.normal, size, "Contact(normal=...)", (_NORMAL, _NORMAL_3D)[size - 2])
            if not np.any(np.asarray(self.normal, dtype=np.float64)):
                raise ProblemError(f"Contact(normal=...) must be {_NORMAL}; got {self.normal!r}")
        if self.obstacle is not None:
            if not isinstance(self.obstacle, Obstacle):
                raise ProblemError(
                    "Contact(obstacle=...) must be a HalfPlane, Disc, Polyline or "
                    f"SignedDistance from signorini.problem.obstacles, got {self.obstacle!r}"
                )
            if callable(self.gap) or np.any(np.asarray(self.gap, dtype=np.float64)):
                raise ProblemError(
                    "Contact: give either gap=... (along the body's normal) or obstacle=... "
                    "(a shape, which gives the gap itself), not both"
                )
            if self.normal is not None:
                raise ProblemError(
                    "Contact: normal=... cannot be given with obstacle=...; against a shape "
                    "the constraint direction is the obstacle's normal at the closest point"
                )

    def gap_field(self) -> Callable[[np.ndarray], np.ndarray]:
        """``ψ`` as a scalar function of ``x (n, 2)`` (for a gap given along the normal)."""
        if callable(self.gap):
            return self.gap
        return constant_field(np.asarray(self.gap, dtype=np.float64).reshape(()), shape=())


@dataclass(frozen=True)
class ExactSolution:
    """A known solution, for error norms.

    Parameters
    ----------
    displacement : callable
        ``u(x)`` of the points ``x (n, 2)``, returning ``(n, 2)``.
    gradient : callable
        ``grad(x)`` returning ``(n, 2, 2)`` with ``grad[:, i, j] = ∂u_i/∂x_j``.

    Raises
    ------
    ProblemError
        If either is not a function of one argument ``x``.
    """

    displacement: VectorField
    gradient: Callable[[np.ndarray], np.ndarray]

    def __post_init__(self) -> None:
        check_function(
            self.displacement,
            "ExactSolution(displacement=...)",
            "a function u(x) of points x (n, 2)",
        )
        check_function(
            self.gradient, "ExactSolution(gradient=...)", "a function grad(x) of points x (n, 2)"
        )


Condition = Dirichlet | Roller | Neumann | Contact
