"""Ready-made problems: the paper's Examples 6.1 and 6.2 (also with friction), and three on
curved geometry.

- :mod:`.paper`: the paper's numerical experiments (Section 6);
- :mod:`.hertz`: an elastic half-disc pressed onto a rigid plane, with the Hertz solution;
- :mod:`.punch`: a rigid punch with rounded corners pressed into a block held against a wall;
- :mod:`.paper_friction`: Example 6.2 with Tresca or Coulomb friction on its contact part;
- :mod:`.partial_slip`: the Hertz half-disc pressed on a plane with Coulomb friction, then
  pulled sideways (Cattaneo–Mindlin), a load path of two steps;
- :mod:`.hertz3d`: the eighth of an elastic ball pressed onto a rigid plane by a total force
  (3D, force control), with the Hertz solution;
- :mod:`.paper3d`: the paper's Examples 6.1 (a manufactured solution, :mod:`.manufactured3d`,
  in contact on a disc) and 6.2 (the pyramid obstacle) on the unit cube (3D);
- :mod:`.punch3d`: a rigid punch with rounded edges pressed into a block held against a wall
  (3D, the half of a symmetric model);
- :mod:`.two_bodies`: contact between two elastic bodies: two cylinders (Hertz), two
  mirror-image half-discs, two blocks with non-matching meshes (the contact patch test);
- :mod:`.two_bodies3d`: two boxes with non-matching meshes in contact (3D, the dual mortar
  coupling on faces; the contact patch test).

:data:`EXAMPLES` holds one :class:`Example` record per built-in example, by the name the
command line takes (``signorini run hertz``): its problem, and where it has them its
per-level measurements for the history and its known pressure (:class:`Metrics`) and the load
steps solved before it on every level. Adding an example is one module and one record.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ..problem import ContactProblem
from .elasticity3d import ELASTICITY_3D_METRICS, elasticity_3d
from .hertz import HERTZ_METRICS, hertz
from .hertz3d import HERTZ_3D_METRICS, hertz_3d, hertz_3d_force_control
from .metrics import Metrics, PressureComparison
from .paper import example_6_1, example_6_2
from .paper3d import EXAMPLE_6_1_3D_METRICS, example_6_1_3d, example_6_2_3d
from .paper_friction import example_6_2_coulomb, example_6_2_tresca
from .partial_slip import PARTIAL_SLIP_METRICS, partial_slip, partial_slip_path
from .partial_slip3d import PARTIAL_SLIP_3D_METRICS, partial_slip_3d, partial_slip_3d_path
from .partial_slip_spheres3d import partial_slip_spheres, partial_slip_spheres_path
from .punch import punch
from .punch3d import punch_3d
from .two_bodies import BLOCKS_METRICS, CYLINDERS_METRICS, hertz_pair, stacked_blocks, two_cylinders
from .two_bodies3d import CUBES_METRICS, stacked_cubes
from .two_spheres3d import SPHERES_METRICS, two_spheres

__all__ = [
    "EXAMPLES",
    "Example",
    "HERTZ_METRICS",
    "Metrics",
    "PARTIAL_SLIP_METRICS",
    "PressureComparison",
    "example_6_1",
    "example_6_2",
    "example_6_1_3d",
    "example_6_2_3d",
    "example_6_2_coulomb",
    "example_6_2_tresca",
    "elasticity_3d",
    "get_example",
    "hertz",
    "hertz_3d",
    "partial_slip",
    "partial_slip_path",
    "punch",
    "punch_3d",
    "hertz_pair",
    "stacked_blocks",
    "stacked_cubes",
    "two_spheres",
    "two_cylinders",
]


@dataclass(frozen=True)
class Example:
    """A built-in example, as the command line runs it.

    Attributes
    ----------
    name : str
        The command line's name (``signorini run <name>``); also the problem's name.
    problem : callable () -> ContactProblem
        The problem on its default initial mesh.
    metrics : Metrics, optional
        Per-level measurements beyond the loop's own (further columns of ``history.csv``),
        and the known pressure drawn beside the computed one (:attr:`pressure`).
    load_path : callable () -> list of ContactProblem, optional
        The steps of a path-dependent example's load path, its problem the last: every level
        of the loop solves the steps before it first (:meth:`steps_before`).
    """

    name: str
    problem: Callable[[], ContactProblem]
    metrics: Metrics | None = None
    load_path: Callable[[], list[ContactProblem]] | None = None

    @property
    def pressure(self) -> Callable | None:
        """The known pressure beside the computed one (``metrics.pressure``), or None."""
        return None if self.metrics is None else self.metrics.pressure

    def steps_before(self) -> list[ContactProblem] | None:
        """The load steps before the example's problem (``adaptive(..., path=...)``), or None
        for an example without a load path."""
        return None if self.load_path is None else self.load_path()[:-1]


#: Every built-in example by the name the command line takes (``signorini run example-6.2``).
EXAMPLES: dict[str, Example] = {
    example.name: example
    for example in (
        Example("example-6.1", example_6_1),
        Example("example-6.2", example_6_2),
        Example("example-6.2-tresca", example_6_2_tresca),
        Example("example-6.2-coulomb", example_6_2_coulomb),
        Example("hertz", hertz, metrics=HERTZ_METRICS),
        Example("punch", punch),
        Example("partial-slip", partial_slip, PARTIAL_SLIP_METRICS, partial_slip_path),
        Example("two-cylinders", two_cylinders, metrics=CYLINDERS_METRICS),
        Example("stacked-blocks", stacked_blocks, metrics=BLOCKS_METRICS),
        Example("hertz-pair", hertz_pair),
        Example("elasticity-3d", elasticity_3d, metrics=ELASTICITY_3D_METRICS),
        Example("hertz-3d", hertz_3d_force_control, metrics=HERTZ_3D_METRICS),
        Example("example-6.1-3d", example_6_1_3d, metrics=EXAMPLE_6_1_3D_METRICS),
        Example("example-6.2-3d", example_6_2_3d),
        Example("punch-3d", punch_3d),
        Example("stacked-cubes", stacked_cubes, metrics=CUBES_METRICS),
        Example("two-spheres", two_spheres, metrics=SPHERES_METRICS),
        Example("partial-slip-3d", partial_slip_3d, PARTIAL_SLIP_3D_METRICS, partial_slip_3d_path),
        Example(
            "partial-slip-spheres",
            partial_slip_spheres,
            PARTIAL_SLIP_3D_METRICS,
            partial_slip_spheres_path,
        ),  # fmt: skip
    )
}


def get_example(name: str) -> ContactProblem:
    """The problem of the built-in example named ``name`` (a key of :data:`EXAMPLES`) on its
    default initial mesh.

    Raises
    ------
    ValueError
        For an unknown name; the message lists the known ones.
    """
    try:
        example = EXAMPLES[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown example {name!r}; choose one of {sorted(EXAMPLES)}") from None
    return example.problem()
