"""The steps of a load path share one mesh including its boundary parts and curves: steps on
the same points and cells but other part labels or curves are refused, naming the step and
what differs (every step is solved on the first step's mesh)."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.contact.load_path import solve_path
from signorini.fem.material import Material
from signorini.loop import adaptive
from signorini.mesh.builders import rectangle
from signorini.mesh.curves import Circle, Line
from signorini.mesh.mesh import Mesh
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann

BASE = rectangle(0.0, 2.0, 0.0, 1.0, nx=4, ny=2)
TOL = 1e-9


def labelled(split: float) -> Mesh:
    """BASE with the bottom part ``x ≤ split`` of y = 0; the rest of y = 0 goes to "right"."""
    x = lambda p: p[:, 0]  # noqa: E731
    y = lambda p: p[:, 1]  # noqa: E731
    return Mesh.from_arrays(
        BASE.points,
        BASE.cells,
        {
            "top": lambda p: np.abs(y(p) - 1) < TOL,
            "left": lambda p: np.abs(x(p)) < TOL,
            "bottom": lambda p: (np.abs(y(p)) < TOL) & (x(p) <= split + TOL),
            "right": lambda p: (np.abs(x(p) - 2) < TOL) | ((np.abs(y(p)) < TOL) & (x(p) > split)),
        },
    )


def block(mesh: Mesh, push: float) -> ContactProblem:
    return ContactProblem(
        mesh,
        Material.from_young(1.0, 0.3),
        {
            "top": Dirichlet((0.0, -push)),
            "left": Neumann(),
            "right": Neumann(),
            "bottom": Contact(gap=0.0),
        },
    )


def test_steps_with_other_part_labels_are_refused():
    steps = [block(labelled(2.0), 0.01), block(labelled(1.0), 0.02)]
    with pytest.raises(ValueError) as info:
        solve_path(steps)
    msg = str(info.value)
    assert msg.startswith("problems[1] is posed on the points and cells of problems[0] but")
    assert "labels 2 boundary edge(s) with other parts" in msg, msg
    assert "(1, 0)–(1.5, 0) is on part 'right', on problems[0] 'bottom'" in msg, msg
    with pytest.raises(ValueError, match=r"problems\[1\] .* labels 2 boundary edge"):
        adaptive(steps[1], path=steps[:1])


def _with_bottom_curve(curve) -> Mesh:
    # one cell row of width 2 along the bottom: its vertices (0, 0) and (2, 0) lie on both the
    # line y = 0 and the circle through them with centre (1, −5)
    mesh = rectangle(0.0, 2.0, 0.0, 1.0, nx=1, ny=1)
    return mesh.with_curve("bottom", curve)


def test_steps_with_another_curve_are_refused():
    circle = Circle((1.0, -5.0), float(np.hypot(1.0, 5.0)))
    steps = [
        block(_with_bottom_curve(Line((0.0, 0.0), (2.0, 0.0))), 0.01),
        block(_with_bottom_curve(circle), 0.02),
    ]
    with pytest.raises(ValueError, match=r"problems\[1\] .* another curve to part 'bottom'"):
        solve_path(steps)
    steps[1] = block(rectangle(0.0, 2.0, 0.0, 1.0, nx=1, ny=1), 0.02)
    with pytest.raises(ValueError, match=r"problems\[1\] .* has no curve on part 'bottom'"):
        solve_path(steps)


def test_equal_meshes_built_twice_are_one_mesh():
    # the same labels and an equal curve on distinct Mesh objects: accepted, and the path's
    # last step equals the static solve of its load (frictionless: path-independent)
    line = lambda: Line((0.0, 0.0), (2.0, 0.0))  # noqa: E731
    steps = [block(labelled(2.0).with_curve("bottom", line()), p) for p in (0.01, 0.02)]
    results = solve_path(steps)
    direct = solve_path(steps[1:])[0]
    assert np.abs(results[1].u - direct.u).max() <= 1e-12 * np.abs(direct.u).max()
