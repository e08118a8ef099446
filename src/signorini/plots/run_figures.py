"""The figures of a run folder: the convergence figures from its history, and from its last
level the mesh (with Γ_D, Γ_N, Γ_C marked), the deformed body and, for an example that knows
its pressure, the pressure beside the known one. Called by the command line after a run and
by ``signorini figures``.

The last level comes as plain data: a mapping of arrays (:func:`run_figures` lists its keys;
:func:`signorini.loop.arrays.level_arrays` builds it from a level of the loop), and the known
pressure as a record of arrays (:class:`KnownPressure`).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from .. import plots
from ..mesh.curves import Line
from ..mesh.mesh import Mesh
from ..output import read_history
from .body3d import plot_body_3d, render_body_3d
from .contact_line import free_boundary_ends
from .contact_map import plot_contact_map
from .mesh import boundary_groups
from .slip_map import plot_slip_map

__all__ = [
    "KnownPressure",
    "body_figures",
    "mesh_title",
    "part_segments",
    "pressure_figure",
    "run_figures",
]

log = logging.getLogger(__name__)

#: How the figure of the mesh labels the parts of each kind (``last["parts"]``' keys).
PART_LABELS = {
    "dirichlet": r"Dirichlet $\Gamma_D$",
    "neumann": r"Neumann $\Gamma_N$",
    "contact": r"contact $\Gamma_C$",
}


class KnownPressure(Protocol):
    """A computed contact pressure beside a known one (e.g.
    :class:`signorini.examples.metrics.PressureComparison`)."""

    x: np.ndarray
    pressure: np.ndarray
    x_reference: np.ndarray
    reference: np.ndarray
    label: str
    title: str


def run_figures(
    example: str,
    out: Path,
    last: Mapping[str, Any] | None = None,
    name: str | None = None,
    degree: int | None = None,
    dim: int | None = None,
) -> list[Path]:
    """The run's convergence figures; with its last level also the mesh and the deformed body
    (in 3D the deformed body's boundary faces, :func:`body_figures`).

    The mesh figure shows the finest level of at most ``plots.READABLE_CELLS`` cells (read back
    from its ``level_NNN.vtu``; the last level when that file is missing or holds another
    mesh), with Γ_D, Γ_N and Γ_C marked. The deformed body is drawn with a stated displacement
    scale and the obstacle's gaps magnified by it (the obstacle drawn where the drawn body
    touches it), the pressure per contact part against its arc length;
    with friction its stick and slip nodes marked and the friction stress drawn with the
    pressure.

    Parameters
    ----------
    example : str
        The run's label (file names; titles when no ``name`` is known).
    out : pathlib.Path
        The run folder, with its ``history.csv``.
    last : mapping, optional
        The last level as plain data (:func:`signorini.loop.arrays.level_arrays`):
        ``level`` (int), ``points (n, 2)``, ``cells (m, 3)``, ``displacement (n_nodes, 2)``
        (vertices first), ``initial`` (the problem's initial :class:`~signorini.mesh.Mesh`,
        whose parts refinement splits), ``parts`` (part names by kind: ``"dirichlet"``,
        ``"neumann"``, ``"contact"``), and per contact node ``contact_points (k, 2)``,
        ``active (k,)``, ``pressure (k,)``, ``gap (k,)``, ``normal (k, 2)``, ``obstacle`` (part
        name -> the obstacle's outline at true scale), ``obstacle_offset`` (part name -> the
        gap vector of each outline point; without it the obstacle is drawn at true scale)
        and ``along`` (part name -> rows and arc length); with friction also ``state (k,)`` (labels,
        :data:`~signorini.plots.deformed.NODE_STATES`),
        ``contact_displacement (k, 2)`` and ``tangential_pressure (k,)``; ``name``, the
        problem's name.
    name : str, optional
        The problem's name (:attr:`ContactProblem.name
        <signorini.problem.problem.ContactProblem.name>`), which every figure's title begins
        with; default ``last["name"]``, else ``example``.
    degree : {2, 1}, optional
        The degree of the run's element, whose optimal rate the reference triangles show;
        default ``last["degree"]``, else 2 (P2).
    dim : {2, 3}, optional
        The mesh's dimension; default ``last["dim"]``, else 2. A 3D level (the arrays of
        :func:`signorini.loop.arrays.body_arrays`) gets its convergence history and the
        picture of its body; with contact also its plane obstacles and the pressure map
        over Γ_C (:func:`body_figures`).
    """
    known = {} if last is None else last
    name = str(known.get("name", example)) if name is None else name
    degree = int(known.get("degree", 2)) if degree is None else degree
    dim = int(known.get("dim", 2)) if dim is None else dim
    drawn = {"title": name, "degree": degree, "dim": dim}
    written = list(plots.make_figures(out / "history.csv", out, example, **drawn))
    if last is None:
        return written
    if dim == 3:
        return written + body_figures(example, out, last, name)
    # the level the mesh figure shows
    history = read_history(out / "history.csv")
    k = plots.readable_level(history["n_cells"])
    level, points, cells = last["level"], last["points"], last["cells"]
    if k != level and (out / f"level_{k:03d}.vtu").is_file():
        p, c = plots.read_level_mesh(out / f"level_{k:03d}.vtu")
        if c.shape[0] == int(history["n_cells"][k]):
            level, points, cells = k, p, c
    initial = last["initial"]
    segments = {
        label: np.concatenate(
            [part_segments(initial, n, points, cells) for n in last["parts"][kind]]
            or [np.zeros((0, 2, 2))]
        )
        for kind, label in PART_LABELS.items()
    }
    # a zoom on the first end of the contact zone, if it ends inside Γ_C
    ends = free_boundary_ends(last["contact_points"], last["active"])
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
        title=mesh_title(name, level, cells.shape[0], last["level"]),
        highlight=plots.boundary_groups(points, cells, segments),
        colors=("#1f77b4", "#2ca02c", "#d62728"),
        **zoom,
    )
    # with friction: stick and slip nodes marked, the friction stress drawn
    friction = {
        key: last[key]
        for key in ("state", "contact_displacement", "tangential_pressure")
        if key in last
    }
    written += plots.plot_deformed(
        last["points"],
        last["cells"],
        last["displacement"][: last["points"].shape[0]],
        out / "deformed",
        plots.ContactDrawing(
            last["contact_points"], last["pressure"], along=last["along"], **friction
        ),
        obstacle=_joined(last["obstacle"].values()),
        # the obstacle where the drawn body touches it: its gaps magnified with the body
        obstacle_offset=_joined(last["obstacle_offset"].values())
        if "obstacle_offset" in last
        else None,
        title=f"{name}: deformed bod{'ies' if last.get('pairs') else 'y'}",
        # bodies in contact pressed together overlap in a magnified drawing
        scale=1.0 if last.get("pairs") else "auto",
    )
    return written


def body_figures(example: str, out: Path, last: Mapping[str, Any], name: str) -> list[Path]:
    """The picture of a 3D level's body (``<example>_body``,
    :func:`~.body3d.plot_body_3d`) and, with PyVista installed (the ``[3d]`` extra), its
    off-screen rendering (``<example>_body_pyvista.png``); without it one line in the log.
    ``last`` holds ``points (n, 3)``, ``faces (k, 3)``, ``displacement (n, 3)`` and ``stress
    (n, 3, 3)`` at the vertices (:func:`signorini.loop.arrays.body_arrays`); with contact
    ``contact`` (:func:`signorini.loop.arrays3d.surface_arrays`): then the body is drawn with
    its plane obstacles, and the pressure over Γ_C as a map (``<example>_contact_pressure``,
    :func:`~.contact_map.plot_contact_map`)."""
    body = (last["points"], last["faces"], last["displacement"], last["stress"])
    surface = last.get("contact")
    drawn = {}
    if surface is not None:
        on = surface["active"]
        drawn = {
            "planes": surface["planes"],
            "touching": (surface["points"][on], surface["displacement"][on]),
        }
    written = plot_body_3d(*body, out / f"{example}_body", title=name, **drawn)
    if surface is not None:
        written += plot_contact_map(
            surface["points"],
            surface["faces"],
            surface["recovered_pressure"],
            surface["active"],
            surface["normal"],
            out / f"{example}_contact_pressure",
            title=name,
        )
    if surface is not None and "state" in surface:
        history = read_history(out / "history.csv") if (out / "history.csv").is_file() else {}
        circles = None
        if "c_over_a_theory" in history and "a" in history:
            a = float(history["a"][-1])
            theory = float(history["c_over_a_theory"][-1])
            circles = {f"Mindlin's stick radius c = {theory * a:.3g}": theory * a,
                       f"contact radius a = {a:.3g}": a}  # fmt: skip
        written += plot_slip_map(
            surface["points"],
            surface["faces"],
            surface["state"],
            surface["slip_direction"],
            surface["normal"],
            out / f"{example}_slip_map",
            title=name,
            circles=circles,
        )[0]
    rendered, note = render_body_3d(*body, out / f"{example}_body_pyvista", **drawn)
    if note:
        log.info(note)
    return written + rendered


def mesh_title(example: str, level: int, n_cells: int, last_level: int) -> str:
    """The mesh figure's title: its level, and when that is not the run's last one, which is
    (the finest mesh is shown only up to ``plots.READABLE_CELLS`` cells)."""
    head = f"{example}: mesh, level {level}, {n_cells} cells"
    if level == last_level:
        return head + " (last level)"
    return head + f"\n(an earlier level, readable; the run ends at level {last_level})"


def _joined(lines) -> np.ndarray | None:
    """Polylines ``(j, 2)`` joined into one, a NaN row between them (None if there are none)."""
    lines = [np.vstack([line, np.full((1, 2), np.nan)]) for line in lines if len(line)]
    return np.vstack(lines) if lines else None


def part_segments(initial: Mesh, part: str, points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """``(k, 2, 2)`` segments that hold the boundary edges of ``part`` in the drawn mesh
    ``(points, cells)``: the part's edges in the initial mesh, which refinement splits; for a
    part carrying a curve (whose new points lie on the curve, off the initial chords) the
    drawn mesh's own boundary edges with both ends on the curve, near the part's initial
    chords (within their largest distance from the curve)."""
    chords = initial.points[initial.facets[initial.part_facets(part)]]
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


def pressure_figure(example: str, out: Path, known: KnownPressure) -> list[Path]:
    """The last level's pressure beside the known one (``<example>_pressure``; e.g. Hertz's
    for ``hertz``), as an example's metrics give it
    (:attr:`Metrics.pressure <signorini.examples.Metrics.pressure>` of the last level); with
    friction also the friction stress beside a known one, the stick and slip nodes marked,
    zoomed on the contact zone (``partial-slip``: Cattaneo–Mindlin's)."""
    return plots.plot_pressure_comparison(
        known.x,
        known.pressure,
        known.x_reference,
        known.reference,
        out / f"{example}_pressure",
        label=known.label,
        title=known.title,
        friction=None
        if getattr(known, "tangential", None) is None
        else plots.FrictionCurves(
            known.tangential, known.tangential_reference, known.tangential_label, known.state
        ),
        window=getattr(known, "window", None),
        xlabel=getattr(known, "xlabel", r"$x$"),
        joined=getattr(known, "joined", False),
    )
