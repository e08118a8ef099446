"""Convergence figures of the paper's Section 6, drawn from a history (one row per level).

- Fig. 6.1(a): energy error ``‖u − u_h‖_a`` and estimator ``η_h`` (5.1) against ``N_dof``
  (:func:`plot_error_and_estimator`); Fig. 6.1(b): the efficiency index
  ``η_h / ‖u − u_h‖_a`` (:func:`plot_efficiency`);
- Figs. 6.2 and 6.4: the contributions ``η_1 … η_7`` of (5.1) (:func:`plot_contributions`);
- Fig. 6.3(a): the estimator alone (:func:`plot_estimator`);
- several runs of one quantity on one plot (:func:`plot_adaptive_vs_uniform`).

All five share one frame (:func:`convergence_figure`): log ``N_dof`` axis, one styled curve
per quantity with its fitted slope in the legend, a reference slope triangle below the data.
A *history* is a mapping from column name to a 1-d array, one entry per level (e.g.
:func:`~signorini.output.read_history` of a run's ``history.csv``), or the path of such a
file. ``NaN`` marks an unknown value; zero and ``NaN`` entries are left out of log plots.
Each function writes ``<path>.png`` and ``<path>.pdf`` and returns the written paths.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib as mpl
import numpy as np

from ..output.history import HistoryLike, check_last, history_columns
from .slopes import draw_slope_triangle, slope_label
from .style import (
    CONTRIBUTIONS,
    RC,
    STYLES,
    format_number,
    log_log_axes,
    new_figure,
    positive,
    save_figure,
    tidy_log_ticks,
)

__all__ = [
    "Curve",
    "convergence_figure",
    "plot_error_and_estimator",
    "plot_efficiency",
    "plot_contributions",
    "plot_estimator",
    "plot_adaptive_vs_uniform",
]

log = logging.getLogger(__name__)

# Colours / markers of the runs compared in plot_adaptive_vs_uniform, in order.
_RUN_COLORS = ("#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2")
_RUN_MARKERS = ("s", "o", "^", "v", "D", "p", "h")


@dataclass(frozen=True)
class Curve:
    """One line of a convergence figure: ``values`` (n,) against ``ndof`` (n,)."""

    ndof: np.ndarray
    values: np.ndarray
    label: str
    color: str
    marker: str

    @classmethod
    def of(cls, key: str, ndof: np.ndarray, values: np.ndarray, last: int) -> Curve:
        """The history column ``key`` in its :data:`STYLES`, its fitted slope in the label."""
        style = STYLES[key]
        label = slope_label(style["label"], ndof, values, last)
        return cls(ndof, values, label, style["color"], style["marker"])


def convergence_figure(
    path: str | os.PathLike,
    curves: Sequence[Curve | str],
    ylabel: str,
    *,
    title: str | None = None,
    height: float = 2.7,
    legend: str = "upper right",
    reference_slope: float | None = -1.0,
    log_y: bool = True,
    decorate: Callable[[Any], None] | None = None,
) -> list[Path]:
    """The frame every convergence figure shares: curves against ``N_dof``, saved.

    Parameters
    ----------
    path : str or os.PathLike
        Output path without extension.
    curves : sequence of Curve or str
        The lines, in legend order; a str is a legend line without a curve (e.g. a term
        that vanishes on every level).
    ylabel : str
        Label of the y axis.
    title : str, optional
        Axes title.
    height : float
        Figure height in inches (the width is one column).
    legend : str
        Legend location on the axes, or ``"outside lower center"`` for two columns below.
    reference_slope : float or None
        Slope of the triangle drawn below the curves; None draws none.
    log_y : bool
        Logarithmic y axis (else linear).
    decorate : callable, optional
        Called with the axes after the curves are drawn, before the legend.

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.
    """
    drawn = [c for c in curves if isinstance(c, Curve)]
    with mpl.rc_context(RC):
        fig = new_figure(height=height)
        ax = fig.add_subplot()
        log_log_axes(ax, ylabel, log_y=log_y)
        for c in curves:
            if isinstance(c, Curve):
                ax.plot(c.ndof, positive(c.values), color=c.color, marker=c.marker, label=c.label)
            else:
                ax.plot([], [], linestyle="none", marker="", label=c)
        if reference_slope is not None:
            draw_slope_triangle(ax, [(c.ndof, c.values) for c in drawn], float(reference_slope))
        if decorate is not None:
            decorate(ax)
        if legend.startswith("outside"):
            fig.legend(loc=legend, ncols=2)
        else:
            ax.legend(loc=legend)
        if title:
            ax.set_title(title)
        tidy_log_ticks(ax)
        return save_figure(fig, path)


def plot_error_and_estimator(
    history: HistoryLike, path: str | os.PathLike, title: str | None = None, last: int = 3
) -> list[Path]:
    """Fig. 6.1(a): energy error and estimator ``η_h`` (5.1) against ``N_dof``, log-log.

    The legend gives the slope of each curve fitted over the last ``last`` levels
    (:func:`~signorini.output.fitted_slope`); a slope −1 triangle (the optimal rate of P2
    in 2D, ``N_dof^{-1}``) is drawn below the data.

    Parameters
    ----------
    history : mapping of str to (n_levels,) array, or path of a CSV history
        Needs the columns ``ndof``, ``eta`` and ``error_energy`` (NaN where unknown).
    path : str or os.PathLike
        Output path without extension.
    title : str, optional
        Axes title.
    last : int, default 3
        Number of final levels used for the fitted slopes.

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.

    Raises
    ------
    ValueError
        If a column is missing or no error value is known.
    """
    check_last(last)
    h = history_columns(history, ("ndof", "eta", "error_energy"))
    ndof = h["ndof"]
    if not np.any(np.isfinite(h["error_energy"]) & (h["error_energy"] > 0)):
        raise ValueError(
            "the history has no positive finite error_energy value; plot the "
            "estimator alone with plot_estimator"
        )
    curves = [Curve.of(key, ndof, h[key], last) for key in ("error_energy", "eta")]
    return convergence_figure(path, curves, "error, estimator", title=title)


def plot_efficiency(
    history: HistoryLike, path: str | os.PathLike, title: str | None = None
) -> list[Path]:
    """Fig. 6.1(b): efficiency index ``η_h / ‖u − u_h‖_a`` against ``N_dof`` (log x axis).

    Parameters
    ----------
    history : mapping of str to (n_levels,) array, or path of a CSV history
        Needs ``ndof`` and either ``efficiency`` or both ``eta`` and ``error_energy``; where
        ``efficiency`` is NaN but ``eta / error_energy`` is known, the quotient is used.
    path : str or os.PathLike
        Output path without extension.
    title : str, optional
        Axes title.

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.

    Raises
    ------
    ValueError
        If the needed columns are missing or no efficiency value is known.
    """
    h = history_columns(history, ("ndof",), ("efficiency", "eta", "error_energy"))
    ndof = h["ndof"]
    eff = h.get("efficiency", np.full(ndof.shape, np.nan))
    if "eta" in h and "error_energy" in h:
        with np.errstate(divide="ignore", invalid="ignore"):
            quotient = h["eta"] / h["error_energy"]
        eff = np.where(np.isfinite(eff), eff, quotient)
    elif "efficiency" not in h:
        raise ValueError(
            "the history needs an 'efficiency' column or both 'eta' and "
            f"'error_energy'; it has {sorted(h)}"
        )
    eff = positive(eff)
    if np.all(np.isnan(eff)):
        raise ValueError("the history has no positive finite efficiency index")
    mean = float(np.nanmean(eff))

    def mean_line(ax: Any) -> None:
        ax.axhline(
            mean, color="0.5", linestyle="--", linewidth=0.8, label=f"mean {format_number(mean)}"
        )
        ax.set_ylim(0.0, 1.2 * float(np.nanmax(eff)))

    style = STYLES["efficiency"]
    return convergence_figure(
        path,
        [Curve(ndof, eff, style["label"], style["color"], style["marker"])],
        r"efficiency index $\eta_h/\|u-u_h\|_a$",
        title=title,
        legend="lower right",
        reference_slope=None,
        log_y=False,
        decorate=mean_line,
    )


def plot_contributions(
    history: HistoryLike, path: str | os.PathLike, title: str | None = None, last: int = 3
) -> list[Path]:
    """Figs. 6.2 / 6.4: the estimator contributions ``η_1 … η_7`` of (5.1) against ``N_dof``.

    Terms that vanish on every level (e.g. ``η_6``, ``η_7`` in Example 6.1, where the whole
    contact boundary is active) cannot be drawn on a log axis; they are listed in the legend
    as ``η_k ≡ 0``. Single zero entries leave a gap. A slope −1 triangle is drawn below the
    curves and the legend gives each fitted slope over the last ``last`` levels.

    Parameters
    ----------
    history : mapping of str to (n_levels,) array, or path of a CSV history
        Needs ``ndof`` and at least one of ``eta_1`` … ``eta_7`` (absent ones are skipped).
    path : str or os.PathLike
        Output path without extension.
    title : str, optional
        Axes title.
    last : int, default 3
        Number of final levels used for the fitted slopes.

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.
    """
    check_last(last)
    h = history_columns(history, ("ndof",), CONTRIBUTIONS)
    keys = [k for k in CONTRIBUTIONS if k in h]
    if not keys:
        raise ValueError(f"the history has none of the columns {', '.join(CONTRIBUTIONS)}")
    curves: list[Curve | str] = []
    for key in keys:
        v = h[key]
        if np.any(np.isfinite(v) & (v > 0)):
            curves.append(Curve.of(key, h["ndof"], v, last))
        elif np.any(v == 0):
            curves.append(STYLES[key]["label"][:-1] + r" \equiv 0$")
        else:
            log.warning("estimator contribution %s has no known value; skipped", key)
    return convergence_figure(
        path, curves, r"$\eta_k$", title=title, height=3.3, legend="outside lower center"
    )


def plot_estimator(
    history: HistoryLike, path: str | os.PathLike, title: str | None = None, last: int = 3
) -> list[Path]:
    """Fig. 6.3(a): the estimator ``η_h`` (5.1) against ``N_dof``, log-log, slope −1 triangle.

    Parameters
    ----------
    history : mapping of str to (n_levels,) array, or path of a CSV history
        Needs the columns ``ndof`` and ``eta``.
    path : str or os.PathLike
        Output path without extension.
    title : str, optional
        Axes title.
    last : int, default 3
        Number of final levels used for the fitted slope.

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.
    """
    check_last(last)
    h = history_columns(history, ("ndof", "eta"))
    curves = [Curve.of("eta", h["ndof"], h["eta"], last)]
    return convergence_figure(path, curves, r"$\eta_h$", title=title)


def plot_adaptive_vs_uniform(
    histories: Mapping[str, HistoryLike],
    path: str | os.PathLike,
    key: str = "eta",
    title: str | None = None,
    last: int = 3,
    reference_slope: float | None = -1.0,
) -> list[Path]:
    """Several runs of one quantity on one log-log plot, each with its fitted slope.

    Meant for adaptive against uniform refinement, or runs with different estimator
    variants (e.g. of ``η_5``).

    Parameters
    ----------
    histories : mapping of str to history
        Legend label -> history (mapping of columns, or path of a CSV file); each needs
        ``ndof`` and ``key``.
    path : str or os.PathLike
        Output path without extension.
    key : str, default "eta"
        Column to compare (e.g. ``"eta"``, ``"error_energy"``, ``"eta_5"``).
    title : str, optional
        Axes title.
    last : int, default 3
        Number of final levels used for the fitted slopes.
    reference_slope : float or None, default -1.0
        Slope of the reference triangle; None draws none.

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.
    """
    check_last(last)
    if not isinstance(histories, Mapping) or not histories:
        raise ValueError("histories must be a non-empty mapping from label to history")
    runs = {str(label): history_columns(h, ("ndof", key)) for label, h in histories.items()}
    curves = [
        Curve(
            h["ndof"],
            h[key],
            slope_label(label, h["ndof"], h[key], last),
            _RUN_COLORS[i % len(_RUN_COLORS)],
            _RUN_MARKERS[i % len(_RUN_MARKERS)],
        )
        for i, (label, h) in enumerate(runs.items())
    ]
    ylabel = STYLES[key]["label"] if key in STYLES else key.replace("_", " ")
    return convergence_figure(
        path,
        curves,
        ylabel,
        title=title,
        height=3.0,
        legend="best",
        reference_slope=reference_slope,
    )
