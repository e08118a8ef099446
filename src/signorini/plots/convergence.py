"""Convergence figures of the paper's Section 6, drawn from a history (one row per level).

- Fig. 6.1(a): energy error ``‖u − u_h‖_a`` and estimator ``η_h`` (5.1) against ``N_dof``
  (:func:`plot_error_and_estimator`); Fig. 6.1(b): the efficiency index
  ``η_h / ‖u − u_h‖_a`` (:func:`plot_efficiency`);
- Figs. 6.2 and 6.4: the contributions ``η_1 … η_7`` of (5.1) (:func:`plot_contributions`);
- Fig. 6.3(a): the estimator alone (:func:`plot_estimator`); without an estimator (3D)
  the errors against ``N_dof`` (:func:`plot_errors`);
- several runs of one quantity on one plot (:func:`plot_adaptive_vs_uniform`).

All five share one frame (:func:`~signorini.plots.frame.convergence_figure`): log ``N_dof``
axis, one styled curve per quantity with its fitted slope in the legend, a reference slope
triangle below the data, exact zeros and round-off on a ``≈0`` strip below the axes: a
contribution below ``ROUNDOFF · η_h``, and η_h or a contribution at or below the round-off
level of η_h (the history's ``eta_roundoff``, docs/method.md, *Round-off*), which is noise
and gets no slope.
The slopes are least-squares fits over the finer half of the run in log ``N_dof``
(:func:`~signorini.plots.slopes.finer_half_slope`), and the legend's title says so.
A *history* is a mapping from column name to a 1-d array, one entry per level (e.g.
:func:`~signorini.output.read_history` of a run's ``history.csv``), or the path of such a
file. ``NaN`` marks an unknown value and is not drawn.
Each function writes ``<path>.png`` and ``<path>.pdf`` and returns the written paths.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ..output.history import HistoryLike, check_last, history_columns
from .frame import Curve, convergence_figure
from .slopes import fit_note, slope_label
from .style import CONTRIBUTIONS, FRICTION_CONTRIBUTIONS, STYLES, format_number, positive

__all__ = [
    "plot_error_and_estimator",
    "plot_efficiency",
    "plot_contributions",
    "plot_estimator",
    "plot_errors",
    "plot_adaptive_vs_uniform",
]

log = logging.getLogger(__name__)

# Colours / markers of the runs compared in plot_adaptive_vs_uniform, in order.
_RUN_COLORS = ("#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2")
_RUN_MARKERS = ("s", "o", "^", "v", "D", "p", "h")


def plot_error_and_estimator(
    history: HistoryLike,
    path: str | os.PathLike,
    title: str | None = None,
    last: int | None = None,
    reference_slope: float = -1.0,
) -> list[Path]:
    """Fig. 6.1(a): energy error and estimator ``η_h`` (5.1) against ``N_dof``, log-log.

    The legend gives the slope of each curve fitted over the finer half of the run
    (:func:`~signorini.plots.slopes.finer_half_slope`) and states that range; a triangle of
    slope ``reference_slope`` (the element's optimal rate in 2D: ``N_dof^{-1}`` for P2,
    ``N_dof^{-1/2}`` for P1) is drawn below the data.

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
    reference_slope : float, default -1.0
        Slope of the reference triangle: the element's optimal rate
        (:func:`~signorini.plots.slopes.optimal_slope`: −1 for P2, −1/2 for P1).

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
    h = history_columns(history, ("ndof", "eta", "error_energy"), ("eta_roundoff",))
    ndof = h["ndof"]
    if not np.any(np.isfinite(h["error_energy"]) & (h["error_energy"] > 0)):
        raise ValueError(
            "the history has no positive finite error_energy value; plot the "
            "estimator alone with plot_estimator"
        )
    curves = [
        Curve.of("error_energy", ndof, h["error_energy"], last),
        Curve.of("eta", ndof, h["eta"], last, floor=h.get("eta_roundoff")),
    ]
    return convergence_figure(
        path,
        curves,
        "error, estimator",
        title=title,
        reference_slope=reference_slope,
        note=fit_note([ndof], last),
    )


def plot_errors(
    history: HistoryLike,
    path: str | os.PathLike,
    title: str | None = None,
    reference_slope: float = -2.0 / 3.0,
) -> list[Path]:
    """The errors against ``N_dof`` of a run without an estimator (3D, docs/method.md,
    *Three dimensions: solving elasticity*): the energy error, and where the history has
    them the H¹ seminorm and L² errors, each with its fitted slope, and a triangle of slope
    ``reference_slope`` (:func:`~signorini.plots.slopes.optimal_slope`; −2/3 for P2 in 3D).

    Parameters
    ----------
    history : mapping of str to (n_levels,) array, or path of a CSV history
        Needs ``ndof`` and ``error_energy``; ``error_h1`` and ``error_l2`` are drawn if present.
    path : str or os.PathLike
        Output path without extension.
    title : str, optional
        Axes title.
    reference_slope : float
        Slope of the reference triangle.

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.
    """
    h = history_columns(history, ("ndof", "error_energy"), ("error_h1", "error_l2"))
    ndof = h["ndof"]
    keys = [k for k in ("error_energy", "error_h1", "error_l2") if k in h]
    curves = [Curve.of(k, ndof, h[k]) for k in keys]
    return convergence_figure(
        path,
        curves,
        "error",
        title=title,
        reference_slope=reference_slope,
        note=fit_note([ndof], None),
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
    reference_slope: float = -1.0,
) -> list[Path]:
    """Figs. 6.2 / 6.4: the estimator contributions ``η_1 … η_7`` of (5.1) against ``N_dof``,
    and for a frictional run the friction work ``η_8``.

    A value that is exactly zero, or round-off (below ``ROUNDOFF`` times ``η_h`` of its level,
    :data:`~signorini.plots.frame.ROUNDOFF`; e.g. ``η_7 ≈ 1e-17``), is drawn as a hollow marker
    on the ``≈0`` strip below the log axes and left out of the fitted slope; a term that is
    zero on every level (``η_6``, ``η_7`` in Example 6.1, where the whole contact boundary is
    active) is listed as ``η_k ≡ 0``. A ``reference_slope`` triangle is drawn below the
    curves and the legend gives each fitted slope over the finer half of the run, and says so.

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
    reference_slope : float, default -1.0
        Slope of the reference triangle: the element's optimal rate
        (:func:`~signorini.plots.slopes.optimal_slope`: −1 for P2, −1/2 for P1).

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.
    """
    if last is not None:
        check_last(last)
    h = history_columns(
        history,
        ("ndof",),
        (*CONTRIBUTIONS, *FRICTION_CONTRIBUTIONS, "n_stick", "eta", "eta_roundoff"),
    )
    keys = [k for k in CONTRIBUTIONS if k in h]
    friction = [k for k in FRICTION_CONTRIBUTIONS if k in h]
    if any(np.any(h[k] > 0) for k in friction) or np.any(h.get("n_stick", 0) > 0):
        keys += friction
    if not keys:
        raise ValueError(f"the history has none of the columns {', '.join(CONTRIBUTIONS)}")
    # η_h of each level, the scale of round-off (from the terms if the column is absent)
    total = np.sqrt(sum(np.nan_to_num(h[k]) ** 2 for k in keys))
    reference = np.where(np.isfinite(h["eta"]), h["eta"], total) if "eta" in h else total
    curves: list[Curve | str] = []
    for key in keys:
        v = h[key]
        if np.any(np.isfinite(v)):
            curves.append(
                Curve.of(key, h["ndof"], v, last, reference=reference, floor=h.get("eta_roundoff"))
            )
        else:
            log.warning("estimator contribution %s has no known value; skipped", key)
    return convergence_figure(
        path,
        curves,
        r"$\eta_k$",
        title=title,
        height=3.4,
        legend="outside lower center",
        reference_slope=reference_slope,
        note=fit_note([h["ndof"]], last),
    )


def plot_estimator(
    history: HistoryLike,
    path: str | os.PathLike,
    title: str | None = None,
    last: int | None = None,
    reference_slope: float = -1.0,
) -> list[Path]:
    """Fig. 6.3(a): the estimator ``η_h`` (5.1) against ``N_dof``, log-log, with a triangle of
    the element's optimal slope (``reference_slope``).

    Parameters
    ----------
    history : mapping of str to (n_levels,) array, or path of a CSV history
        Needs the columns ``ndof`` and ``eta``.
    path : str or os.PathLike
        Output path without extension.
    title : str, optional
        Axes title.
    last : int, optional
        Fit the slopes over the last ``last`` levels instead of the finer half of the run.
    reference_slope : float, default -1.0
        Slope of the reference triangle: the element's optimal rate
        (:func:`~signorini.plots.slopes.optimal_slope`: −1 for P2, −1/2 for P1).

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.
    """
    if last is not None:
        check_last(last)
    h = history_columns(history, ("ndof", "eta"), ("eta_roundoff",))
    curves = [Curve.of("eta", h["ndof"], h["eta"], last, floor=h.get("eta_roundoff"))]
    return convergence_figure(
        path,
        curves,
        r"$\eta_h$",
        title=title,
        reference_slope=reference_slope,
        note=fit_note([h["ndof"]], last),
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
    runs = {
        str(label): history_columns(h, ("ndof", key), ("eta_roundoff",))
        for label, h in histories.items()
    }
    curves = [
        _run_curve(
            label,
            h,
            key,
            last,
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


def _run_curve(
    label: str, h: dict[str, np.ndarray], key: str, last: int | None, color: str, marker: str
) -> Curve:
    """One run of :func:`plot_adaptive_vs_uniform`; an η at or below its round-off level
    (``eta_roundoff``) is noise: out of the fit, drawn as :meth:`Curve.of` draws it."""
    values = h[key]
    floor = h.get("eta_roundoff") if key.startswith("eta") else None
    noise = None if floor is None else np.isfinite(values) & (values <= floor)
    if noise is None or not noise.any():
        return Curve(h["ndof"], values, slope_label(label, h["ndof"], values, last), color, marker)
    fitted = np.where(noise, np.nan, values)
    name = slope_label(label, h["ndof"], fitted, last) if (~noise).any() else f"{label} (noise)"
    return Curve(h["ndof"], values, name, color, marker, np.zeros(values.shape, bool), noise, floor)
