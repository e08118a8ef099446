"""Slopes on log-log convergence plots: fitted slopes in legends and reference triangles.

The triangle's geometry (:func:`triangle_vertices`) is plain NumPy on the curves' decimal
logarithms; :func:`add_slope_triangle` draws it with its two leg labels.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib.patches import Polygon
from numpy.typing import ArrayLike

from ..output.history import fitted_slope
from .style import format_number

__all__ = [
    "add_slope_triangle",
    "draw_slope_triangle",
    "fit_note",
    "fit_start",
    "finer_half_slope",
    "optimal_slope",
    "slope_label",
    "steady_slope",
    "triangle_vertices",
]


def optimal_slope(degree: int = 2, dim: int = 2) -> float:
    """The slope of the reference triangle: the optimal rate ``N_dof^{-k/d}`` of the energy
    error of elements of degree k in dimension d (``h^k`` with ``N_dof ~ h^{-d}``): in 2D
    −1 for P2, −1/2 for P1 (:attr:`Element.degree <signorini.fem.element.Element.degree>`);
    in 3D −2/3 for P2."""
    if isinstance(degree, bool) or degree not in (1, 2):
        raise ValueError(f"degree must be 1 (P1) or 2 (P2), got {degree!r}")
    if isinstance(dim, bool) or dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim!r}")
    return -int(degree) / float(dim)


def fit_start(ndof: ArrayLike) -> float:
    """First ``N_dof`` of the finer half of a run: ``sqrt(min N_dof · max N_dof)``, the middle
    of the run's ``N_dof`` range on a log scale (over all its levels, drawn or not)."""
    x = np.asarray(ndof, dtype=np.float64)
    x = x[np.isfinite(x) & (x > 0)]
    if x.size == 0:
        raise ValueError("ndof has no positive finite value")
    return float(np.sqrt(x.min() * x.max()))


def finer_half_slope(ndof: ArrayLike, values: ArrayLike) -> float:
    """Least-squares slope of ``log(values)`` against ``log(ndof)`` over the finer half of a run.

    The fit uses every level with ``N_dof >= fit_start(ndof)`` (:func:`fit_start`) and a
    positive finite value, through :func:`~signorini.output.fitted_slope`. Half the run in
    log ``N_dof`` is many levels on an adaptive run, so one level's jump (a term that is
    zero or tiny on a few levels) moves the slope little; the pre-asymptotic start is left out.

    Raises
    ------
    ValueError
        As :func:`~signorini.output.fitted_slope`, when fewer than two valid points lie in
        the finer half.
    """
    x = np.asarray(ndof, dtype=np.float64)
    y = np.asarray(values, dtype=np.float64)
    if x.ndim != 1 or x.shape != y.shape:
        raise ValueError(
            f"ndof and values must be 1-d arrays of equal length, got shapes {x.shape} and "
            f"{y.shape}"
        )
    keep = (x >= fit_start(x) * (1.0 - 1e-12)) & np.isfinite(y) & (y > 0)
    return fitted_slope(x[keep], y[keep], last=max(int(np.count_nonzero(keep)), 2))


def fit_note(ndof_runs: Sequence[ArrayLike], last: int | None = None) -> str:
    """What a legend says about its slopes: the range each one is fitted over.

    Parameters
    ----------
    ndof_runs : sequence of (n,) array_like
        ``N_dof`` of each run drawn (one entry for a figure of one run).
    last : int or None
        None: the finer half of each run (:func:`finer_half_slope`), stated as
        ``N_dof ≥`` its start when there is one run; an int: the last ``last`` levels.
    """
    if last is not None:
        return f"slopes: least squares over the last {last} levels"
    if len(ndof_runs) == 1:
        start = int(np.ceil(fit_start(ndof_runs[0]) * (1.0 - 1e-12)))
        return rf"slopes: least squares on $N_{{\mathrm{{dof}}}} \geq {start}$"
    return "slopes: least squares on the finer half of each run"


#: The largest scatter of a curve about its fitted line, as the root mean square of the
#: residuals of ``log10(values)`` (decades), for which its slope is printed.
FIT_SCATTER = 0.15


def fit_window(ndof: ArrayLike, last: int | None) -> np.ndarray:
    """(n,) bool: the levels a slope is fitted over: the finer half of the run
    (``N_dof >= fit_start(ndof)``, :func:`fit_start`) for ``last=None``, else the last
    ``last`` levels."""
    x = np.asarray(ndof, dtype=np.float64)
    if last is None:
        return x >= fit_start(x) * (1.0 - 1e-12)
    window = np.zeros(x.shape, dtype=bool)
    window[-last:] = True
    return window


def steady_slope(ndof: ArrayLike, values: ArrayLike, last: int | None = None) -> float | None:
    """The fitted slope of a curve where it means a rate, else None.

    The slope (least squares of ``log values`` against ``log N_dof`` over the levels of
    :func:`fit_window`) is a rate only if the curve is positive and finite (above round-off:
    the caller puts NaN where it is not) on *every* level of the window, and the fitted line
    describes it: the root mean square of the residuals of ``log10(values)`` is at most
    :data:`FIT_SCATTER` decades. A term that vanishes on some levels, or jumps by a decade
    inside the window, has no rate: a slope fitted to it (e.g. "slope 1.09" for a term that is
    round-off on five of nine levels) would read as divergence.

    Parameters
    ----------
    ndof, values : (n,) array_like
        ``N_dof`` and the curve's value on each level.
    last : int or None
        None: the finer half of the run; an int: the last ``last`` levels.

    Returns
    -------
    float or None
        The slope, or None when it is no rate (or fewer than two levels lie in the window).
    """
    x = np.asarray(ndof, dtype=np.float64)
    y = np.asarray(values, dtype=np.float64)
    if x.ndim != 1 or x.shape != y.shape:
        raise ValueError(
            f"ndof and values must be 1-d arrays of equal length, got shapes {x.shape} and "
            f"{y.shape}"
        )
    window = fit_window(x, last)
    xw, yw = x[window], y[window]
    if xw.size < 2 or not (np.all(np.isfinite(yw) & (yw > 0)) and np.all(xw > 0)):
        return None
    lx, ly = np.log10(xw), np.log10(yw)
    if np.ptp(lx) == 0.0:
        return None
    slope, intercept = np.polyfit(lx, ly, 1)
    scatter = float(np.sqrt(np.mean((ly - (slope * lx + intercept)) ** 2)))
    return float(slope) if scatter <= FIT_SCATTER else None


def slope_label(label: str, ndof: np.ndarray, values: np.ndarray, last: int | None) -> str:
    """``label`` followed by the fitted slope (two decimals) where it is a rate
    (:func:`steady_slope`: over the finer half of the run for ``last=None``, else over the
    last ``last`` levels), ``label (no steady rate)`` where it is not, and ``label`` alone
    when fewer than two levels have a value."""
    slope = steady_slope(ndof, values, last)
    if slope is None:
        y = np.asarray(values, dtype=np.float64)
        return (
            label if np.count_nonzero(np.isfinite(y) & (y > 0)) < 2 else f"{label} (no steady rate)"
        )
    return f"{label}, slope {format_number(slope)}"


def _valid_logs(series: Sequence[tuple[np.ndarray, np.ndarray]]) -> list[tuple[np.ndarray, ...]]:
    """``(log10 x, log10 y)`` of each curve's positive finite points sorted by x; curves
    with fewer than two such points are dropped."""
    logs = []
    for x, y in series:
        if x.shape != y.shape:
            raise ValueError(f"abscissae {x.shape} and ordinates {y.shape} differ in shape")
        ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
        if np.count_nonzero(ok) >= 2:
            order = np.argsort(x[ok], kind="stable")
            logs.append((np.log10(x[ok][order]), np.log10(y[ok][order])))
    return logs


def triangle_vertices(
    series: Sequence[tuple[np.ndarray, np.ndarray]],
    slope: float,
    where: float = 0.55,
    size: float = 0.22,
) -> np.ndarray | None:
    """Corners of a slope triangle lying just below curves ``(x, y)`` on log-log axes.

    The hypotenuse has the given slope (decades per decade). The triangle is centred at the
    fraction ``where`` of the curves' log x range, its horizontal leg spans the fraction
    ``size`` of it (between 0.15 and 1 decade), and it is pushed down until it lies below
    every curve by a gap of ``max(0.12, 6 %`` of the log y range``)`` decades. Where no curve
    covers the triangle's x range, the curves are extended flat from their ends.

    Parameters
    ----------
    series : sequence of ((n,) float array, (n,) float array)
        The curves; zero, negative and non-finite points are ignored.
    slope : float
        Slope of the hypotenuse.
    where, size : float
        Centre and width of the triangle as fractions of the log x range.

    Returns
    -------
    (3, 2) float array or None
        Start and end of the hypotenuse, then the right-angle corner, in data coordinates;
        None when no curve has two valid points.
    """
    if not (0.0 <= where <= 1.0 and 0.0 < size <= 1.0 and np.isfinite(slope)):
        raise ValueError(
            f"need 0 <= where <= 1, 0 < size <= 1 and a finite slope, got "
            f"where={where}, size={size}, slope={slope}"
        )
    logs = _valid_logs(series)
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
    return 10.0 ** np.array([[x0, y0], [x1, y1], list(corner)])


def draw_slope_triangle(
    ax: Any,
    series: Sequence[tuple[np.ndarray, np.ndarray]],
    slope: float,
    where: float = 0.55,
    size: float = 0.22,
    color: str = "0.25",
) -> Polygon | None:
    """:func:`add_slope_triangle` for curves ``(x, y)`` with their own abscissae."""
    verts = triangle_vertices(series, slope, where, size)
    if verts is None:
        return None
    (x0, y0), (x1, y1), corner = verts
    tri = Polygon(verts, closed=True, fill=False, edgecolor=color, linewidth=0.9, zorder=3)
    ax.add_patch(tri)
    # room for the "1" below the horizontal leg: 7 % of the log y range of the data
    lo, hi = sorted(ax.dataLim.intervaly)
    if lo > 0 and hi > lo:
        drop = 10.0 ** (-0.07 * np.log10(hi / lo))
        ax.update_datalim([(np.sqrt(x0 * x1), min(y0, y1) * drop)], updatex=False)
        ax.autoscale_view(scalex=False)
    ax.annotate(
        "1",
        xy=(np.sqrt(x0 * x1), min(y0, y1)),
        xytext=(0, -2),
        textcoords="offset points",
        ha="center",
        va="top",
        color=color,
    )
    left = corner[0] == x0
    ax.annotate(
        format_number(slope, 0) if float(slope).is_integer() else format_number(slope),
        xy=(corner[0], np.sqrt(y0 * y1)),
        xytext=(-3 if left else 3, 0),
        textcoords="offset points",
        ha="right" if left else "left",
        va="center",
        color=color,
    )
    return tri


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
    ``1`` and the vertical leg with the slope. Placement: :func:`triangle_vertices`.

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
    series = [(x, np.asarray(c, dtype=np.float64)) for c in curves]
    return draw_slope_triangle(ax, series, slope, where, size, color)
