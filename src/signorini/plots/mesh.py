"""Fig. 6.3(b): a triangulation with chosen boundary edges highlighted.

Takes plain arrays (``points``, ``cells``, vertex pairs), not a :class:`~signorini.mesh.Mesh`,
so a mesh can be drawn from files; only the array shapes a drawing needs are checked here
(the mesh layer owns the geometric checks).
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import matplotlib as mpl
import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.tri import Triangulation
from numpy.typing import ArrayLike

from .style import RC, SINGLE_COLUMN, new_figure, save_figure

__all__ = ["plot_mesh", "mesh_arrays", "line_width"]

_HIGHLIGHT_COLORS = ("#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd")


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
        Vertex pairs of edges drawn thick (e.g. the contact boundary, in red); a mapping
        draws several groups, each labelled with its key.
    highlight_label : str
        Legend label of ``highlight`` when it is a single array.

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
        fig = new_figure(height=SINGLE_COLUMN)
        ax = fig.add_subplot()
        ax.triplot(
            Triangulation(p[:, 0], p[:, 1], c),
            color="0.15",
            linewidth=line_width(c.shape[0]),
            rasterized=big,
        )
        for i, (label, e) in enumerate(groups.items()):
            if e.shape[0] == 0:
                continue
            color = _HIGHLIGHT_COLORS[i % len(_HIGHLIGHT_COLORS)]
            ax.add_collection(
                LineCollection(
                    p[e], colors=color, linewidths=2.0, label=label, zorder=4, capstyle="round"
                )
            )
        ax.set_aspect("equal")
        ax.set_xlabel(r"$x$")
        ax.set_ylabel(r"$y$")
        ax.autoscale_view()
        if any(e.shape[0] for e in groups.values()):
            fig.legend(loc="outside lower center", ncols=min(len(groups), 3))
        if title:
            ax.set_title(title)
        return save_figure(fig, path)
