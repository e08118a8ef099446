"""Data given by the user as functions of points: the one place where they are called and
their output checked.

The calling convention (docs/method.md, *User functions*), the same for the body force ``f``,
Dirichlet values ``u_D``, tractions ``g``, gaps ``ψ`` and exact solutions:

- the function receives the points as one array ``x`` of shape ``(n, 2)``, always
  two-dimensional (row ``i`` is the point ``(x_i, y_i)``), so ``x[:, 0]`` and ``x[..., 0]`` are
  both the abscissae;
- extra data are passed by name: a traction whose signature has a parameter ``normal`` is
  called ``g(x, normal=n)`` with the outward unit normals ``n (n, 2)`` at the points, a
  traction of one argument is called ``g(x)``; the older form ``g(x, n)``, with the normal as a
  second positional argument, still works and warns (:class:`DeprecationWarning`);
- it returns one value per point, ``(n,)`` for a scalar (gap), ``(n, 2)`` for a vector
  (displacement, traction, body force), ``(n, 2, 2)`` for a gradient, or a single value of the
  per-point shape (``()``, ``(2,)``, ``(2, 2)``), which is the same at every point.

:func:`check_function` checks a function's signature when a condition or problem is built;
:func:`evaluate_field` calls it and checks what it returns, so that the numerical layers below
(:mod:`signorini.fem`) can trust their data. A function that raises, or returns the wrong shape,
NaN or inf, is reported as a :class:`ProblemError` that names the condition and its part.
"""

from __future__ import annotations

import inspect
import warnings
from collections.abc import Callable

import numpy as np

__all__ = [
    "ProblemError",
    "VectorField",
    "check_function",
    "check_numbers",
    "constant_field",
    "evaluate_field",
]

VectorField = Callable[[np.ndarray], np.ndarray]

#: How :func:`check_function` says a function is called: ``f(x)``, ``f(x, normal=n)``, or the
#: deprecated ``f(x, n)``.
CALL_X, CALL_NAMED, CALL_POSITIONAL = "x", "named", "positional"


#: The largest magnitude of a length (a Dirichlet value, a gap; a number given or a
#: function's value) and of a displacement the loads cause: its square summed over 1e8
#: entries (a norm, an energy, the estimator's η7²) stays below the largest double, 1.8e308.
#: Loads themselves scale with the stiffness (E may be 1e300) and are bounded through the
#: displacement they cause (:func:`signorini.contact.admissible.check_load_size`)
DATA_MAX = float(np.sqrt(np.finfo(np.float64).max / 1e8))


def _too_large(values: np.ndarray) -> bool:
    return values.size > 0 and float(np.abs(values).max()) > DATA_MAX


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


def check_numbers(
    value, size: int, argument: str, expected: str, *, shown=None, bounded: bool = False
) -> None:
    """Check data given as numbers: ``size`` finite real numbers.

    Parameters
    ----------
    value : object
        The data as given.
    size : int
        How many numbers: 2 for a vector, 1 for a scalar.
    argument : str
        The argument, as the user wrote it, e.g. ``"Dirichlet(value=...)"``.
    expected : str
        What the argument may be, e.g. ``"two finite numbers (u_x, u_y) or a function u_D(x)"``.
    shown : object, optional
        The argument as the user gave it, for the message, where ``value`` is a part of it.
    bounded : bool
        A length (a displacement, a gap): its magnitude must not exceed :data:`DATA_MAX`.

    Raises
    ------
    ProblemError
        Naming the argument, what was expected and what was given; also for a length beyond
        :data:`DATA_MAX` in magnitude.
    """
    bad = isinstance(value, str | bytes)
    if not bad:
        try:
            values = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            bad = True
        else:
            bad = values.size != size or values.ndim > 1 or not np.isfinite(values).all()
    shown = value if shown is None else shown
    if bad:
        raise ProblemError(f"{argument} must be {expected}; got {shown!r}")
    if bounded and _too_large(values):
        raise ProblemError(
            f"{argument} = {shown!r} is beyond ±{DATA_MAX:.3g}, where the sums of squares "
            "the computation forms (norms, energies) overflow double precision; state the "
            "problem in units that make its data smaller"
        )


def check_function(
    func: Callable, argument: str, expected: str, *, normal: bool = False, stacklevel: int = 4
) -> str:
    """Check that a user function can be called by the convention, and say how to call it.

    Parameters
    ----------
    func : callable
    argument : str
        The argument, as the user wrote it, e.g. ``"Neumann(traction=...)"``.
    expected : str
        What the argument may be (for the error message).
    normal : bool
        Whether the function may receive the outward unit normal (a traction).
    stacklevel : int
        Passed to :func:`warnings.warn` for the deprecated form, so that the warning points at
        the user's line.

    Returns
    -------
    str
        ``CALL_X`` (``func(x)``), ``CALL_NAMED`` (``func(x, normal=n)``) or ``CALL_POSITIONAL``
        (``func(x, n)``, deprecated: a :class:`DeprecationWarning` is issued).

    Raises
    ------
    ProblemError
        If ``func`` is not callable, or its signature admits none of these calls.
    """
    if not callable(func):
        raise ProblemError(f"{argument} must be {expected}; got {func!r}")
    try:
        sig = inspect.signature(func)
    except (TypeError, ValueError):  # no signature to read (some builtins): call it f(x)
        return CALL_X
    params = sig.parameters.values()
    if normal and (
        any(p.kind == p.VAR_KEYWORD for p in params)
        or any(
            p.name == "normal" and p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)
            for p in params
        )
    ):
        if _binds(sig, None, normal=None):
            return CALL_NAMED
    if _binds(sig, None):
        return CALL_X
    if normal and _binds(sig, None, None):
        warnings.warn(
            f"{argument}: a traction g(x, n) that takes the normal as a second positional "
            "argument is deprecated; name the parameter `normal` (def g(x, normal): ...), it "
            "is passed by name, or write g(x) if the traction does not depend on the normal",
            DeprecationWarning,
            stacklevel=stacklevel,
        )
        return CALL_POSITIONAL
    raise ProblemError(f"{argument} must be {expected}; got a function with signature {sig}")


def _binds(sig: inspect.Signature, *args, **kwargs) -> bool:
    try:
        sig.bind(*args, **kwargs)
    except TypeError:
        return False
    return True


def evaluate_field(
    func: Callable,
    x: np.ndarray,
    what: str,
    shape: tuple[int, ...] = (2,),
    *,
    normal: np.ndarray | None = None,
    bounded: bool = False,
) -> np.ndarray:
    """Evaluate a user function at points ``x (..., 2)``, checking its output.

    The function receives the points flattened to ``(n, 2)`` (and the normals, if given,
    broadcast to the points and flattened the same way); its values are returned in the shape
    of ``x``.

    Parameters
    ----------
    func : callable
        ``func(x)``, or ``func(x, normal)`` when ``normal`` is given (the form of
        :meth:`~signorini.problem.conditions.Neumann.field`).
    x : (..., 2) float array
    what : str
        How to name the function in an error message, e.g. ``"the gap function of contact
        part 'bottom'"``.
    shape : tuple of int
        Shape of the value at one point: ``(2,)`` for a vector field, ``()`` for a scalar
        field, ``(2, 2)`` for a gradient.
    normal : (..., 2) float array, optional
        Outward unit normals, broadcastable to ``x``.
    bounded : bool
        A length (a Dirichlet value, a gap): its values must not exceed :data:`DATA_MAX` in
        magnitude.

    Returns
    -------
    (...) + shape float array

    Raises
    ------
    ProblemError
        If the function raises, returns something other than ``(n,) + shape`` numbers (or one
        value of shape ``shape``), NaN or infinite values, or (``bounded``) values beyond
        :data:`DATA_MAX` in magnitude.
    """
    x = np.asarray(x, dtype=np.float64)
    lead = x.shape[:-1]
    points = np.array(x.reshape(-1, x.shape[-1]))  # (n, 2), or (n, 3) in 3D
    args = (points,)
    if normal is not None:
        args += (np.array(np.broadcast_to(normal, x.shape).reshape(points.shape)),)
    try:
        raw = func(*args)
    except ProblemError:
        raise
    except Exception as err:
        raise ProblemError(f"{what} raised {type(err).__name__}: {err}") from err
    if raw is None:
        raise ProblemError(f"{what} returned None (is a return statement missing?)")
    try:
        values = np.asarray(raw, dtype=np.float64)
    except (TypeError, ValueError):
        raise ProblemError(
            f"{what} must return an array of numbers, got {type(raw).__name__}"
        ) from None
    expected = points.shape[:1] + shape
    if values.shape == shape:  # one value for every point
        values = np.broadcast_to(values, expected).copy()
    elif values.shape != expected:
        raise ProblemError(
            f"{what} must return shape {expected} for points of shape {points.shape}, "
            f"got {values.shape}"
        )
    if not np.isfinite(values).all():
        bad = ~np.isfinite(values.reshape(points.shape[0], -1)).all(axis=1)
        k = int(np.argmax(bad))
        raise ProblemError(
            f"{what} returned NaN or inf at x = {tuple(points[k].tolist())} "
            f"({int(bad.sum())} of {points.shape[0]} points)"
        )
    if bounded and _too_large(values):
        k = int(np.argmax(np.abs(values).reshape(points.shape[0], -1).max(axis=1)))
        raise ProblemError(
            f"{what} returned {np.abs(values).max():.6g} in magnitude at x = "
            f"({points[k, 0]:.12g}, {points[k, 1]:.12g}), beyond ±{DATA_MAX:.3g}, where the sums "
            "of squares the computation forms (norms, energies) overflow double precision; "
            "state the problem in units that make its data smaller"
        )
    return values.reshape(lead + shape)
