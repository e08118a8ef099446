"""Figures of the paper's Section 6 (and a few more) drawn from plain data.

Every function here takes dictionaries of arrays or arrays, never the package's solver objects,
so that a figure can be redrawn from the files a run leaves on disk (``history.csv``, meshes).
The figures reproduce

- Fig. 6.1(a): energy error ``‖u − u_h‖_a`` and estimator ``η_h`` (5.1) against ``N_dof``
  (:func:`plot_error_and_estimator`), Fig. 6.1(b): the efficiency index ``η_h / ‖u − u_h‖_a``
  (:func:`plot_efficiency`);
- Figs. 6.2 and 6.4: the contributions ``η_1 … η_7`` of (5.1) (:func:`plot_contributions`);
- Fig. 6.3(a): the estimator alone (:func:`plot_estimator`) and Fig. 6.3(b): an adaptive mesh
  (:func:`plot_mesh`);

and add the deformed body with the contact pressure (:func:`plot_deformed`) and several runs
on one plot (:func:`plot_adaptive_vs_uniform`).

Conventions
-----------
- Each ``plot_*`` function writes ``<path>.png`` (150 dpi) and ``<path>.pdf``, creates the
  parent folders and returns the written paths. A ``.png`` or ``.pdf`` suffix on ``path`` is
  dropped; any other suffix is kept (``fig6.1`` gives ``fig6.1.png``).
- Figures are built on the Agg canvas without pyplot, so no figure is left open in pyplot's
  registry, nothing is shown and the caller's pyplot backend is untouched. Styling is applied
  through a local ``rc_context``; the global ``rcParams`` are not changed.
- Each quantity keeps its colour, marker and label in every figure (:data:`STYLES`).
- A *history* is a mapping from column name to a 1-d array, one entry per level, e.g. the
  result of :func:`read_history` on the ``history.csv`` of a run, or a path to such a file.
  ``NaN`` marks an unknown value; zero and ``NaN`` entries are left out of log-log plots.
"""

from __future__ import annotations

import csv
import logging
import os
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import matplotlib as mpl
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Polygon
from matplotlib.ticker import LogFormatterSciNotation, LogLocator, NullFormatter
from matplotlib.tri import Triangulation
from numpy.typing import ArrayLike

from ..mesh.mesh import boundary_edges

__all__ = [
    "STYLES",
    "read_history",
    "fitted_slope",
    "add_slope_triangle",
    "plot_error_and_estimator",
    "plot_efficiency",
    "plot_contributions",
    "plot_estimator",
    "plot_mesh",
    "plot_deformed",
    "plot_adaptive_vs_uniform",
    "make_figures",
]

log = logging.getLogger(__name__)

HistoryLike = Mapping[str, ArrayLike] | str | os.PathLike

#: Colour, marker and label of every plotted quantity, the same in all figures.
STYLES: dict[str, dict[str, str]] = {
    "error_energy": {"color": "#1f77b4", "marker": "o", "label": r"$\|u-u_h\|_a$"},
    "error_h1": {"color": "#17becf", "marker": "x", "label": r"$|u-u_h|_{H^1}$"},
    "eta": {"color": "#d62728", "marker": "s", "label": r"$\eta_h$"},
    "efficiency": {"color": "#222222", "marker": "o", "label": r"$\eta_h/\|u-u_h\|_a$"},
    "eta_1": {"color": "#ff7f0e", "marker": "^", "label": r"$\eta_1$"},
    "eta_2": {"color": "#2ca02c", "marker": "v", "label": r"$\eta_2$"},
    "eta_3": {"color": "#9467bd", "marker": "<", "label": r"$\eta_3$"},
    "eta_4": {"color": "#8c564b", "marker": ">", "label": r"$\eta_4$"},
    "eta_5": {"color": "#e377c2", "marker": "D", "label": r"$\eta_5$"},
    "eta_6": {"color": "#7f7f7f", "marker": "p", "label": r"$\eta_6$"},
    "eta_7": {"color": "#bcbd22", "marker": "h", "label": r"$\eta_7$"},
    "pressure": {"color": "#08306b", "marker": "o", "label": r"$p_h$"},
    "contact": {"color": "#d62728", "marker": "", "label": r"$\Gamma_C$"},
    "obstacle": {"color": "#333333", "marker": "", "label": "obstacle"},
}

CONTRIBUTIONS = tuple(f"eta_{k}" for k in range(1, 8))

# Colours / markers of the runs compared in plot_adaptive_vs_uniform, in order.
_RUN_COLORS = ("#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2")
_RUN_MARKERS = ("s", "o", "^", "v", "D", "p", "h")
_HIGHLIGHT_COLORS = ("#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd")

NDOF_LABEL = r"$N_{\mathrm{dof}}$"
SINGLE_COLUMN = 3.5  # inches
DPI = 150

_RC: dict[str, Any] = {
    "font.size": 8,
    "axes.labelsize": 9,
    "axes.titlesize": 9,
    "legend.fontsize": 7,
    "xtick.labelsize": 8,
    "ytick.labelsize": 8,
    "lines.linewidth": 1.2,
    "lines.markersize": 4,
    "grid.linewidth": 0.4,
    "grid.alpha": 0.45,
    "legend.framealpha": 0.9,
    "legend.handlelength": 2.0,
    "mathtext.fontset": "dejavusans",
    "axes.unicode_minus": True,
    "pdf.fonttype": 42,
    "ps.fonttype": 42,
    "savefig.dpi": DPI,
}


# ---------------------------------------------------------------------------------------------
# history table
# ---------------------------------------------------------------------------------------------
def _parse_column(name: str, values: list[str]) -> np.ndarray:
    """Integer, float (empty -> NaN) or str array from the text entries of one CSV column."""
    text = [v.strip() for v in values]
    filled = [v for v in text if v]
    if not filled:
        return np.array(text, dtype=str)
    if len(filled) == len(text):
        try:
            return np.array([int(v) for v in text], dtype=np.int64)
        except ValueError:
            pass
    try:
        return np.array([float(v) if v else np.nan for v in text], dtype=np.float64)
    except ValueError:
        return np.array(values, dtype=str)


def read_history(path: str | os.PathLike) -> dict[str, np.ndarray]:
    """Read a convergence history written as CSV (one row per level, a header line first).

    Parameters
    ----------
    path : str or os.PathLike
        CSV file, e.g. the ``history.csv`` of a run.

    Returns
    -------
    dict of str to (n_levels,) array
        One array per column, in the file's column order: ``int64`` when every entry is an
        integer, ``float64`` when every non-empty entry is a number (empty entries and
        ``nan`` become NaN), otherwise ``str``.

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    ValueError
        If the file has no header, repeated or empty column names, or a row whose number of
        fields differs from the header's.
    """
    path = Path(path)
    with path.open(newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    rows = [r for r in rows if r]  # blank lines
    if not rows:
        raise ValueError(f"{path}: empty file, expected a CSV header line")
    header = [h.strip() for h in rows[0]]
    if any(not h for h in header):
        raise ValueError(f"{path}: empty column name in the header {header}")
    if len(set(header)) != len(header):
        dup = sorted({h for h in header if header.count(h) > 1})
        raise ValueError(f"{path}: repeated column name(s) {dup}")
    body = rows[1:]
    for i, r in enumerate(body, start=2):
        if len(r) != len(header):
            raise ValueError(f"{path}: line {i} has {len(r)} fields, the header has {len(header)}")
    columns = list(zip(*body, strict=True)) if body else [()] * len(header)
    return {h: _parse_column(h, list(c)) for h, c in zip(header, columns, strict=True)}


def _history(
    history: HistoryLike, required: Sequence[str], optional: Sequence[str] = ()
) -> dict[str, np.ndarray]:
    """Float columns ``required`` (all) and ``optional`` (when present) of a history."""
    if isinstance(history, (str, os.PathLike)):
        history = read_history(history)
    if not isinstance(history, Mapping):
        raise ValueError(
            "a history must be a mapping from column name to 1-d array, or the "
            f"path of a CSV file; got {type(history).__name__}"
        )
    missing = [k for k in required if k not in history]
    if missing:
        raise ValueError(f"the history lacks column(s) {missing}; it has {sorted(history)}")
    out: dict[str, np.ndarray] = {}
    for key in [*required, *(k for k in optional if k in history)]:
        a = np.asarray(history[key])
        if a.ndim != 1:
            raise ValueError(f"history column {key!r} must be 1-d, got shape {a.shape}")
        try:
            out[key] = a.astype(np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"history column {key!r} is not numeric") from None
    lengths = {k: v.size for k, v in out.items()}
    if len(set(lengths.values())) > 1:
        raise ValueError(f"history columns have different lengths: {lengths}")
    if "ndof" in out:
        ndof = out["ndof"]
        if ndof.size == 0:
            raise ValueError("the history is empty (no levels)")
        if not np.all(np.isfinite(ndof) & (ndof > 0)):
            raise ValueError(f"ndof must be positive and finite, got {ndof}")
    return out


# ---------------------------------------------------------------------------------------------
# slopes
# ---------------------------------------------------------------------------------------------
def _check_last(last: object) -> None:
    if isinstance(last, bool) or not isinstance(last, (int, np.integer)) or last < 2:
        raise ValueError(f"last must be an integer >= 2, got {last!r}")


def fitted_slope(ndof: ArrayLike, values: ArrayLike, last: int = 3) -> float:
    """Least-squares slope of ``log(values)`` against ``log(ndof)`` over the last points.

    Points where ``ndof`` or ``values`` is zero, negative or not finite are dropped first;
    the fit then uses the last ``last`` of the remaining points (all of them if fewer).

    Parameters
    ----------
    ndof : (n,) array_like of float
        Numbers of degrees of freedom, one per level.
    values : (n,) array_like of float
        The quantity, e.g. ``eta`` or ``error_energy``.
    last : int, default 3
        How many of the last valid points to fit (at least 2).

    Returns
    -------
    float
        The observed rate, e.g. ``-1`` for a quantity decaying like ``N_dof^{-1}``.

    Raises
    ------
    ValueError
        If the arrays are not 1-d of equal length, ``last < 2``, fewer than two valid points
        remain, or all remaining points have the same ``ndof``.
    """
    _check_last(last)
    try:
        x = np.asarray(ndof, dtype=np.float64)
        y = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError("ndof and values must be numeric arrays") from None
    if x.ndim != 1 or y.ndim != 1 or x.shape != y.shape:
        raise ValueError(
            f"ndof and values must be 1-d arrays of equal length, got shapes "
            f"{x.shape} and {y.shape}"
        )
    keep = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    lx, ly = np.log(x[keep])[-last:], np.log(y[keep])[-last:]
    if lx.size < 2:
        raise ValueError(f"a slope needs at least 2 positive finite points, got {lx.size}")
    dx = lx - lx.mean()
    sxx = float(dx @ dx)
    if sxx == 0.0:
        raise ValueError("a slope needs at least 2 distinct ndof values")
    return float(dx @ (ly - ly.mean())) / sxx


def _fmt_number(value: float, digits: int = 2) -> str:
    return f"{value:.{digits}f}".replace("-", "\u2212")


def _slope_label(label: str, ndof: np.ndarray, values: np.ndarray, last: int) -> str:
    """``label`` followed by the fitted slope, or ``label`` alone when there is no slope."""
    try:
        return f"{label}, slope {_fmt_number(fitted_slope(ndof, values, last))}"
    except ValueError:
        return label


def add_slope_triangle(
    ax: Any,
    ndof: ArrayLike,
    curves: Sequence[ArrayLike],
    slope: float = -1.0,
    where: float = 0.55,
    size: float = 0.22,
    color: str = "0.25",
) -> Polygon | None:
    """Draw a slope triangle just below the curves of a log-log plot.

    The hypotenuse has the given slope (in decades per decade); the horizontal leg is labelled
    ``1`` and the vertical leg with the slope. The triangle is centred at the fraction
    ``where`` of the (logarithmic) ``ndof`` range, its horizontal leg spans the fraction
    ``size`` of it, and it is pushed down until it lies below every curve with a small gap.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Axes with logarithmic x and y scales.
    ndof : (n,) array_like of float
        Abscissae shared by the curves.
    curves : sequence of (n,) array_like of float
        Ordinates; zero or NaN entries are ignored.
    slope : float, default -1.0
        Slope of the hypotenuse.
    where, size : float
        Centre and width of the triangle as fractions of the log ``ndof`` range.
    color : str
        Colour of the triangle and its labels.

    Returns
    -------
    matplotlib.patches.Polygon or None
        The triangle, or None when no curve has two valid points.
    """
    x = np.asarray(ndof, dtype=np.float64)
    return _place_triangle(
        ax, [(x, np.asarray(c, dtype=np.float64)) for c in curves], slope, where, size, color
    )


def _place_triangle(
    ax: Any,
    series: Sequence[tuple[np.ndarray, np.ndarray]],
    slope: float,
    where: float = 0.55,
    size: float = 0.22,
    color: str = "0.25",
) -> Polygon | None:
    """:func:`add_slope_triangle` for curves ``(x, y)`` with their own abscissae."""
    if not (0.0 <= where <= 1.0 and 0.0 < size <= 1.0 and np.isfinite(slope)):
        raise ValueError(
            f"need 0 <= where <= 1, 0 < size <= 1 and a finite slope, got "
            f"where={where}, size={size}, slope={slope}"
        )
    logs = []
    for x, y in series:
        if x.shape != y.shape:
            raise ValueError(f"abscissae {x.shape} and ordinates {y.shape} differ in shape")
        ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
        if np.count_nonzero(ok) >= 2:
            order = np.argsort(x[ok], kind="stable")
            logs.append((np.log10(x[ok][order]), np.log10(y[ok][order])))
    if not logs:
        return None
    lo = min(a[0] for a, _ in logs)
    hi = max(a[-1] for a, _ in logs)
    span = hi - lo
    run = float(np.clip(size * span, 0.15, 1.0)) if span > 0 else 0.3
    x0 = lo + where * span - run / 2
    x1 = x0 + run
    yspan = max(b.max() for _, b in logs) - min(b.min() for _, b in logs)
    gap = max(0.12, 0.06 * yspan)
    t = np.linspace(x0, x1, 9)
    # Highest start y0 with y0 + slope (t - x0) <= curve(t) - gap for every curve and every t
    # inside that curve's range (clamped to the curves' ends if no curve covers any t).
    bounds = []
    for a, b in logs:
        inside = (t >= a[0]) & (t <= a[-1])
        if inside.any():
            ti = t[inside]
            bounds.append(np.min(np.interp(ti, a, b) - gap - slope * (ti - x0)))
    if not bounds:
        bounds = [np.min(np.interp(t, a, b) - gap - slope * (t - x0)) for a, b in logs]
    y0 = float(min(bounds))
    y1 = y0 + slope * run
    corner = (x1, y0) if slope > 0 else (x0, y1)
    verts = 10.0 ** np.array([[x0, y0], [x1, y1], list(corner)])
    tri = Polygon(verts, closed=True, fill=False, edgecolor=color, linewidth=0.9, zorder=3)
    ax.add_patch(tri)
    ax.annotate(
        "1",
        xy=(10 ** ((x0 + x1) / 2), 10 ** min(y0, y1)),
        xytext=(0, -2),
        textcoords="offset points",
        ha="center",
        va="top",
        color=color,
    )
    left = corner[0] == x0
    ax.annotate(
        _fmt_number(slope, 0) if float(slope).is_integer() else _fmt_number(slope),
        xy=(10 ** corner[0], 10 ** ((y0 + y1) / 2)),
        xytext=(-3 if left else 3, 0),
        textcoords="offset points",
        ha="right" if left else "left",
        va="center",
        color=color,
    )
    return tri


# ---------------------------------------------------------------------------------------------
# figure plumbing
# ---------------------------------------------------------------------------------------------
def _stem(path: str | os.PathLike) -> Path:
    p = Path(path)
    if p.suffix.lower() in (".png", ".pdf"):
        p = p.with_suffix("")
    if not p.name or p.name in (".", ".."):
        raise ValueError(f"not a file path for a figure: {str(path)!r}")
    return p


def _new_figure(width: float = SINGLE_COLUMN, height: float = 2.7) -> Figure:
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _save(fig: Figure, path: str | os.PathLike) -> list[Path]:
    """Write ``<path>.png`` and ``<path>.pdf`` and release the figure's artists."""
    stem = _stem(path)
    stem.parent.mkdir(parents=True, exist_ok=True)
    written = [stem.with_name(stem.name + ".png"), stem.with_name(stem.name + ".pdf")]
    try:
        fig.savefig(written[0], dpi=DPI)
        fig.savefig(written[1], metadata={"CreationDate": None})
    finally:
        fig.clear()
    log.info("wrote %s", ", ".join(str(p) for p in written))
    return written


def _positive(values: np.ndarray) -> np.ndarray:
    """Copy with zero, negative and non-finite entries replaced by NaN (gaps on log axes)."""
    out = np.array(values, dtype=np.float64)
    out[~(np.isfinite(out) & (out > 0))] = np.nan
    return out


def _loglog(ax: Any, ylabel: str) -> None:
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.grid(True, which="major", linestyle="-")
    ax.grid(True, which="minor", linestyle=":", alpha=0.3)
    ax.set_xlabel(NDOF_LABEL)
    ax.set_ylabel(ylabel)


def _tidy_log_ticks(ax: Any) -> None:
    """Label only major ticks; below two decades add 2 and 5 times powers of ten as majors.

    Matplotlib otherwise labels minor ticks on short log axes, and the labels overlap.
    """
    for axis, (lo, hi) in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
        if axis.get_scale() != "log":
            continue
        axis.set_minor_formatter(NullFormatter())
        if lo > 0 and np.log10(hi / lo) < 2.0:
            axis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))
            axis.set_major_formatter(
                LogFormatterSciNotation(labelOnlyBase=False, minor_thresholds=(np.inf, np.inf))
            )


def _plot_quantity(
    ax: Any, ndof: np.ndarray, values: np.ndarray, key: str, label: str, **kw: Any
) -> Any:
    style = STYLES[key]
    (line,) = ax.plot(
        ndof, _positive(values), color=style["color"], marker=style["marker"], label=label, **kw
    )
    return line


# ---------------------------------------------------------------------------------------------
# Section 6 figures
# ---------------------------------------------------------------------------------------------
def plot_error_and_estimator(
    history: HistoryLike, path: str | os.PathLike, title: str | None = None, last: int = 3
) -> list[Path]:
    """Fig. 6.1(a): energy error and estimator ``η_h`` (5.1) against ``N_dof``, log-log.

    The legend gives the slope of each curve fitted over the last ``last`` levels
    (:func:`fitted_slope`); a slope −1 triangle (the optimal rate of P2 in 2D,
    ``N_dof^{-1}``) is drawn below the data.

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
    _check_last(last)
    h = _history(history, ("ndof", "eta", "error_energy"))
    ndof, eta, err = h["ndof"], h["eta"], h["error_energy"]
    if not np.any(np.isfinite(err) & (err > 0)):
        raise ValueError(
            "the history has no positive finite error_energy value; plot the "
            "estimator alone with plot_estimator"
        )
    with mpl.rc_context(_RC):
        fig = _new_figure()
        ax = fig.add_subplot()
        _loglog(ax, "error, estimator")
        _plot_quantity(
            ax,
            ndof,
            err,
            "error_energy",
            _slope_label(STYLES["error_energy"]["label"], ndof, err, last),
        )
        _plot_quantity(ax, ndof, eta, "eta", _slope_label(STYLES["eta"]["label"], ndof, eta, last))
        add_slope_triangle(ax, ndof, [err, eta], slope=-1.0)
        ax.legend(loc="upper right")
        if title:
            ax.set_title(title)
        _tidy_log_ticks(ax)
        return _save(fig, path)


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
    h = _history(history, ("ndof",), ("efficiency", "eta", "error_energy"))
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
    eff = np.where(np.isfinite(eff) & (eff > 0), eff, np.nan)
    if np.all(np.isnan(eff)):
        raise ValueError("the history has no positive finite efficiency index")
    style = STYLES["efficiency"]
    with mpl.rc_context(_RC):
        fig = _new_figure()
        ax = fig.add_subplot()
        ax.set_xscale("log")
        ax.grid(True, which="major", linestyle="-")
        ax.grid(True, which="minor", axis="x", linestyle=":", alpha=0.3)
        ax.plot(ndof, eff, color=style["color"], marker=style["marker"], label=style["label"])
        mean = float(np.nanmean(eff))
        ax.axhline(
            mean, color="0.5", linestyle="--", linewidth=0.8, label=f"mean {_fmt_number(mean)}"
        )
        ax.set_ylim(0.0, 1.2 * float(np.nanmax(eff)))
        ax.set_xlabel(NDOF_LABEL)
        ax.set_ylabel(r"efficiency index $\eta_h/\|u-u_h\|_a$")
        ax.legend(loc="lower right")
        if title:
            ax.set_title(title)
        _tidy_log_ticks(ax)
        return _save(fig, path)


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
    _check_last(last)
    h = _history(history, ("ndof",), CONTRIBUTIONS)
    keys = [k for k in CONTRIBUTIONS if k in h]
    if not keys:
        raise ValueError("the history has none of the columns eta_1 ... eta_7")
    ndof = h["ndof"]
    with mpl.rc_context(_RC):
        fig = _new_figure(height=3.3)
        ax = fig.add_subplot()
        _loglog(ax, r"$\eta_k$")
        drawn, handles = [], []
        for key in keys:
            v = h[key]
            label = STYLES[key]["label"]
            if np.any(np.isfinite(v) & (v > 0)):
                handles.append(_plot_quantity(ax, ndof, v, key, _slope_label(label, ndof, v, last)))
                drawn.append(v)
            elif np.any(v == 0):
                handles.append(
                    Line2D([], [], linestyle="none", marker="", label=label[:-1] + r" \equiv 0$")
                )
            else:
                log.warning("estimator contribution %s has no known value; skipped", key)
        add_slope_triangle(ax, ndof, drawn, slope=-1.0)
        fig.legend(handles=handles, loc="outside lower center", ncols=2)
        if title:
            ax.set_title(title)
        _tidy_log_ticks(ax)
        return _save(fig, path)


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
    _check_last(last)
    h = _history(history, ("ndof", "eta"))
    ndof, eta = h["ndof"], h["eta"]
    with mpl.rc_context(_RC):
        fig = _new_figure()
        ax = fig.add_subplot()
        _loglog(ax, r"$\eta_h$")
        _plot_quantity(ax, ndof, eta, "eta", _slope_label(STYLES["eta"]["label"], ndof, eta, last))
        add_slope_triangle(ax, ndof, [eta], slope=-1.0)
        ax.legend(loc="upper right")
        if title:
            ax.set_title(title)
        _tidy_log_ticks(ax)
        return _save(fig, path)


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
    _check_last(last)
    if not isinstance(histories, Mapping) or not histories:
        raise ValueError("histories must be a non-empty mapping from label to history")
    runs = {str(label): _history(h, ("ndof", key)) for label, h in histories.items()}
    ylabel = STYLES[key]["label"] if key in STYLES else key.replace("_", " ")
    with mpl.rc_context(_RC):
        fig = _new_figure(height=3.0)
        ax = fig.add_subplot()
        _loglog(ax, ylabel)
        for i, (label, h) in enumerate(runs.items()):
            ax.plot(
                h["ndof"],
                _positive(h[key]),
                color=_RUN_COLORS[i % len(_RUN_COLORS)],
                marker=_RUN_MARKERS[i % len(_RUN_MARKERS)],
                label=_slope_label(label, h["ndof"], h[key], last),
            )
        if reference_slope is not None:
            _place_triangle(
                ax, [(h["ndof"], h[key]) for h in runs.values()], slope=float(reference_slope)
            )
        ax.legend(loc="best")
        if title:
            ax.set_title(title)
        _tidy_log_ticks(ax)
        return _save(fig, path)


# ---------------------------------------------------------------------------------------------
# meshes and solutions
# ---------------------------------------------------------------------------------------------
def _mesh_arrays(points: ArrayLike, cells: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    try:
        p = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError("points must be a numeric (n_points, 2) array") from None
    if p.ndim != 2 or p.shape[1] != 2 or p.shape[0] < 3:
        raise ValueError(f"points must have shape (n_points >= 3, 2), got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError("points contain NaN or inf")
    c = np.asarray(cells)
    if c.ndim != 2 or c.shape[1] != 3 or c.shape[0] == 0:
        raise ValueError(f"cells must have shape (n_cells >= 1, 3), got {c.shape}")
    if not np.issubdtype(c.dtype, np.integer):
        raise ValueError(f"cells must be an integer array, got dtype {c.dtype}")
    if c.min() < 0 or c.max() >= p.shape[0]:
        raise ValueError(
            f"cells refer to vertices outside 0..{p.shape[0] - 1} (range {c.min()}..{c.max()})"
        )
    return p, c.astype(np.int64)


def _edge_pairs(edges: ArrayLike, n_points: int, what: str) -> np.ndarray:
    e = np.asarray(edges)
    if e.size == 0:
        return np.zeros((0, 2), dtype=np.int64)
    if e.ndim != 2 or e.shape[1] != 2 or not np.issubdtype(e.dtype, np.integer):
        raise ValueError(
            f"{what} must be an integer (k, 2) array of vertex pairs, got shape "
            f"{e.shape} and dtype {e.dtype}"
        )
    if e.min() < 0 or e.max() >= n_points:
        raise ValueError(f"{what} refer to vertices outside 0..{n_points - 1}")
    return e.astype(np.int64)


def _line_width(n_cells: int) -> float:
    """Mesh line width in points: thinner as the mesh gets finer."""
    return float(np.clip(0.8 * np.sqrt(400.0 / max(n_cells, 1)), 0.1, 0.8))


def plot_mesh(
    points: ArrayLike,
    cells: ArrayLike,
    path: str | os.PathLike,
    title: str | None = None,
    highlight: ArrayLike | Mapping[str, ArrayLike] | None = None,
    highlight_label: str = r"contact boundary $\Gamma_C$",
) -> list[Path]:
    """Fig. 6.3(b): a triangulation, thin lines, equal aspect, with boundary edges highlighted.

    Parameters
    ----------
    points : (n_points, 2) float array
        Vertex coordinates.
    cells : (n_cells, 3) int array
        Triangles.
    path : str or os.PathLike
        Output path without extension.
    title : str, optional
        Axes title.
    highlight : (k, 2) int array or mapping of str to (k, 2) int array, optional
        Vertex pairs of edges drawn thick (e.g. the contact boundary, in red); a mapping
        draws several groups, each labelled with its key.
    highlight_label : str
        Legend label of ``highlight`` when it is a single array.

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.
    """
    p, c = _mesh_arrays(points, cells)
    if highlight is None:
        groups: dict[str, np.ndarray] = {}
    elif isinstance(highlight, Mapping):
        groups = {str(k): _edge_pairs(v, len(p), f"highlight[{k!r}]") for k, v in highlight.items()}
    else:
        groups = {highlight_label: _edge_pairs(highlight, len(p), "highlight")}
    big = c.shape[0] > 20000
    with mpl.rc_context(_RC):
        fig = _new_figure(height=SINGLE_COLUMN)
        ax = fig.add_subplot()
        ax.triplot(
            Triangulation(p[:, 0], p[:, 1], c),
            color="0.15",
            linewidth=_line_width(c.shape[0]),
            rasterized=big,
        )
        for i, (label, e) in enumerate(groups.items()):
            if e.shape[0] == 0:
                continue
            color = _HIGHLIGHT_COLORS[i % len(_HIGHLIGHT_COLORS)]
            ax.add_collection(
                LineCollection(
                    p[e], colors=color, linewidths=2.0, label=label, zorder=4, capstyle="round"
                )
            )
        ax.set_aspect("equal")
        ax.set_xlabel(r"$x$")
        ax.set_ylabel(r"$y$")
        ax.autoscale_view()
        if any(e.shape[0] for e in groups.values()):
            fig.legend(loc="outside lower center", ncols=min(len(groups), 3))
        if title:
            ax.set_title(title)
        return _save(fig, path)


def _vertex_displacement(displacement: ArrayLike, n_points: int) -> np.ndarray:
    """(n_points, 2) vertex displacement from ``(m, 2)`` or interleaved ``(2 m,)``, m >= n."""
    try:
        u = np.asarray(displacement, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError("displacement must be a numeric array") from None
    if u.ndim == 1 and u.size % 2 == 0:
        u = u.reshape(-1, 2)
    if u.ndim != 2 or u.shape[1] != 2 or u.shape[0] < n_points:
        raise ValueError(
            f"displacement must have shape (m, 2) or (2 m,) with m >= n_points = "
            f"{n_points}, got {np.shape(displacement)}"
        )
    u = u[:n_points]
    if not np.all(np.isfinite(u)):
        raise ValueError("displacement contains NaN or inf")
    return u


def _contact_coordinate(cp: np.ndarray) -> tuple[np.ndarray, str]:
    """Abscissa along the contact boundary: x or y for an axis-parallel one, else arclength."""
    span = np.ptp(cp, axis=0)
    tol = 1e-12 * max(float(span.max()), 1.0)
    if span[1] <= tol:
        return cp[:, 0], r"$x$"
    if span[0] <= tol:
        return cp[:, 1], r"$y$"
    centred = cp - cp.mean(axis=0)
    direction = np.linalg.svd(centred, full_matrices=False)[2][0]
    if direction[np.argmax(np.abs(direction))] < 0:
        direction = -direction
    t = centred @ direction
    return t - t.min(), r"$s$ (along $\Gamma_C$)"


def plot_deformed(
    points: ArrayLike,
    cells: ArrayLike,
    displacement: ArrayLike,
    path: str | os.PathLike,
    contact_points: ArrayLike | None = None,
    pressure: ArrayLike | None = None,
    scale: float = 1.0,
    obstacle: ArrayLike | None = None,
    title: str | None = None,
    show_mesh: bool = True,
) -> list[Path]:
    """The deformed body coloured by ``|u_h|``, and the contact pressure along ``Γ_C``.

    The body is drawn at ``points + scale * displacement`` (vertices only; the P2 solution is
    drawn piecewise linearly), coloured by the unscaled ``|u_h|`` with Gouraud shading; the
    reference configuration's boundary is dashed. When ``pressure`` is given, a second axes
    below shows it against the coordinate along the contact boundary (``x`` or ``y`` for an
    axis-parallel ``Γ_C``, arclength otherwise).

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
    contact_points : (k, 2) float array, optional
        Reference coordinates of the contact nodes (needed with ``pressure``).
    pressure : (k,) float array, optional
        Contact pressure at ``contact_points`` (e.g. ``p_z`` of docs/method.md, *Discrete problem*).
    scale : float, default 1.0
        Magnification of the displacement in the drawing.
    obstacle : (j, 2) float array, optional
        Polyline of the obstacle in physical coordinates, drawn on the body's axes.
    title : str, optional
        Title of the body's axes.
    show_mesh : bool, default True
        Draw the deformed triangulation with faint lines.

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF files written.
    """
    p, c = _mesh_arrays(points, cells)
    u = _vertex_displacement(displacement, p.shape[0])
    scale = float(scale)
    if not np.isfinite(scale):
        raise ValueError(f"scale must be finite, got {scale}")
    if (contact_points is None) != (pressure is None):
        raise ValueError("contact_points and pressure must be given together")
    if pressure is not None:
        cp = np.asarray(contact_points, dtype=np.float64)
        pr = np.asarray(pressure, dtype=np.float64)
        if cp.ndim != 2 or cp.shape[1] != 2 or cp.shape[0] == 0:
            raise ValueError(f"contact_points must have shape (k >= 1, 2), got {cp.shape}")
        if pr.shape != (cp.shape[0],):
            raise ValueError(
                f"pressure must have shape ({cp.shape[0]},) to match contact_points, got {pr.shape}"
            )
    if obstacle is not None:
        obs = np.asarray(obstacle, dtype=np.float64)
        if obs.ndim != 2 or obs.shape[1] != 2 or obs.shape[0] < 2:
            raise ValueError(f"obstacle must be a (j >= 2, 2) polyline, got {obs.shape}")
    q = p + scale * u
    magnitude = np.hypot(u[:, 0], u[:, 1])
    big = c.shape[0] > 20000
    with mpl.rc_context(_RC):
        if pressure is None:
            fig = _new_figure(height=3.0)
            ax = fig.add_subplot()
        else:
            fig = _new_figure(height=4.8)
            ax, axp = fig.subplots(2, 1, gridspec_kw={"height_ratios": [2.4, 1.0]})
        tri = Triangulation(q[:, 0], q[:, 1], c)
        image = ax.tripcolor(tri, magnitude, shading="gouraud", cmap="viridis", rasterized=big)
        if show_mesh:
            ax.triplot(
                tri,
                color="white",
                alpha=0.35,
                linewidth=0.5 * _line_width(c.shape[0]),
                rasterized=big,
            )
        ref = LineCollection(
            p[boundary_edges(c)],
            colors="0.4",
            linewidths=0.8,
            linestyles="--",
            label="reference",
            zorder=2,
        )
        ax.add_collection(ref)
        if obstacle is not None:
            st = STYLES["obstacle"]
            ax.plot(
                obs[:, 0], obs[:, 1], color=st["color"], linewidth=2.0, label=st["label"], zorder=5
            )
        ax.set_aspect("equal")
        ax.autoscale_view()
        ax.set_xlabel(r"$x$")
        ax.set_ylabel(r"$y$")
        cax = ax.inset_axes((1.04, 0.0, 0.05, 1.0))  # follows the equal-aspect box
        fig.colorbar(image, cax=cax, label=r"$|u_h|$")
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncols=2, frameon=False)
        heading = (
            title
            if title
            else ("deformed body" + (f" (displacement \u00d7{scale:g})" if scale != 1.0 else ""))
        )
        ax.set_title(heading)
        if pressure is not None:
            t, tlabel = _contact_coordinate(cp)
            order = np.argsort(t, kind="stable")
            st = STYLES["pressure"]
            axp.plot(
                t[order],
                pr[order],
                color=st["color"],
                marker=st["marker"] if t.size <= 80 else "",
                markersize=2.5,
                label=st["label"],
            )
            axp.axhline(0.0, color="0.5", linewidth=0.6)
            axp.grid(True, linestyle="-")
            axp.set_xlabel(tlabel)
            axp.set_ylabel(r"contact pressure $p_h$")
        return _save(fig, path)


# ---------------------------------------------------------------------------------------------
# all figures of an example
# ---------------------------------------------------------------------------------------------
def _example_kind(name: str) -> str | None:
    m = re.search(r"6\s*[._-]?\s*([12])(?!\d)", name)
    return f"6.{m.group(1)}" if m else None


def make_figures(
    history_path: str | os.PathLike, out_dir: str | os.PathLike, example_name: str
) -> list[Path]:
    """The convergence figures of one example, drawn from its ``history.csv``.

    - Example 6.1 (names like ``"example-6.1"``, ``"6.1"``): error and estimator
      (Fig. 6.1(a)), efficiency index (Fig. 6.1(b)), contributions (Fig. 6.2).
    - Example 6.2: estimator (Fig. 6.3(a)) and contributions (Fig. 6.4).
    - Any other name: the 6.1 set when the history has a known ``error_energy``, else the
      6.2 set.

    Meshes and deformed bodies need more than the history; callers draw them with
    :func:`plot_mesh` and :func:`plot_deformed`.

    Parameters
    ----------
    history_path : str or os.PathLike
        The run's CSV history.
    out_dir : str or os.PathLike
        Folder for the figures (created if needed); files are named
        ``<example>_<figure>.png`` / ``.pdf``.
    example_name : str
        Name of the example, used to choose the figures and name the files.

    Returns
    -------
    list of pathlib.Path
        All files written.
    """
    history = read_history(history_path)
    slug = re.sub(r"[^A-Za-z0-9._-]+", "_", str(example_name)).strip("_.") or "example"
    out = Path(out_dir)
    kind = _example_kind(str(example_name))
    if kind is None:
        err = np.asarray(history.get("error_energy", [np.nan]), dtype=np.float64)
        kind = "6.1" if np.any(np.isfinite(err) & (err > 0)) else "6.2"
    written: list[Path] = []
    if kind == "6.1":
        written += plot_error_and_estimator(history, out / f"{slug}_error_estimator")
        written += plot_efficiency(history, out / f"{slug}_efficiency")
    else:
        written += plot_estimator(history, out / f"{slug}_estimator")
    written += plot_contributions(history, out / f"{slug}_contributions")
    return written
