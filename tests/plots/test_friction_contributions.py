"""η8 in the contributions figure: drawn for a frictional run, left out of a frictionless
one (whose history has eta_8 ≡ 0 and no sticking node), so frictionless figures stay as
they were."""

from __future__ import annotations

import numpy as np
import pytest

import signorini.plots.convergence as convergence
from signorini.plots import plot_contributions

from .figure_checks import synthetic_history


@pytest.fixture
def drawn(monkeypatch):
    """The labels of the curves each call of plot_contributions draws."""
    calls = []

    def capture(path, curves, *args, **kwargs):
        calls.append([c.label for c in curves if not isinstance(c, str)])
        return []

    monkeypatch.setattr(convergence, "convergence_figure", capture)
    return calls


def test_eta_8_is_drawn_for_a_frictional_run_only(drawn, tmp_path):
    h = synthetic_history()
    n = h["ndof"].size
    plot_contributions(h, tmp_path / "none")  # an old history: no eta_8 column
    plot_contributions({**h, "eta_8": np.zeros(n), "n_stick": np.zeros(n)}, tmp_path / "zero")
    plot_contributions({**h, "eta_8": 1e-3 / h["ndof"], "n_stick": np.zeros(n)}, tmp_path / "w")
    # a frictional run in full stick: η8 = 0 on every level, yet a frictional run
    plot_contributions({**h, "eta_8": np.zeros(n), "n_stick": np.full(n, 3)}, tmp_path / "s")
    print("\n".join(", ".join(labels) for labels in drawn))
    frictionless, zero, work, stick = drawn
    assert frictionless == zero and len(frictionless) == 7
    assert not any(r"\eta_8" in label for label in frictionless)
    for labels in (work, stick):
        assert labels[:7] == frictionless
        assert len(labels) == 8 and r"\eta_8" in labels[-1]
