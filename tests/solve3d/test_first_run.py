"""The first 3D run a user makes: ``signorini run elasticity-3d --uniform`` prints what a
level without contact has (the estimator, the errors), writes an honest history and draws
its figures."""

from __future__ import annotations

import csv
import re

import pytest

from signorini.cli import main
from signorini.loop.record import COLUMNS_3D, NO_CONTACT_COLUMNS, NO_ESTIMATE_COLUMNS

from ..plots.figure_checks import png_size


def _run(tmp_path, capsys, *extra: str) -> tuple[list[str], list[dict]]:
    out = tmp_path / "run"
    args = ["run", "elasticity-3d", "--uniform", "--max-ndof", "2000", "--out", str(out)]
    assert main([*args, *extra]) == 0
    lines = capsys.readouterr().out.splitlines()
    return lines, list(csv.DictReader(open(out / "history.csv")))


def test_the_level_lines_show_what_exists(tmp_path, capsys):
    lines, rows = _run(tmp_path, capsys, "--no-figures")
    assert lines[0].startswith("elasticity-3d: uniform, max_ndof=2000 -> ")
    levels = [line for line in lines if line.startswith("level ")]
    assert len(levels) == len(rows) == 2
    for line in lines:
        assert not re.search(r"nan|active|eta5", line), line
    assert re.search(
        r"ndof +81 +cells +48 +eta \d\.\d{4}e\+01 +eff \d\d\.\d{3} +error 7\.8100e-01 +h1 .* l2 .* "
        r"pardiso",
        levels[0],
    )
    assert re.search(r"error 2\.0330e-01 \(-0\.53\) +h1 [0-9.e-]+ \(-0\.5\d\)", levels[1])


def test_the_history_has_the_estimator_and_leaves_contact_out(tmp_path, capsys):
    _, rows = _run(tmp_path, capsys, "--no-figures")
    columns = set(rows[0])
    assert not columns & set(NO_CONTACT_COLUMNS)
    assert set(NO_ESTIMATE_COLUMNS) <= columns
    assert {"ndof", "error_energy", "error_h1", "error_l2", "rate_energy"} <= columns
    assert all("nan" not in (r["error_energy"], r["error_l2"], r["eta"]) for r in rows)
    for r in rows:  # the efficiency index is η_h over the energy error
        assert float(r["efficiency"]) == float(r["eta"]) / float(r["error_energy"])
    described = (tmp_path / "run" / "history.md").read_text()
    assert "tetrahedra of the mesh" in described and "`eta`" in described
    assert "`n_active`" not in described
    assert set(columns) - {"t_output", "error_l2", "rate_energy", "rate_h1", "rate_l2"} <= set(
        COLUMNS_3D
    )


def test_an_iterative_solve_prints_its_iterations(tmp_path, capsys):
    lines, rows = _run(tmp_path, capsys, "--no-figures", "--backend", "amg")
    levels = [line for line in lines if line.startswith("level ")]
    its = [int(re.search(r"amg (\d+) its", line).group(1)) for line in levels]
    assert its == [int(r["linear_iterations"]) for r in rows]
    assert all(0 < k < 200 for k in its)


def test_the_figures_of_a_3d_run(tmp_path, capsys):
    """With the estimator a 3D run gets the convergence figures of Section 6 (error and η_h,
    the efficiency index, η's terms) and the body; no contact figures without contact."""
    lines, _ = _run(tmp_path, capsys)
    out = tmp_path / "run"
    assert "figures: elasticity-3d_error_estimator.png" in lines[-2]
    stems = ("error_estimator", "efficiency", "contributions", "body")
    for stem in stems:
        png = out / f"elasticity-3d_{stem}.png"
        assert png.stat().st_size > 5000 and png.with_suffix(".pdf").stat().st_size > 5000
    assert png_size(out / "elasticity-3d_body.png") == (840, 720)
    assert not list(out.glob("*pressure*")) and not list(out.glob("*mesh*"))
    # ``signorini figures`` redraws the history of the 3D run (no level: no body)
    (out / "elasticity-3d_error_estimator.png").unlink()
    assert main(["figures", "elasticity-3d", str(out)]) == 0
    assert (out / "elasticity-3d_error_estimator.png").stat().st_size > 5000


def test_without_pyvista_one_line_in_the_log(tmp_path, capsys, caplog):
    import importlib.util
    import logging

    if importlib.util.find_spec("pyvista") is not None:
        pytest.skip("pyvista is installed: the rendering is drawn")
    caplog.set_level(logging.INFO, logger="signorini.plots")
    lines, _ = _run(tmp_path, capsys, "--quiet")
    assert lines == []
    said = [r.getMessage() for r in caplog.records if r.getMessage().startswith("pyvista")]
    assert len(said) == 1
