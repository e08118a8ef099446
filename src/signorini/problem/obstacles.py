"""Rigid obstacles given as shapes: the gap and the constraint direction at boundary points.

Every obstacle answers :meth:`Obstacle.gap_and_direction` for points ``x (n, 2)``: with ``q``
the point of the obstacle closest to ``z``, ``n_z`` is the obstacle's unit normal at ``q``
pointing *into* the obstacle and ``psi(z)`` the signed distance from ``z`` to the obstacle
(positive outside, negative when ``z`` penetrates), so that ``q = z + psi(z) n_z`` in both
cases. The constraint ``u(z).n_z <= psi(z)`` is the linearisation of the exact
non-penetration condition at ``q``, exact for a flat obstacle (docs/method.md, *Obstacles as
shapes*).

Where the closest point is not unique (a point on the bisector of a sharp inner corner, in the
middle of a slot), every piece of the boundary whose distance is within ``1e-12`` times the
obstacle's scale of the smallest one is a candidate; ``n_z`` is the normalised mean of the
candidates' directions, ``psi`` is unchanged, and when that mean vanishes (opposite
candidates) ``n_z`` is the first candidate's direction in the order of the pieces.

Every shape subclasses :class:`~signorini.problem.obstacle_base.Obstacle` (exported here and
as ``signorini.Obstacle``), which checks ``x`` and asks the shape's ``_gap_and_direction``: a
shape of one's own is a subclass with that one method. This module holds the built-in shapes
(:class:`Polyline` from ``polyline.py``).

The obstacles are immutable and check their arguments when built; :meth:`gap_and_direction`
checks ``x``. The work is vectorized over points; :class:`Polyline` loops over its pieces
(segments and corner arcs), each iteration a NumPy operation on all points or a subset.
"""

from __future__ import annotations

import numpy as np

from .obstacle_base import TIE, Obstacle, checked_point, checked_positive
from .polyline import Polyline

__all__ = ["Disc", "HalfPlane", "Obstacle", "Polyline", "SignedDistance"]


class HalfPlane(Obstacle):
    """The half-plane ``{y : (y - point) . normal <= 0}``.

    Parameters
    ----------
    point : (2,) float array
        A point of the boundary line.
    normal : (2,) float array
        Outward normal of the obstacle (pointing away from it, towards the body); normalised.
        The constraint direction is ``-normal`` and ``psi(z) = (z - point) . normal``.
    """

    def __init__(self, point, normal):
        self.point = checked_point(point, "HalfPlane", "point")
        normal = checked_point(normal, "HalfPlane", "normal")
        length = np.hypot(*normal)
        if length == 0:
            raise ValueError("HalfPlane: normal must be a non-zero vector, got (0, 0)")
        self.normal = normal / length
        self.point.flags.writeable = False
        self.normal.flags.writeable = False

    def __repr__(self) -> str:
        return f"HalfPlane(point={self.point.tolist()}, normal={self.normal.tolist()})"

    def _gap_and_direction(self, x):
        psi = (x - self.point) @ self.normal
        return psi, np.broadcast_to(-self.normal, x.shape).copy()


class Disc(Obstacle):
    """The disc ``{y : |y - center| <= radius}`` (a cylinder in plane strain).

    ``psi(z) = |z - center| - radius`` and ``n_z = (center - z) / |center - z|`` for points
    inside and outside alike. At the centre itself every boundary point is closest and no
    direction exists: points closer than ``1e-12 * radius`` to the centre are an error.

    Parameters
    ----------
    center : (2,) float array
    radius : float, > 0
    """

    def __init__(self, center, radius):
        self.center = checked_point(center, "Disc", "center")
        self.radius = checked_positive(radius, "Disc", "radius")
        self.center.flags.writeable = False

    def __repr__(self) -> str:
        return f"Disc(center={self.center.tolist()}, radius={self.radius!r})"

    def _gap_and_direction(self, x):
        to_center = self.center - x
        distance = np.hypot(to_center[:, 0], to_center[:, 1])
        at_center = distance <= TIE * self.radius
        if at_center.any():
            k = int(np.flatnonzero(at_center)[0])
            raise ValueError(
                f"{self!r}: x[{k}] = {x[k].tolist()} lies at the centre, where no direction "
                "to the closest point exists"
            )
        return distance - self.radius, to_center / distance[:, None]


class SignedDistance(Obstacle):
    """An obstacle given by a signed-distance function ``phi`` (negative inside).

    ``psi(z) = phi(z)`` and ``n_z = -grad phi(z) / |grad phi(z)|``. The gradient is ``grad(x)``
    when given, otherwise central differences with the step ``h = eps**(1/3) * scale``
    (about ``6e-6 * scale``), which balances truncation and round-off; their error is
    ``O(h**2)`` where ``phi`` is smooth, and at kinks of ``phi`` (the bisector of a corner)
    the difference quotient averages the one-sided gradients.

    A distance is 1-Lipschitz, so each of its two difference quotients is at most 1 and their
    vector at most ``sqrt(2)`` long (1 where ``phi`` is smooth; more only at a kink, where the
    two quotients may come from different branches). Longer quotients (e.g. from
    ``|x|**2 - R**2`` instead of ``|x| - R`` away from the origin) show that ``phi`` is not a
    distance, so ``psi`` would be a wrong gap: the points are refused. A flatter ``phi`` (a
    distance divided by a constant) is not detected.

    Parameters
    ----------
    phi : callable
        ``phi(x)`` for ``x (n, 2)`` returns ``(n,)`` finite values: the signed distance.
    grad : callable, optional
        ``grad(x)`` for ``x (n, 2)`` returns ``(n, 2)`` finite values, non-zero.
    scale : float, > 0
        A length typical of the obstacle (its size), setting the difference step.
    """

    def __init__(self, phi, grad=None, scale=1.0):
        if not callable(phi):
            raise ValueError(f"SignedDistance: phi must be callable, got {phi!r}")
        if grad is not None and not callable(grad):
            raise ValueError(f"SignedDistance: grad must be callable or None, got {grad!r}")
        self.phi = phi
        self.grad = grad
        self.scale = checked_positive(scale, "SignedDistance", "scale")
        self.step = np.finfo(np.float64).eps ** (1 / 3) * self.scale

    def __repr__(self) -> str:
        name = getattr(self.phi, "__name__", repr(self.phi))
        return f"SignedDistance(phi={name}, scale={self.scale!r})"

    def _call(self, function, name: str, x: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
        try:
            raw = function(x)
        except Exception as err:
            raise ValueError(
                f"{self!r}: {name}(x) raised {type(err).__name__}: {err} (called with points "
                f"x of shape {x.shape})"
            ) from err
        try:
            value = np.asarray(raw, dtype=np.float64)
        except (TypeError, ValueError) as err:
            raise ValueError(f"{self!r}: {name}(x) did not return numbers: {err}") from err
        if value.shape != shape:
            raise ValueError(
                f"{self!r}: {name}(x) must return shape {shape} for x of shape {x.shape}, "
                f"got {value.shape}"
            )
        bad = ~np.isfinite(value.reshape(shape[0], -1)).all(axis=1)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise ValueError(f"{self!r}: {name}(x) is not finite at x[{k}] = {x[k].tolist()}")
        return value

    def _shifted(self, x: np.ndarray, shifts: np.ndarray) -> np.ndarray:
        """``(k, n)`` the values ``phi(x + s)`` at the points ``x (n, d)`` moved by each of
        the ``shifts (k, d)`` (one call of ``phi``, shift by shift)."""
        stacked = (x[None, :, :] + shifts[:, None, :]).reshape(-1, x.shape[1])
        values = self._call(self.phi, "phi", stacked, (len(shifts) * len(x),))
        return values.reshape(len(shifts), len(x))

    def _direction(self, x: np.ndarray, gradient: np.ndarray, length: np.ndarray) -> np.ndarray:
        """``n_z = −∇phi/|∇phi|`` ``(n, d)`` from the gradient ``(n, d)`` of ``phi`` at
        ``x (n, d)`` and its length ``(n,)``, refused where the gradient vanishes or where
        difference quotients are longer than ``√d`` (``phi`` not 1-Lipschitz)."""
        flat = length <= 1e-12
        if flat.any():
            k = int(np.flatnonzero(flat)[0])
            raise ValueError(
                f"{self!r}: the gradient of phi vanishes at x[{k}] = {x[k].tolist()}, so no "
                "direction to the obstacle exists there"
            )
        d = gradient.shape[1]
        if self.grad is None and (length > np.sqrt(d) * (1 + 1e-6)).any():
            k = int(np.argmax(length))
            raise ValueError(
                f"{self!r}: phi is not a signed distance: its difference quotients have "
                f"length {length[k]:.6g} > sqrt({d}) at x[{k}] = {x[k].tolist()}"
            )
        return -gradient / length[:, None]

    def _gap_and_direction(self, x):
        n_points = x.shape[0]
        psi = self._call(self.phi, "phi", x, (n_points,))
        if self.grad is not None:
            gradient = self._call(self.grad, "grad", x, (n_points, 2))
        else:
            h = self.step
            values = self._shifted(x, np.array([[h, 0.0], [-h, 0.0], [0.0, h], [0.0, -h]]))
            gradient = np.stack([values[0] - values[1], values[2] - values[3]], axis=1) / (2 * h)
        length = np.hypot(gradient[:, 0], gradient[:, 1])
        return psi, self._direction(x, gradient, length)
