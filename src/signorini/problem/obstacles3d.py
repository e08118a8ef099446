"""Rigid obstacles of space: the gap and the constraint direction at points ``x (n, 3)``
(docs/method.md, *Three dimensions: contact on faces*).

The protocol is the plane shapes' (:class:`~signorini.problem.obstacle_base.Obstacle`, with
``dim = 3``): with ``q`` the point of the obstacle closest to ``z``, ``n_z`` is the obstacle's
unit normal at ``q`` pointing *into* the obstacle and ``psi(z)`` the signed distance (positive
outside, negative when ``z`` penetrates), so that ``q = z + psi(z) n_z``
(:meth:`~signorini.problem.obstacle_base.Obstacle.closest_point`) and the constraint
``u(z)·n_z ≤ psi(z)`` is the linearisation of non-penetration at ``q``, exact for a plane.
:meth:`~signorini.problem.obstacle_base.Obstacle.moved` translates any of them by ``(3,)``.

The shapes are immutable and check their arguments when built; the work is vectorised over
the points.
"""

from __future__ import annotations

import numpy as np

from .obstacle_base import TIE, Obstacle, checked_point, checked_positive
from .obstacles import SignedDistance

__all__ = ["Ball", "Cylinder", "HalfSpace", "SignedDistance3D"]


def _unit(vector: np.ndarray, owner: str, name: str) -> np.ndarray:
    """``vector (3,)`` normalised, refused when zero."""
    length = float(np.linalg.norm(vector))
    if length == 0:
        raise ValueError(f"{owner}: {name} must be a non-zero vector, got (0, 0, 0)")
    return vector / length


def _frozen(*arrays: np.ndarray) -> None:
    for a in arrays:
        a.flags.writeable = False


class HalfSpace(Obstacle):
    """The half-space ``{y : (y − point)·normal ≤ 0}`` (a rigid plane foundation).

    ``psi(z) = (z − point)·normal``, ``n_z = −normal``.

    Parameters
    ----------
    point : (3,) float array
        A point of the boundary plane.
    normal : (3,) float array
        Outward normal of the obstacle (towards the body); normalised.
    """

    dim = 3

    def __init__(self, point, normal):
        self.point = checked_point(point, "HalfSpace", "point", 3)
        self.normal = _unit(checked_point(normal, "HalfSpace", "normal", 3), "HalfSpace", "normal")
        _frozen(self.point, self.normal)

    def __repr__(self) -> str:
        return f"HalfSpace(point={self.point.tolist()}, normal={self.normal.tolist()})"

    def _gap_and_direction(self, x):
        psi = (x - self.point) @ self.normal
        return psi, np.broadcast_to(-self.normal, x.shape).copy()


def _towards(to_axis: np.ndarray, radius: float, owner: Obstacle, x: np.ndarray, what: str):
    """``|v| − radius`` and ``v / |v|`` of the vectors ``v (n, 3)`` from the points to the
    centre (axis), refused where ``|v| ≤ TIE radius`` (no direction)."""
    distance = np.linalg.norm(to_axis, axis=1)
    at = distance <= TIE * radius
    if at.any():
        k = int(np.flatnonzero(at)[0])
        raise ValueError(
            f"{owner!r}: x[{k}] = {x[k].tolist()} lies on the {what}, where no direction to the "
            "closest point exists"
        )
    return distance - radius, to_axis / distance[:, None]


class Ball(Obstacle):
    """The ball ``{y : |y − center| ≤ radius}``.

    ``psi(z) = |z − center| − radius`` and ``n_z = (center − z)/|center − z|``, inside and
    outside alike; the centre itself has no direction (refused).

    Parameters
    ----------
    center : (3,) float array
    radius : float, > 0
    """

    dim = 3

    def __init__(self, center, radius):
        self.center = checked_point(center, "Ball", "center", 3)
        self.radius = checked_positive(radius, "Ball", "radius")
        _frozen(self.center)

    def __repr__(self) -> str:
        return f"Ball(center={self.center.tolist()}, radius={self.radius!r})"

    def _gap_and_direction(self, x):
        return _towards(self.center - x, self.radius, self, x, "centre")


class Cylinder(Obstacle):
    """The infinite solid circular cylinder of radius ``radius`` about the line
    ``point + s axis``.

    With ``v`` the vector from ``z`` to its foot on the axis, ``psi(z) = |v| − radius`` and
    ``n_z = v/|v|`` (radial; the closest point of the mantle), inside and outside alike; points
    on the axis have no direction (refused).

    Parameters
    ----------
    point : (3,) float array
        A point of the axis.
    axis : (3,) float array
        The axis direction; normalised.
    radius : float, > 0
    """

    dim = 3

    def __init__(self, point, axis, radius):
        self.point = checked_point(point, "Cylinder", "point", 3)
        self.axis = _unit(checked_point(axis, "Cylinder", "axis", 3), "Cylinder", "axis")
        self.radius = checked_positive(radius, "Cylinder", "radius")
        _frozen(self.point, self.axis)

    def __repr__(self) -> str:
        return (
            f"Cylinder(point={self.point.tolist()}, axis={self.axis.tolist()}, "
            f"radius={self.radius!r})"
        )

    def _gap_and_direction(self, x):
        r = x - self.point
        to_axis = np.outer(r @ self.axis, self.axis) - r  # (n, 3)
        return _towards(to_axis, self.radius, self, x, "axis")


class SignedDistance3D(SignedDistance):
    """An obstacle of space given by a signed-distance function ``phi`` (negative inside):
    ``psi(z) = phi(z)``, ``n_z = −∇phi/|∇phi|``.

    As :class:`~signorini.problem.obstacles.SignedDistance` on points ``(n, 3)``: ``grad(x)``
    returns ``(n, 3)`` when given, otherwise central differences with the step
    ``eps^{1/3} scale`` along each axis; a quotient vector longer than ``√3`` (the bound of a
    1-Lipschitz function) shows that ``phi`` is not a distance and is refused.

    Parameters
    ----------
    phi : callable
        ``phi(x (n, 3)) -> (n,)``.
    grad : callable, optional
        ``grad(x (n, 3)) -> (n, 3)``.
    scale : float, > 0
    """

    dim = 3

    def __repr__(self) -> str:
        return "SignedDistance3D" + super().__repr__()[len("SignedDistance") :]

    def _gap_and_direction(self, x):
        n_points = x.shape[0]
        psi = self._call(self.phi, "phi", x, (n_points,))
        if self.grad is not None:
            gradient = self._call(self.grad, "grad", x, (n_points, 3))
        else:
            values = self._shifted(x, self.step * np.vstack([np.eye(3), -np.eye(3)]))  # (6, n)
            gradient = (values[:3] - values[3:]).T / (2 * self.step)
        return psi, self._direction(x, gradient, np.linalg.norm(gradient, axis=1))
