"""The deformed body coloured by ``|u_h|``, and the contact pressure along ``Γ_C``.

The displacement is magnified or shrunk by a stated factor (:func:`displacement_scale`): at
true scale a large displacement folds the drawn body over itself, a small one is invisible.
The obstacle's gaps are magnified by the same factor, so that the drawn body touches the drawn
obstacle where the body is in contact, and passes through it nowhere.
With friction the contact nodes that stick and slip are marked on the body, and the friction
stress p_t is drawn with the pressure.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib as mpl
import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.transforms import offset_copy
from matplotlib.tri import Triangulation
from numpy.typing import ArrayLike

from ..mesh.topology import boundary_facets
from .contact_line import contact_coordinate
from .contact_stress import draw_states, draw_stresses, part_widths
from .mesh import line_width, mesh_arrays
from .style import RC, STYLES, fit_title, new_figure, save_figure, trim_height

__all__ = [
    "ContactDrawing",
    "plot_deformed",
    "displacement_scale",
    "scale_text",
    "NODE_STATES",
]

#: Largest displacement drawn, as a fraction of the body's size, when it is rescaled.
DRAWN_FRACTION = 0.1
#: Displacements between these fractions of the body's size are drawn at true scale.
TRUE_SCALE_RANGE = (0.02, 0.25)
#: The obstacle drawn from gaps is left out where the drawn gap exceeds this fraction of the
#: body's size (a shape far from most of a curved contact part, e.g. the plane under a disc).
OBSTACLE_REACH = 0.25
#: With the displacement magnified, the obstacle is drawn only where its magnified gap is
#: below this fraction of the body's size: near the contact zone, where the drawn body meets
#: it (farther out, the magnified gaps of a curved side bend a plane into a curve).
MAGNIFIED_REACH = 0.1

#: The states a contact node may be in, as ``ContactDrawing(state=...)`` names them.
NODE_STATES = ("inactive", "stick", "slip")


def displacement_scale(points: ArrayLike, displacement: ArrayLike) -> float:
    """The factor the displacement is drawn with: 1 when that is readable, else a 1-2-5 value.

    With ``size`` the larger side of the bounding box of ``points`` and ``u_max`` the largest
    ``|u|``: 1 when ``u_max / size`` lies in :data:`TRUE_SCALE_RANGE` (or ``u_max = 0``),
    else the largest value ``{1, 2, 5} · 10^k`` with ``scale · u_max <= DRAWN_FRACTION ·
    size``.

    Parameters
    ----------
    points : (n, d) float array
        Reference coordinates (d = 2, or 3 given as an ``(n, 3)`` array).
    displacement : (n, d) float array
        The displacement at ``points``.
    """
    p = np.asarray(points, dtype=np.float64)
    d = 3 if p.ndim == 2 and p.shape[1] == 3 else 2
    p = p.reshape(-1, d)
    u = np.asarray(displacement, dtype=np.float64).reshape(-1, d)
    size = float(np.ptp(p, axis=0).max()) if p.size else 0.0
    u_max = float(np.max(np.hypot.reduce(u, axis=1))) if u.size else 0.0
    if not (np.isfinite(size) and np.isfinite(u_max)):
        raise ValueError("points and displacement must be finite")
    if size == 0.0 or u_max == 0.0:
        return 1.0
    low, high = TRUE_SCALE_RANGE
    if low <= u_max / size <= high:
        return 1.0
    raw = DRAWN_FRACTION * size / u_max
    exponent = np.floor(np.log10(raw))
    mantissa = max(m for m in (1.0, 2.0, 5.0) if m <= raw / 10.0**exponent * (1 + 1e-12))
    return float(mantissa * 10.0**exponent)


def scale_text(scale: float) -> str:
    """How a title states the drawing scale: ``"displacement ×0.1"``, or true scale."""
    if scale == 1.0:
        return "displacement at true scale"
    return f"displacement \u00d7{scale:g}"


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


def _draw_body(
    fig: Any,
    ax: Any,
    p: np.ndarray,
    c: np.ndarray,
    u: np.ndarray,
    scale: float,
    obstacle: np.ndarray | None,
    obstacle_label: str,
    show_mesh: bool,
    states: tuple[np.ndarray, np.ndarray] | None = None,
) -> None:
    """The body at ``p + scale u`` coloured by ``|u|``, its reference boundary dashed; with
    ``states`` (drawn positions ``(k, 2)`` and states ``(k,)`` of the contact nodes) the
    stick and slip nodes marked."""
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
            p[boundary_facets(c)],
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
            linewidth=1.5,
            label=obstacle_label,
            zorder=5,
        )
    if states is not None:
        draw_states(ax, *states)
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_xlabel(r"$x$")
    ax.set_ylabel(r"$y$")
    cax = ax.inset_axes((1.04, 0.0, 0.05, 1.0))  # follows the equal-aspect box
    fig.colorbar(image, cax=cax, label=r"$|u_h|$")
    # below the x label at a fixed distance, whatever the height of the (equal-aspect) box
    below = offset_copy(ax.transAxes, fig=fig, y=-27.0, units="points")
    ax.legend(
        loc="upper center", bbox_to_anchor=(0.5, 0.0), bbox_transform=below, ncols=2, frameon=False
    )


@dataclass(frozen=True)
class ContactDrawing:
    """What :func:`plot_deformed` draws of the contact boundary (plain arrays; every field is
    described under :func:`plot_deformed`'s ``contact``)."""

    contact_points: ArrayLike | None = None
    pressure: ArrayLike | None = None
    gap: ArrayLike | None = None
    normal: ArrayLike | None = None
    state: ArrayLike | None = None
    contact_displacement: ArrayLike | None = None
    tangential_pressure: ArrayLike | None = None
    along: Mapping[str, tuple[ArrayLike, ArrayLike]] | None = None


def plot_deformed(
    points: ArrayLike,
    cells: ArrayLike,
    displacement: ArrayLike,
    path: str | os.PathLike,
    contact: ContactDrawing | None = None,
    *,
    scale: float | str = "auto",
    obstacle: ArrayLike | None = None,
    obstacle_offset: ArrayLike | None = None,
    title: str | None = None,
    show_mesh: bool = True,
) -> list[Path]:
    """The deformed body coloured by ``|u_h|``, and the contact pressure along ``Γ_C``.

    The body is drawn at ``points + scale * displacement`` (vertices only; the P2 solution is
    drawn piecewise linearly), coloured by the unscaled ``|u_h|`` with Gouraud shading; the
    reference configuration's boundary is dashed. The title's last line states the scale.
    When ``pressure`` is given, a second axes below shows it against the coordinate along the
    contact boundary (:func:`~signorini.plots.contact_line.contact_coordinate`), with the
    friction stress ``tangential_pressure`` when that is given. With ``state`` the contact
    nodes that stick and that slip are marked on the drawn body (at ``contact_points + scale
    * contact_displacement``). The figure's height follows the drawn body's aspect ratio.

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
    contact : ContactDrawing, optional
        The contact boundary's arrays; its fields, each optional:

    contact_points : (k, 2) float array, optional
        Reference coordinates of the contact nodes (needed with ``pressure``, ``gap``).
    pressure : (k,) float array, optional
        Contact pressure at ``contact_points`` (e.g. ``p_z`` of docs/method.md, *Discrete
        problem*).
    gap : (k,) float array, optional
        The gap ``ψ`` at ``contact_points`` along ``normal`` (k, 2): the obstacle is then
        drawn at ``contact_points + scale * gap * normal``, ordered along the boundary, with
        its gaps magnified as the displacement is (at true scale, the obstacle's surface for
        a gap given along the body's normal, the closest points of a shape); left out where
        ``scale * |gap|`` exceeds :data:`OBSTACLE_REACH` times the body's size. Not together
        with ``obstacle``.
    state : (k,) str array, optional
        Each contact node's state, one of :data:`NODE_STATES` (``"inactive"``, ``"stick"``,
        ``"slip"``): the stick and slip nodes are marked. Needs ``contact_displacement``.
    contact_displacement : (k, 2) float array, optional
        The displacement of the contact nodes (where their states are marked).
    tangential_pressure : (k,) float array, optional
        The friction stress p_t at ``contact_points``, drawn with the pressure.
    along : mapping, optional
        Contact part name -> ``(rows, s)``: the rows of ``contact_points`` on the part and
        their arc length along it (:func:`signorini.loop.arrays.arc_lengths`). The stresses
        are then drawn per part against ``s``, the parts side by side
        (:mod:`signorini.plots.contact_stress`); else against
        :func:`~signorini.plots.contact_line.contact_coordinate`.

    scale : float or "auto", default "auto"
        Magnification of the displacement in the drawing; "auto":
        :func:`displacement_scale`.
    obstacle : (j, 2) float array, optional
        Polyline of the obstacle in physical coordinates (NaN rows break it) at true scale
        (e.g. :func:`signorini.loop.arrays.obstacle_outline`); drawn as given unless
        ``obstacle_offset`` is given.
    obstacle_offset : (j, 2) float array, optional
        The gap vector ``ψ n`` from the body's point ``x`` each point of ``obstacle`` belongs
        to (:func:`signorini.loop.arrays.obstacle_offset`). The obstacle is then drawn where
        the drawn body touches it: at ``x + scale ψ n = obstacle + (scale − 1) *
        obstacle_offset``, its gaps magnified as the displacement is, so that a contact node
        (``u·n = ψ``), drawn at ``x + scale u``, lies on it, as the true body lies on the
        true obstacle; points with ``scale |ψ n|`` beyond :data:`OBSTACLE_REACH` times the
        body's size (:data:`MAGNIFIED_REACH` for ``scale > 1``) are left out. A rigid plane
        under a flat side is drawn as a plane moved by the magnified gap; under a curved
        side (a disc on a plane) as the curve the magnified gaps trace; a gap function ψ as
        ``x + scale ψ n``. The legend and the title say the gaps' scale; without
        ``obstacle_offset``, that the obstacle is at true scale.
    title : str, optional
        First line of the body's title (default "deformed body").
    show_mesh : bool, default True
        Draw the deformed triangulation with faint lines.
    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.
    """
    cd = ContactDrawing() if contact is None else contact
    contact_points, pressure, gap, normal = cd.contact_points, cd.pressure, cd.gap, cd.normal
    state, contact_displacement = cd.state, cd.contact_displacement
    tangential_pressure, along = cd.tangential_pressure, cd.along
    p, c = mesh_arrays(points, cells)
    u = _vertex_displacement(displacement, p.shape[0])
    if isinstance(scale, str):
        if scale != "auto":
            raise ValueError(f"scale must be a positive number or 'auto', got {scale!r}")
        scale = displacement_scale(p, u)
    scale = float(scale)
    if not (np.isfinite(scale) and scale > 0):
        raise ValueError(f"scale must be a positive number or 'auto', got {scale!r}")
    if (pressure is not None or gap is not None) and contact_points is None:
        raise ValueError("contact_points and pressure (or gap) must be given together")
    if (gap is None) != (normal is None):
        raise ValueError("gap and normal must be given together")
    if gap is not None and obstacle is not None:
        raise ValueError("give the obstacle either as a polyline or by gap and normal, not both")
    cp = None if contact_points is None else np.asarray(contact_points, np.float64).reshape(-1, 2)
    if pressure is not None:
        pr = np.asarray(pressure, dtype=np.float64)
        if pr.shape != (cp.shape[0],):
            raise ValueError(
                f"pressure must have shape ({cp.shape[0]},) to match contact_points, got {pr.shape}"
            )
    pt = _friction_stress(tangential_pressure, pressure, cp)
    states = None
    if state is not None:
        states = _checked_states(state, contact_displacement, cp)
    reach = OBSTACLE_REACH * float(np.ptp(p, axis=0).max())
    obs = None if obstacle is None else np.asarray(obstacle, dtype=np.float64).reshape(-1, 2)
    offset = None
    if obstacle_offset is not None:
        if obs is None:
            raise ValueError("obstacle_offset is the obstacle's: give obstacle too")
        offset = np.asarray(obstacle_offset, dtype=np.float64)
        if offset.shape != obs.shape:
            raise ValueError(
                f"obstacle_offset must have the shape of obstacle {obs.shape}, got {offset.shape}"
            )
    if gap is not None:
        g = np.asarray(gap, dtype=np.float64)
        n = np.asarray(normal, dtype=np.float64)
        if g.shape != (cp.shape[0],) or n.shape != cp.shape:
            raise ValueError(
                f"gap must have shape ({cp.shape[0]},) and normal {cp.shape} to match "
                f"contact_points, got {g.shape} and {n.shape}"
            )
        order = np.argsort(contact_coordinate(cp)[0], kind="stable")
        obs, offset = (cp + g[:, None] * n)[order], (g[:, None] * n)[order]
    if offset is not None:  # where the drawn body touches the obstacle
        obs = obs + (scale - 1.0) * offset
        drawn_gap = scale * np.hypot(offset[:, 0], offset[:, 1])
        far = drawn_gap > (reach if scale <= 1.0 else MAGNIFIED_REACH / OBSTACLE_REACH * reach)
        obs[far] = np.nan  # a gap in the drawn line
        if np.isnan(obs).all():
            obs = None
    drawn = [p + scale * u] + ([] if obs is None else [obs])
    lo = np.min([np.nanmin(d, axis=0) for d in drawn], axis=0)
    hi = np.max([np.nanmax(d, axis=0) for d in drawn], axis=0)
    aspect = float((hi[1] - lo[1]) / max(hi[0] - lo[0], 1e-300))
    body = float(np.clip(2.2 * aspect, 0.8, 3.0))  # inches of the equal-aspect box
    said, obstacle_label = scale_text(scale), STYLES["obstacle"]["label"]
    if obs is not None and scale != 1.0:
        if offset is not None:  # the obstacle where the drawn body touches it
            said = f"displacement and obstacle gaps \u00d7{scale:g}"
            obstacle_label += f", gaps \u00d7{scale:g}"
        else:
            said += ", obstacle at true scale"
            obstacle_label += " (true scale)"
    head = f"{title}\n{said}" if title else f"deformed body, {said}"
    parts = _checked_along(along, cp) if pressure is not None else None
    with mpl.rc_context(RC):
        if pressure is None:
            fig = new_figure(height=body + 1.45)
            ax = fig.add_subplot()
        else:
            fig = new_figure(height=body + 1.45 + 1.7)
            grid = fig.add_gridspec(
                2,
                1 if parts is None else len(parts),
                height_ratios=[body + 1.0, 1.2],
                width_ratios=None if parts is None else part_widths(parts),
            )
            ax = fig.add_subplot(grid[0, :])
            axp = [fig.add_subplot(grid[1, 0])]
            axp += [fig.add_subplot(grid[1, j], sharey=axp[0]) for j in range(1, grid.ncols)]
        if states is not None:
            states = (cp + scale * states[0], states[1])
        _draw_body(fig, ax, p, c, u, scale, obs, obstacle_label, show_mesh, states)
        ax.set_title(fit_title(head, fig))
        if pressure is not None:
            draw_stresses(axp, cp, pr, pt, None if states is None else states[1], parts)
        trim_height(fig)
        return save_figure(fig, path)


def _friction_stress(
    tangential: ArrayLike | None, pressure: ArrayLike | None, cp: np.ndarray | None
) -> np.ndarray | None:
    """``tangential_pressure`` checked: given with ``pressure``, one value per contact point."""
    if tangential is None:
        return None
    if pressure is None:
        raise ValueError("tangential_pressure is drawn with the pressure: give pressure too")
    pt = np.asarray(tangential, dtype=np.float64)
    if pt.shape != (cp.shape[0],):
        raise ValueError(
            f"tangential_pressure must have shape ({cp.shape[0]},) to match contact_points, "
            f"got {pt.shape}"
        )
    return pt


def _checked_states(
    state: ArrayLike, contact_displacement: ArrayLike | None, cp: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray]:
    """``(contact_displacement (k, 2), state (k,))`` checked against ``contact_points``."""
    if cp is None or contact_displacement is None:
        raise ValueError("state needs contact_points and contact_displacement")
    st = np.asarray(state)
    uc = np.asarray(contact_displacement, dtype=np.float64)
    if st.shape != (cp.shape[0],) or uc.shape != cp.shape:
        raise ValueError(
            f"state must have shape ({cp.shape[0]},) and contact_displacement {cp.shape} to "
            f"match contact_points, got {st.shape} and {uc.shape}"
        )
    if not np.isin(st, NODE_STATES).all():
        raise ValueError(f"state must hold the labels {', '.join(map(repr, NODE_STATES))}")
    return uc, st


def _checked_along(
    along: Mapping[str, tuple[ArrayLike, ArrayLike]] | None, cp: np.ndarray
) -> dict[str, tuple[np.ndarray, np.ndarray]] | None:
    """``along`` (part name -> rows of ``contact_points`` and their arc length) checked."""
    if along is None:
        return None
    if not isinstance(along, Mapping) or not along:
        raise ValueError("along must map contact part names to (rows, arc length)")
    out = {}
    for name, (rows, s) in along.items():
        rows = np.asarray(rows, dtype=np.int64)
        s = np.asarray(s, dtype=np.float64)
        if rows.ndim != 1 or s.shape != rows.shape or not np.isfinite(s).all():
            raise ValueError(
                f"along[{name!r}] must be (rows, arc length), two 1-d arrays of one length "
                f"with finite lengths, got shapes {rows.shape} and {s.shape}"
            )
        if rows.size and (rows.min() < 0 or rows.max() >= cp.shape[0]):
            raise ValueError(
                f"along[{name!r}]: rows must index contact_points (0 to {cp.shape[0] - 1})"
            )
        out[str(name)] = (rows, s)
    return out
