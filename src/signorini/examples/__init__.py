"""Ready-made problems: the paper's Examples 6.1 and 6.2, and two on curved geometry.

- :mod:`.paper`: the paper's numerical experiments (Section 6);
- :mod:`.hertz`: an elastic half-disc pressed onto a rigid plane, with the Hertz solution;
- :mod:`.punch`: a rigid punch with rounded corners pressed into a block held against a wall.

:data:`EXAMPLES` names them for the command line (``signorini run hertz``); an example may
also supply per-level measurements for the history (:data:`METRICS`).
"""

from __future__ import annotations

from collections.abc import Callable

from ..problem import ContactProblem
from .hertz import HERTZ_METRICS, hertz
from .metrics import Metrics
from .paper import example_6_1, example_6_2
from .punch import punch

__all__ = [
    "EXAMPLES",
    "METRICS",
    "Metrics",
    "example_6_1",
    "example_6_2",
    "get_example",
    "hertz",
    "punch",
]

#: The examples by the name the command line takes (``signorini run example-6.2``).
EXAMPLES: dict[str, Callable[..., ContactProblem]] = {
    "example-6.1": example_6_1,
    "example-6.2": example_6_2,
    "hertz": hertz,
    "punch": punch,
}

#: Per-level measurements of an example beyond the loop's own, by the example's name: the
#: command line writes them as further columns of ``history.csv``.
METRICS: dict[str, Metrics] = {"hertz": HERTZ_METRICS}


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
