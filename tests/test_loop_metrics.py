"""An example's own measurements in the adaptive loop's records (``adaptive(metrics=...)``)."""

from __future__ import annotations

import math

import pytest

from signorini import adaptive
from signorini.examples import example_6_2


def test_measurements_become_columns_of_every_level():
    seen = []

    def metrics(result):
        seen.append(result.ndof)
        return {"twice_force": 2.0 * result.total_contact_force, "undefined": math.nan}

    levels = list(adaptive(example_6_2(), max_ndof=1500, metrics=metrics))
    assert len(levels) >= 3
    assert seen == [level.record.ndof for level in levels]
    for level in levels:
        row = level.record.row()
        assert row["twice_force"] == 2.0 * level.record.contact_force
        assert math.isnan(row["undefined"])
        assert list(row)[-2:] == ["twice_force", "undefined"]


@pytest.mark.parametrize(
    ("metrics", "match"),
    [
        (lambda r: {"eta": 1.0}, "'eta' is not a new column name"),
        (lambda r: {3: 1.0}, "3 is not a new column name"),
        (lambda r: {"a": "x"}, "the value of 'a' must be a real number"),
        (lambda r: {"a": True}, "the value of 'a' must be a real number"),
        (lambda r: [1.0], "must return a mapping"),
    ],
)
def test_bad_measurements_are_refused_naming_the_column(metrics, match):
    with pytest.raises(ValueError, match=match):
        next(adaptive(example_6_2(), max_ndof=1500, metrics=metrics))


def test_metrics_must_be_callable():
    with pytest.raises(ValueError, match="metrics must be a function"):
        adaptive(example_6_2(), metrics={"a": 1.0})
