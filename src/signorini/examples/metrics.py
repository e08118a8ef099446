"""What an example measures on each level beyond the loop's own columns.

A :class:`Metrics` is called with a level's :class:`~signorini.contact.solution.ContactResult`
and returns a few named floats; :func:`signorini.adaptive` (``metrics=...``) adds them to the
level's record (:attr:`LevelRecord.extra <signorini.LevelRecord.extra>`), so the command line
writes them as further columns of ``history.csv`` and describes them in ``history.md``. It may
also give a reference pressure to draw beside the computed one.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

from ..contact.solution import ContactResult

__all__ = ["ErrorRates", "Metrics", "PressureComparison", "error_rate_metrics"]


@dataclass(frozen=True)
class PressureComparison:
    """A computed contact pressure along a coordinate, beside a known one.

    Attributes
    ----------
    x : (m,) float array
        The coordinate of each node along the contact zone (length units).
    pressure : (m,) float array
        The computed consistent pressure p_z (stress units; NaN where there is none).
    x_reference : (r,) float array
        Where the known pressure is given (length units).
    reference : (r,) float array
        The known pressure there (stress units).
    label : str
        What the known pressure is (for a legend), e.g. ``"Hertz"``.
    title : str
        Title of the figure.
    tangential : (m,) float array or None
        With friction: the computed friction stress p_t,z at the nodes.
    tangential_reference : (r,) float array or None
        The known friction stress at ``x_reference`` (e.g. Cattaneo–Mindlin's).
    tangential_label : str
        What the known friction stress is (for a legend).
    state : (m,) str array or None
        ``"inactive"``, ``"stick"`` or ``"slip"`` per node.
    window : (2,) float or None
        The x range to show (a zoom on the contact zone).
    xlabel : str
        What ``x`` is (the figure's x-axis label).
    joined : bool
        The computed values are joined by a line (a pressure linear between the nodes along
        a line, e.g. through a 3D contact zone), not markers only.
    """

    x: np.ndarray
    pressure: np.ndarray
    x_reference: np.ndarray
    reference: np.ndarray
    label: str
    title: str = ""
    tangential: np.ndarray | None = None
    tangential_reference: np.ndarray | None = None
    tangential_label: str = ""
    state: np.ndarray | None = None
    window: tuple[float, float] | None = None
    xlabel: str = r"$x$"
    joined: bool = False


@dataclass(frozen=True)
class Metrics:
    """Per-level measurements of an example.

    Parameters
    ----------
    measure : callable ``measure(result) -> dict[str, float]``
        The measurements of one level's solution, by column name.
    columns : mapping of str to str
        Each column ``measure`` returns, with its meaning and unit (for ``history.md``).
    pressure : callable ``pressure(result) -> PressureComparison``, optional
        A known pressure to draw beside the computed one (the command line's figure
        ``<example>_pressure``).
    """

    measure: Callable[[ContactResult], dict[str, float]]
    columns: Mapping[str, str] = field(default_factory=dict)
    pressure: Callable[[ContactResult], PressureComparison] | None = None

    def __call__(self, result: ContactResult) -> dict[str, float]:
        """``measure(result)``."""
        return self.measure(result)


class ErrorRates:
    """The L² error of each level and the observed rates ``log(e_k / e_{k−1}) / log(N_k /
    N_{k−1})`` of the energy, H¹ and L² errors against the previous level's (NaN on the first
    level of a run: a level no finer than the one before starts a new run), for a problem
    with an exact solution (:meth:`ContactResult.errors`)."""

    def __init__(self) -> None:
        self.previous: tuple[float, dict[str, float]] | None = None

    def __call__(self, result: ContactResult) -> dict[str, float]:
        errors = result.errors()
        n = float(result.ndof)
        out = {"error_l2": errors["error_l2"]}
        for name in ("error_energy", "error_h1", "error_l2"):
            rate = math.nan
            if self.previous is not None and self.previous[0] < n:  # else a new run
                old_n, old = self.previous
                rate = math.log(errors[name] / old[name]) / math.log(n / old_n)
            out[f"rate_{name.removeprefix('error_')}"] = rate
        self.previous = (n, errors)
        return out


def error_rate_metrics() -> Metrics:
    """The measurements of a 3D example with an exact solution: the L² error and the observed
    rates of the three errors against the free unknowns (:class:`ErrorRates`; P2 tetrahedra:
    −2/3 for the energy and H¹ errors, −1 for the L² error)."""
    return Metrics(
        ErrorRates(),
        {
            "error_l2": "‖u − u_h‖_{L²(Ω)} against the exact solution",
            "rate_energy": "observed rate of error_energy against ndof (expected −2/3)",
            "rate_h1": "observed rate of error_h1 against ndof (expected −2/3)",
            "rate_l2": "observed rate of error_l2 against ndof (expected −1)",
        },
    )
