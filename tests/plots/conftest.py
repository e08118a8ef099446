"""The ``captured`` fixture: what every figure drawn in a test shows; every such figure must
also be free of layout faults (:func:`~.figure_checks.layout_faults`)."""

from __future__ import annotations

import pytest
from matplotlib.figure import Figure

from .figure_checks import describe, layout_faults


@pytest.fixture
def captured(monkeypatch):
    """A list that receives :func:`describe` of every figure as its PNG is saved; saving a
    figure with a layout fault (clipped or overlapping text, a wide empty band) fails."""
    seen: list[dict] = []
    original = Figure.savefig

    def spy(fig, fname, *args, **kwargs):
        if str(fname).endswith(".png"):
            faults = layout_faults(fig)
            assert not faults, f"{fname}: " + "; ".join(faults)
            seen.append(describe(fig) | {"file": str(fname)})
        return original(fig, fname, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", spy)
    return seen
