"""``partial-slip-3d`` (Cattaneo–Mindlin in 3D): the half ball pressed, then pulled along x,
through two load steps of ``solve`` (docs/method.md, *Friction in three dimensions*)."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.contact.solution import SLIP, STICK, solve
from signorini.examples.partial_slip3d import partial_slip_3d_metrics, partial_slip_3d_path


@pytest.mark.slow
def test_a_central_stick_disc_inside_a_slip_annulus_near_mindlins_radius():
    """On the default mesh (h = 0.1 R at the pole: about two cells across the contact
    radius a ≈ 0.097 R) the stick set is a few rows, so c is resolved to about one row's
    share of Γ_C: |c/a − (1 − Q/(F P))^{1/3}| ≤ 0.15 (measured 0.107). The states form a
    disc inside an annulus: every stick row is nearer the axis than the farthest slip row,
    and the mean radius of the slip rows exceeds that of the stick rows."""
    steps = partial_slip_3d_path()
    result = None
    for step in steps:  # a loop over load steps
        result = solve(step, step.mesh, previous=result)
        assert result.report.kkt.max <= 1e-10
    m = partial_slip_3d_metrics(result)
    assert 0.2 < m["q_over_fp"] < 0.8  # partial slip
    x = result.space.node_points[result.contact.node]
    r = np.hypot(x[:, 0], x[:, 1])
    stick, slip = result.state == STICK, result.state == SLIP
    assert stick.any() and slip.any()
    assert r[stick].max() < r[slip].max() and r[stick].mean() < r[slip].mean()
    assert abs(m["c_over_a"] - m["c_over_a_theory"]) <= 0.15


@pytest.mark.slow
def test_the_run_records_the_states_in_its_history_and_vtu(tmp_path, capsys):
    """``signorini run partial-slip-3d --uniform`` (one level, about 11k unknowns): the
    history's friction columns, described in history.md, agree with the example's own counts
    and with the level's VTU file read back; the tangential KKT residuals meet 1e-12."""
    import csv

    import meshio

    from signorini.cli import main

    out = tmp_path / "run"
    args = ["run", "partial-slip-3d", "--uniform", "--max-ndof", "12000", "--no-figures"]
    assert main([*args, "--out", str(out)]) == 0
    capsys.readouterr()
    (row,) = list(csv.DictReader(open(out / "history.csv")))
    assert int(row["n_stick"]) == float(row["stick_nodes"]) > 0
    assert int(row["n_slip"]) == float(row["slip_nodes"]) > 0
    for name in ("kkt_tangential_bound", "kkt_tangential_complementarity"):
        assert float(row[name]) <= 1e-12, name
    described = (out / "history.md").read_text()
    table = {line.split("`")[1] for line in described.splitlines() if line.startswith("| `")}
    assert table - {"linear_iterations"} == set(row)
    state = meshio.read(out / "level_000.vtu").point_data["contact_state"]
    assert int((state == STICK).sum()) == int(row["n_stick"])
    assert int((state == SLIP).sum()) == int(row["n_slip"])
