"""The estimator's term names are the one list the history columns, their descriptions and
the figures' styles are derived from (signorini.estimator.names)."""

from __future__ import annotations

import dataclasses

import numpy as np

from signorini.estimator import TERM_TABLE, TERMS
from signorini.estimator.residual import Estimate
from signorini.loop.record import COLUMNS, LevelRecord
from signorini.plots.style import CONTRIBUTIONS, FRICTION_CONTRIBUTIONS, STYLES, TERM_LOOKS


def test_the_terms_are_eta_1_to_eta_8_with_the_friction_work_last():
    assert TERMS == tuple(f"eta_{k}" for k in range(1, 9))
    assert [t.friction for t in TERM_TABLE] == [False] * 7 + [True]
    assert [t.label for t in TERM_TABLE] == [rf"$\eta_{k}$" for k in range(1, 9)]


def test_history_columns_follow_the_terms():
    columns = list(COLUMNS)
    start = columns.index("eta") + 1
    assert tuple(columns[start : start + len(TERMS)]) == TERMS
    assert [COLUMNS[t.name] for t in TERM_TABLE] == [t.description for t in TERM_TABLE]
    assert "friction work" in COLUMNS["eta_8"] and "contribution η_3" in COLUMNS["eta_3"]
    fields = [f.name for f in dataclasses.fields(LevelRecord) if f.name != "extra"]
    assert fields == [name for name in columns if name in fields]  # the same order
    assert set(TERMS) <= set(fields)


def test_estimate_names_its_rows_by_the_terms():
    rows = np.arange(1.0, 9.0)[:, None] ** 2 * np.ones((8, 3)) / 3.0
    est = Estimate(rows, np.zeros((7, 4)), "consistent")
    values = est.as_dict()
    assert list(values) == ["eta", *TERMS]
    np.testing.assert_allclose([values[name] for name in TERMS], np.arange(1.0, 9.0))


def test_figure_styles_follow_the_terms():
    assert CONTRIBUTIONS + FRICTION_CONTRIBUTIONS == TERMS
    assert len(TERM_LOOKS) == len(TERMS)
    for term, (color, marker) in zip(TERM_TABLE, TERM_LOOKS, strict=True):
        assert STYLES[term.name] == {"color": color, "marker": marker, "label": term.label}
    # every term drawn in its own colour and marker
    assert len({c for c, _ in TERM_LOOKS}) == len({m for _, m in TERM_LOOKS}) == len(TERMS)
