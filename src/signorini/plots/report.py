"""The convergence figures a finished run gets, chosen by what its history contains."""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..output.history import read_history
from .convergence import (
    plot_contributions,
    plot_efficiency,
    plot_error_and_estimator,
    plot_errors,
    plot_estimator,
)
from .slopes import optimal_slope
from .style import CONTRIBUTIONS

__all__ = ["make_figures", "has_known_values"]


def has_known_values(history: Mapping[str, np.ndarray], column: str) -> bool:
    """Whether ``column`` is in the history with at least one positive finite number."""
    if column not in history:
        return False
    try:
        values = np.asarray(history[column], dtype=np.float64)
    except ValueError:  # an all-empty column reads as text
        return False
    return bool(np.any(np.isfinite(values) & (values > 0)))


def _estimated(history: Mapping[str, np.ndarray]) -> bool:
    """Whether the history has an estimator: an ``eta`` column with a finite value (a 3D
    run has none)."""
    if "eta" not in history:
        return False
    try:
        return bool(np.isfinite(np.asarray(history["eta"], dtype=np.float64)).any())
    except ValueError:  # an all-empty column reads as text
        return False


def make_figures(
    history_path: str | os.PathLike,
    out_dir: str | os.PathLike,
    example_name: str,
    title: str | None = None,
    degree: int = 2,
    dim: int = 2,
) -> list[Path]:
    """The convergence figures of one run, drawn from its ``history.csv``.

    - A known exact error (a positive finite ``error_energy`` on some level): error and
      estimator (Fig. 6.1(a)) and the efficiency index (Fig. 6.1(b)); otherwise the
      estimator alone (Fig. 6.3(a)).
    - Estimator contributions ``eta_1`` … ``eta_7`` in the history: their figure (Figs. 6.2,
      6.4), where a term that vanishes on every level is listed as ``≡ 0`` instead of drawn.

    - Without an estimator (a 3D run: no finite ``eta``): with a known error the errors alone
      (:func:`~.convergence.plot_errors`), else no convergence figure.

    Meshes and deformed bodies need more than the history; callers draw them with
    :func:`~signorini.plots.plot_mesh` and :func:`~signorini.plots.plot_deformed`.

    Parameters
    ----------
    history_path : str or os.PathLike
        The run's CSV history.
    out_dir : str or os.PathLike
        Folder for the figures (created if needed).
    example_name : str
        Name of the run; files are named ``<example_name>_<figure>.png`` / ``.pdf`` (with
        characters other than letters, digits, ``.``, ``_``, ``-`` replaced by ``_``).
    title : str, optional
        Title of every figure (the command line gives the problem's ``name``).
    degree : {2, 1}
        The degree of the run's element: the reference triangles have its optimal slope
        (:func:`~signorini.plots.slopes.optimal_slope`: −1 for P2, −1/2 for P1).
    dim : {2, 3}
        The mesh's dimension, which the optimal slope depends on (3D P2: −2/3).

    Returns
    -------
    list of pathlib.Path
        All files written.
    """
    history = read_history(history_path)
    slug = re.sub(r"[^A-Za-z0-9._-]+", "_", str(example_name)).strip("_.") or "example"
    out = Path(out_dir)
    written: list[Path] = []
    drawn = {"title": title, "reference_slope": optimal_slope(degree, dim)}
    if not _estimated(history):  # a 3D run: no estimator to draw
        if has_known_values(history, "error_energy"):
            return plot_errors(history, out / f"{slug}_errors", **drawn)
        return []
    if has_known_values(history, "error_energy"):
        written += plot_error_and_estimator(history, out / f"{slug}_error_estimator", **drawn)
        written += plot_efficiency(history, out / f"{slug}_efficiency", title=title)
    else:
        written += plot_estimator(history, out / f"{slug}_estimator", **drawn)
    if any(k in history for k in CONTRIBUTIONS):
        written += plot_contributions(history, out / f"{slug}_contributions", **drawn)
    return written
