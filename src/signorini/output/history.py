"""The convergence history: one CSV row per level, its reader, and observed rates.

A run writes ``history.csv`` with :class:`HistoryWriter`, rewritten atomically after every
level; :func:`read_history` reads it back as one array per column, and :func:`fitted_slope`
gives the observed rate of a column against ``N_dof`` (docs/method.md, *The paper's
examples*: the optimal rate of P2 is ``N_dof^{-1}``). This module is the one owner of the
file's format; the figures (:mod:`signorini.plots`) and the tests read histories through it.
"""

from __future__ import annotations

import csv
import errno
import io as _io
import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from .files import atomic_write
from .guard import read_bounded

__all__ = [
    "HistoryWriter",
    "read_history",
    "history_columns",
    "fitted_slope",
    "write_columns",
]

#: A history: a mapping from column name to (n_levels,) array, or the path of a CSV file.
HistoryLike = Mapping[str, ArrayLike] | str | os.PathLike


class HistoryWriter:
    """A CSV convergence history rewritten atomically after every level.

    Columns appear in the order they are first seen; a column missing from a row is left
    empty in it. Floats are written with ``repr`` (they read back bit for bit), NaN as
    ``nan``.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file (replaced if it exists).
    rows : sequence of mapping, optional
        Rows already written (e.g. read back from the file to continue a run); they are
        written again as they are.
    """

    def __init__(self, path: str | os.PathLike, rows: Sequence[Mapping] = ()) -> None:
        self.path = Path(path)
        self.rows: list[dict] = [dict(r) for r in rows]

    def append(self, row: Mapping[str, object]) -> None:
        """Add one level's row and rewrite the file."""
        self.rows.append(dict(row))
        columns: list[str] = []
        for r in self.rows:
            columns += [c for c in r if c not in columns]
        out = _io.StringIO()
        writer = csv.DictWriter(out, fieldnames=columns, lineterminator="\n")
        writer.writeheader()
        for r in self.rows:
            writer.writerow({c: _fmt(r.get(c, "")) for c in columns})
        atomic_write(self.path, out.getvalue().encode())


def write_columns(path: str | os.PathLike, columns: Mapping[str, str]) -> Path:
    """Write the description of a history's columns as a Markdown table (atomically).

    Parameters
    ----------
    path : str or os.PathLike
        The file, e.g. ``history.md`` beside ``history.csv``.
    columns : mapping of str to str
        Column name to its meaning and unit.
    """
    lines = [
        "# Columns of history.csv",
        "",
        "One row per level. Units are those of the problem's data (consistent units: if E is "
        "in MPa and lengths in mm, forces are in N/mm of thickness).",
        "",
        "| column | meaning |",
        "|---|---|",
        *(f"| `{name}` | {text} |" for name, text in columns.items()),
    ]
    return atomic_write(path, ("\n".join(lines) + "\n").encode())


def _fmt(value: object) -> object:
    if isinstance(value, float):
        return "nan" if math.isnan(value) else repr(value)
    return value


def _parse_column(values: list[str]) -> np.ndarray:
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
        If the file is not a regular file (a named pipe, a device: never waited on or read
        without end), is larger than :data:`~.guard.MAX_TEXT_BYTES`, has no header,
        repeated or empty column names, or a row whose number of fields differs from the
        header's.
    """
    path = Path(path)
    data = read_bounded(path, follow_links=True)
    if data is None:
        raise FileNotFoundError(errno.ENOENT, os.strerror(errno.ENOENT), str(path))
    try:
        text = data.decode("utf-8")
        rows = [r for r in csv.reader(_io.StringIO(text, newline="")) if r]  # blank lines dropped
    except (UnicodeDecodeError, csv.Error) as exc:
        raise ValueError(f"{path}: not a CSV history ({exc})") from None
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
    return {h: _parse_column(list(c)) for h, c in zip(header, columns, strict=True)}


def history_columns(
    history: HistoryLike, required: Sequence[str], optional: Sequence[str] = ()
) -> dict[str, np.ndarray]:
    """Float columns ``required`` (all) and ``optional`` (when present) of a history.

    Parameters
    ----------
    history : mapping of str to (n_levels,) array, or path of a CSV history
    required, optional : sequence of str
        Column names.

    Returns
    -------
    dict of str to (n_levels,) float array

    Raises
    ------
    ValueError
        If a required column is missing, a column is not 1-d or not numeric, the columns
        differ in length, or ``ndof`` (when asked for) is empty or not positive.
    """
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


def check_last(last: object) -> None:
    """Raise ValueError unless ``last`` (how many final levels a slope uses) is an int >= 2."""
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
    check_last(last)
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
