"""A 3D contact run of the command line, ``signorini run hertz-3d --uniform``: its history
holds the estimator's columns (η and its terms, the obstacle's term beside it) and the contact
columns that mean something on faces (n_active, contact_force, the KKT residuals, the node
classes of Section 4) and agrees with its own VTU file read back; history.md describes exactly the
columns written; fields.md the 3D contact fields; the figures of a 3D contact run are drawn
and listed."""

from __future__ import annotations

import csv

import meshio
import numpy as np
import pytest

from signorini.cli import main
from signorini.loop.record import FACE_CONTACT_LEFT_OUT, NO_ESTIMATE_COLUMNS

from ..plots.figure_checks import png_size


def _run(tmp_path, capsys, *extra: str):
    out = tmp_path / "run"
    args = ["run", "hertz-3d", "--uniform", "--max-ndof", "20000", "--out", str(out)]
    assert main([*args, *extra]) == 0
    lines = capsys.readouterr().out.splitlines()
    return out, lines, list(csv.DictReader(open(out / "history.csv")))


def test_the_history_of_a_3d_contact_run(tmp_path, capsys):
    out, lines, rows = _run(tmp_path, capsys, "--no-figures")
    (row,) = rows
    columns = set(row)
    assert {"n_active", "n_constrained", "contact_force", "kkt_primal", "kkt_dual"} <= columns
    assert {"kkt_complementarity", "a", "p0", "total_force"} <= columns
    assert not columns & set(FACE_CONTACT_LEFT_OUT)
    classes = {"n_full_contact", "n_semi_contact", "n_no_contact"}
    assert set(NO_ESTIMATE_COLUMNS) | classes | {"osc_obstacle"} <= columns
    assert float(row["eta"]) > 0
    assert sum(int(row[c]) for c in classes) == int(row["n_constrained"])
    for name in ("kkt_primal", "kkt_dual", "kkt_complementarity", "kkt_stationarity"):
        assert float(row[name]) <= 1e-10, name
    # the history against the level's VTU file
    data = meshio.read(out / "level_000.vtu")
    pd = data.point_data
    assert int(row["n_active"]) == int(pd["active"].sum()) > 0
    force = float(row["contact_force"])
    assert force == pytest.approx(float(pd["contact_force"].sum()), rel=1e-12)
    assert float(row["total_force"]) == pytest.approx(4 * force, rel=1e-15)
    assert int(row["n_constrained"]) == int(np.isfinite(pd["gap"]).sum())
    # every column described, nothing else
    described = (out / "history.md").read_text()
    table = {line.split("`")[1] for line in described.splitlines() if line.startswith("| `")}
    assert table - {"linear_iterations"} == columns  # described as absent with a direct solver
    assert "transformed" in described  # the 3D meaning of n_active and the KKT columns
    fields = (out / "fields.md").read_text()
    assert "`recovered_pressure`" in fields and "VTK_QUADRATIC_TETRA" in fields
    assert "levels.pvd" in fields and 'file="level_000.vtu"' in (out / "levels.pvd").read_text()
    assert any(line.startswith("level   0") and "active" in line for line in lines)


@pytest.mark.slow
def test_the_figures_of_a_3d_contact_run(tmp_path, capsys):
    out, lines, _ = _run(tmp_path, capsys)
    listed = lines[-2]
    for stem in ("hertz-3d_body", "hertz-3d_contact_pressure", "hertz-3d_pressure"):
        assert f"{stem}.png" in listed
        assert (out / f"{stem}.png").stat().st_size > 10_000
        assert (out / f"{stem}.pdf").stat().st_size > 5_000
    assert png_size(out / "hertz-3d_contact_pressure.png")[0] > 500
    assert "contact pressure over Γ_C" in " ".join(lines)
