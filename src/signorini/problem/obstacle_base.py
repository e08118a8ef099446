"""The obstacle protocol (docs/method.md, *Obstacles as shapes*): :class:`Obstacle`, the base
every shape subclasses, and the argument checks the built-in shapes share.

An obstacle answers :meth:`Obstacle.gap_and_direction` for points ``x (n, d)`` (``d`` its
:attr:`Obstacle.dim`: 2 for the plane shapes, 3 for the solids of ``obstacles3d.py``): with ``q``
the point of the obstacle closest to ``z``, ``n_z`` is the obstacle's unit normal at ``q``
pointing *into* the obstacle and ``psi(z)`` the signed distance from ``z`` to the obstacle
(positive outside, negative when ``z`` penetrates), so that ``q = z + psi(z) n_z``. The one
call site is the contact layer's constraint data (``contact/constraint_data.py``).
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

__all__ = [
    "TIE",
    "UNIT_RTOL",
    "MovedObstacle",
    "Obstacle",
    "checked_point",
    "checked_positive",
    "cross",
    "finite_array",
    "unit_vectors",
]

#: candidates whose distance is within TIE * scale of the smallest are all closest
TIE = 1e-12


def finite_array(value, owner: str, name: str) -> np.ndarray:
    """``value`` as a finite float64 array (a copy)."""
    try:
        array = np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise ValueError(f"{owner}: {name} must be numeric, got {value!r}") from err
    if not np.isfinite(array).all():
        raise ValueError(f"{owner}: {name} has non-finite entries")
    return array


def checked_point(value, owner: str, name: str, dim: int = 2) -> np.ndarray:
    """``value`` as a finite ``(dim,)`` float64 array (a copy), refused naming ``owner``."""
    array = finite_array(value, owner, name)
    if array.shape != (dim,):
        raise ValueError(f"{owner}: {name} must have shape ({dim},), got {array.shape}")
    return array


def checked_positive(value, owner: str, name: str, allow_zero: bool = False) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError) as err:
        raise ValueError(f"{owner}: {name} must be a number, got {value!r}") from err
    if not np.isfinite(number) or number < 0 or (number == 0 and not allow_zero):
        bound = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"{owner}: {name} must be finite and {bound}, got {value!r}")
    return number


def unit_vectors(vectors: np.ndarray) -> np.ndarray:
    return vectors / np.hypot(vectors[..., 0], vectors[..., 1])[..., None]


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


class Obstacle(ABC):
    """A rigid obstacle, the base of every shape: :meth:`gap_and_direction` checks the points
    and asks the subclass's :meth:`_gap_and_direction`, the one method a new shape writes.

    A shape of one's own is a subclass, e.g. a flat foundation ``y >= -d`` below the body::

        class Floor(Obstacle):
            def __init__(self, depth):
                self.depth = depth

            def _gap_and_direction(self, x):
                return x[:, 1] + self.depth, np.tile([0.0, -1.0], (len(x), 1))

    and is given as ``Contact(obstacle=Floor(0.1))``. A solid of space sets ``dim = 3`` and
    answers for points ``(n, 3)`` (``obstacles3d.py``).
    """

    #: the dimension of the points the shape answers for
    dim: int = 2

    def gap_and_direction(self, x) -> tuple[np.ndarray, np.ndarray]:
        """Signed distance and constraint direction at the points ``x``.

        Parameters
        ----------
        x : (n, d) float array
            Points, e.g. the body's boundary nodes (``d`` = :attr:`dim`).

        Returns
        -------
        psi : (n,) float array
            Signed distance from each point to the obstacle: positive outside, negative inside.
        n : (n, d) float array
            Unit normal of the obstacle at the closest point, pointing into the obstacle;
            ``x + psi[:, None] * n`` is that closest point.

        Raises
        ------
        ValueError
            Naming the shape: for points that are not a finite ``(n, d)`` array, or where the
            shape's answer is not ``(n,)`` and ``(n, d)`` finite numbers with unit directions
            (within :data:`UNIT_RTOL`).
        """
        try:
            points = np.asarray(x, dtype=np.float64)
        except (TypeError, ValueError) as err:
            raise ValueError(f"{self!r}: x must be a numeric (n, {self.dim}) array") from err
        if points.ndim != 2 or points.shape[1] != self.dim:
            raise ValueError(f"{self!r}: x must have shape (n, {self.dim}), got {points.shape}")
        if not np.isfinite(points).all():
            k = int(np.flatnonzero(~np.isfinite(points).all(axis=1))[0])
            raise ValueError(f"{self!r}: x[{k}] is not finite: {points[k]}")
        psi, n = self._gap_and_direction(points)
        return _checked_answer(self, points, psi, n)

    def closest_point(self, x) -> np.ndarray:
        """``(n, d)`` the point ``q = x + psi(x) n_x`` of the obstacle's surface closest to
        each point ``x (n, d)`` (:meth:`gap_and_direction`)."""
        psi, n = self.gap_and_direction(x)
        return np.asarray(x, dtype=np.float64) + psi[:, None] * n

    @abstractmethod
    def _gap_and_direction(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``psi (n,)`` and ``n (n, d)`` as :meth:`gap_and_direction` returns them, at the
        checked points ``x (n, d)`` (finite float64)."""

    @property
    def displacement(self) -> np.ndarray:
        """``(d,)`` the prescribed rigid displacement of the obstacle from where it was given
        (zero; :meth:`moved` sets it). The friction law measures slip relative to it
        (docs/method.md, *Obstacle motion*)."""
        return np.zeros(self.dim)

    def moved(self, displacement) -> MovedObstacle:
        """This obstacle translated rigidly by ``displacement (d,)`` (length units), e.g. one
        load step of a path: ``Disc(c, r).moved((0.1 * t, -0.02))``.

        The gap and direction are those of the moved shape; a friction law on the contact
        part measures the slip relative to the obstacle, so that dragging the obstacle and
        moving the body the other way are the same (docs/method.md, *Obstacle motion*).
        Moving a moved obstacle adds the displacements.
        """
        return MovedObstacle(self, displacement)


#: how far from 1 the length of a direction an obstacle returns may be
UNIT_RTOL = 1e-6


def _checked_answer(shape: Obstacle, x: np.ndarray, psi, n) -> tuple[np.ndarray, np.ndarray]:
    """``psi (n,)`` and ``n (n, d)`` as a shape returned them for ``x (n, d)``, refused with
    a ValueError naming the shape unless finite numbers of those shapes with unit ``n``."""
    try:
        psi, n = np.asarray(psi, dtype=np.float64), np.asarray(n, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise ValueError(f"{shape!r}: gap_and_direction did not return numbers: {err}") from err
    if psi.shape != x.shape[:1] or n.shape != x.shape:
        raise ValueError(
            f"{shape!r}: gap_and_direction must return psi of shape {x.shape[:1]} and n of "
            f"shape {x.shape} for x of shape {x.shape}, got {psi.shape} and {n.shape}"
        )
    bad = ~(np.isfinite(psi) & np.isfinite(n).all(axis=1))
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"{shape!r}: gap_and_direction is not finite at x[{k}] = {x[k].tolist()} (psi "
            f"{psi[k]}, n {n[k].tolist()})"
        )
    length = np.hypot(n[:, 0], n[:, 1]) if x.shape[1] == 2 else np.linalg.norm(n, axis=1)
    off = np.abs(length - 1.0) > UNIT_RTOL
    if off.any():
        k = int(np.flatnonzero(off)[0])
        raise ValueError(
            f"{shape!r}: gap_and_direction must return unit directions n; at x[{k}] = "
            f"{x[k].tolist()} it returned {n[k].tolist()} of length {length[k]:.6g}"
        )
    return psi, n


class MovedObstacle(Obstacle):
    """An obstacle translated rigidly by a prescribed displacement (:meth:`Obstacle.moved`).

    Parameters
    ----------
    shape : Obstacle
        The obstacle where it was given.
    displacement : (d,) float array
        Its rigid displacement from there (``d`` the shape's :attr:`~Obstacle.dim`).
    """

    def __init__(self, shape: Obstacle, displacement):
        if not isinstance(shape, Obstacle):
            raise ValueError(f"MovedObstacle: shape must be an Obstacle, got {shape!r}")
        self.dim = shape.dim
        d = checked_point(displacement, "Obstacle.moved", "displacement", shape.dim)
        if isinstance(shape, MovedObstacle):
            shape, d = shape.shape, shape.displacement + d
        self.shape = shape
        self._displacement = d
        self._displacement.flags.writeable = False

    @property
    def displacement(self) -> np.ndarray:
        return self._displacement

    def __repr__(self) -> str:
        return f"{self.shape!r}.moved({self._displacement.tolist()})"

    def _gap_and_direction(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return self.shape.gap_and_direction(x - self._displacement)
