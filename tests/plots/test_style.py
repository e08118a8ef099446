"""Figure creation and saving, styles and log axes (:mod:`signorini.plots.style`)."""

from __future__ import annotations

import matplotlib as mpl
import numpy as np
import pytest

from signorini.plots import STYLES, plot_estimator
from signorini.plots.style import (
    CONTRIBUTIONS,
    DPI,
    SINGLE_COLUMN,
    fit_title,
    new_figure,
    positive,
    save_figure,
)

from .figure_checks import check_written, png_size


@pytest.mark.parametrize(
    ("name", "stem"),
    [("fig.png", "fig"), ("fig.PDF", "fig"), ("fig6.1", "fig6.1"), ("sub/dir/fig", "sub/dir/fig")],
)
def test_save_figure_names_and_folders(tmp_path, name, stem):
    fig = new_figure(height=2.0)
    fig.add_subplot().plot([0, 1], [0, 1])
    written = save_figure(fig, tmp_path / name)
    assert written == [tmp_path / f"{stem}.png", tmp_path / f"{stem}.pdf"]
    assert all(p.stat().st_size > 1000 for p in written)
    assert png_size(written[0]) == (round(SINGLE_COLUMN * DPI), round(2.0 * DPI))
    assert not fig.axes  # released after saving


def test_save_figure_rejects_a_folder_name(tmp_path):
    with pytest.raises(ValueError, match="not a file path"):
        save_figure(new_figure(), "")
    assert not any(tmp_path.iterdir())


def test_figures_leave_pyplot_and_the_global_style_alone(tmp_path):
    import matplotlib.pyplot as plt

    before = dict(mpl.rcParams)
    ndof = np.array([100.0, 400.0, 1600.0])
    check_written(plot_estimator({"ndof": ndof, "eta": 1 / ndof}, tmp_path / "e"), tmp_path / "e")
    assert plt.get_fignums() == []
    changed = {k for k in before if mpl.rcParams[k] != before[k]}
    assert not changed, f"global rcParams changed: {sorted(changed)}"


def test_every_contribution_has_a_style_of_its_own():
    assert CONTRIBUTIONS == tuple(f"eta_{k}" for k in range(1, 8))
    styles = [STYLES[k] for k in CONTRIBUTIONS]
    assert len({s["color"] for s in styles}) == 7 and len({s["marker"] for s in styles}) == 7
    assert [s["label"] for s in styles] == [rf"$\eta_{k}$" for k in range(1, 8)]


def test_positive_marks_gaps_for_log_axes():
    values = np.array([1.0, 0.0, -2.0, np.nan, np.inf, 3.0])
    out = positive(values)
    np.testing.assert_array_equal(out, [1.0, np.nan, np.nan, np.nan, np.nan, 3.0])
    assert values[1] == 0.0  # a copy


def test_fit_title_wraps_long_titles_at_spaces():
    fig = new_figure()  # 3.5 in wide: about 46 characters of the 9 pt title font
    title = "inclined_block: deformed body and contact pressure"
    with mpl.rc_context({"axes.titlesize": 9}):
        assert fit_title(title, fig) == "inclined_block: deformed body and contact\npressure"
        assert fit_title("short\ntwo lines", fig) == "short\ntwo lines"
        math = r"a long title with mathtext $\eta_h \leq \mathrm{something\ quite\ long}$ in it"
        assert fit_title(math, fig) == math
