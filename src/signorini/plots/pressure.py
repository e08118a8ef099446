"""A computed contact pressure beside a known one (e.g. Hertz's p0 √(1 − x²/a²))."""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib as mpl
import numpy as np
from numpy.typing import ArrayLike

from .style import RC, STYLES, fit_title, new_figure, save_figure

__all__ = ["plot_pressure_comparison"]


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
) -> list[Path]:
    """The nodal pressure p_z against x, with the known pressure drawn as a line beside it.

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

    Returns
    -------
    list of pathlib.Path
        The PNG and the PDF file.

    Raises
    ------
    ValueError
        If ``x`` and ``pressure`` (or ``x_reference`` and ``reference``) differ in shape or
        are not 1-d.
    """
    arrays = []
    for a, b, what in ((x, pressure, "x and pressure"), (x_reference, reference, "reference")):
        a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
        if a.ndim != 1 or a.shape != b.shape:
            raise ValueError(f"{what} must be 1-d arrays of one length, got {a.shape}, {b.shape}")
        arrays += [a, b]
    x, pressure, x_reference, reference = arrays
    keep = np.isfinite(x) & np.isfinite(pressure)
    order = np.argsort(x[keep], kind="stable")
    st = STYLES["pressure"]
    with mpl.rc_context(RC):
        fig = new_figure()
        ax = fig.add_subplot()
        ax.plot(x_reference, reference, color="0.35", linewidth=1.0, label=label)
        ax.plot(
            x[keep][order],
            pressure[keep][order],
            color=st["color"],
            marker=st["marker"],
            markersize=2.5,
            linestyle="none",
            label=st["label"],
        )
        ax.axhline(0.0, color="0.5", linewidth=0.6)
        ax.grid(True, linestyle="-")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(r"contact pressure $p_h$")
        ax.legend(loc="upper right", fontsize=6)
        if title:
            ax.set_title(fit_title(title, fig))
        return save_figure(fig, path)
