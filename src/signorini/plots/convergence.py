"""Convergence figures of the paper's Section 6, drawn from a history (one row per level).

- Fig. 6.1(a): energy error ``‖u − u_h‖_a`` and estimator ``η_h`` (5.1) against ``N_dof``
  (:func:`plot_error_and_estimator`); Fig. 6.1(b): the efficiency index
  ``η_h / ‖u − u_h‖_a`` (:func:`plot_efficiency`);
- Figs. 6.2 and 6.4: the contributions ``η_1 … η_7`` of (5.1) (:func:`plot_contributions`);
- Fig. 6.3(a): the estimator alone (:func:`plot_estimator`);
- several runs of one quantity on one plot (:func:`plot_adaptive_vs_uniform`).

All five share one frame (:func:`convergence_figure`): log ``N_dof`` axis, one styled curve
per quantity with its fitted slope in the legend, a reference slope triangle below the data.
The slopes are least-squares fits over the finer half of the run in log ``N_dof``
(:func:`~signorini.plots.slopes.finer_half_slope`), and the legend's title says so.
A *history* is a mapping from column name to a 1-d array, one entry per level (e.g.
:func:`~signorini.output.read_history` of a run's ``history.csv``), or the path of such a
file. ``NaN`` marks an unknown value and is not drawn. A value that is exactly zero, or (for
the contributions ``η_k``) round-off below ``ROUNDOFF · η_h`` of its level, cannot be drawn
on a log axis: it is drawn as a hollow marker on a strip labelled ``≈0`` below the axes, so
the log axis keeps the meaningful range and no gap is left unexplained.
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
from .slopes import draw_slope_triangle, fit_note, slope_label
from .style import (
    CONTRIBUTIONS,
    FRICTION_CONTRIBUTION,
    RC,
    STYLES,
    fit_title,
    format_number,
    log_log_axes,
    new_figure,
    positive,
    save_figure,
    tidy_log_ticks,
)

__all__ = [
    "ROUNDOFF",
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

#: A contribution ``η_k`` below ``ROUNDOFF · η_h`` of its level is round-off (e.g. η_7 of a
#: fully active contact boundary, ~1e-17 against η_h ~ 1e-2): drawn as ≈ 0, not fitted.
ROUNDOFF = 1e-10


@dataclass(frozen=True)
class Curve:
    """One line of a convergence figure: ``values`` (n,) against ``ndof`` (n,)."""

    ndof: np.ndarray
    values: np.ndarray
    label: str
    color: str
    marker: str
    #: (n,) bool: levels whose value is exactly zero or round-off, drawn on the ``≈0`` strip
    #: (None: those where ``values == 0``).
    negligible: np.ndarray | None = None

    @property
    def near_zero(self) -> np.ndarray:
        """(n,) bool: the levels drawn on the ``≈0`` strip instead of the log axis."""
        if self.negligible is not None:
            return np.asarray(self.negligible, dtype=bool)
        return np.asarray(self.values) == 0.0

    @classmethod
    def of(
        cls,
        key: str,
        ndof: np.ndarray,
        values: np.ndarray,
        last: int | None = None,
        reference: np.ndarray | None = None,
    ) -> Curve:
        """The history column ``key`` in its :data:`STYLES`, its fitted slope in the label.

        With ``reference`` (n,), values ``<= ROUNDOFF * reference`` count as round-off: on the
        ``≈0`` strip and out of the fit, like exact zeros.
        """
        style = STYLES[key]
        values = np.asarray(values, dtype=np.float64)
        small = np.isfinite(values) & (values <= 0.0)
        if reference is not None:
            small |= np.isfinite(values) & (values <= ROUNDOFF * np.asarray(reference))
        shown = np.where(small, np.nan, values)
        if np.any(np.isfinite(shown) & (shown > 0)):
            label = slope_label(style["label"], ndof, shown, last)
        elif np.all(values[small] == 0.0):
            label = style["label"][:-1] + r" \equiv 0$"
        else:
            label = style["label"][:-1] + r" \approx 0$ (round-off)"
        return cls(ndof, values, label, style["color"], style["marker"], small)


def convergence_figure(
    path: str | os.PathLike,
    curves: Sequence[Curve | str],
    ylabel: str,
    *,
    title: str | None = None,
    height: float = 2.7,
    legend: str = "best",
    reference_slope: float | None = -1.0,
    log_y: bool = True,
    decorate: Callable[[Any], None] | None = None,
    note: str | None = None,
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
    note : str, optional
        Title of the legend (e.g. the range the slopes are fitted over).

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.
    """
    drawn = [c for c in curves if isinstance(c, Curve)]
    strip = log_y and any(c.near_zero.any() for c in drawn)
    with mpl.rc_context(RC):
        fig = new_figure(height=height + (0.3 if strip else 0.0))
        if strip:
            ax, zero_ax = fig.subplots(
                2, 1, sharex=True, gridspec_kw={"height_ratios": [1.0, 0.13], "hspace": 0.0}
            )
        else:
            ax, zero_ax = fig.add_subplot(), None
        log_log_axes(ax, ylabel, log_y=log_y)
        n_rows = sum(1 for c in drawn if c.near_zero.any())
        rows = iter(np.linspace(-0.5, 0.5, n_rows) if n_rows > 1 else [0.0])
        for c in curves:
            if not isinstance(c, Curve):
                ax.plot([], [], linestyle="none", marker="", label=c)
                continue
            shown = positive(np.where(c.near_zero, np.nan, c.values))
            if np.any(np.isfinite(shown)):
                ax.plot(c.ndof, shown, color=c.color, marker=c.marker, label=c.label)
            else:  # only ≈0 values: the legend entry shows the strip's hollow marker
                ax.plot([], [], color=c.color, marker=c.marker, mfc="none", ls="", label=c.label)
            if zero_ax is not None and c.near_zero.any():
                zero_ax.plot(  # each curve on its own row of the strip, so none hides another
                    c.ndof[c.near_zero],
                    np.full(np.count_nonzero(c.near_zero), next(rows)),
                    color=c.color,
                    marker=c.marker,
                    mfc="none",
                    linestyle="none",
                    clip_on=False,
                )
        if zero_ax is not None:
            _zero_strip(ax, zero_ax)
            note = "\n".join(filter(None, [note, _ZERO_NOTE]))
        if reference_slope is not None:
            series = [(c.ndof, np.where(c.near_zero, np.nan, c.values)) for c in drawn]
            draw_slope_triangle(ax, series, float(reference_slope))
        if decorate is not None:
            decorate(ax)
        if legend.startswith("outside"):
            fig.legend(loc=legend, ncols=2, title=note)
        if title:
            ax.set_title(fit_title(title, fig))
        tidy_log_ticks(ax)
        if zero_ax is not None:
            _clear_bottom_tick(ax)
        if not legend.startswith("outside"):
            # the note as a caption under the axes: in the legend it would cover the data
            if note:
                fig.supxlabel(note, fontsize="x-small", color="0.3")
            _place_legend(fig, ax, legend)
        return save_figure(fig, path)


_ZERO_NOTE = r"$\approx$0: exactly 0, or round-off below $10^{-10}\,\eta_h$"

_LEGEND_PLACES = ("upper right", "lower left", "lower right", "upper left", "center right")


def _place_legend(fig: Any, ax: Any, loc: str) -> None:
    """The in-axes legend at ``loc`` or else the first place where it hides no marker of a
    curve (the fewest if it hides some everywhere): matplotlib's "best" can settle on a
    corner over the data."""
    renderer = fig.canvas.get_renderer()
    points = [
        xy[np.all(np.isfinite(xy), axis=1)]
        for line in ax.get_lines()
        if line.get_marker() not in ("", "None", None)
        for xy in [line.get_xydata()]
    ]
    best = None
    for place in ([loc] if loc != "best" else []) + list(_LEGEND_PLACES):
        ax.legend(loc=place)
        fig.get_layout_engine().execute(fig)
        box = ax.get_legend().get_window_extent(renderer)
        hidden = 0
        for xy in points:
            px = ax.transData.transform(xy)
            inside = (px > [box.x0, box.y0]) & (px < [box.x1, box.y1])
            hidden += int(np.count_nonzero(inside.all(axis=1)))
        # the slope triangle and its labels count as one point each
        hidden += sum(box.overlaps(a.get_window_extent(renderer)) for a in ax.texts + ax.patches)
        if best is None or hidden < best[0]:
            best = (hidden, place)
        if hidden == 0:
            return
    ax.legend(loc=best[1])


def _clear_bottom_tick(ax: Any, room: float = 0.07) -> None:
    """Lower the log axis so that no labelled tick sits within ``room`` (a fraction of the
    axis height) of its bottom, where its label would run into the ``≈0`` strip's label."""
    lo, hi = np.log10(ax.get_ylim())
    ticks = np.log10([t for t in ax.get_yticks() if t > 0])
    near = ticks[(ticks >= lo) & (ticks < lo + room * (hi - lo))]
    if near.size:
        ax.set_ylim(10.0 ** (near.min() - room * (hi - lo)), 10.0**hi)


def _zero_strip(ax: Any, zero_ax: Any) -> None:
    """The ``≈0`` strip below the log axes: one tick ``≈0``, the x axis moved onto it."""
    zero_ax.set_ylim(-1.0, 1.0)
    zero_ax.set_yticks([0.0], [r"$\approx$0"])
    zero_ax.grid(True, which="major", axis="x", linestyle="-")
    zero_ax.grid(True, which="minor", axis="x", linestyle=":", alpha=0.3)
    zero_ax.set_xlabel(ax.get_xlabel())
    ax.set_xlabel("")
    ax.tick_params(axis="x", which="both", labelbottom=False)
    ax.spines["bottom"].set_linestyle((0, (2, 2)))
    zero_ax.spines["top"].set_visible(False)


def plot_error_and_estimator(
    history: HistoryLike,
    path: str | os.PathLike,
    title: str | None = None,
    last: int | None = None,
) -> list[Path]:
    """Fig. 6.1(a): energy error and estimator ``η_h`` (5.1) against ``N_dof``, log-log.

    The legend gives the slope of each curve fitted over the finer half of the run
    (:func:`~signorini.plots.slopes.finer_half_slope`) and states that range; a slope −1
    triangle (the optimal rate of P2 in 2D, ``N_dof^{-1}``) is drawn below the data.

    Parameters
    ----------
    history : mapping of str to (n_levels,) array, or path of a CSV history
        Needs the columns ``ndof``, ``eta`` and ``error_energy`` (NaN where unknown).
    path : str or os.PathLike
        Output path without extension.
    title : str, optional
        Axes title.
    last : int, optional
        Fit the slopes over the last ``last`` levels instead of the finer half of the run.

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.

    Raises
    ------
    ValueError
        If a column is missing or no error value is known.
    """
    if last is not None:
        check_last(last)
    h = history_columns(history, ("ndof", "eta", "error_energy"))
    ndof = h["ndof"]
    if not np.any(np.isfinite(h["error_energy"]) & (h["error_energy"] > 0)):
        raise ValueError(
            "the history has no positive finite error_energy value; plot the "
            "estimator alone with plot_estimator"
        )
    curves = [Curve.of(key, ndof, h[key], last) for key in ("error_energy", "eta")]
    return convergence_figure(
        path, curves, "error, estimator", title=title, note=fit_note([ndof], last)
    )


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
    history: HistoryLike,
    path: str | os.PathLike,
    title: str | None = None,
    last: int | None = None,
) -> list[Path]:
    """Figs. 6.2 / 6.4: the estimator contributions ``η_1 … η_7`` of (5.1) against ``N_dof``,
    and for a frictional run the friction work ``η_8``.

    A value that is exactly zero, or round-off (below ``ROUNDOFF`` times ``η_h`` of its level,
    e.g. ``η_7 ≈ 1e-17``), is drawn as a hollow marker on the ``≈0`` strip below the log axes
    and left out of the fitted slope; a term that is zero on every level (``η_6``, ``η_7`` in
    Example 6.1, where the whole contact boundary is active) is listed as ``η_k ≡ 0``. A slope
    −1 triangle is drawn below the curves and the legend gives each fitted slope over the
    finer half of the run, and says so.

    Parameters
    ----------
    history : mapping of str to (n_levels,) array, or path of a CSV history
        Needs ``ndof`` and at least one of ``eta_1`` … ``eta_7`` (absent ones are skipped).
        ``eta_8`` is drawn when the run is frictional: positive on some level, or some
        node sticks (``n_stick``); a frictionless run's ``eta_8 ≡ 0`` is left out.
    path : str or os.PathLike
        Output path without extension.
    title : str, optional
        Axes title.
    last : int, optional
        Fit the slopes over the last ``last`` levels instead of the finer half of the run.

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.
    """
    if last is not None:
        check_last(last)
    h = history_columns(
        history, ("ndof",), (*CONTRIBUTIONS, FRICTION_CONTRIBUTION, "n_stick", "eta")
    )
    keys = [k for k in CONTRIBUTIONS if k in h]
    if FRICTION_CONTRIBUTION in h and (
        np.any(h[FRICTION_CONTRIBUTION] > 0) or np.any(h.get("n_stick", 0) > 0)
    ):
        keys.append(FRICTION_CONTRIBUTION)
    if not keys:
        raise ValueError(f"the history has none of the columns {', '.join(CONTRIBUTIONS)}")
    # η_h of each level, the scale of round-off (from the terms if the column is absent)
    total = np.sqrt(sum(np.nan_to_num(h[k]) ** 2 for k in keys))
    reference = np.where(np.isfinite(h["eta"]), h["eta"], total) if "eta" in h else total
    curves: list[Curve | str] = []
    for key in keys:
        v = h[key]
        if np.any(np.isfinite(v)):
            curves.append(Curve.of(key, h["ndof"], v, last, reference=reference))
        else:
            log.warning("estimator contribution %s has no known value; skipped", key)
    return convergence_figure(
        path,
        curves,
        r"$\eta_k$",
        title=title,
        height=3.4,
        legend="outside lower center",
        note=fit_note([h["ndof"]], last),
    )


def plot_estimator(
    history: HistoryLike,
    path: str | os.PathLike,
    title: str | None = None,
    last: int | None = None,
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
    last : int, optional
        Fit the slope over the last ``last`` levels instead of the finer half of the run.

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.
    """
    if last is not None:
        check_last(last)
    h = history_columns(history, ("ndof", "eta"))
    curves = [Curve.of("eta", h["ndof"], h["eta"], last)]
    return convergence_figure(
        path, curves, r"$\eta_h$", title=title, note=fit_note([h["ndof"]], last)
    )


def plot_adaptive_vs_uniform(
    histories: Mapping[str, HistoryLike],
    path: str | os.PathLike,
    key: str = "eta",
    title: str | None = None,
    last: int | None = None,
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
    last : int, optional
        Fit the slopes over the last ``last`` levels instead of the finer half of the run.
    reference_slope : float or None, default -1.0
        Slope of the reference triangle; None draws none.

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.
    """
    if last is not None:
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
        legend="lower left",
        reference_slope=reference_slope,
        note=fit_note([h["ndof"] for h in runs.values()], last),
    )
