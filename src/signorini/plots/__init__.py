"""Figures of the paper's Section 6 (and a few more), drawn from plain data on disk.

Every function takes dictionaries of arrays or arrays, never the package's solver objects,
so that a figure can be redrawn from the files a run leaves (``history.csv``, meshes).

- :mod:`.style`: colours, markers and labels of every quantity, figure creation and saving;
- :mod:`.convergence`: the figures against ``N_dof`` (Figs. 6.1, 6.2, 6.3(a), 6.4), on the
  frame of :mod:`.frame`;
- :mod:`.slopes`: fitted slopes in legends (over the finer half of the run, stated in the
  legend; printed only where the curve has a steady rate) and slope triangles;
- :mod:`.mesh`: a triangulation (Fig. 6.3(b)); :mod:`.deformed`: the deformed body with its
  obstacles where the drawn body touches them (their gaps magnified as the displacement is),
  and the contact stresses per contact part against arc length (:mod:`.contact_stress`;
  without arc lengths against the coordinate of :mod:`.contact_line`); :mod:`.pressure`: a
  computed pressure beside a known one (with friction, the friction stress beside a known
  one, zoomed on the contact zone);
- :mod:`.report`: the figures a finished run gets, chosen by what its history contains;
  :mod:`.run_figures`: a run folder's figures, from its history and its last level as plain
  arrays.

:func:`read_history` and :func:`fitted_slope` belong to :mod:`signorini.output.history` and
are re-exported here.
"""

from ..output.history import fitted_slope, read_history
from .convergence import (
    plot_adaptive_vs_uniform,
    plot_contributions,
    plot_efficiency,
    plot_error_and_estimator,
    plot_estimator,
)
from .deformed import ContactDrawing, displacement_scale, plot_deformed
from .mesh import READABLE_CELLS, boundary_groups, plot_mesh, read_level_mesh, readable_level
from .pressure import FrictionCurves, plot_pressure_comparison
from .report import make_figures
from .slopes import add_slope_triangle, finer_half_slope
from .style import STYLES

__all__ = [
    "ContactDrawing",
    "FrictionCurves",
    "STYLES",
    "read_history",
    "fitted_slope",
    "add_slope_triangle",
    "plot_error_and_estimator",
    "plot_efficiency",
    "plot_contributions",
    "plot_estimator",
    "plot_mesh",
    "plot_deformed",
    "plot_pressure_comparison",
    "displacement_scale",
    "plot_adaptive_vs_uniform",
    "make_figures",
    "finer_half_slope",
    "READABLE_CELLS",
    "readable_level",
    "read_level_mesh",
    "boundary_groups",
]
