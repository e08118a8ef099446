"""The punch example (signorini.examples.punch): a rounded rigid punch pressed into a block
held by a rigid wall, two contact zones meeting at the block's corner (2, 1)."""

from __future__ import annotations

import numpy as np
import pytest

from signorini import adaptive
from signorini.examples import punch
from signorini.output import fitted_slope

CORNER = (2.0, 1.0)


@pytest.fixture(scope="module")
def levels():
    return list(adaptive(punch(), max_ndof=8_000))


def corner_rows(result) -> np.ndarray:
    points = result.space.node_points[result.contact.nodes]
    return np.flatnonzero(np.all(points == CORNER, axis=1))


def test_every_level_meets_kkt_to_1e_10(levels):
    worst = max(level.result.report.kkt.max for level in levels)
    print(f"\nlargest relative KKT residual over {len(levels)} levels: {worst:.2e}")
    assert worst <= 1e-10


def test_both_zones_are_in_contact_at_the_corner(levels):
    """The corner node carries one constraint per zone, both active with a positive force:
    its displacement is then fixed by the two obstacles, (0, −d) to round-off."""
    for level in levels:
        result = level.result
        rows = corner_rows(result)
        parts = [result.contact.parts[p] for p in result.contact.part[rows]]
        assert sorted(parts) == ["right", "top"], parts
        assert result.active[rows].all()
        assert np.all(result.contact_force[rows] > 0), result.contact_force[rows]
        u = result.u[result.contact.nodes[rows[0]]]
        assert np.abs(u - [0.0, -0.01]).max() < 1e-12, u
    forces = levels[-1].result.contact_force[corner_rows(levels[-1].result)]
    print(f"\ncorner forces Λ (top, right) on the last level: {forces}")


def test_contact_zone_under_the_punch_ends_on_its_rounded_corner(levels):
    """The punch's corner arc spans 1 ≤ x ≤ 1.2 (radius 0.2, left side at x = 1): contact
    starts on it, where the punch's bottom is above the block's top, not at x = 1.2."""
    profile = levels[-1].result.contact_profile("top")
    touching = profile.points[profile.contact_force > 0, 0]
    start = touching.min()
    print(f"\ncontact under the punch from x = {start:.4f} to {touching.max():.4f}")
    assert 1.1 < start < 1.2 and touching.max() == 2.0
    wall = levels[-1].result.contact_profile("right")
    assert (wall.contact_force > 0).sum() > 10 and wall.points[
        wall.contact_force > 0, 1
    ].max() == 1.0


def test_estimator_decays_like_one_over_ndof(levels):
    ndof = [level.record.ndof for level in levels]
    eta = [level.record.eta for level in levels]
    slope = fitted_slope(ndof, eta, last=5)
    print(f"\nη_h slope over the last 5 levels ({ndof[-5]} to {ndof[-1]} unknowns): {slope:.3f}")
    assert slope <= -0.9, f"η_h decays like Ndof^{slope:.3f}"


def test_command_line_runs_the_punch(tmp_path):
    from signorini.cli import main
    from signorini.output import read_history

    out = tmp_path / "punch"
    argv = ["run", "punch", "--max-ndof", "600", "--no-figures", "--quiet", "--out", str(out)]
    assert main(argv) == 0
    history = read_history(out / "history.csv")
    assert history["level"].size >= 3 and np.all(history["n_active"] > 0)
    assert (out / "level_000.vtu").is_file()
