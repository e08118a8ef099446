"""Ready-made problems: the paper's Examples 6.1 and 6.2 (also with friction), and three on
curved geometry.

- :mod:`.paper`: the paper's numerical experiments (Section 6);
- :mod:`.hertz`: an elastic half-disc pressed onto a rigid plane, with the Hertz solution;
- :mod:`.punch`: a rigid punch with rounded corners pressed into a block held against a wall;
- :mod:`.friction`: Example 6.2 with Tresca or Coulomb friction on its contact part;
- :mod:`.partial_slip`: the Hertz half-disc pressed on a plane with Coulomb friction, then
  pulled sideways (Cattaneo–Mindlin), a load path of two steps.

:data:`EXAMPLES` names them for the command line (``signorini run hertz``); an example may
also supply per-level measurements for the history (:data:`METRICS`) and the load steps
solved before it on every level (:data:`LOAD_PATHS`).
"""

from __future__ import annotations

from collections.abc import Callable

from ..problem import ContactProblem
from .friction import example_6_2_coulomb, example_6_2_tresca
from .hertz import HERTZ_METRICS, hertz
from .metrics import Metrics
from .paper import example_6_1, example_6_2
from .partial_slip import PARTIAL_SLIP_METRICS, partial_slip, partial_slip_path
from .punch import punch

__all__ = [
    "EXAMPLES",
    "LOAD_PATHS",
    "METRICS",
    "Metrics",
    "example_6_1",
    "example_6_2",
    "example_6_2_coulomb",
    "example_6_2_tresca",
    "get_example",
    "get_load_path",
    "hertz",
    "partial_slip",
    "partial_slip_path",
    "punch",
]

#: The examples by the name the command line takes (``signorini run example-6.2``).
EXAMPLES: dict[str, Callable[..., ContactProblem]] = {
    "example-6.1": example_6_1,
    "example-6.2": example_6_2,
    "example-6.2-tresca": example_6_2_tresca,
    "example-6.2-coulomb": example_6_2_coulomb,
    "hertz": hertz,
    "punch": punch,
    "partial-slip": partial_slip,
}

#: Per-level measurements of an example beyond the loop's own, by the example's name: the
#: command line writes them as further columns of ``history.csv``.
METRICS: dict[str, Metrics] = {"hertz": HERTZ_METRICS, "partial-slip": PARTIAL_SLIP_METRICS}

#: The load paths of path-dependent examples, by name: the steps, the example's problem the
#: last; every level of the loop solves the steps before it first (``adaptive(...,
#: path=steps[:-1])``).
LOAD_PATHS: dict[str, Callable[..., list[ContactProblem]]] = {"partial-slip": partial_slip_path}


def get_example(name: str) -> ContactProblem:
    """The example named ``name`` (a key of :data:`EXAMPLES`) on its default initial mesh.

    Raises
    ------
    ValueError
        For an unknown name; the message lists the known ones.
    """
    try:
        return EXAMPLES[name]()
    except KeyError:
        raise ValueError(f"unknown example {name!r}; choose one of {sorted(EXAMPLES)}") from None


def get_load_path(name: str) -> list[ContactProblem] | None:
    """The load steps solved before the example named ``name`` on every level (the first
    steps of its :data:`LOAD_PATHS` entry), or None for an example without a load path."""
    if name not in LOAD_PATHS:
        return None
    return LOAD_PATHS[name]()[:-1]
