"""A run's figures, and the uniform refinement it is compared with (``--compare-uniform``).
matplotlib is imported only when figures are drawn."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..examples import Metrics
from ..loop import AdaptiveOptions, Level, adaptive
from ..output import HistoryWriter
from ..output.run import RunFolder
from ..problem.problem import ContactProblem
from .levels import write_levels

__all__ = ["compare_uniform", "draw_figures", "figures", "figures_command", "pressure_figure"]


def figures(
    example: str,
    out: Path,
    last: Level | None = None,
    name: str | None = None,
    element: str | None = None,
    dim: int | None = None,
) -> list[Path]:
    """The run's figures (:func:`signorini.plots.run_figures.run_figures`), titled with the
    problem's ``name``, the reference slopes of its ``element`` in dimension ``dim`` (default:
    the last level's problem's, element and mesh's); a 3D level as the arrays of its body
    (:func:`~signorini.loop.arrays.body_arrays`)."""
    from ..fem.element import element_of
    from ..loop.arrays import body_arrays, level_arrays
    from ..plots.run_figures import run_figures

    arrays = None
    if last is not None:
        arrays = body_arrays(last) if last.result.mesh.dim == 3 else level_arrays(last)
        result = last.result
        if result.mesh.dim == 3 and result.contact.size and result.contact.has_friction:
            from ..output.vtu3d import friction_fields_3d

            nodes = np.unique(result.contact.faces)  # the rows of surface_arrays' points
            fields = friction_fields_3d(result, result.space.n_nodes)
            arrays["contact"]["state"] = fields["contact_state"][nodes]
            arrays["contact"]["slip_direction"] = fields["slip_direction"][nodes]
    degree = None if element is None else element_of(element).degree
    return run_figures(example, out, arrays, name, degree, dim)


def figures_command(name: str, out: Path, status) -> list[Path]:
    """``signorini figures PROBLEM DIR``: redraw the convergence figures of the run in
    ``DIR``, once the problem named is checked to be the one that produced its levels
    (:func:`~signorini.cli.identity.check_problem`). The folder is locked while drawing
    (``status.folder``; released by the caller)."""
    from ..output.run import RunFolder
    from .identity import check_problem
    from .problems import label, load
    from .settings import recorded_arguments

    folder = RunFolder.open(out, purpose="draw the figures")
    status.folder = folder
    job = load(name)
    options = AdaptiveOptions.from_record(recorded_arguments(folder.manifest, folder.file))
    check_problem(folder, name, job, options, f"figures {name} {out}")
    drawn = {"name": job.problem.name, "element": options.element, "dim": job.problem.mesh.dim}
    return figures(label(name), folder.path, **drawn)


def pressure_figure(example: str, out: Path, last: Level, metrics: Metrics) -> list[Path]:
    """The last level's pressure beside the known one the example's ``metrics`` give."""
    from ..plots.run_figures import pressure_figure as draw

    return draw(example, out, metrics.pressure(last.result))


def draw_figures(
    label: str,
    folder: RunFolder,
    last: Level | None,
    metrics: Metrics | None,
    say: Callable[[str], None],
) -> None:
    """Announce, draw and record the figures of a run whose last level is ``last`` (None:
    the convergence figures of its history only)."""
    out = folder.path
    three = last is not None and last.result.mesh.dim == 3  # no mesh figure in 3D
    kinds = "convergence history, mesh, deformed body" if last else "convergence history"
    if three:
        kinds = "convergence history, deformed body"
        if last.result.contact.size:
            kinds += ", contact pressure over Γ_C"
    say(f"drawing the figures of {label} ({kinds}) ...")
    written = figures(label, out, last)
    if last is not None and metrics is not None and metrics.pressure is not None:
        written += pressure_figure(label, out, last, metrics)
    folder.add_files(*(str(p.relative_to(out)) for p in written))
    say(f"figures: {', '.join(str(p.name) for p in written)}")


def compare_uniform(
    problem: ContactProblem,
    options: AdaptiveOptions,
    no_figures: bool,
    folder: RunFolder,
    say: Callable[[str], None],
    metrics: Metrics | None = None,
    path: Sequence[ContactProblem] | None = None,
) -> None:
    """Uniform refinement to the same budget (with the run's options, but no tolerance), and
    one plot of both convergence histories."""
    from .. import plots
    from ..fem.element import element_of
    from ..plots.slopes import optimal_slope

    out = folder.path
    uni = folder.sub_folder("uniform")  # refused if it is a link out of the folder
    folder.add_files("uniform/history.csv")
    history = HistoryWriter(uni / "history.csv")
    say(f"{problem.name}: uniform refinement for comparison -> {uni}")
    uniform = replace(options, uniform=True, tol=AdaptiveOptions.tol)
    levels = adaptive(problem, uniform, metrics=metrics, path=path)
    write_levels(levels, history, folder, vtu=False, save_state=False, say=say)
    if no_figures:
        return
    say("drawing adaptive against uniform refinement ...")
    histories = {"adaptive": out / "history.csv", "uniform": uni / "history.csv"}
    degree = element_of(options.element).degree
    drawn = {"title": problem.name, "reference_slope": optimal_slope(degree, problem.mesh.dim)}
    written = plots.plot_adaptive_vs_uniform(
        histories, out / "adaptive_vs_uniform", key="eta", **drawn
    )
    if problem.exact is not None:
        written += plots.plot_adaptive_vs_uniform(
            histories, out / "adaptive_vs_uniform_error", key="error_energy", **drawn
        )
    folder.add_files(*(str(Path(p).relative_to(out)) for p in written))
    say(f"figures: {', '.join(str(p.name) for p in written)}")
