"""The deformed-body figure of the built-in examples draws each obstacle's real shape at true
scale (the plane under ``hertz`` straight, the rounded corner of ``punch``'s polyline round),
and the pressure against the true arc length of each contact part, the parts apart."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.examples import hertz, punch
from signorini.loop import adaptive
from signorini.loop.arrays import arc_lengths, level_arrays
from signorini.plots.contact_stress import NARROWEST, part_widths
from signorini.plots.deformed import ContactDrawing, plot_deformed
from signorini.plots.run_figures import _joined


def last_arrays(problem, max_ndof: int) -> dict:
    *_, last = adaptive(problem, max_ndof=max_ndof)
    return level_arrays(last)


def part_edge_length(a: dict, name: str) -> float:
    """The longest chord of the part's contact edges (a cell size on the part)."""
    rows, s = a["along"][name]
    return float(np.diff(s).max()) * 2.0


@pytest.fixture(scope="module")
def hertz_arrays():
    return last_arrays(hertz(), 1500)


@pytest.fixture(scope="module")
def punch_arrays():
    return last_arrays(punch(), 1500)


@pytest.mark.slow
def test_hertz_plane_is_drawn_straight_and_the_arc_spans_pi_r(hertz_arrays, tmp_path, captured):
    a = hertz_arrays
    outline = a["obstacle"]["arc"]
    shown = np.isfinite(outline[:, 0])
    assert shown.sum() > 100
    # the plane y = 0 (once drawn as the parabola points + scale·ψ·n)
    np.testing.assert_array_equal(outline[shown, 1], 0.0)
    assert outline[shown, 0].min() < -0.5 and outline[shown, 0].max() > 0.5
    rows, s = a["along"]["arc"]
    h = part_edge_length(a, "arc")
    assert s[0] >= 0.0 and np.all(np.diff(s) > 0)
    assert abs(s.max() - np.pi * 1.0) <= h  # the half-circle of radius 1, not 2 = its chord
    # s follows the arc: the nodes' angle on the circle (centre (0, 1)) is s / R from the start
    x = a["contact_points"][rows]
    angle = np.unwrap(np.arctan2(x[:, 1] - 1.0, x[:, 0]))
    np.testing.assert_allclose(np.abs(angle - angle[0]), s - s[0], atol=1e-3 * np.pi)
    # the figure draws both as given
    plot_deformed(
        a["points"], a["cells"], a["displacement"][: len(a["points"])], tmp_path / "d",
        ContactDrawing(a["contact_points"], a["pressure"], along=a["along"]),
        obstacle=_joined(a["obstacle"].values()),
    )  # fmt: skip
    (info,) = captured
    x_drawn, y_drawn = info["lines"]["obstacle (true scale)"]
    np.testing.assert_array_equal(y_drawn[np.isfinite(y_drawn)], 0.0)
    assert " ".join(info["titles"][0].split()).endswith(
        "displacement \u00d710, obstacle at true scale"
    )
    (s_drawn, p_drawn) = info["lines"]["$p_h$"]
    np.testing.assert_array_equal(s_drawn, s)
    np.testing.assert_array_equal(p_drawn, a["pressure"][rows])
    assert info["titles"][1] == "contact part 'arc'" and info["xlabel"][1] == r"arc length $s$"


@pytest.mark.slow
def test_punch_outline_is_its_polyline_with_rounded_corners(punch_arrays, tmp_path, captured):
    a = punch_arrays
    problem = punch()
    tool = problem.conditions["top"].obstacle
    top = a["obstacle"]["top"]
    top = top[np.isfinite(top[:, 0])]
    psi, _ = tool.gap_and_direction(top)
    assert np.abs(psi).max() <= 1e-12  # every drawn point on the punch's boundary
    # the flat bottom y = H - d = 0.99 and the rounded corner: centre (1.2, 1.19), r = 0.2
    assert np.sum(np.abs(top[:, 1] - 0.99) <= 1e-12) > 20
    r = np.hypot(top[:, 0] - 1.2, top[:, 1] - 1.19)
    on_arc = np.abs(r - 0.2) <= 1e-12
    angle = np.degrees(np.arctan2(top[on_arc, 1] - 1.19, top[on_arc, 0] - 1.2))
    assert on_arc.sum() > 50 and angle.max() > -90.5 and angle.min() < -150.0
    # no point of the hook the scaled gaps drew: nothing above the corner's centre
    assert top[:, 1].max() < 1.19
    # the wall x = 2, and each part's arc length from 0 to its length
    wall = a["obstacle"]["right"]
    np.testing.assert_array_equal(wall[np.isfinite(wall[:, 0]), 0], 2.0)
    lengths = {name: s.max() for name, (rows, s) in a["along"].items()}
    assert lengths["top"] == pytest.approx(2.0, abs=part_edge_length(a, "top"))
    assert lengths["right"] == pytest.approx(1.0, abs=part_edge_length(a, "right"))
    # the wall gets a third of the row (not 0.27 of one shared axis): widths follow lengths
    widths = part_widths(a["along"])
    assert widths[1] / sum(widths) == pytest.approx(1 / 3, abs=0.02)
    plot_deformed(
        a["points"], a["cells"], a["displacement"][: len(a["points"])], tmp_path / "d",
        ContactDrawing(a["contact_points"], a["pressure"], along=a["along"]),
        obstacle=_joined(a["obstacle"].values()),
    )  # fmt: skip
    (info,) = captured
    assert info["titles"][1:] == ["contact part 'top'", "contact part 'right'"]
    s_top = info["lines_by_axes"][1][0][0]
    s_right = info["lines_by_axes"][2][0][0]
    assert s_top.min() == 0.0 and s_right.max() == pytest.approx(lengths["right"])


def test_part_widths_have_a_floor():
    along = {
        "long": (np.arange(3), np.array([0.0, 5.0, 10.0])),
        "short": (np.arange(2), np.array([0.0, 0.1])),
    }
    widths = part_widths(along)
    assert widths[1] == NARROWEST and widths[0] == pytest.approx(10.0 / 10.1)


def test_arc_lengths_on_a_closed_chain_start_at_its_first_edge():
    """A part with no first vertex (a closed boundary) is measured from its first edge's
    start; a square of side 1 has perimeter 4."""
    from types import SimpleNamespace

    corners = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    mids = 0.5 * (corners + np.roll(corners, -1, axis=0))
    points = np.vstack([corners, mids])
    facet_nodes = np.column_stack([np.arange(4), (np.arange(4) + 1) % 4, 4 + np.arange(4)])
    local = np.column_stack([np.arange(4), (np.arange(4) + 1) % 4, 4 + np.arange(4)])
    cs = SimpleNamespace(
        parts=("loop",), facet_part=np.zeros(4, int), facet_nodes=facet_nodes, facet_local=local
    )
    rows, s = arc_lengths(cs, points)["loop"]
    np.testing.assert_array_equal(rows, [0, 4, 1, 5, 2, 6, 3, 7])
    np.testing.assert_allclose(s, [0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5])


def test_a_gap_function_is_drawn_as_the_surface_x_plus_psi_n():
    """Example 6.2's obstacle ψ(y) = -0.2 + 0.5 |y - 0.5| along the normal (1, 0) of the side
    x = 1 is the V-shaped surface x = 1 + ψ(y), unscaled (once drawn as 1 + scale ψ)."""
    from signorini.examples import get_example

    a = last_arrays(get_example("example-6.2"), 800)
    outline = a["obstacle"]["right"]
    outline = outline[np.isfinite(outline[:, 0])]
    assert outline[:, 1].min() == 0.0 and outline[:, 1].max() == 1.0
    psi = -0.2 + 0.5 * np.abs(outline[:, 1] - 0.5)
    np.testing.assert_allclose(outline[:, 0], 1.0 + psi, rtol=0, atol=1e-14)
