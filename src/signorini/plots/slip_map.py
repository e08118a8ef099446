"""The stick/slip map of Γ_C in three dimensions (docs/method.md, *Friction in three
dimensions: the disc law*): the contact faces projected onto the plane normal to the mean
constraint direction (as :mod:`.contact_map`), their straight edges drawn thin, each node
coloured by its state (free, stick, slip) and an arrow along the slip direction
``Λ_t / ‖Λ_t‖`` at each slipping node; optionally circles about the origin of the plane
(for ``partial-slip-3d``: Mindlin's stick radius c and the contact radius a).
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import matplotlib as mpl
import numpy as np
from matplotlib.tri import Triangulation
from numpy.typing import ArrayLike

from .contact_map import MESH_ALPHA, contact_window, plane_axes
from .style import RC, fit_title, new_figure, save_figure, trim_height

__all__ = ["STATE_COLOURS", "plot_slip_map"]

#: State code (0 free, 1 stick, 2 slip, as ``contact_state`` of the VTU files) -> label, colour.
STATE_COLOURS = {0: ("free", "#bbbbbb"), 1: ("stick", "#1f77b4"), 2: ("slip", "#d62728")}


def plot_slip_map(
    points: ArrayLike,
    faces: ArrayLike,
    state: ArrayLike,
    direction: ArrayLike,
    normal: ArrayLike,
    path: str | os.PathLike,
    title: str | None = None,
    circles: Mapping[str, float] | None = None,
) -> tuple[list[Path], dict[str, np.ndarray]]:
    """The nodes of Γ_C by state and the slip directions, seen along the obstacle's normal.

    Parameters
    ----------
    points : (m, 3) float array
        The P2 nodes of the contact faces.
    faces : (f, 6) int array
        Each contact face's nodes (rows of ``points``), vertices first.
    state : (m,) int array
        0 free, 1 stick, 2 slip at each node.
    direction : (m, 3) float array
        The unit slip direction at each node (Cartesian; used at slip nodes).
    normal : (m, 3) float array
        Each node's constraint direction; their mean over the nodes in contact (state > 0)
        is the projection's normal (:func:`~.contact_map.plane_axes`).
    path : str or os.PathLike
        Output path without extension (``.png`` and ``.pdf``).
    title : str, optional
        The first line of the title.
    circles : mapping, optional
        Label -> radius of a circle about the plane's origin drawn dashed.

    Returns
    -------
    (list of pathlib.Path, dict)
        The files written, and the data drawn: ``uv (m, 2)`` the projected nodes, ``state
        (m,)``, ``slip (s,)`` the slipping nodes' rows and ``arrows (s, 2)`` their directions
        projected onto the plane.

    Raises
    ------
    ValueError
        If the arrays' shapes do not agree.
    """
    x = np.asarray(points, dtype=np.float64)
    tri6 = np.asarray(faces, dtype=np.int64)
    code = np.asarray(state, dtype=np.int64)
    d = np.asarray(direction, dtype=np.float64)
    n_z = np.asarray(normal, dtype=np.float64)
    m = x.shape[0]
    if x.shape != (m, 3) or d.shape != (m, 3) or n_z.shape != (m, 3) or code.shape != (m,):
        raise ValueError(
            f"points, direction, normal (m, 3) and state (m,) expected, got {x.shape}, "
            f"{d.shape}, {n_z.shape}, {code.shape}"
        )
    if tri6.ndim != 2 or tri6.shape[1] != 6:
        raise ValueError(f"faces must have shape (f, 6), got {tri6.shape}")
    on = code > 0
    axes, labels = plane_axes(n_z[on].sum(axis=0) if on.any() else n_z.sum(axis=0))
    uv = x @ axes.T
    slip = np.flatnonzero(code == 2)
    arrows = d[slip] @ axes.T
    low, high = contact_window(uv, on)
    with mpl.rc_context(RC):
        fig = new_figure(4.2, 3.9)
        ax = fig.add_subplot()
        ax.triplot(Triangulation(uv[:, 0], uv[:, 1], tri6[:, :3]), color="k", linewidth=0.3,
                   alpha=MESH_ALPHA)  # fmt: skip
        for value, (label, colour) in STATE_COLOURS.items():  # a loop over three states
            at = code == value
            ax.scatter(*uv[at].T, s=6, color=colour, label=f"{label} ({int(at.sum())})", zorder=3)
        if slip.size:
            ax.quiver(*uv[slip].T, *arrows.T, color=STATE_COLOURS[2][1], angles="xy",
                      width=0.004, zorder=4)  # fmt: skip
        t = np.linspace(0.0, 2.0 * np.pi, 181)
        for (label, radius), style in zip((circles or {}).items(), ("--", ":"), strict=False):
            ax.plot(radius * np.cos(t), radius * np.sin(t), "k", linestyle=style, linewidth=0.9,
                    label=label)  # fmt: skip
        ax.set(xlim=(low[0], high[0]), ylim=(low[1], high[1]), aspect="equal")
        ax.set_xlabel(labels[0])
        ax.set_ylabel(labels[1])
        fig.legend(loc="outside lower center", ncols=3, fontsize=6)
        head = f"{title}: " if title else ""
        ax.set_title(fit_title(f"{head}stick and slip over $\\Gamma_C$", fig))
        trim_height(fig)  # the equal-aspect window leaves no empty band above or below
        written = save_figure(fig, path)
    return written, {"uv": uv, "state": code, "slip": slip, "arrows": arrows}
