"""Data given by the user as functions of ``x``: the one place where they are called and
their output checked.

Body force ``f``, Dirichlet values ``u_D``, tractions ``g``, gaps ``ψ`` and exact solutions are
functions of points ``x (..., 2)``; a constant is turned into such a function by
:func:`constant_field`. :func:`evaluate_field` calls one and checks the shape and finiteness of
what it returns, so that the numerical layers below (:mod:`signorini.fem`) can trust their
data.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["ProblemError", "VectorField", "constant_field", "evaluate_field"]

VectorField = Callable[[np.ndarray], np.ndarray]


class ProblemError(ValueError):
    """Raised for an ill-posed or inconsistent problem definition."""


def constant_field(value: float | tuple[float, ...], shape: tuple[int, ...] = (2,)) -> VectorField:
    """The field ``x (..., 2) -> value`` broadcast to ``(...) + shape``.

    Parameters
    ----------
    value : float or sequence of float
        ``shape`` numbers (a scalar for ``shape = ()``).
    shape : tuple of int
        Shape of the value at one point: ``(2,)`` for a vector field, ``()`` for a scalar.
    """
    v = np.asarray(value, dtype=np.float64).reshape(shape)
    return lambda x: np.broadcast_to(v, np.shape(x)[:-1] + shape).copy()


def evaluate_field(
    func: VectorField, x: np.ndarray, what: str, shape: tuple[int, ...] = (2,)
) -> np.ndarray:
    """Evaluate a user function at points ``x (..., 2)``, checking its output.

    Parameters
    ----------
    func : callable
        ``func(x)``; its value must broadcast to ``x.shape[:-1] + shape``.
    x : (..., 2) float array
    what : str
        How to name the function in an error message, e.g. ``"the gap function of contact
        part 'bottom'"``.
    shape : tuple of int
        Shape of the value at one point: ``(2,)`` for a vector field, ``()`` for a scalar
        field, ``(2, 2)`` for a gradient.

    Returns
    -------
    (...) + shape float array

    Raises
    ------
    ProblemError
        If the value does not broadcast to the expected shape, or is NaN or infinite.
    """
    values = np.asarray(func(x), dtype=np.float64)
    expected = np.shape(x)[:-1] + shape
    if values.shape != expected:
        try:
            values = np.broadcast_to(values, expected).copy()
        except ValueError:
            raise ProblemError(
                f"{what} must return shape {expected} for points of shape "
                f"{np.shape(x)}, got {values.shape}"
            ) from None
    if not np.isfinite(values).all():
        raise ProblemError(f"{what} returned NaN or inf")
    return values
