"""The frame every convergence figure shares (:func:`convergence_figure`): log ``N_dof``
axis, one styled :class:`Curve` per quantity with its fitted slope in the legend, a reference
slope triangle below the data, the legend where it hides no marker.

A value that is exactly zero, or (for the contributions ``η_k``) round-off below
``ROUNDOFF · η_h`` of its level, cannot be drawn on a log axis: it is drawn as a hollow marker
on a strip labelled ``≈0`` below the axes, so the log axis keeps the meaningful range and no
gap is left unexplained. The figures themselves are in :mod:`signorini.plots.convergence`.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib as mpl
import numpy as np

from .slopes import draw_slope_triangle, slope_label
from .style import (
    RC,
    STYLES,
    fit_title,
    log_log_axes,
    new_figure,
    positive,
    save_figure,
    tidy_log_ticks,
)

__all__ = ["ROUNDOFF", "Curve", "convergence_figure"]

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
    #: (n,) bool: levels whose value is at or below η_h's round-off level (``floor`` of
    #: :meth:`of`): noise, drawn as hollow markers without a line and out of every fit.
    noise: np.ndarray | None = None
    #: (n,) the round-off level of η_h per level, drawn as a dashed line where ``noise``.
    floor: np.ndarray | None = None

    @property
    def unfitted(self) -> np.ndarray:
        """(n,) bool: the levels out of every fit and triangle: ≈0 or noise."""
        return self.near_zero | self.noise if self.at_floor else self.near_zero

    @property
    def at_floor(self) -> bool:
        """Whether some level's value is noise (at η_h's round-off level)."""
        return self.noise is not None and bool(np.any(self.noise))

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
        floor: np.ndarray | None = None,
    ) -> Curve:
        """The history column ``key`` in its :data:`STYLES`, its fitted slope in the label.

        With ``reference`` (n,), values ``<= ROUNDOFF * reference`` count as round-off: on the
        ``≈0`` strip and out of the fit, like exact zeros. Values ``<= floor`` (n,), the
        round-off level of η_h of each level (the history's ``eta_roundoff``,
        :func:`~signorini.estimator.roundoff.roundoff_level`; NaN where unknown), are noise:
        drawn as hollow markers above the dashed round-off level, out of the fit; noise has
        no rate, and none is printed for it.
        """
        style = STYLES[key]
        values = np.asarray(values, dtype=np.float64)
        small = np.isfinite(values) & (values <= 0.0)
        if reference is not None:
            small |= np.isfinite(values) & (values <= ROUNDOFF * np.asarray(reference))
        noise = np.zeros(values.shape, dtype=bool)
        if floor is not None:
            floor = np.asarray(floor, dtype=np.float64)
            noise = np.isfinite(values) & (values <= floor) & ~small
        shown = np.where(small | noise, np.nan, values)
        if np.any(np.isfinite(shown) & (shown > 0)):
            label = slope_label(style["label"], ndof, shown, last)
        elif noise.any():
            label = style["label"] + " (noise)"
        elif np.all(values[small] == 0.0):
            label = style["label"][:-1] + r" \equiv 0$"
        else:
            label = style["label"][:-1] + r" \approx 0$ (round-off)"
        marker = style["color"], style["marker"]
        return cls(ndof, values, label, *marker, small, noise, floor if noise.any() else None)


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
        floors: list[tuple[np.ndarray, np.ndarray]] = []
        rows = iter(np.linspace(-0.5, 0.5, n_rows) if n_rows > 1 else [0.0])
        for c in curves:
            if not isinstance(c, Curve):
                ax.plot([], [], linestyle="none", marker="", label=c)
                continue
            noise = c.unfitted & ~c.near_zero
            shown = positive(np.where(c.unfitted, np.nan, c.values))
            hollow = {"color": c.color, "marker": c.marker, "mfc": "none", "ls": ""}
            if np.any(np.isfinite(shown)):
                ax.plot(c.ndof, shown, color=c.color, marker=c.marker, label=c.label)
            if noise.any():  # noise: hollow markers, no line, and the level they are under
                solid = np.any(np.isfinite(shown))
                ax.plot(c.ndof[noise], c.values[noise], **hollow, label="_" if solid else c.label)
                floors.append((c.ndof, c.floor))
            elif not np.any(np.isfinite(shown)):  # only ≈0 values: the strip's hollow marker
                ax.plot([], [], **hollow, label=c.label)
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
        if floors:  # one dashed line: the curves share η_h's round-off level
            ndof, level = floors[0]
            # a dash at each level's value, so that a run of one level shows it too
            ax.plot(
                ndof, level, color="0.45", ls="--", lw=0.9, marker="_", ms=9, label=_FLOOR_LABEL
            )
            if not any(", slope" in c.label for c in drawn):
                note = None  # no slope is stated: no range it is fitted over
        if zero_ax is not None:
            _zero_strip(ax, zero_ax)
            note = "\n".join(filter(None, [note, _ZERO_NOTE]))
        if reference_slope is not None:
            series = [(c.ndof, np.where(c.unfitted, np.nan, c.values)) for c in drawn]
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
_FLOOR_LABEL = r"round-off level of $\eta_h$: below it, noise (no rate)"

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
