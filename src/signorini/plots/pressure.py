"""A computed contact pressure beside a known one (e.g. Hertz's p0 √(1 − x²/a²)); with
friction also the friction stress beside a known one (e.g. Cattaneo–Mindlin's), the stick and
slip nodes marked, zoomed on the contact zone."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import matplotlib as mpl
import numpy as np
from numpy.typing import ArrayLike

from .contact_stress import FRICTION_STYLES, draw_rug
from .style import RC, STYLES, fit_title, new_figure, save_figure

__all__ = ["FrictionCurves", "plot_pressure_comparison"]

#: Drawing order: the computed nodal values (markers) below the known curves (lines), so that
#: ~300 markers do not hide the curve they are compared with.
MARKER_ZORDER, REFERENCE_ZORDER = 2.0, 3.0


@dataclass(frozen=True)
class FrictionCurves:
    """The friction part of a pressure figure (plain arrays).

    Attributes
    ----------
    tangential : (m,) float array
        The friction stress p_t,z at the nodes ``x``, drawn as markers.
    reference : (r,) float array, optional
        The known friction stress at ``x_reference``, drawn as a dashed line.
    label : str
        Its legend entry.
    state : (m,) str array, optional
        ``"inactive"``, ``"stick"`` or ``"slip"`` per node: marked in a strip at the bottom.
    """

    tangential: ArrayLike
    reference: ArrayLike | None = None
    label: str = ""
    state: ArrayLike | None = None


def _pair(a: ArrayLike | None, b: ArrayLike | None, what: str) -> tuple[np.ndarray, ...]:
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    if a.ndim != 1 or a.shape != b.shape:
        raise ValueError(f"{what} must be 1-d arrays of one length, got {a.shape}, {b.shape}")
    return a, b


def plot_pressure_comparison(
    x: ArrayLike,
    pressure: ArrayLike,
    x_reference: ArrayLike,
    reference: ArrayLike,
    path: str | os.PathLike,
    *,
    label: str = "reference",
    title: str = "",
    xlabel: str = r"$x$",
    friction: FrictionCurves | None = None,
    window: tuple[float, float] | None = None,
    joined: bool = False,
) -> list[Path]:
    """The nodal pressure p_z against x, with the known pressure drawn as a line above it.

    The computed values are small hollow markers drawn below the known curves, the legend sits
    under the axes (where it hides no data).

    Parameters
    ----------
    x, pressure : (m,) float arrays
        The nodes' coordinate along the contact zone (length units) and their consistent
        pressure p_z (stress units); NaN entries (Dirichlet nodes) are left out. Drawn as
        markers in the order of ``x``.
    x_reference, reference : (r,) float arrays
        The known pressure, drawn as a line.
    path : str or os.PathLike
        ``<path>.png`` and ``<path>.pdf`` are written.
    label, title, xlabel : str
        Legend entry of the known pressure, title, x-axis label.
    friction : FrictionCurves, optional
        The friction stress at the nodes, a known one at ``x_reference`` and the nodes'
        stick/slip states.
    window : (2,) float, optional
        The x range shown (a zoom on the contact zone).
    joined : bool
        Join the computed values by a thin line (a pressure linear between the nodes).

    Returns
    -------
    list of pathlib.Path
        The PNG and the PDF file.

    Raises
    ------
    ValueError
        If ``x`` and ``pressure`` (or ``x_reference`` and ``reference``, or the friction
        arrays) differ in shape or are not 1-d.
    """
    x, pressure = _pair(x, pressure, "x and pressure")
    x_reference, reference = _pair(x_reference, reference, "reference")
    f = FrictionCurves(None) if friction is None else friction
    pt = None if f.tangential is None else _pair(x, f.tangential, "x and tangential")[1]
    qt = None
    if f.reference is not None:
        qt = _pair(x_reference, f.reference, "tangential reference")[1]
    st = None if f.state is None else np.asarray(f.state)
    if st is not None and st.shape != x.shape:
        raise ValueError(f"state must have shape {x.shape}, got {st.shape}")
    keep = np.isfinite(x) & np.isfinite(pressure)
    order = np.flatnonzero(keep)[np.argsort(x[keep], kind="stable")]
    style = STYLES["pressure"]
    size = 2.5 if order.size <= 80 else 1.8
    with mpl.rc_context(RC):
        fig = new_figure(height=3.2 if pt is None else 3.6)
        ax = fig.add_subplot()
        ax.plot(
            x_reference, reference, color="0.15", linewidth=1.3, label=label,
            zorder=REFERENCE_ZORDER,
        )  # fmt: skip
        ax.plot(
            x[order], pressure[order], color=style["color"], marker=style["marker"],
            markersize=size, markerfacecolor="none", markeredgewidth=0.6,
            linestyle="-" if joined else "none", linewidth=0.7, label=style["label"],
            zorder=MARKER_ZORDER,
        )  # fmt: skip
        if qt is not None:
            ax.plot(
                x_reference, qt, color="0.15", linewidth=1.3, linestyle="--",
                label=f.label, zorder=REFERENCE_ZORDER,
            )  # fmt: skip
        if pt is not None:
            ft = FRICTION_STYLES["tangential_pressure"]
            ax.plot(
                x[order], pt[order], color=ft["color"], marker=ft["marker"], markersize=size,
                markerfacecolor="none", markeredgewidth=0.6, linestyle="none",
                label=ft["label"], zorder=MARKER_ZORDER,
            )  # fmt: skip
        if st is not None:
            draw_rug(ax, x[order], st[order], legend=True)
        ax.axhline(0.0, color="0.5", linewidth=0.6, zorder=1)
        ax.grid(True, linestyle="-")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(r"contact pressure $p_h$" if pt is None else "contact stresses")
        if window is not None:
            ax.set_xlim(*window)
        fig.legend(loc="outside lower center", ncols=2, fontsize=6)
        if title:
            ax.set_title(fit_title(title, fig))
        return save_figure(fig, path)
