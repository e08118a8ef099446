"""The look shared by every figure: styles, figure creation, saving and log axes.

- Figures are built on the Agg canvas without pyplot, so no figure is left open in pyplot's
  registry, nothing is shown and the caller's pyplot backend is untouched. Styling is applied
  through a local ``rc_context`` (:data:`RC`); the global ``rcParams`` are not changed.
- Each quantity keeps its colour, marker and label in every figure (:data:`STYLES`).
- :func:`save_figure` writes ``<path>.png`` (150 dpi) and ``<path>.pdf`` and creates the
  parent folders. A ``.png`` or ``.pdf`` suffix on ``path`` is dropped; any other suffix is
  kept (``fig6.1`` gives ``fig6.1.png``).
"""

from __future__ import annotations

import logging
import os
import textwrap
from pathlib import Path
from typing import Any

import matplotlib as mpl
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.font_manager import FontProperties
from matplotlib.ticker import FixedLocator, LogFormatterSciNotation, LogLocator, NullFormatter

from ..estimator.names import TERM_TABLE
from ..output.files import replacing

__all__ = [
    "STYLES",
    "CONTRIBUTIONS",
    "FRICTION_CONTRIBUTIONS",
    "TERM_LOOKS",
    "RC",
    "DPI",
    "SINGLE_COLUMN",
    "NDOF_LABEL",
    "new_figure",
    "save_figure",
    "positive",
    "log_log_axes",
    "tidy_log_ticks",
    "log_tick_sets",
    "format_number",
    "fit_title",
    "trim_height",
]

log = logging.getLogger(__name__)

#: The history columns of the estimator's contributions η_1 … η_7 (paper, (5.1)).
CONTRIBUTIONS = tuple(term.name for term in TERM_TABLE if not term.friction)

#: The history columns of the contributions of frictional runs only: the friction work η_8
#: (docs/method.md, *Estimator*, "With friction").
FRICTION_CONTRIBUTIONS = tuple(term.name for term in TERM_TABLE if term.friction)

#: Colour and marker of each estimator term, in the order of
#: :data:`~signorini.estimator.names.TERM_TABLE`.
TERM_LOOKS: tuple[tuple[str, str], ...] = (
    ("#ff7f0e", "^"),
    ("#2ca02c", "v"),
    ("#9467bd", "<"),
    ("#8c564b", ">"),
    ("#e377c2", "D"),
    ("#7f7f7f", "p"),
    ("#bcbd22", "h"),
    ("#393b79", "*"),
)

#: Colour, marker and label of every plotted quantity (keyed by its history column), the
#: same in all figures.
STYLES: dict[str, dict[str, str]] = {
    "error_energy": {"color": "#1f77b4", "marker": "o", "label": r"$\|u-u_h\|_a$"},
    "error_h1": {"color": "#17becf", "marker": "x", "label": r"$|u-u_h|_{H^1}$"},
    "error_l2": {"color": "#9467bd", "marker": "^", "label": r"$\|u-u_h\|_{L^2}$"},
    "eta": {"color": "#d62728", "marker": "s", "label": r"$\eta_h$"},
    "efficiency": {"color": "#222222", "marker": "o", "label": r"$\eta_h/\|u-u_h\|_a$"},
    **{
        term.name: {"color": color, "marker": marker, "label": term.label}
        for term, (color, marker) in zip(TERM_TABLE, TERM_LOOKS, strict=True)
    },
    "pressure": {"color": "#08306b", "marker": "o", "label": r"$p_h$"},
    "contact": {"color": "#d62728", "marker": "", "label": r"$\Gamma_C$"},
    "obstacle": {"color": "#333333", "marker": "", "label": "obstacle"},
}

NDOF_LABEL = r"$N_{\mathrm{dof}}$"
SINGLE_COLUMN = 3.5  # inches
DPI = 150

#: Local matplotlib settings of every figure.
RC: dict[str, Any] = {
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


def format_number(value: float, digits: int = 2) -> str:
    """``value`` with ``digits`` decimals and a typographic minus sign."""
    return f"{value:.{digits}f}".replace("-", "\u2212")


def fit_title(title: str, fig: Figure, share: float = 0.9) -> str:
    """``title`` with its lines wrapped at spaces to fit ``share`` of the figure's width.

    The width of a character is taken as 0.6 em of the title font (DejaVu Sans averages
    about 0.55 em), so a wrapped line is not wider than the figure and is not clipped. A line
    with mathtext (``$``) is not wrapped.
    """
    size = FontProperties(size=mpl.rcParams["axes.titlesize"]).get_size_in_points()
    chars = max(int(share * fig.get_figwidth() * 72.0 / (0.6 * size)), 10)
    lines = []
    for line in str(title).splitlines() or [""]:
        if "$" in line:  # mathtext: a break inside $...$ would not render; left as is
            lines.append(line)
            continue
        lines += textwrap.wrap(line, chars, break_long_words=False, break_on_hyphens=False) or [""]
    return "\n".join(lines)


def trim_height(fig: Figure, passes: int = 3, pad: float = 0.06) -> None:
    """Lower the figure to what its content needs, plus ``pad`` inches above and below.

    An equal-aspect box (a body, a mesh) keeps its shape inside the cell the layout gives it;
    when the cell is taller than the box and its labels, the difference would be left empty.
    The layout and the extents are computed without rendering the figure.
    """
    engine = fig.get_layout_engine()
    renderer = fig.canvas.get_renderer()
    # data clipped to its axes cannot reach out of them: leave it out of the extents (for a
    # mesh of many cells, measuring every triangle would cost more than drawing the figure)
    for ax in fig.axes:
        for artist in (*ax.collections, *ax.lines, *ax.patches, *ax.images):
            if artist.get_clip_on() and artist.get_clip_box() is not None:
                artist.set_in_layout(False)
    for _ in range(passes):
        engine.execute(fig)
        for ax in fig.axes:
            ax.apply_aspect()
        needed = fig.get_tightbbox(renderer).height + 2.0 * pad  # inches
        if fig.get_figheight() - needed < 0.02:
            return
        fig.set_figheight(needed)


def _stem(path: str | os.PathLike) -> Path:
    p = Path(path)
    if p.suffix.lower() in (".png", ".pdf"):
        p = p.with_suffix("")
    if not p.name or p.name in (".", ".."):
        raise ValueError(f"not a file path for a figure: {str(path)!r}")
    return p


def new_figure(width: float = SINGLE_COLUMN, height: float = 2.7) -> Figure:
    """A figure of ``width`` × ``height`` inches on its own Agg canvas (no pyplot)."""
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def save_figure(fig: Figure, path: str | os.PathLike) -> list[Path]:
    """Write ``<path>.png`` and ``<path>.pdf`` and release the figure's artists.

    Returns
    -------
    list of pathlib.Path
        The PNG and the PDF file, in this order.
    """
    stem = _stem(path)
    stem.parent.mkdir(parents=True, exist_ok=True)
    written = [stem.with_name(stem.name + ".png"), stem.with_name(stem.name + ".pdf")]
    try:  # atomically: a run killed while drawing leaves no empty or partial file
        with replacing(written[0], same_name=True) as tmp:
            fig.savefig(tmp, dpi=DPI)
        with replacing(written[1], same_name=True) as tmp:
            fig.savefig(tmp, metadata={"CreationDate": None})
    finally:
        fig.clear()
    log.info("wrote %s", ", ".join(str(p) for p in written))
    return written


def positive(values: np.ndarray) -> np.ndarray:
    """Copy with zero, negative and non-finite entries replaced by NaN (gaps on log axes)."""
    out = np.array(values, dtype=np.float64)
    out[~(np.isfinite(out) & (out > 0))] = np.nan
    return out


def log_log_axes(ax: Any, ylabel: str, log_y: bool = True) -> None:
    """Logarithmic ``N_dof`` axis (and y axis unless ``log_y`` is False) with grids."""
    ax.set_xscale("log")
    if log_y:
        ax.set_yscale("log")
    ax.grid(True, which="major", linestyle="-")
    ax.grid(True, which="minor", axis="both" if log_y else "x", linestyle=":", alpha=0.3)
    ax.set_xlabel(NDOF_LABEL)
    ax.set_ylabel(ylabel)


#: Mantissas of the major ticks a short log axis may get, coarsest first.
TICK_MANTISSAS: tuple[tuple[float, ...], ...] = (
    (1.0,),
    (1.0, 2.0, 5.0),
    (1.0, 2.0, 3.0, 5.0),
    (1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0),
    tuple(np.arange(1.0, 10.0, 0.5)),
    tuple(np.arange(1.0, 10.0, 0.25)),
)


def log_tick_sets(lo: float, hi: float) -> list[np.ndarray]:
    """The candidate major ticks of a log axis over ``[lo, hi]``, one array per
    :data:`TICK_MANTISSAS` (coarsest first): ``m · 10^k`` inside the interval."""
    k = np.arange(np.floor(np.log10(lo)) - 1, np.ceil(np.log10(hi)) + 1)
    sets = []
    for mantissas in TICK_MANTISSAS:
        t = np.unique(np.outer(10.0**k, mantissas).ravel())
        sets.append(t[(t >= lo * (1 - 1e-9)) & (t <= hi * (1 + 1e-9))])
    return sets


def tidy_log_ticks(ax: Any) -> None:
    """Label only major ticks, and give a log axis of less than two decades the most labelled
    ticks whose labels do not overlap.

    Matplotlib labels minor ticks on short log axes, and where no more than one power or
    1-2-5 value lies in the view it falls back to linear ticks (5000, 5500, …, 9000) whose
    labels ``5.5×10³`` run into each other. A short axis gets the finest set of
    :func:`log_tick_sets` with two ticks or more in its view, then coarser ones while two of
    their labels overlap, as measured by the figure's renderer after its layout (a set of one
    tick cannot overlap).
    """
    fig = ax.get_figure()
    for axis, limits in ((ax.xaxis, ax.get_xlim), (ax.yaxis, ax.get_ylim)):
        if axis.get_scale() != "log":
            continue
        axis.set_minor_formatter(NullFormatter())
        lo, hi = sorted(limits())
        if not (lo > 0 and np.log10(hi / lo) < 2.0):
            continue
        axis.set_major_formatter(
            LogFormatterSciNotation(labelOnlyBase=False, minor_thresholds=(np.inf, np.inf))
        )
        sets = log_tick_sets(lo, hi)
        start = next((j for j, t in enumerate(sets) if t.size >= 2), len(sets) - 1)
        for ticks in sets[start::-1]:
            axis.set_major_locator(FixedLocator(ticks))
            if ticks.size < 2 or not _labels_overlap(fig, axis):
                break
        axis.set_minor_locator(LogLocator(base=10.0, subs=np.arange(1.0, 10.0)))
        limits_set = ax.set_xlim if axis is ax.xaxis else ax.set_ylim
        limits_set(lo, hi)  # fixed ticks must not widen the view


def _labels_overlap(fig: Figure, axis: Any) -> bool:
    """Whether two tick labels of ``axis`` overlap in the laid-out figure."""
    engine = fig.get_layout_engine()
    if engine is not None:
        engine.execute(fig)
    fig.draw_without_rendering()
    renderer = fig.canvas.get_renderer()
    boxes = [t.get_window_extent(renderer) for t in axis.get_ticklabels() if t.get_text()]
    boxes.sort(key=lambda b: (b.x0, b.y0))
    return any(
        min(a.x1, b.x1) - max(a.x0, b.x0) > 0.5 and min(a.y1, b.y1) - max(a.y0, b.y0) > 0.5
        for i, a in enumerate(boxes)
        for b in boxes[i + 1 :]
    )
