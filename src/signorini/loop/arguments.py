"""The arguments of :func:`signorini.loop.adaptive`, checked before any work (the command
line checks its options with the same function)."""

from __future__ import annotations

import math
import numbers

import numpy as np

from ..algebra.backends import BACKENDS
from ..estimator.marking import check_theta
from ..estimator.residual import ETA5_VARIANTS

__all__ = ["check_loop_arguments"]


def _check_count(value: object, name: str, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    if value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value}")
    return int(value)


def _check_real(value: object, name: str, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name} must be {what}, got {value!r}")
    value = float(value)
    if math.isnan(value):
        raise ValueError(f"{name} must be {what}, got nan")
    return value


def check_loop_arguments(
    *,
    theta: object = 0.4,
    max_ndof: object = 100_000,
    tol: object = 0.0,
    max_levels: object = 100,
    uniform: object = False,
    eta5: object = "consistent",
    backend: object = "auto",
    first_level: object = 0,
    prefix: str = "",
) -> dict:
    """The arguments of :func:`adaptive`, checked; a ``ValueError`` naming the first bad one.

    ``prefix`` is put before each name in the messages (the command line passes ``"--"``
    and spells the names with dashes).
    """

    def name(n: str) -> str:
        return prefix + (n.replace("_", "-") if prefix else n)

    if not isinstance(uniform, bool | np.bool_):
        raise ValueError(f"{name('uniform')} must be True or False, got {uniform!r}")
    theta = check_theta(theta, name("theta"))
    max_ndof = _check_real(max_ndof, name("max_ndof"), "a positive number")
    if max_ndof <= 0:
        raise ValueError(f"{name('max_ndof')} must be positive, got {max_ndof:g}")
    tol = _check_real(tol, name("tol"), "a number >= 0")
    if tol < 0:
        raise ValueError(f"{name('tol')} must be a number >= 0, got {tol:g}")
    max_levels = _check_count(max_levels, name("max_levels"), 1)
    if eta5 not in ETA5_VARIANTS:
        raise ValueError(f"{name('eta5')} must be one of {list(ETA5_VARIANTS)}, got {eta5!r}")
    backends = ("auto", *BACKENDS)
    if backend not in backends:
        raise ValueError(f"{name('backend')} must be one of {list(backends)}, got {backend!r}")
    first_level = _check_count(first_level, name("first_level"), 0)
    if first_level >= max_levels:
        raise ValueError(
            f"{name('first_level')} must be below {name('max_levels')}={max_levels}, "
            f"got {first_level}"
        )
    return {
        "theta": theta,
        "max_ndof": max_ndof,
        "tol": tol,
        "max_levels": max_levels,
        "uniform": bool(uniform),
        "eta5": eta5,
        "backend": backend,
        "first_level": first_level,
    }
