"""Which figures a finished run gets (:mod:`signorini.plots.report`): chosen by what the
history contains, never by the run's name."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.plots import make_figures
from signorini.plots.report import has_known_values

from .figure_checks import check_written, legend_slope, synthetic_history, write_csv


def without_error(h: dict) -> dict:
    """``h`` as a run without an exact solution writes it: error and efficiency unknown."""
    unknown = np.full(h["ndof"].size, np.nan)
    return {**h, "error_energy": unknown, "error_h1": unknown, "efficiency": unknown}


def test_has_known_values():
    h = {"a": np.array([np.nan, 0.0, 2.0]), "b": np.array([np.nan, 0.0]), "c": np.array(["", ""])}
    assert has_known_values(h, "a")
    assert not has_known_values(h, "b") and not has_known_values(h, "c")
    assert not has_known_values(h, "missing")


@pytest.mark.slow  # several figures each
@pytest.mark.parametrize(
    ("name", "exact", "figures"),
    [
        # the name says 6.2, the history has an exact error: the error figures are drawn
        ("example-6.2", True, ["error_estimator", "efficiency", "contributions"]),
        ("example-6.1", False, ["estimator", "contributions"]),
        ("my run/1", True, ["error_estimator", "efficiency", "contributions"]),
    ],
)
def test_figures_follow_the_history(tmp_path, name, exact, figures):
    h = synthetic_history()
    csv_path = write_csv(tmp_path / "history.csv", h if exact else without_error(h))
    written = make_figures(csv_path, tmp_path / "figs", name)
    slug = name.replace(" ", "_").replace("/", "_")
    expected = [tmp_path / "figs" / f"{slug}_{f}.{ext}" for f in figures for ext in ("png", "pdf")]
    assert written == expected
    for i in range(0, len(written), 2):
        check_written(written[i : i + 2], written[i].with_suffix(""))


@pytest.mark.slow
def test_eta6_eta7_drawn_when_they_do_not_vanish(tmp_path, captured):
    h = synthetic_history(zero_terms=())
    make_figures(write_csv(tmp_path / "a.csv", without_error(h)), tmp_path, "a")
    legend = captured[-1]["legend"]
    assert len(legend) == 7 and all(legend_slope(t) is not None for t in legend)
    h = synthetic_history(zero_terms=("eta_6", "eta_7"))
    make_figures(write_csv(tmp_path / "b.csv", without_error(h)), tmp_path, "b")
    legend = captured[-1]["legend"]
    assert legend[5:] == [r"$\eta_6 \equiv 0$", r"$\eta_7 \equiv 0$"]


def test_no_contributions_figure_without_their_columns(tmp_path):
    ndof = np.array([100, 400, 1600])
    path = write_csv(tmp_path / "h.csv", {"ndof": ndof, "eta": 1.0 / ndof})
    written = make_figures(path, tmp_path, "run")
    assert [p.name for p in written] == ["run_estimator.png", "run_estimator.pdf"]
