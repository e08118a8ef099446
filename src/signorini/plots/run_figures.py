"""The figures of a run folder: the convergence figures from its history, and from its last
level the mesh (with Γ_D, Γ_N, Γ_C marked), the deformed body and, for an example that knows
its pressure, the pressure beside the known one. Called by the command line after a run and
by ``signorini figures``."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import plots
from ..examples import Metrics
from ..loop import Level
from ..mesh.curves import Line
from ..mesh.mesh import Mesh
from ..output import read_history
from .deformed import free_boundary_ends
from .mesh import boundary_groups

__all__ = ["part_segments", "pressure_figure", "run_figures"]


def run_figures(example: str, out: Path, last: Level | None = None) -> list[Path]:
    """The run's convergence figures; with its last level also the mesh and the deformed body.

    The mesh figure shows the finest level of at most ``plots.READABLE_CELLS`` cells (read back
    from its ``level_NNN.vtu``; the last level when that file is missing or holds another
    mesh), with Γ_D, Γ_N and Γ_C marked. The deformed body is drawn with a stated displacement
    scale, the obstacle at its gap with the same scale; with friction its stick and slip nodes
    marked and the friction stress drawn with the pressure.
    """
    written = list(plots.make_figures(out / "history.csv", out, example))
    if last is None:
        return written
    res = last.result
    mesh = res.mesh
    # the level the mesh figure shows
    history = read_history(out / "history.csv")
    k = plots.readable_level(history["n_cells"])
    level, points, cells = last.record.level, mesh.points, mesh.cells
    if k != level and (out / f"level_{k:03d}.vtu").is_file():
        p, c = plots.read_level_mesh(out / f"level_{k:03d}.vtu")
        if c.shape[0] == int(history["n_cells"][k]):
            level, points, cells = k, p, c
    problem = res.problem
    initial = problem.mesh
    kinds = {
        r"Dirichlet $\Gamma_D$": problem.dirichlet_parts,
        r"Neumann $\Gamma_N$": problem.neumann_parts,
        r"contact $\Gamma_C$": problem.contact_parts,
    }
    segments = {
        label: np.concatenate(
            [part_segments(initial, n, points, cells) for n in parts] or [np.zeros((0, 2, 2))]
        )
        for label, parts in kinds.items()
    }
    # a zoom on the first end of the contact zone, if it ends inside Γ_C
    cs = res.contact
    ends = free_boundary_ends(res.space.node_points[cs.nodes], res.active)
    zoom = {}
    if len(ends):
        half = 0.06 * float(np.ptp(points, axis=0).max())
        # the window inside the body's bounding box, so it shows mesh, not empty space
        centre = np.clip(ends[0], points.min(axis=0) + 0.9 * half, points.max(axis=0) - 0.9 * half)
        zoom = {"zoom": (*centre, half), "zoom_title": "end of the contact zone"}
    written += plots.plot_mesh(
        points,
        cells,
        out / "mesh",
        title=f"{example}: mesh, level {level}, {cells.shape[0]} cells",
        highlight=plots.boundary_groups(points, cells, segments),
        colors=("#1f77b4", "#2ca02c", "#d62728"),
        **zoom,
    )
    friction = {}
    if cs.has_friction:  # stick and slip nodes marked, the friction stress drawn
        friction = {
            "state": res.state,
            "contact_displacement": res.u[cs.nodes],
            "tangential_pressure": res.tangential_pressure,
        }
    written += plots.plot_deformed(
        mesh.points,
        mesh.cells,
        res.u[: mesh.n_points],
        out / "deformed",
        contact_points=res.space.node_points[cs.nodes],
        pressure=res.pressure,
        gap=cs.gap,
        normal=cs.normal,
        title=f"{example}: deformed body",
        **friction,
    )
    return written


def part_segments(initial: Mesh, part: str, points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """``(k, 2, 2)`` segments that hold the boundary edges of ``part`` in the drawn mesh
    ``(points, cells)``: the part's edges in the initial mesh, which refinement splits; for a
    part carrying a curve (whose new points lie on the curve, off the initial chords) the
    drawn mesh's own boundary edges with both ends on the curve, near the part's initial
    chords (within their largest distance from the curve)."""
    chords = initial.points[initial.edges[initial.part_edges(part)]]
    curve = initial.curves[initial.part_index(part)]
    if curve is None or isinstance(curve, Line):
        return chords
    size = float(np.ptp(points, axis=0).max())

    def off(x: np.ndarray) -> np.ndarray:
        return np.hypot(*(curve.project(x) - x).T)

    bulge = float(off(chords.mean(axis=1)).max()) + 1e-9 * size
    near = boundary_groups(points, cells, {part: chords}, tol=bulge / size)[part]
    on = (off(points[near[:, 0]]) <= 1e-9 * size) & (off(points[near[:, 1]]) <= 1e-9 * size)
    return points[near[on]]


def pressure_figure(example: str, out: Path, last: Level, metrics: Metrics) -> list[Path]:
    """The last level's pressure beside the known one the example's ``metrics`` give
    (``<example>_pressure``; e.g. Hertz's for ``hertz``)."""
    known = metrics.pressure(last.result)
    return plots.plot_pressure_comparison(
        known.x,
        known.pressure,
        known.x_reference,
        known.reference,
        out / f"{example}_pressure",
        label=known.label,
        title=known.title,
    )
