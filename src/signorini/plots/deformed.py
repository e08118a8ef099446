"""The deformed body coloured by ``|u_h|``, and the contact pressure along ``Γ_C``."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import matplotlib as mpl
import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.tri import Triangulation
from numpy.typing import ArrayLike

from ..mesh.mesh import boundary_edges
from .mesh import line_width, mesh_arrays
from .style import RC, STYLES, new_figure, save_figure

__all__ = ["plot_deformed", "contact_coordinate"]


def _vertex_displacement(displacement: ArrayLike, n_points: int) -> np.ndarray:
    """(n_points, 2) vertex displacement from ``(m, 2)`` or interleaved ``(2 m,)``, m >= n."""
    u = np.asarray(displacement, dtype=np.float64)
    if u.ndim == 1 and u.size % 2 == 0:
        u = u.reshape(-1, 2)
    if u.ndim != 2 or u.shape[1] != 2 or u.shape[0] < n_points:
        raise ValueError(
            f"displacement must have shape (m, 2) or (2 m,) with m >= n_points = "
            f"{n_points}, got {np.shape(displacement)}"
        )
    return u[:n_points]


def contact_coordinate(cp: np.ndarray) -> tuple[np.ndarray, str]:
    """Abscissa along the contact boundary and its axis label.

    Parameters
    ----------
    cp : (k, 2) float array
        Points on the contact boundary, in any order.

    Returns
    -------
    t : (k,) float array
        ``x`` or ``y`` for an axis-parallel boundary, else the arclength ``s`` along the
        points' principal direction (starting at 0, increasing with the direction's largest
        component).
    label : str
        ``"$x$"``, ``"$y$"`` or ``"$s$ (along $\\Gamma_C$)"``.
    """
    span = np.ptp(cp, axis=0)
    tol = 1e-12 * max(float(span.max()), 1.0)
    if span[1] <= tol:
        return cp[:, 0], r"$x$"
    if span[0] <= tol:
        return cp[:, 1], r"$y$"
    centred = cp - cp.mean(axis=0)
    direction = np.linalg.svd(centred, full_matrices=False)[2][0]
    if direction[np.argmax(np.abs(direction))] < 0:
        direction = -direction
    t = centred @ direction
    return t - t.min(), r"$s$ (along $\Gamma_C$)"


def _draw_body(
    fig: Any,
    ax: Any,
    p: np.ndarray,
    c: np.ndarray,
    u: np.ndarray,
    scale: float,
    obstacle: np.ndarray | None,
    show_mesh: bool,
) -> None:
    """The body at ``p + scale u`` coloured by ``|u|``, its reference boundary dashed."""
    big = c.shape[0] > 20000
    q = p + scale * u
    tri = Triangulation(q[:, 0], q[:, 1], c)
    image = ax.tripcolor(
        tri, np.hypot(u[:, 0], u[:, 1]), shading="gouraud", cmap="viridis", rasterized=big
    )
    if show_mesh:
        ax.triplot(
            tri, color="white", alpha=0.35, linewidth=0.5 * line_width(c.shape[0]), rasterized=big
        )
    ax.add_collection(
        LineCollection(
            p[boundary_edges(c)],
            colors="0.4",
            linewidths=0.8,
            linestyles="--",
            label="reference",
            zorder=2,
        )
    )
    if obstacle is not None:
        st = STYLES["obstacle"]
        ax.plot(
            obstacle[:, 0],
            obstacle[:, 1],
            color=st["color"],
            linewidth=2.0,
            label=st["label"],
            zorder=5,
        )
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_xlabel(r"$x$")
    ax.set_ylabel(r"$y$")
    cax = ax.inset_axes((1.04, 0.0, 0.05, 1.0))  # follows the equal-aspect box
    fig.colorbar(image, cax=cax, label=r"$|u_h|$")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncols=2, frameon=False)


def _draw_pressure(ax: Any, contact_points: np.ndarray, pressure: np.ndarray) -> None:
    """The pressure against the coordinate along the contact boundary."""
    t, tlabel = contact_coordinate(contact_points)
    order = np.argsort(t, kind="stable")
    st = STYLES["pressure"]
    ax.plot(
        t[order],
        pressure[order],
        color=st["color"],
        marker=st["marker"] if t.size <= 80 else "",
        markersize=2.5,
        label=st["label"],
    )
    ax.axhline(0.0, color="0.5", linewidth=0.6)
    ax.grid(True, linestyle="-")
    ax.set_xlabel(tlabel)
    ax.set_ylabel(r"contact pressure $p_h$")


def plot_deformed(
    points: ArrayLike,
    cells: ArrayLike,
    displacement: ArrayLike,
    path: str | os.PathLike,
    contact_points: ArrayLike | None = None,
    pressure: ArrayLike | None = None,
    scale: float = 1.0,
    obstacle: ArrayLike | None = None,
    title: str | None = None,
    show_mesh: bool = True,
) -> list[Path]:
    """The deformed body coloured by ``|u_h|``, and the contact pressure along ``Γ_C``.

    The body is drawn at ``points + scale * displacement`` (vertices only; the P2 solution is
    drawn piecewise linearly), coloured by the unscaled ``|u_h|`` with Gouraud shading; the
    reference configuration's boundary is dashed. When ``pressure`` is given, a second axes
    below shows it against the coordinate along the contact boundary
    (:func:`contact_coordinate`).

    Parameters
    ----------
    points : (n_points, 2) float array
        Vertex coordinates of the reference configuration.
    cells : (n_cells, 3) int array
        Triangles.
    displacement : (m, 2) float array, or (2 m,) interleaved, m >= n_points
        Displacement; only the first ``n_points`` rows are used, so the P2 nodal
        displacement (vertices first) can be passed as is.
    path : str or os.PathLike
        Output path without extension.
    contact_points : (k, 2) float array, optional
        Reference coordinates of the contact nodes (needed with ``pressure``).
    pressure : (k,) float array, optional
        Contact pressure at ``contact_points`` (e.g. ``p_z`` of docs/method.md, *Discrete
        problem*).
    scale : float, default 1.0
        Magnification of the displacement in the drawing.
    obstacle : (j, 2) float array, optional
        Polyline of the obstacle in physical coordinates, drawn on the body's axes.
    title : str, optional
        Title of the body's axes.
    show_mesh : bool, default True
        Draw the deformed triangulation with faint lines.

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.
    """
    p, c = mesh_arrays(points, cells)
    u = _vertex_displacement(displacement, p.shape[0])
    scale = float(scale)
    if (contact_points is None) != (pressure is None):
        raise ValueError("contact_points and pressure must be given together")
    if pressure is not None:
        cp = np.asarray(contact_points, dtype=np.float64).reshape(-1, 2)
        pr = np.asarray(pressure, dtype=np.float64)
        if pr.shape != (cp.shape[0],):
            raise ValueError(
                f"pressure must have shape ({cp.shape[0]},) to match contact_points, got {pr.shape}"
            )
    obs = None if obstacle is None else np.asarray(obstacle, dtype=np.float64).reshape(-1, 2)
    with mpl.rc_context(RC):
        if pressure is None:
            fig = new_figure(height=3.0)
            ax = fig.add_subplot()
        else:
            fig = new_figure(height=4.8)
            ax, axp = fig.subplots(2, 1, gridspec_kw={"height_ratios": [2.4, 1.0]})
        _draw_body(fig, ax, p, c, u, scale, obs, show_mesh)
        magnified = f" (displacement \u00d7{scale:g})" if scale != 1.0 else ""
        ax.set_title(title if title else "deformed body" + magnified)
        if pressure is not None:
            _draw_pressure(axp, cp, pr)
        return save_figure(fig, path)
