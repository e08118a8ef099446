"""The README's example of :mod:`signorini.plots`, run exactly as written."""

from __future__ import annotations

import pytest

from signorini.cli import main

README_EXAMPLE = """\
from signorini import plots
history = plots.read_history("results/example-6.1/history.csv")
plots.plot_contributions(history, "results/example-6.1/contributions", title="Example 6.1")
"""


@pytest.mark.slow
def test_readme_example_draws_a_figure_from_a_history(tmp_path, monkeypatch, captured):
    monkeypatch.chdir(tmp_path)
    assert main(["run", "example-6.1", "--max-ndof", "800", "--quiet", "--no-figures"]) == 0
    exec(compile(README_EXAMPLE, "README.md", "exec"), {})
    out = tmp_path / "results" / "example-6.1"
    assert (out / "contributions.png").stat().st_size > 5000
    assert (out / "contributions.pdf").stat().st_size > 5000
    (info,) = captured
    assert info["titles"][0] == "Example 6.1"
    assert [t.split(",")[0] for t in info["legend"]] == [
        *(rf"$\eta_{k}$" for k in range(1, 6)),
        r"$\eta_6 \equiv 0$",
        r"$\eta_7 \equiv 0$",
    ]
