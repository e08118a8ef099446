"""The picture of a 3D body: the boundary faces of its deformed mesh, coloured by the von
Mises stress (docs/method.md, *Three dimensions: solving elasticity*).

Drawn with matplotlib's ``Poly3DCollection`` (one collection of the faces' corner points,
no loop over faces): the boundary faces only, which grow like ``N^{2/3}``; beyond
:data:`MAX_FACES` the faces turned away from the viewer are left out, then every k-th face
of the rest, and the title says what was drawn. A contact run's plane obstacles are drawn
as translucent squares under the body, moved along their normal to where the magnified body
touches them (as the 2D figure draws its obstacles: :func:`plane_offset`). With the optional
``[3d]`` extra (PyVista) :func:`render_body_3d` renders the same surface off screen.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.ticker import MaxNLocator
from numpy.typing import ArrayLike

from ..output.vtu import von_mises
from .contact_map import plane_axes
from .deformed import displacement_scale
from .style import fit_title, new_figure, save_figure

__all__ = [
    "MAX_FACES",
    "VIEW",
    "face_colours",
    "plane_offset",
    "plane_squares",
    "plot_body_3d",
    "render_body_3d",
    "shown_faces",
]

log = logging.getLogger(__name__)

#: Most boundary faces one picture draws (beyond: back faces out, then every k-th face).
MAX_FACES = 30_000
#: The view ``(elevation, azimuth)`` in degrees (matplotlib's ``view_init``).
VIEW = (25.0, -55.0)
#: How far a drawn plane reaches beyond the drawn body's box (a fraction of the box's size).
PLANE_REACH = 0.1

Plane = tuple[np.ndarray, np.ndarray]


def _eye(view: tuple[float, float]) -> np.ndarray:
    """The unit vector towards the viewer of ``view`` (elevation, azimuth in degrees)."""
    elev, azim = np.radians(view)
    return np.array([np.cos(elev) * np.cos(azim), np.cos(elev) * np.sin(azim), np.sin(elev)])


def plane_offset(plane: Plane, points: np.ndarray, displacement: np.ndarray, scale: float) -> float:
    """How far along its normal ``m`` a plane obstacle ``(point, m)`` is drawn from where it
    is, so that the body drawn at ``x + scale · u`` touches it: ``min_z (x_z + scale · u_z −
    point)·m`` over the nodes in contact ``points (j, 3)``, ``displacement (j, 3)`` (0
    without them). A node in contact has ``(x + u − point)·m = 0``, so the offset is that of
    the magnified gaps, ``(1 − scale) ψ``, at the node of the largest gap."""
    point, m = (np.asarray(a, dtype=np.float64) for a in plane)
    if points.shape[0] == 0:
        return 0.0
    return float(((points + scale * displacement - point) @ m).min())


def plane_squares(
    planes: Sequence[Plane],
    touching: tuple[ArrayLike, ArrayLike] | None,
    scale: float,
    low: np.ndarray,
    high: np.ndarray,
) -> list[np.ndarray]:
    """``(4, 3)`` the square drawn of each plane: moved to where the body drawn at ``x +
    scale · u`` touches it (:func:`plane_offset` of the nodes in contact ``touching``),
    covering the drawn body's box ``[low, high]``."""
    contact = [np.zeros((0, 3)), np.zeros((0, 3))] if touching is None else touching
    contact = [np.asarray(a, dtype=np.float64).reshape(-1, 3) for a in contact]
    return [
        _plane_polygon(plane, plane_offset(plane, *contact, scale), low, high)
        for plane in planes  # a loop over the plane obstacles
    ]


def _plane_polygon(plane: Plane, offset: float, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """``(4, 3)`` the square of the plane ``(point, m)`` moved by ``offset`` along ``m`` that
    covers the box ``[low, high]`` seen along ``m``, :data:`PLANE_REACH` beyond it."""
    point, m = (np.asarray(a, dtype=np.float64) for a in plane)
    axes, _ = plane_axes(m)
    centre = point + offset * m
    box = np.array(np.meshgrid(*zip(low, high, strict=True))).reshape(3, -1).T  # (8, 3)
    st = (box - centre) @ axes.T
    reach = PLANE_REACH * float((high - low).max())
    lo, hi = st.min(axis=0) - reach, st.max(axis=0) + reach
    square = np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])
    return centre + square @ axes


def face_colours(faces: np.ndarray, nodal: np.ndarray) -> np.ndarray:
    """``(k,)`` the value of each face: the mean of ``nodal (n,)`` at its corners
    ``faces (k, 3)``."""
    return nodal[faces].mean(axis=1)


def shown_faces(
    corners: np.ndarray, view: tuple[float, float] = VIEW, max_faces: int = MAX_FACES
) -> tuple[np.ndarray, str]:
    """The faces a picture draws and what it says of them.

    Parameters
    ----------
    corners : (k, 3, 3) float array
        Each boundary face's corner points, in outward order (the right-hand normal
        ``(x1 − x0) × (x2 − x0)`` points out of the body).
    view, max_faces
        The viewer's direction (elevation, azimuth in degrees) and the most faces drawn.

    Returns
    -------
    rows : (j,) int array
        All faces if ``k ≤ max_faces``; else the faces whose outward normal has a positive
        component towards the viewer, and of those every ``⌈j₀ / max_faces⌉``-th.
    note : str
        Empty when every face is drawn, else what was drawn (the figure's footnote).
    """
    k = corners.shape[0]
    rows = np.arange(k)
    if k <= max_faces:
        return rows, ""
    eye = _eye(view)
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    rows = rows[normal @ eye > 0]
    step = -(-rows.size // max_faces)
    rows = rows[::step]
    thinned = f", 1 in {step}" if step > 1 else ""
    return rows, f"drawn: {rows.size} of {k} boundary faces (facing the viewer{thinned})"


def plot_body_3d(
    points: ArrayLike,
    faces: ArrayLike,
    displacement: ArrayLike,
    stress: ArrayLike,
    path: str | os.PathLike,
    title: str | None = None,
    planes: Sequence[Plane] = (),
    touching: tuple[ArrayLike, ArrayLike] | None = None,
) -> list[Path]:
    """The deformed body's boundary faces coloured by the von Mises stress, magnified by
    :func:`~.deformed.displacement_scale` (stated in the title), with the plane obstacles
    where the magnified body touches them.

    Parameters
    ----------
    points : (n, 3) float array
        The mesh's vertices.
    faces : (k, 3) int array
        The boundary faces' vertices, in outward order.
    displacement : (n, 3) float array
        ``u_h`` at the vertices.
    stress : (n, 3, 3) float array
        The nodal Cauchy stress at the vertices; a face's colour is the mean von Mises
        stress of its corners.
    path : str or os.PathLike
        Output path without extension (``.png`` and ``.pdf`` are written).
    title : str, optional
        The first line of the title.
    planes : sequence of (point (3,), normal (3,))
        Plane obstacles, ``normal`` the obstacle's outward one (towards the body).
    touching : ((j, 3), (j, 3)) float arrays, optional
        The nodes in contact and their displacements: each plane is moved to where the
        drawn body touches it (:func:`plane_offset`); without them drawn where it is.

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    from matplotlib import cm, colormaps, colors
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    x = np.asarray(points, dtype=np.float64)
    u = np.asarray(displacement, dtype=np.float64)
    tri = np.asarray(faces, dtype=np.int64)
    scale = displacement_scale(x, u)
    corners = (x + scale * u)[tri]  # (k, 3, 3)
    rows, note = shown_faces(corners, VIEW, MAX_FACES)
    value = face_colours(tri, von_mises(np.asarray(stress, dtype=np.float64)))
    norm = colors.Normalize(float(value.min()), float(value.max()) or 1.0)
    low, high = corners.reshape(-1, 3).min(axis=0), corners.reshape(-1, 3).max(axis=0)
    fig = new_figure(5.6, 4.8)
    ax = fig.add_subplot(projection="3d")
    ax.computed_zorder = False  # a plane seen from the body's side lies behind it
    squares = plane_squares(planes, touching, scale, low, high)
    for plane, square in zip(planes, squares, strict=True):  # a loop over the planes
        behind = float(np.asarray(plane[1]) @ _eye(VIEW)) > 0
        ax.add_collection3d(
            Poly3DCollection([square], facecolors="0.6", edgecolors="0.3", linewidths=0.5,
                             alpha=0.35, zorder=0 if behind else 2),
        )  # fmt: skip
    ax.add_collection3d(
        Poly3DCollection(
            corners[rows],
            facecolors=colormaps["viridis"](norm(value[rows])),
            edgecolors="k",
            linewidths=0.1 if rows.size > 2000 else 0.3,
            zorder=1,
        )
    )
    if squares:
        drawn = np.vstack([corners.reshape(-1, 3), *squares])
        low, high = drawn.min(axis=0), drawn.max(axis=0)
    ax.set(xlim=(low[0], high[0]), ylim=(low[1], high[1]), zlim=(low[2], high[2]))
    for name, axis in (("x", ax.xaxis), ("y", ax.yaxis), ("z", ax.zaxis)):
        axis.set_label_text(name)
        axis.labelpad = 8  # clear of the tick labels, which mplot3d sets close to the axis
    box = np.maximum(high - low, 1e-3 * (high - low).max())
    ax.set_box_aspect(box)
    for axis, length in zip((ax.xaxis, ax.yaxis, ax.zaxis), box / box.max(), strict=True):
        # fewer ticks on a short axis: labels along a foreshortened axis would overlap
        axis.set_major_locator(MaxNLocator(nbins=max(2, round(4 * float(length))), prune=None))
    ax.view_init(*VIEW)
    fig.colorbar(cm.ScalarMappable(norm, "viridis"), ax=ax, shrink=0.7, label="von Mises")
    head = f"{title}: " if title else ""
    obstacle = ", the plane where the drawn body touches it" if squares else ""
    text = f"{head}deformed body, displacement × {scale:g}{obstacle}"
    # the axes sit left of the colour bar: a title centred on them may use 70 % of the width
    ax.set_title(fit_title(text, fig, share=0.7) + (f"\n{note}" if note else ""))
    return save_figure(fig, path)


def render_body_3d(
    points: ArrayLike,
    faces: ArrayLike,
    displacement: ArrayLike,
    stress: ArrayLike,
    path: str | os.PathLike,
    planes: Sequence[Plane] = (),
    touching: tuple[ArrayLike, ArrayLike] | None = None,
) -> tuple[list[Path], str]:
    """The picture of :func:`plot_body_3d` rendered off screen by PyVista (the optional
    ``[3d]`` extra) as ``<path>.png``: all boundary faces, the same magnification, view and
    planes (``planes``, ``touching`` as there).

    VTK renders off screen through EGL or OSMesa (or a display); where it has none it may
    end the process (measured: a segmentation fault when OSMesa is asked for and missing),
    so the rendering runs in a child process (:data:`RENDER_SECONDS` at most) and a failed
    one costs the picture only.

    Returns
    -------
    written : list of pathlib.Path
        ``[<path>.png]``, or empty when PyVista is not installed or cannot render here.
    note : str
        Empty when written, else the one line for the run's log saying why not.
    """
    import importlib.util
    import subprocess
    import sys
    import tempfile

    if importlib.util.find_spec("pyvista") is None:
        return [], "pyvista not installed (the [3d] extra): no PyVista rendering"
    x = np.asarray(points, dtype=np.float64)
    u = np.asarray(displacement, dtype=np.float64)
    tri = np.asarray(faces, dtype=np.int64)
    scale = displacement_scale(x, u)
    drawn = x + scale * u
    low, high = drawn.min(axis=0), drawn.max(axis=0)
    centre, size = 0.5 * (low + high), float((high - low).max())
    out = Path(f"{os.fspath(path)}.png")
    with tempfile.TemporaryDirectory() as folder:
        scene = Path(folder) / "scene.npz"
        np.savez(
            scene,
            points=drawn,
            cells=np.hstack([np.full((tri.shape[0], 1), 3), tri]).ravel(),
            value=face_colours(tri, von_mises(np.asarray(stress, dtype=np.float64))),
            squares=np.reshape(plane_squares(planes, touching, scale, low, high), (-1, 4, 3)),
            camera=np.array([centre + 3 * size * _eye(VIEW), centre, [0.0, 0.0, 1.0]]),
        )
        command = [sys.executable, "-c", RENDER, os.fspath(scene), os.fspath(out)]
        try:
            done = subprocess.run(
                command + [f"displacement × {scale:g}"],
                capture_output=True,
                timeout=RENDER_SECONDS,
                check=False,
            )
        except subprocess.TimeoutExpired:
            return [], f"pyvista did not render off screen within {RENDER_SECONDS:g} s"
    if done.returncode != 0 or not out.is_file():
        return [], (
            f"pyvista could not render off screen (exit status {done.returncode}): VTK needs "
            "EGL or OSMesa (or a display)"
        )
    return [out], ""


#: The most seconds the off-screen rendering may take.
RENDER_SECONDS = 120.0

#: The child process of :func:`render_body_3d` (NumPy and PyVista only): the scene of the
#: ``.npz`` file ``argv[1]`` rendered into ``argv[2]``, ``argv[3]`` written on it.
RENDER = """
import sys
import numpy as np
import pyvista
scene = np.load(sys.argv[1])
surface = pyvista.PolyData(scene["points"], scene["cells"])
surface.cell_data["von Mises"] = scene["value"]
plotter = pyvista.Plotter(off_screen=True, window_size=(1200, 1000))
plotter.add_mesh(surface, scalars="von Mises", show_edges=True, cmap="viridis")
for square in scene["squares"]:
    plane = pyvista.PolyData(square, np.array([4, 0, 1, 2, 3]))
    plotter.add_mesh(plane, color="gray", opacity=0.35, show_edges=True)
plotter.camera_position = [tuple(row) for row in scene["camera"]]
plotter.reset_camera()
plotter.add_text(sys.argv[3], font_size=10)
plotter.screenshot(sys.argv[2])
plotter.close()
"""
