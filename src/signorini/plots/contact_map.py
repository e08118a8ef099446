"""The contact pressure over Γ_C in three dimensions as a map (docs/method.md, *Three
dimensions: contact on faces*, "What a 3D contact run shows").

The contact parts' P2 faces are projected onto the plane normal to the mean direction ``n``
of the rows in contact (Γ_C's tangent plane at the contact zone; for a plane Γ_C the plane
itself), each face split into the four triangles of its six nodes. On them the recovered
pressure is drawn as it is defined, linear between the nodes (its value at a midpoint is
the mean of its edge's ends); the contact zone's boundary is the 0.5-level of the active
flag interpolated the same way, and the faces' straight edges are drawn thin. The window
is the contact zone with a margin (the whole surface when nothing is in contact); only the
faces turned towards the obstacle (outward normal along ``n``) are drawn, so that a curved
part does not fold over itself in the projection.
"""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib as mpl
import numpy as np
from matplotlib.lines import Line2D
from matplotlib.tri import Triangulation
from numpy.typing import ArrayLike

from .style import RC, fit_title, new_figure, save_figure

__all__ = ["SUB_TRIANGLES", "contact_window", "plane_axes", "plot_contact_map"]

#: The four triangles of a six-node face (vertices 0, 1, 2, midpoints 3 = 01, 4 = 12, 5 = 20),
#: each in the face's orientation.
SUB_TRIANGLES = np.array([[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]])
#: The window's margin around the contact zone, a fraction of the zone's larger extent.
MARGIN = 0.6
#: A direction within this (max-norm) of a coordinate axis is that axis (labels x, y, z).
AXIS_TOL = 1e-9
#: The opacity of the faces' edges (black).
MESH_ALPHA = 0.5
#: The colour of the contact zone's boundary.
ZONE_COLOUR = "#d62728"


def plane_axes(normal: ArrayLike) -> tuple[np.ndarray, list[str]]:
    """``(2, 3)`` orthonormal axes of the plane normal to ``normal (3,)`` and their labels:
    the two other coordinate axes (in increasing order, ``x``, ``y``, ``z``) when ``normal``
    is a coordinate axis, else ``s₁`` along the coordinate axis least aligned with
    ``normal`` (projected onto the plane) and ``s₂ = n × s₁``."""
    n = np.asarray(normal, dtype=np.float64)
    n = n / np.linalg.norm(n)
    k = int(np.argmax(np.abs(n)))
    if np.abs(np.abs(n) - np.eye(3)[k]).max() <= AXIS_TOL:
        keep = [i for i in range(3) if i != k]
        return np.eye(3)[keep], [f"${'xyz'[i]}$" for i in keep]
    a = np.eye(3)[int(np.argmin(np.abs(n)))]
    s1 = a - (a @ n) * n
    s1 /= np.linalg.norm(s1)
    return np.stack([s1, np.cross(n, s1)]), [r"$s_1$", r"$s_2$"]


def contact_window(uv: np.ndarray, active: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The drawn window ``(low (2,), high (2,))``: the box of the active points of ``uv (m,
    2)`` widened by :data:`MARGIN` of its larger side, within the box of all points (all of
    it when none is active)."""
    low_all, high_all = uv.min(axis=0), uv.max(axis=0)
    if not active.any():
        return low_all, high_all
    low, high = uv[active].min(axis=0), uv[active].max(axis=0)
    pad = MARGIN * max(float((high - low).max()), 1e-3 * float((high_all - low_all).max()))
    return np.maximum(low - pad, low_all), np.minimum(high + pad, high_all)


def plot_contact_map(
    points: ArrayLike,
    faces: ArrayLike,
    pressure: ArrayLike,
    active: ArrayLike,
    normal: ArrayLike,
    path: str | os.PathLike,
    title: str | None = None,
) -> list[Path]:
    """The recovered contact pressure over Γ_C as a map, with the contact zone's boundary and
    the mesh on the contact surface.

    Parameters
    ----------
    points : (m, 3) float array
        The P2 nodes of the contact faces.
    faces : (f, 6) int array
        Each contact face's nodes (rows of ``points``): three vertices in outward order,
        then the midpoints of ab, bc, ca.
    pressure : (m,) float array
        The recovered pressure at the nodes (stress units, those of E).
    active : (m,) bool array
        The nodes in contact.
    normal : (m, 3) float array
        Each node's constraint direction ``n_z`` (0 at a node without a row); the mean over
        the active nodes (over all without contact) is the projection's normal.
    path : str or os.PathLike
        Output path without extension (``.png`` and ``.pdf`` are written).
    title : str, optional
        The first line of the title (the problem's name).

    Returns
    -------
    list of pathlib.Path
        The files written.

    Raises
    ------
    ValueError
        If the arrays' shapes do not agree, or no face is turned towards the obstacle.
    """
    x = np.asarray(points, dtype=np.float64)
    tri6 = np.asarray(faces, dtype=np.int64)
    p = np.asarray(pressure, dtype=np.float64)
    on = np.asarray(active, dtype=bool)
    n_z = np.asarray(normal, dtype=np.float64)
    m = x.shape[0]
    if x.shape != (m, 3) or tri6.ndim != 2 or tri6.shape[1] != 6 or n_z.shape != (m, 3):
        raise ValueError(
            f"points (m, 3), faces (f, 6) and normal (m, 3) expected, got {x.shape}, "
            f"{tri6.shape}, {n_z.shape}"
        )
    if p.shape != (m,) or on.shape != (m,):
        raise ValueError(f"pressure and active must have shape ({m},), got {p.shape}, {on.shape}")
    mean = n_z[on].sum(axis=0) if on.any() else n_z.sum(axis=0)
    axes, labels = plane_axes(mean)
    n = mean / np.linalg.norm(mean)
    corners = x[tri6[:, :3]]
    outward = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    shown = tri6[outward @ n > 0]
    if shown.shape[0] == 0:
        raise ValueError("no contact face is turned towards the obstacle (along n)")
    uv = x @ axes.T
    low, high = contact_window(uv, on)
    inside = ((uv[shown] >= low) & (uv[shown] <= high)).all(axis=2).any(axis=1)
    shown = shown[inside]
    sub = Triangulation(uv[:, 0], uv[:, 1], shown[:, SUB_TRIANGLES].reshape(-1, 3))
    edges = Triangulation(uv[:, 0], uv[:, 1], shown[:, :3])
    with mpl.rc_context(RC):
        fig = new_figure(4.2, 3.7)
        ax = fig.add_subplot()
        image = ax.tripcolor(sub, p, shading="gouraud", cmap="viridis", rasterized=True)
        ax.triplot(edges, color="k", linewidth=0.3, alpha=MESH_ALPHA)
        if on.any() and not on[shown].all():
            ax.tricontour(sub, on.astype(np.float64), levels=[0.5], colors=ZONE_COLOUR,
                          linewidths=1.2)  # fmt: skip
        ax.set(xlim=(low[0], high[0]), ylim=(low[1], high[1]), aspect="equal")
        ax.set_xlabel(labels[0])
        ax.set_ylabel(labels[1])
        fig.colorbar(image, ax=ax, shrink=0.85, label=r"recovered pressure $p_h$ (units of $E$)")
        handles = [
            Line2D([], [], color=ZONE_COLOUR, linewidth=1.2, label="contact zone boundary"),
            Line2D([], [], color="k", alpha=MESH_ALPHA, linewidth=0.5, label=r"mesh of $\Gamma_C$"),
        ]
        fig.legend(handles=handles, loc="outside lower center", ncols=2, fontsize=6)
        where = _plane_note(axes, labels)
        head = f"{title}: " if title else ""
        ax.set_title(fit_title(f"{head}contact pressure over $\\Gamma_C${where}", fig))
        return save_figure(fig, path)


def _plane_note(axes: np.ndarray, labels: list[str]) -> str:
    """The title's line of the projection plane's axes, e.g. ``s₁ = (0.71, 0, 0.71)``: the
    components to two decimals (a component below 0.005 shown as 0), on a line of its own
    (mathtext is not wrapped)."""
    if labels[0] != r"$s_1$":
        return ""
    parts = [
        f"{label} = ({', '.join(f'{v:.2f}'.rstrip('0').rstrip('.') for v in a + 0.0)})"
        for label, a in zip(labels, np.where(np.abs(axes) < 5e-3, 0.0, axes), strict=True)
    ]
    return "\n" + ", ".join(parts)
