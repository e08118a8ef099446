"""A magnified drawing magnifies the obstacle's gaps too: each contact node, drawn at
``x + s u``, lies on the drawn obstacle, so no body appears to pass through a rigid plane
(:func:`signorini.plots.plot_deformed` with ``obstacle_offset``)."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.examples import hertz, punch
from signorini.loop import adaptive
from signorini.loop.arrays import level_arrays
from signorini.plots.deformed import ContactDrawing, plot_deformed
from signorini.plots.run_figures import _joined
from signorini.plots.style import DPI

#: Half the width of the drawn obstacle line (1.5 pt), in pixels of the saved PNG: a node
#: this close to the line's centre is drawn on it.
HALF_LINE = 0.5 * 1.5 / 72.0 * DPI


def last_level(problem, max_ndof: int):
    *_, last = adaptive(problem, max_ndof=max_ndof)
    return last


def pixel_distance(points: np.ndarray, polyline: np.ndarray) -> np.ndarray:
    """(k,) distance of each point to a polyline broken by NaN rows (same coordinates)."""
    a, b = polyline[:-1], polyline[1:]
    keep = np.isfinite(a).all(axis=1) & np.isfinite(b).all(axis=1)
    a, b = a[keep], b[keep]
    d = b - a
    t = np.einsum("pkj,kj->pk", points[:, None, :] - a[None], d) / np.einsum("kj,kj->k", d, d)
    nearest = a[None] + np.clip(t, 0.0, 1.0)[..., None] * d[None]
    return np.hypot(*(points[:, None, :] - nearest).transpose(2, 0, 1)).min(axis=1)


def draw(level, tmp_path, captured, offsets: bool) -> tuple[dict, np.ndarray, np.ndarray]:
    """The deformed figure of ``level``; what it shows, its active contact nodes as drawn
    (pixels), and their reference coordinates."""
    a = level_arrays(level)
    res = level.result
    u_c = res.u[res.contact.nodes]
    plot_deformed(
        a["points"], a["cells"], a["displacement"][: len(a["points"])], tmp_path / "d",
        ContactDrawing(a["contact_points"], a["pressure"], along=a["along"]),
        obstacle=_joined(a["obstacle"].values()),
        obstacle_offset=_joined(a["obstacle_offset"].values()) if offsets else None,
    )  # fmt: skip
    info = captured[-1]
    assert "\u00d710" in info["titles"][0]  # the displacement drawn ten times magnified
    x = a["contact_points"][a["active"]]
    drawn = x + 10.0 * u_c[a["active"]]
    return info, info["data_to_display"][0].transform(drawn), x


@pytest.fixture(scope="module")
def punch_level():
    return last_level(punch(), 1500)


def test_punch_nodes_in_contact_lie_on_the_drawn_punch(punch_level, tmp_path, captured):
    """The flat punch (depth 0.01) and the wall x = 2: every active node, magnified ten
    times, is drawn on the drawn obstacle (exactly under the flat bottom and on the wall;
    on the rounded corner within half the line's width, the share of the tangential
    displacement along the curved outline); at true scale the punch's flat bottom was
    drawn (10 − 1) · 0.01 above the nodes it presses, through the body."""
    info, nodes, x = draw(punch_level, tmp_path, captured, offsets=True)
    assert " ".join(info["titles"][0].split()) == (
        "deformed body, displacement and obstacle gaps \u00d710"
    )
    line = np.column_stack(info["lines"]["obstacle, gaps \u00d710"])
    on_line = pixel_distance(nodes, info["data_to_display"][0].transform(line))
    under = (x[:, 0] > 1.25) & (x[:, 0] < 1.9) & (x[:, 1] == 1.0)  # under the flat bottom
    flat = under | (x[:, 0] == 2.0)  # and on the wall
    print(f"{len(nodes)} active nodes: {on_line[flat].max():.1e} px off the flat parts, ")
    print(f"{on_line.max():.2f} px at most, half the line is {HALF_LINE:.2f} px")
    assert flat.sum() > 20 and on_line[flat].max() < 1e-6
    assert on_line.max() < HALF_LINE
    # the flat bottom is drawn at 1 − 10 · 0.01 = 0.9, where the pressed nodes are drawn
    bottom = line[np.isfinite(line[:, 1]) & (line[:, 0] > 1.45) & (line[:, 0] < 1.95)]
    np.testing.assert_allclose(bottom[:, 1], 0.9, rtol=0, atol=1e-12)
    # before: the obstacle at true scale, 0.09 above the drawn nodes
    info, nodes, _ = draw(punch_level, tmp_path, captured, offsets=False)
    true_line = np.column_stack(info["lines"]["obstacle (true scale)"])
    off = pixel_distance(nodes, info["data_to_display"][0].transform(true_line))
    print(f"at true scale: {off[under].min():.1f} to {off.max():.1f} px off")
    assert under.sum() >= 8 and off[under].min() > 5 * HALF_LINE


def test_hertz_disc_rests_on_the_drawn_plane_where_it_touches(tmp_path, captured):
    """The disc on the plane y = 0: the drawn plane follows the magnified gaps of the curved
    side, so every active node lies on it (within half the line's width: the tangential
    displacement along the curve), and it is drawn only near the contact zone."""
    level = last_level(hertz(), 1500)
    info, nodes, _ = draw(level, tmp_path, captured, offsets=True)
    line = np.column_stack(info["lines"]["obstacle, gaps \u00d710"])
    on_line = pixel_distance(nodes, info["data_to_display"][0].transform(line))
    print(f"{len(nodes)} active nodes, at most {on_line.max():.2f} px off the drawn plane")
    assert len(nodes) >= 10 and on_line.max() < HALF_LINE
    shown = line[np.isfinite(line[:, 0])]
    # only where the magnified gap is at most 0.1 of the body's size 2: 10 ψ <= 0.2, the
    # drawn plane 9 ψ below y = 0
    assert shown[:, 1].min() >= -0.18 - 1e-12 and np.abs(shown[:, 0]).max() < 0.25
