"""The ``captured`` fixture: what every figure drawn in a test shows."""

from __future__ import annotations

import pytest
from matplotlib.figure import Figure

from .figure_checks import describe


@pytest.fixture
def captured(monkeypatch):
    """A list that receives :func:`describe` of every figure as its PNG is saved."""
    seen: list[dict] = []
    original = Figure.savefig

    def spy(fig, fname, *args, **kwargs):
        if str(fname).endswith(".png"):
            seen.append(describe(fig))
        return original(fig, fname, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", spy)
    return seen
