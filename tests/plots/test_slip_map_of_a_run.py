"""The stick/slip map through a run: ``signorini run partial-slip-3d`` writes the map of its
last level, readable, and the counts it shows are the history's stick and slip nodes."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from signorini.cli import main


@pytest.mark.slow  # one level of partial-slip-3d (its press and pull steps), about 30 s
def test_a_frictional_3d_run_draws_its_slip_map(tmp_path, captured):
    out = tmp_path / "ps"
    assert main(["run", "partial-slip-3d", "--max-levels", "1", "--out", str(out), "--quiet",
                 "--no-vtu"]) == 0  # fmt: skip
    assert (out / "partial-slip-3d_slip_map.png").is_file()
    assert (out / "partial-slip-3d_slip_map.pdf").is_file()
    row = list(csv.DictReader(open(out / "history.csv")))[-1]
    stick, slip = int(row["n_stick"]), int(row["n_slip"])
    assert stick > 0 and slip > 0  # Mindlin's annulus: both states on the disc
    (info,) = [i for i in captured if Path(i["file"]).stem == "partial-slip-3d_slip_map"]
    assert f"stick ({stick})" in info["legend"] and f"slip ({slip})" in info["legend"]
    assert any(text.startswith("Mindlin's stick radius c = ") for text in info["legend"])


@pytest.mark.slow  # two short 3D runs and their figures, about 30 s
def test_the_figures_of_3d_runs_are_readable(tmp_path, captured):
    """Every figure of an obstacle run (hertz-3d) and of a pair run (two-spheres) is saved
    without clipped or overlapping text or a wide empty band (the ``captured`` fixture)."""
    assert main(["run", "hertz-3d", "--max-ndof", "8000", "--out", str(tmp_path / "h"),
                 "--quiet", "--no-vtu"]) == 0  # fmt: skip
    assert main(["run", "two-spheres", "--max-levels", "5", "--out", str(tmp_path / "s"),
                 "--quiet", "--no-vtu"]) == 0  # fmt: skip
    stems = {Path(i["file"]).stem for i in captured}
    print(sorted(stems))
    for name in ("hertz-3d", "two-spheres"):
        assert {f"{name}_body", f"{name}_contact_pressure", f"{name}_estimator"} <= stems
