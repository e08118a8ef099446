"""The contact pressure (and the friction stress) along Γ_C, one axes per contact part against
the part's arc length, and the stick and slip nodes of a frictional contact.

The arc length is the true length along the part's boundary (from
:func:`signorini.loop.arrays.arc_lengths`), so a curved part spans its length (a half-circle
of radius R spans πR) and two parts are drawn apart, each labelled with its name, their
widths in proportion to their lengths (none narrower than :data:`NARROWEST` of the row).
Without arc lengths one axes shows all nodes against
:func:`~signorini.plots.contact_line.contact_coordinate`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .contact_line import contact_coordinate
from .style import STYLES

__all__ = [
    "FRICTION_STYLES",
    "NARROWEST",
    "draw_stresses",
    "draw_rug",
    "draw_states",
    "part_widths",
]

#: How the stick and slip nodes of a frictional contact and its friction stress are drawn.
FRICTION_STYLES: dict[str, dict[str, str]] = {
    "stick": {"color": "#1b9e77", "marker": "o", "label": "stick"},
    "slip": {"color": "#e7298a", "marker": "D", "label": "slip"},
    "tangential_pressure": {"color": "#d95f02", "marker": "s", "label": r"$p_{t,h}$"},
}

#: The narrowest a contact part's axes may be, as a fraction of the row of parts.
NARROWEST = 0.25


def part_widths(along: Mapping[str, tuple[np.ndarray, np.ndarray]]) -> list[float]:
    """Width ratios of the parts' axes: their lengths, none below :data:`NARROWEST` of the
    sum."""
    lengths = np.array([float(s.max()) if s.size else 0.0 for _, s in along.values()])
    total = max(float(lengths.sum()), 1e-300)
    return list(np.maximum(lengths / total, NARROWEST))


def draw_states(ax: Any, at: np.ndarray, state: np.ndarray, legend: bool = True) -> None:
    """Markers on the contact nodes that stick and that slip, at the points ``at (k, 2)``
    (labelled for the legend, or not)."""
    size = 3.0 if state.size <= 200 else 1.5
    for key in ("stick", "slip"):
        on = state == key
        if not on.any():
            continue
        st = FRICTION_STYLES[key]
        ax.plot(
            at[on, 0],
            at[on, 1],
            linestyle="",
            marker=st["marker"],
            markersize=size,
            color=st["color"],
            label=st["label"] if legend else f"_{st['label']}",
            zorder=6,
        )


def draw_rug(ax: Any, t: np.ndarray, state: np.ndarray, legend: bool = False) -> None:
    """The stick and slip nodes as ticks in a strip at the bottom of the axes, below the
    curves (which stay visible); labelled for the legend, or not."""
    transform = ax.get_xaxis_transform()  # x in data, y in axes coordinates
    for key in ("stick", "slip"):
        on = state == key
        if not on.any():
            continue
        st = FRICTION_STYLES[key]
        ax.plot(
            t[on],
            np.full(int(on.sum()), 0.04 if key == "stick" else 0.09),
            transform=transform,
            linestyle="",
            marker="|",
            markersize=4.0,
            color=st["color"],
            label=st["label"] if legend else f"_{st['label']}",
            zorder=2,
        )


def _draw_part(
    ax: Any, t: np.ndarray, curves: list[tuple[str, np.ndarray]], state: np.ndarray | None
) -> None:
    """The curves against ``t`` (sorted here), drawn above the stick/slip strip."""
    order = np.argsort(t, kind="stable")
    for key, values in curves:
        st = STYLES.get(key) or FRICTION_STYLES[key]
        ax.plot(
            t[order],
            values[order],
            color=st["color"],
            marker=st["marker"] if t.size <= 80 and state is None else "",
            markersize=2.5,
            label=st["label"],
            zorder=4,
        )
    if state is not None:
        draw_rug(ax, t, state)
    ax.axhline(0.0, color="0.5", linewidth=0.6, zorder=1)
    ax.grid(True, linestyle="-")


def draw_stresses(
    axes: Sequence[Any],
    contact_points: np.ndarray,
    pressure: np.ndarray,
    tangential: np.ndarray | None,
    state: np.ndarray | None,
    along: Mapping[str, tuple[np.ndarray, np.ndarray]] | None,
) -> None:
    """The pressure (and the friction stress, the stick and slip nodes in a strip below)
    against the arc length of each contact part: one axes per part of ``along`` (name ->
    ``(rows, s)``), or, without ``along``, one axes against
    :func:`~signorini.plots.contact_line.contact_coordinate`."""
    if along is None:
        t, tlabel = contact_coordinate(contact_points)
        parts = [(None, np.arange(t.size), t)]
    else:
        parts = [(name, rows, s) for name, (rows, s) in along.items()]
        tlabel = r"arc length $s$"
    for ax, (name, rows, t) in zip(axes, parts, strict=True):
        curves = [("pressure", pressure[rows])]
        if tangential is not None:
            curves.append(("tangential_pressure", tangential[rows]))
        _draw_part(ax, t, curves, None if state is None else state[rows])
        ax.set_xlabel(tlabel)
        if name is not None:
            ax.set_title(f"contact part {name!r}", fontsize="small")
        if ax is not axes[0]:
            ax.tick_params(labelleft=False)
    first = axes[0]
    if tangential is None:
        first.set_ylabel(r"contact pressure $p_h$")
    else:
        first.set_ylabel("contact stresses")
        lo, hi = first.get_ylim()
        first.set_ylim(lo, hi + 0.45 * (hi - lo))  # an empty band on top for the legend
        first.legend(loc="upper center", ncols=2)
