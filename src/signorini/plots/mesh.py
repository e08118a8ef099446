"""Fig. 6.3(b): a triangulation with chosen boundary edges highlighted.

Takes plain arrays (``points``, ``cells``, vertex pairs), not a :class:`~signorini.mesh.Mesh`,
so a mesh can be drawn from files; only the array shapes a drawing needs are checked here
(the mesh layer owns the geometric checks).

A fine adaptive mesh (tens of thousands of cells) prints as a grey blotch; the paper shows a
level of a few thousand cells. :func:`readable_level` picks such a level of a run,
:func:`read_level_mesh` reads its triangulation back from the run's ``level_NNN.vtu``, and
:func:`boundary_groups` finds which of its boundary edges lie on Γ_D, Γ_N and Γ_C.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib as mpl
import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.patches import Rectangle
from matplotlib.tri import Triangulation
from numpy.typing import ArrayLike

from ..mesh.topology import boundary_facets
from .style import RC, fit_title, new_figure, save_figure, trim_height

__all__ = [
    "plot_mesh",
    "mesh_arrays",
    "line_width",
    "readable_level",
    "read_level_mesh",
    "boundary_groups",
    "READABLE_CELLS",
]

_HIGHLIGHT_COLORS = ("#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd")

#: The most cells a mesh figure of one column shows legibly (the paper's Fig. 6.3(b) has a
#: few thousand).
READABLE_CELLS = 3000


def readable_level(n_cells: ArrayLike, most: int = READABLE_CELLS) -> int:
    """Index of the finest level with at most ``most`` cells (the first level if none has).

    Parameters
    ----------
    n_cells : (n_levels,) array_like of int
        Cells of each level, e.g. the history's ``n_cells`` column.
    """
    n = np.asarray(n_cells, dtype=np.float64).reshape(-1)
    if n.size == 0:
        raise ValueError("n_cells is empty: the run has no level")
    ok = np.flatnonzero(np.isfinite(n) & (n <= most))
    return int(ok[-1]) if ok.size else 0


def read_level_mesh(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray]:
    """Vertex ``points (n_points, 2)`` and ``cells (n_cells, 3)`` of a run's level VTU file.

    The file holds the P2 nodes (vertices first, then edge midpoints) and ``triangle6``
    cells (3 vertices, then 3 midpoints), or for a P1 run the vertices and ``triangle``
    cells, as :func:`~signorini.output.write_vtu` writes them; the triangulation is the
    first three columns and the vertices they number.

    Raises
    ------
    ValueError
        Naming the file, if it is unreadable (truncated, or not a VTU file: ``meshio.read``
        would end the process with ``sys.exit``, so the VTU reader is called itself) or not
        a level file of a run.
    """
    import meshio

    try:
        m = meshio.vtu.read(os.fspath(path))
    except Exception as exc:
        detail = f"{type(exc).__name__}: {exc}" if str(exc) else type(exc).__name__
        raise ValueError(
            f"{path} is not a readable level file of a run ({detail}; truncated, or not a VTU "
            "file signorini wrote)"
        ) from None
    blocks = [b.data for b in m.cells if b.type in ("triangle6", "triangle")]
    if len(blocks) != 1:
        raise ValueError(
            f"{path} holds no single triangle6 (or triangle) block: not a level file of a run"
        )
    cells = np.asarray(blocks[0][:, :3], dtype=np.int64)
    n_points = int(cells.max()) + 1
    if np.unique(cells).size != n_points:
        raise ValueError(f"{path}: the cells' vertices are not the first nodes")
    return np.asarray(m.points[:n_points, :2], dtype=np.float64), cells


def boundary_groups(
    points: ArrayLike,
    cells: ArrayLike,
    segments: Mapping[str, ArrayLike],
    tol: float = 1e-9,
) -> dict[str, np.ndarray]:
    """The boundary edges of a triangulation that lie on given segments, by group.

    A boundary edge belongs to the first group one of whose segments contains its midpoint
    (distance below ``tol`` times the mesh's size). Use the edges of a coarser mesh of the
    same refinement history (e.g. the initial mesh's parts): refinement splits boundary
    edges, so every edge of a finer mesh lies on one of them.

    Parameters
    ----------
    points : (n_points, 2) float array
    cells : (n_cells, 3) int array
    segments : mapping of str to (k, 2, 2) float array
        Group name -> end points of its segments.

    Returns
    -------
    dict of str to (m, 2) int array
        Group name -> vertex pairs of the boundary edges on it (the keys of ``segments``).
    """
    p, c = mesh_arrays(points, cells)
    edges = boundary_facets(c)
    mid = p[edges].mean(axis=1)  # (m, 2)
    size = float(np.ptp(p, axis=0).max()) if p.size else 1.0
    free = np.ones(edges.shape[0], dtype=bool)
    out = {}
    for name, seg in segments.items():
        seg = np.asarray(seg, dtype=np.float64).reshape(-1, 2, 2)
        if seg.shape[0] == 0:
            out[str(name)] = np.zeros((0, 2), dtype=np.int64)
            continue
        a, d = seg[:, 0], seg[:, 1] - seg[:, 0]  # (k, 2)
        rel = mid[:, None, :] - a[None, :, :]  # (m, k, 2)
        t = np.clip(np.einsum("mkj,kj->mk", rel, d) / np.einsum("kj,kj->k", d, d), 0.0, 1.0)
        dist = np.linalg.norm(rel - t[..., None] * d[None], axis=2).min(axis=1)
        on = free & (dist <= tol * size)
        out[str(name)] = edges[on]
        free &= ~on
    return out


def _integer_rows(a: ArrayLike, width: int, what: str) -> np.ndarray:
    """``a`` as an int64 ``(k, width)`` array; a ValueError naming ``what`` otherwise."""
    a = np.asarray(a)
    if a.size == 0:
        return np.zeros((0, width), dtype=np.int64)
    if a.ndim != 2 or a.shape[1] != width or not np.issubdtype(a.dtype, np.integer):
        raise ValueError(
            f"{what} must be an integer (k, {width}) array, got shape {a.shape} and dtype {a.dtype}"
        )
    return a.astype(np.int64)


def mesh_arrays(points: ArrayLike, cells: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """``points`` as float ``(n_points, 2)`` and ``cells`` as int64 ``(n_cells, 3)``.

    Raises
    ------
    ValueError
        For other shapes or non-integer cells (matplotlib's ``Triangulation`` rejects cells
        naming a vertex outside ``points``).
    """
    p = np.asarray(points, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 2:
        raise ValueError(f"points must have shape (n_points, 2), got {p.shape}")
    return p, _integer_rows(cells, 3, "cells")


def line_width(n_cells: int) -> float:
    """Mesh line width in points: thinner as the mesh gets finer."""
    return float(np.clip(0.8 * np.sqrt(400.0 / max(n_cells, 1)), 0.1, 0.8))


def plot_mesh(
    points: ArrayLike,
    cells: ArrayLike,
    path: str | os.PathLike,
    title: str | None = None,
    highlight: ArrayLike | Mapping[str, ArrayLike] | None = None,
    highlight_label: str = r"contact boundary $\Gamma_C$",
    colors: Sequence[str] = _HIGHLIGHT_COLORS,
    zoom: tuple[float, float, float] | None = None,
    zoom_title: str = "zoom",
) -> list[Path]:
    """Fig. 6.3(b): a triangulation, thin lines, equal aspect, with boundary edges highlighted.

    Parameters
    ----------
    points : (n_points, 2) float array
        Vertex coordinates.
    cells : (n_cells, 3) int array
        Triangles.
    path : str or os.PathLike
        Output path without extension.
    title : str, optional
        Axes title.
    highlight : (k, 2) int array or mapping of str to (k, 2) int array, optional
        Vertex pairs of edges drawn in colour over the mesh (e.g. the contact boundary, in
        red); a mapping draws several groups, each labelled with its key (empty groups are
        left out).
    highlight_label : str
        Legend label of ``highlight`` when it is a single array.
    colors : sequence of str
        Colours of the highlighted groups, in order (repeated if there are more groups).
    zoom : (x, y, half_width), optional
        A second panel below shows the square window of this centre and half width (e.g.
        around a free-boundary end, :func:`~signorini.plots.contact_line.free_boundary_ends`);
        the window is outlined on the whole mesh.
    zoom_title : str
        Title of the zoom panel.

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.
    """
    p, c = mesh_arrays(points, cells)
    if highlight is None:
        highlight = {}
    elif not isinstance(highlight, Mapping):
        highlight = {highlight_label: highlight}
    groups = {str(k): _integer_rows(v, 2, f"highlight[{k!r}]") for k, v in highlight.items()}
    big = c.shape[0] > 20000
    with mpl.rc_context(RC):
        span = np.ptp(p, axis=0) if p.size else np.ones(2)
        aspect = float(span[1] / max(span[0], 1e-300))
        # the equal-aspect box is ~3 in wide; the height follows, plus title, labels, legend
        body = float(np.clip(2.9 * aspect, 0.8, 3.0))
        if zoom is None:
            fig = new_figure(height=body + 1.1)
            ax, axz = fig.add_subplot(), None
        else:
            fig = new_figure(height=body + 1.1 + 2.1)
            ax, axz = fig.subplots(2, 1, gridspec_kw={"height_ratios": [body + 0.5, 1.9]})
        tri = Triangulation(p[:, 0], p[:, 1], c)
        for a, width, labelled in ((ax, line_width(c.shape[0]), True), (axz, 0.5, False)):
            if a is None:
                continue
            a.triplot(tri, color="0.15", linewidth=width, rasterized=big)
            for i, (label, e) in enumerate(groups.items()):
                if e.shape[0] == 0:
                    continue
                a.add_collection(
                    LineCollection(  # thin: the refinement along the boundary stays visible
                        p[e],
                        colors=colors[i % len(colors)],
                        linewidths=1.1 if labelled else 1.6,
                        label=label if labelled else "_" + label,
                        zorder=4,
                        capstyle="butt",
                    )
                )
            a.set_aspect("equal")
            a.set_xlabel(r"$x$")
            a.set_ylabel(r"$y$")
        ax.autoscale_view()
        if axz is not None:
            x, y, half = (float(v) for v in zoom)
            if not (np.isfinite([x, y, half]).all() and half > 0):
                raise ValueError(f"zoom must be (x, y, half_width > 0), got {zoom}")
            axz.set_xlim(x - half, x + half)
            axz.set_ylim(y - half, y + half)
            axz.set_title(fit_title(zoom_title, fig))
            ax.add_patch(
                Rectangle((x - half, y - half), 2 * half, 2 * half, fill=False, lw=0.9, zorder=5)
            )
        if any(e.shape[0] for e in groups.values()):
            shown = sum(1 for e in groups.values() if e.shape[0])
            fig.legend(loc="outside lower center", ncols=min(shown, 3))
        if title:
            ax.set_title(fit_title(title, fig))
        trim_height(fig)
        return save_figure(fig, path)
