"""Shared data and checks of the figure tests: a synthetic history, the written files, and
what a figure shows (legend texts with the data of each labelled line)."""

from __future__ import annotations

import csv
import re
import struct
from pathlib import Path

import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure

from signorini.plots.style import CONTRIBUTIONS, DPI

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
NDOF = np.array([150.0, 420.0, 1100.0, 2900.0, 7600.0, 20000.0])


def synthetic_history(zero_terms: tuple[str, ...] = ("eta_6", "eta_7")) -> dict[str, np.ndarray]:
    """eta = 3 / ndof, error = 2 / ndof, eta_k = 0.3 k ndof^(-0.5 - 0.1 k) (zero for
    ``zero_terms``): every contribution has its own rate."""
    n = NDOF.size
    h = {
        "level": np.arange(n),
        "ndof": NDOF.astype(np.int64),
        "n_cells": (NDOF / 6).astype(np.int64),
        "eta": 3.0 / NDOF,
        "error_energy": 2.0 / NDOF,
        "error_h1": 2.5 / NDOF,
        "efficiency": np.full(n, 1.5),
        "pdas_iterations": np.full(n, 2),
        "n_active": np.arange(n) * 4,
    }
    for k, key in enumerate(CONTRIBUTIONS, start=1):
        h[key] = np.zeros(n) if key in zero_terms else 0.3 * k * NDOF ** (-0.5 - 0.1 * k)
    return h


def write_csv(path: Path, h: dict[str, np.ndarray]) -> Path:
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(list(h))
        w.writerows(zip(*(v.tolist() for v in h.values()), strict=True))
    return path


def png_size(path: Path) -> tuple[int, int]:
    """Width and height from the IHDR chunk of a PNG file."""
    data = path.read_bytes()
    assert data[:8] == PNG_SIGNATURE
    assert data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def check_written(paths: list[Path], stem: Path, width_in: float | None = None) -> None:
    """``paths`` are ``<stem>.png`` and ``<stem>.pdf``, both real, non-trivial files."""
    assert [Path(p) for p in paths] == [Path(f"{stem}.png"), Path(f"{stem}.pdf")]
    png, pdf = (Path(p) for p in paths)
    assert png.read_bytes()[:8] == PNG_SIGNATURE
    assert png.stat().st_size > 5000
    assert pdf.read_bytes()[:5] == b"%PDF-"
    assert pdf.stat().st_size > 5000
    if width_in is not None:
        assert png_size(png)[0] == round(width_in * DPI)


def describe(fig: Figure) -> dict:
    """What a figure shows, read from its artists just before it is saved."""
    legends = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend()]
    lines = {
        line.get_label(): (
            np.asarray(line.get_xdata(), dtype=float),
            np.asarray(line.get_ydata(), dtype=float),
        )
        for ax in fig.axes
        for line in ax.get_lines()
        if not line.get_label().startswith("_")
    }
    segments = {
        c.get_label(): [np.asarray(s) for s in c.get_segments()]
        for ax in fig.axes
        for c in ax.collections
        if isinstance(c, LineCollection) and not c.get_label().startswith("_")
    }
    return {
        "legend": [t.get_text() for lg in legends for t in lg.get_texts()],
        "legend_title": "\n".join(lg.get_title().get_text() for lg in legends),
        "caption": fig._supxlabel.get_text() if fig._supxlabel is not None else "",
        "lines": lines,
        "segments": segments,
        "xlabel": [ax.get_xlabel() for ax in fig.axes],
        "ylabel": [ax.get_ylabel() for ax in fig.axes],
        "ylim": [ax.get_ylim() for ax in fig.axes],
        "data_lim": [ax.dataLim.frozen() for ax in fig.axes],
        "scales": [(ax.get_xscale(), ax.get_yscale()) for ax in fig.axes],
        "texts": [t.get_text() for ax in fig.axes for t in ax.texts],
        "titles": [ax.get_title() for ax in fig.axes],
        "patches": [p for ax in fig.axes for p in ax.patches],
        "xticks": [list(ax.get_xticks()) for ax in fig.axes],
        "lines_by_axes": [
            [
                (np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float))
                for ln in ax.get_lines()
            ]
            for ax in fig.axes
        ],
        "legend_boxes": [lg.get_window_extent(fig.canvas.get_renderer()) for lg in legends],
        "data_to_display": [ax.transData.frozen() for ax in fig.axes],
        "zorders_by_axes": [[ln.get_zorder() for ln in ax.get_lines()] for ax in fig.axes],
        "yticklabels": [[t.get_text() for t in ax.get_yticklabels()] for ax in fig.axes],
    }


def legend_slope(label: str) -> float | None:
    """The slope a legend label states (``"…, slope −1.23"``), or None."""
    m = re.search(r", slope ([\u2212-]?\d+\.\d+)$", label)
    return float(m.group(1).replace("\u2212", "-")) if m else None


def _boxes(fig: Figure, renderer) -> list[tuple[str, object]]:
    """``(name, window extent)`` of every text a reader reads, and of every legend."""
    boxes = []
    axes = [a for ax in fig.axes for a in (ax, *ax.child_axes) if a.get_visible()]
    for i, ax in enumerate(axes):
        for title in (ax.title, ax._left_title, ax._right_title):
            if title.get_text():
                boxes.append(
                    (f"axes {i} title {title.get_text()!r}", title.get_window_extent(renderer))
                )
        for axis, name in ((ax.xaxis, "x"), (ax.yaxis, "y")):
            if axis.label.get_visible() and axis.label.get_text():
                label = axis.label
                boxes.append(
                    (
                        f"axes {i} {name} label {label.get_text()!r}",
                        label.get_window_extent(renderer),
                    )
                )
            # matplotlib draws the ticks inside the view interval (on the axis' scale)
            scale = axis.get_transform()
            lo, hi = sorted(scale.transform(np.asarray(axis.get_view_interval())))
            slack = 1e-9 * (hi - lo)
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                loc = float(scale.transform(np.array([tick.get_loc()]))[0])
                if not lo - slack <= loc <= hi + slack:
                    continue
                for label in (tick.label1, tick.label2):
                    if label.get_visible() and label.get_text():
                        b = label.get_window_extent(renderer)
                        boxes.append((f"axes {i} {name} tick {label.get_text()!r}", b))
        for t in ax.texts:
            if t.get_visible() and t.get_text():
                boxes.append((f"axes {i} text {t.get_text()!r}", t.get_window_extent(renderer)))
        if ax.get_legend() is not None:
            boxes.append((f"axes {i} legend", ax.get_legend().get_window_extent(renderer)))
    for k, lg in enumerate(fig.legends):
        boxes.append((f"figure legend {k}", lg.get_window_extent(renderer)))
    for t in fig.texts:
        if t.get_visible() and t.get_text():
            boxes.append((f"figure text {t.get_text()!r}", t.get_window_extent(renderer)))
    return boxes


def layout_faults(fig: Figure, margin_in: float = 0.3) -> list[str]:
    """What a reader of the saved figure would stumble on, as sentences (empty: none).

    - a text or legend that leaves the canvas, even in part (a clipped title);
    - two texts or legends that overlap (an x label under a legend, a legend over the slope
      triangle's labels, two tick labels of one axis: ``5×10³`` into ``5.5×10³`` on a short
      log axis);
    - a legend inside the axes over a marker of a curve;
    - an empty horizontal band of the canvas taller than ``margin_in`` inches, between the
      drawn elements or at the top or bottom (a wide body in a tall figure).
    """
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    frame = fig.bbox
    faults = []
    boxes = _boxes(fig, renderer)
    tol = 0.5  # pixels
    for name, b in boxes:
        if (
            b.x0 < frame.x0 - tol
            or b.y0 < frame.y0 - tol
            or b.x1 > frame.x1 + tol
            or b.y1 > frame.y1 + tol
        ):
            faults.append(f"{name} leaves the canvas: {b.bounds} outside {frame.bounds}")
    for i in range(len(boxes)):
        for j in range(i + 1, len(boxes)):
            (n1, b1), (n2, b2) = boxes[i], boxes[j]
            w = min(b1.x1, b2.x1) - max(b1.x0, b2.x0)
            h = min(b1.y1, b2.y1) - max(b1.y0, b2.y0)
            if w > tol and h > tol:
                faults.append(f"{n1} and {n2} overlap by {w:.1f} x {h:.1f} px")
    # a legend inside the axes must not hide the data: no marker of a curve under it
    for i, ax in enumerate(fig.axes):
        lg = ax.get_legend()
        if lg is None:
            continue
        box = lg.get_window_extent(renderer)
        for line in ax.get_lines():
            xy = line.get_xydata()
            xy = xy[np.all(np.isfinite(xy), axis=1)]
            if xy.size == 0 or line.get_marker() in ("", "None", None):
                continue
            px = ax.transData.transform(xy)
            under = (
                (px[:, 0] > box.x0)
                & (px[:, 0] < box.x1)
                & (px[:, 1] > box.y0)
                & (px[:, 1] < box.y1)
            )
            if under.any():
                n, what = np.count_nonzero(under), line.get_label()
                faults.append(f"axes {i} legend hides {n} point(s) of {what!r}")
    # empty horizontal bands: cover [0, height] with every drawn box
    drawn = [b for _, b in boxes]
    drawn += [
        a.get_window_extent(renderer)
        for ax in fig.axes
        for a in (ax, *ax.child_axes)
        if a.get_visible()
    ]
    spans = sorted((max(b.y0, frame.y0), min(b.y1, frame.y1)) for b in drawn)
    top, largest = frame.y0, (0.0, "")
    for lo, hi in spans:
        if lo - top > largest[0]:
            largest = (lo - top, f"at {top / fig.dpi:.2f}-{lo / fig.dpi:.2f} in")
        top = max(top, hi)
    if frame.y1 - top > largest[0]:
        largest = (frame.y1 - top, "at the top")
    if largest[0] > margin_in * fig.dpi:
        faults.append(f"an empty band of {largest[0] / fig.dpi:.2f} in {largest[1]}")
    return faults
