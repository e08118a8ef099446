"""η8 on a load step (docs/method.md, *Load paths*): the friction law acts on the slip from
the previous step, and so does the friction work η8 measures. A step that repeats its
predecessor's load does not slip: its η8 is round-off, not the previous step's."""

from __future__ import annotations

import numpy as np

from signorini.contact.solution import solve
from signorini.estimator import estimate
from signorini.fem.material import Material
from signorini.mesh.builders import rectangle
from signorini.problem import Contact, ContactProblem, Coulomb, Dirichlet, Neumann
from signorini.problem.obstacles import Disc


def block() -> ContactProblem:
    """The block (0, 2) × (0, 1) pressed by 0.02 and pulled by 0.01 at its top onto a
    rigid cylinder touching the middle of its bottom, Coulomb 0.5: stick and slip zones."""
    return ContactProblem(
        rectangle(0.0, 2.0, 0.0, 1.0, nx=16, ny=8),
        Material.from_young(1.0, 0.3),
        {
            "left": Neumann(),
            "right": Neumann(),
            "top": Dirichlet((0.01, -0.02)),
            "bottom": Contact(obstacle=Disc((1.0, -12.5), 12.5), friction=Coulomb(0.5)),
        },
    )


def test_a_repeated_load_step_has_no_friction_work():
    problem = block()
    first = solve(problem)
    again = solve(problem, previous=first)
    assert np.abs(again.u - first.u).max() < 1e-12 * np.abs(first.u).max()
    assert np.abs(again.tangential_reference).max() > 1e-3  # the slip of step 1
    eta_first = estimate(first).as_dict()
    eta_again = estimate(again).as_dict()
    assert eta_first["eta_8"] > 1e-3 * eta_first["eta"], eta_first
    assert eta_again["eta_8"] < 1e-6 * eta_first["eta_8"], (eta_again["eta_8"], eta_first)
    # the other terms read the same solution
    for name in ("eta_1", "eta_2", "eta_3", "eta_5"):
        assert abs(eta_again[name] - eta_first[name]) <= 1e-9 * eta_first[name], name
