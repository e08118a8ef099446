"""The adaptive loop's options (signorini.loop.options): defaults, checks naming the field,
the record a run folder stores, and ``adaptive``'s keyword changes."""

from __future__ import annotations

import dataclasses
import json

import pytest

from signorini import adaptive
from signorini.algebra import SOLVERS, auto_solver, superlu_solver
from signorini.examples import example_6_2
from signorini.loop import AdaptiveOptions, OptionError


def test_defaults_are_the_loops():
    options = AdaptiveOptions()
    assert (options.theta, options.max_ndof, options.tol, options.max_levels) == (
        0.4,
        100_000,
        0.0,
        100,
    )
    assert not options.uniform and options.warm_start and not options.fallback
    assert options.eta5_variant == "consistent" and options.solver is auto_solver
    with pytest.raises(dataclasses.FrozenInstanceError):
        options.theta = 0.5


@pytest.mark.parametrize(
    ("change", "field", "message"),
    [
        ({"theta": 0.0}, "theta", r"theta must lie in \(0, 1\], got 0.0"),
        ({"theta": "0.4"}, "theta", "theta must be a number"),
        ({"max_ndof": -5}, "max_ndof", "max_ndof must be positive, got -5"),
        ({"max_ndof": float("nan")}, "max_ndof", "max_ndof must be a positive number, got nan"),
        ({"tol": -1.0}, "tol", "tol must be a number >= 0, got -1"),
        ({"max_levels": 2.5}, "max_levels", "max_levels must be an integer >= 1, got 2.5"),
        ({"uniform": 1}, "uniform", "uniform must be True or False, got 1"),
        ({"warm_start": None}, "warm_start", "warm_start must be True or False"),
        ({"fallback": "no"}, "fallback", "fallback must be True or False"),
        ({"eta5_variant": "printed"}, "eta5_variant", "eta5_variant must be one of"),
        ({"solver": "pardiso"}, "solver", "solver must be an SPDSolver or a solver factory"),
    ],
)
def test_a_bad_value_raises_naming_the_field(change, field, message):
    with pytest.raises(OptionError, match=message) as info:
        AdaptiveOptions(**change)
    assert info.value.field == field and str(info.value).startswith(field)
    assert isinstance(info.value, ValueError)
    with pytest.raises(OptionError, match=message):  # a changed copy is checked too
        dataclasses.replace(AdaptiveOptions(), **change)


def test_values_are_normalised_and_a_budget_keeps_its_type():
    options = AdaptiveOptions(theta=1, max_ndof=2500, tol=0, max_levels=3)
    assert options.theta == 1.0 and isinstance(options.theta, float)
    assert options.max_ndof == 2500 and isinstance(options.max_ndof, int)
    assert AdaptiveOptions(max_ndof=float("inf")).max_ndof == float("inf")
    assert isinstance(options.tol, float)


def test_the_record_holds_every_field_and_the_solver_by_name():
    options = AdaptiveOptions(theta=0.5, max_ndof=3000, eta5_variant="paper", solver=superlu_solver)
    record = options.to_record()
    assert list(record) == [f.name for f in dataclasses.fields(AdaptiveOptions)]
    assert record["solver"] == "scipy" and json.loads(json.dumps(record)) == record
    assert AdaptiveOptions.from_record(record) == options
    with pytest.raises(ValueError, match="not a registered backend"):
        AdaptiveOptions(solver=lambda request: None).to_record()


def test_a_record_written_before_the_rename_is_read():
    """Manifests of earlier runs name the η5 variant ``eta5`` and the solver ``backend``,
    and hold the command line's own flags beside the options."""
    old = {
        "uniform": False,
        "theta": 0.5,
        "max_ndof": 2500,
        "tol": 0.0,
        "max_levels": 100,
        "eta5": "paper",
        "backend": "scipy",
        "fallback": False,
        "no_vtu": False,
        "compare_uniform": False,
    }
    options = AdaptiveOptions.from_record(old)
    assert options == AdaptiveOptions(
        theta=0.5, max_ndof=2500, eta5_variant="paper", solver=superlu_solver
    )
    with pytest.raises(OptionError, match="unknown backend 'mumps'") as info:
        AdaptiveOptions.from_record({"backend": "mumps"})
    assert info.value.field == "solver"
    assert set(SOLVERS) >= {"auto", "pardiso", "scipy"}


def test_adaptive_takes_options_and_keyword_changes_alike():
    problem = example_6_2()
    options = AdaptiveOptions(max_ndof=1500, theta=0.5)
    by_object = [lv.record.ndof for lv in adaptive(problem, options)]
    by_keywords = [lv.record.ndof for lv in adaptive(problem, max_ndof=1500, theta=0.5)]
    changed = [lv.record.ndof for lv in adaptive(problem, options, theta=0.3)]
    assert by_object == by_keywords and len(by_object) > 3
    assert changed != by_object and max(changed) <= 1500
    with pytest.raises(TypeError, match=r"unexpected keyword arguments \['thetaa'\]"):
        adaptive(problem, thetaa=0.5)
    with pytest.raises(ValueError, match="options must be an AdaptiveOptions, got dict"):
        adaptive(problem, {"theta": 0.5})
