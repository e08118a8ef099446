"""The options of the adaptive loop: one frozen object that owns their defaults and checks.

:class:`AdaptiveOptions` is what :func:`signorini.adaptive` runs with, what the command line
builds from its flags and what a run folder's manifest records (:meth:`~AdaptiveOptions.
to_record`) and ``--resume`` rebuilds (:meth:`~AdaptiveOptions.from_record`). A bad value
raises :class:`OptionError`, a ``ValueError`` that names the field; the command line spells
the field as its flag itself.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass, fields

import numpy as np

from ..algebra.backends.selection import auto_solver, solver_factory, solver_name
from ..algebra.backends.solvers import SolverFactory, SPDSolver
from ..estimator.marking import check_theta
from ..estimator.residual import ETA5_VARIANTS
from ..fem.element import element_of

__all__ = ["AdaptiveOptions", "LEGACY_KEYS", "OptionError"]

#: keys of a manifest written before the options had their present names -> the field
LEGACY_KEYS = {"eta5": "eta5_variant", "backend": "solver"}


class OptionError(ValueError):
    """An option with a bad value; the message begins with the field's name.

    Attributes
    ----------
    field : str
        The field of :class:`AdaptiveOptions`.
    """

    def __init__(self, field: str, message: str) -> None:
        super().__init__(message)
        self.field = field


@dataclass(frozen=True)
class AdaptiveOptions:
    """How the adaptive loop runs (paper, Section 6; docs/method.md, *Marking and
    refinement*). Checked when made; ``dataclasses.replace(options, theta=0.5)`` makes a
    changed copy, checked again.

    Attributes
    ----------
    theta : float
        Dörfler parameter in (0, 1] (ignored when ``uniform``).
    max_ndof : int or float
        Budget of free unknowns (:attr:`~signorini.loop.LevelRecord.ndof`), positive (``inf``
        for none): no level exceeds it.
    tol : float
        Stop once the estimator η_h reaches this value (>= 0).
    max_levels : int
        Stop after the level with index ``max_levels - 1`` (at least 1).
    uniform : bool
        Refine every cell (NVB with all edges bisected) instead of Dörfler marking.
    eta5_variant : {"consistent", "paper"}
        Variant of the estimator's η5 (:func:`~signorini.estimator.estimate`).
    warm_start : bool
        Start each solve from the previous level's prolongated solution and contact set (with
        friction, the semismooth Newton method from its update rule at that solution).
    fallback : bool
        Where PDAS cycles or reaches its iteration bound, finish that level's solve with the
        primal active set method instead of raising (:func:`signorini.solve`). Frictional
        solves need no flag: where their states cycle they go on one node at a time, and
        Coulomb's then by the fixed point on its slip bound (docs/method.md, *When the
        iteration cycles*).
    solver : SolverFactory or SPDSolver
        The linear solver of every level (:func:`signorini.solve`'s ``solver``): a factory
        makes one per solve, default :func:`~signorini.algebra.auto_solver`; a solver object
        is used by every level and not closed. A run folder records it by its name in
        :data:`signorini.algebra.SOLVERS`.
    element : {"P2", "P1"}
        The finite element of every level (any case; stored upper-case): the paper's P2, or
        P1 with its residual estimator (docs/method.md, *P1 elements and their estimator*).

    Raises
    ------
    OptionError
        A ``ValueError`` naming the first field with a bad value.
    """

    theta: float = 0.4
    max_ndof: int | float = 100_000
    tol: float = 0.0
    max_levels: int = 100
    uniform: bool = False
    eta5_variant: str = ETA5_VARIANTS[0]
    warm_start: bool = True
    fallback: bool = False
    solver: SolverFactory | SPDSolver = auto_solver
    element: str = "P2"

    def __post_init__(self) -> None:
        for name in ("uniform", "warm_start", "fallback"):
            self._set(name, _flag(getattr(self, name), name))
        try:
            self._set("theta", check_theta(self.theta, "theta"))
        except ValueError as exc:
            raise OptionError("theta", str(exc)) from None
        max_ndof = _real(self.max_ndof, "max_ndof", "a positive number")
        if max_ndof <= 0:
            raise OptionError("max_ndof", f"max_ndof must be positive, got {max_ndof:g}")
        self._set("max_ndof", max_ndof)
        tol = _real(self.tol, "tol", "a number >= 0")
        if tol < 0:
            raise OptionError("tol", f"tol must be a number >= 0, got {tol:g}")
        self._set("tol", float(tol))
        self._set("max_levels", check_count(self.max_levels, "max_levels", 1))
        if self.eta5_variant not in ETA5_VARIANTS:
            raise OptionError(
                "eta5_variant",
                f"eta5_variant must be one of {list(ETA5_VARIANTS)}, got {self.eta5_variant!r}",
            )
        try:
            self._set("element", element_of(self.element).name)
        except ValueError as exc:
            raise OptionError("element", str(exc)) from None
        solver = self.solver
        if not isinstance(solver, SPDSolver) and (isinstance(solver, str) or not callable(solver)):
            raise OptionError(
                "solver",
                "solver must be an SPDSolver or a solver factory (e.g. "
                f"signorini.algebra.superlu_solver), got {solver!r}",
            )

    def _set(self, name: str, value: object) -> None:
        object.__setattr__(self, name, value)

    # ------------------------------------------------------------------ the manifest
    def to_record(self) -> dict[str, object]:
        """The options as JSON values by field name, the solver by its registry name.

        Raises
        ------
        ValueError
            If the solver is not a factory of :data:`signorini.algebra.SOLVERS`.
        """
        record = {f.name: getattr(self, f.name) for f in fields(self)}
        record["solver"] = solver_name(self.solver)
        return record

    @classmethod
    def from_record(cls, record: Mapping[str, object]) -> AdaptiveOptions:
        """The options :meth:`to_record` recorded; a record written before the fields had
        their present names (``eta5``, ``backend``: :data:`LEGACY_KEYS`) is read too, and
        keys that are no field are ignored (the command line records its own beside them).
        A field missing from the record takes its default.

        Raises
        ------
        OptionError
            For a bad value or an unknown solver name.
        """
        names = {f.name for f in fields(cls)}
        values = {}
        for key, value in record.items():
            key = LEGACY_KEYS.get(key, key)
            if key in names:
                values[key] = value
        if "solver" in values:
            try:
                values["solver"] = solver_factory(values["solver"])
            except ValueError as exc:
                raise OptionError("solver", f"solver: {exc}") from None
        return cls(**values)


def _flag(value: object, name: str) -> bool:
    if not isinstance(value, bool | np.bool_):
        raise OptionError(name, f"{name} must be True or False, got {value!r}")
    return bool(value)


def _real(value: object, name: str, what: str) -> int | float:
    """A real number, an integer kept as int (a budget prints as given); NaN refused."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise OptionError(name, f"{name} must be {what}, got {value!r}")
    if isinstance(value, numbers.Integral):
        return int(value)
    value = float(value)
    if math.isnan(value):
        raise OptionError(name, f"{name} must be {what}, got nan")
    return value


def check_count(value: object, name: str, minimum: int) -> int:
    """An integer ``>= minimum`` (not a bool); an :class:`OptionError` naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise OptionError(name, f"{name} must be an integer >= {minimum}, got {value!r}")
    if value < minimum:
        raise OptionError(name, f"{name} must be an integer >= {minimum}, got {value}")
    return int(value)
