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
    }


def legend_slope(label: str) -> float | None:
    """The slope a legend label states (``"…, slope −1.23"``), or None."""
    m = re.search(r", slope ([\u2212-]?\d+\.\d+)$", label)
    return float(m.group(1).replace("\u2212", "-")) if m else None
