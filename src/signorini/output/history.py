"""The convergence history: one CSV row per level, rewritten atomically after every level."""

from __future__ import annotations

import csv
import io as _io
import math
import os
from collections.abc import Mapping
from pathlib import Path

from .files import atomic_write

__all__ = ["HistoryWriter"]


class HistoryWriter:
    """A CSV convergence history rewritten atomically after every level.

    Parameters
    ----------
    path : path of the CSV file (replaced if it exists)
    """

    def __init__(self, path: str | os.PathLike) -> None:
        self.path = Path(path)
        self.rows: list[dict] = []

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


def _fmt(value: object) -> object:
    if isinstance(value, float):
        return "nan" if math.isnan(value) else repr(value)
    return value
