"""The problem a user states (:mod:`signorini.problem.problem`): one condition per part, a
Dirichlet part, straight contact parts with their outward normals, the Dirichlet nodes and
the paper's Ndof."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.fem.material import Material
from signorini.fem.space import P2Space
from signorini.mesh.builders import rectangle
from signorini.mesh.mesh import Mesh
from signorini.mesh.refine import refine_uniform
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann, ProblemError

MATERIAL = Material.from_young(10.0, 0.3)


def _square():
    return rectangle(nx=2, ny=2)


def right_contact(**contact) -> ContactProblem:
    """The unit square held on the left, free on top and bottom, in contact on the right."""
    return ContactProblem(
        _square(),
        MATERIAL,
        {"left": Dirichlet(), "top": Neumann(), "bottom": Neumann(), "right": Contact(**contact)},
    )


def test_parts_by_kind_and_contact_normals():
    pb = ContactProblem(
        rectangle(0, 2, 0, 1, nx=4, ny=2),
        MATERIAL,
        {"left": Dirichlet(), "top": Neumann(), "right": Contact(), "bottom": Contact(0.1)},
    )
    assert pb.dirichlet_parts == ["left"]
    assert pb.neumann_parts == ["top"]
    assert pb.contact_parts == ["right", "bottom"]
    assert np.array_equal(pb.contact_normals["right"], [1.0, 0.0])
    assert np.array_equal(pb.contact_normals["bottom"], [0.0, -1.0])


def test_dirichlet_nodes_and_free_ndof():
    mesh = rectangle(0, 2, 0, 1, nx=4, ny=2)
    pb = ContactProblem(
        mesh,
        MATERIAL,
        {"left": Dirichlet(), "bottom": Dirichlet(), "top": Neumann(), "right": Contact()},
    )
    space = P2Space(mesh)
    nodes = pb.dirichlet_nodes(space)
    x = space.node_points[nodes]
    # the closure of the left side (5 nodes) and the bottom (9 nodes) share the corner
    assert nodes.size == 5 + 9 - 1
    assert np.all((np.abs(x[:, 0]) < 1e-14) | (np.abs(x[:, 1]) < 1e-14))
    assert np.all(np.diff(nodes) > 0)
    assert pb.free_ndof(mesh) == space.n_dofs - 2 * 13
    # on a refined mesh: the P2 nodes (vertices and midpoints) of 4 + 8 edges
    fine = refine_uniform(mesh).mesh
    assert pb.free_ndof(fine) == P2Space(fine).n_dofs - 2 * (9 + 17 - 1)


def test_part_without_condition():
    with pytest.raises(ProblemError, match=r"boundary part\(s\) \['left'\] have no condition"):
        ContactProblem(
            _square(), MATERIAL, {"top": Dirichlet(), "right": Neumann(), "bottom": Contact()}
        )


def test_condition_on_unknown_part():
    with pytest.raises(ProblemError, match=r"parts the mesh does not have: \['side'\]"):
        ContactProblem(
            _square(),
            MATERIAL,
            {
                "top": Dirichlet(),
                "right": Neumann(),
                "left": Neumann(),
                "bottom": Contact(),
                "side": Neumann(),
            },
        )


def test_no_dirichlet_part():
    with pytest.raises(ProblemError, match="needs a Dirichlet part"):
        ContactProblem(
            _square(),
            MATERIAL,
            {"top": Neumann(), "right": Neumann(), "left": Neumann(), "bottom": Contact()},
        )


def test_condition_of_wrong_type():
    with pytest.raises(ProblemError, match="must be Dirichlet, Neumann or Contact"):
        ContactProblem(
            _square(),
            MATERIAL,
            {"top": Dirichlet(), "right": Neumann(), "left": Neumann(), "bottom": (0.0, 0.0)},
        )


def test_curved_contact_part():
    m = _square()
    mesh = Mesh.from_arrays(
        m.points,
        m.cells,
        {
            "corner": lambda x: (np.abs(x[:, 1]) < 1e-12) | (np.abs(x[:, 0] - 1) < 1e-12),
            "rest": lambda x: (np.abs(x[:, 1] - 1) < 1e-12) | (np.abs(x[:, 0]) < 1e-12),
        },
    )
    with pytest.raises(ProblemError, match="'corner' is not straight"):
        ContactProblem(mesh, MATERIAL, {"rest": Dirichlet(), "corner": Contact()})


@pytest.mark.parametrize("normal", [(-1.0, 0.0), (0.0, -1.0), (1.0, 0.1)])
def test_normal_that_is_not_the_outward_normal(normal):
    with pytest.raises(ProblemError, match="is not its outward normal"):
        right_contact(normal=normal)


def test_zero_normal():
    with pytest.raises(ProblemError, match="non-zero finite vector"):
        right_contact(normal=(0.0, 0.0))
    with pytest.raises(ProblemError, match="non-zero finite vector"):
        right_contact(normal=(np.nan, 1.0))


def test_outward_normal_accepted_unnormalised():
    assert np.allclose(right_contact(normal=(3.0, 0.0)).contact_normals["right"], [1.0, 0.0])


def test_material_must_be_a_material():
    with pytest.raises(ProblemError, match="material must be a signorini Material"):
        ContactProblem(
            _square(),
            (1.0, 1.0),
            {"left": Dirichlet(), "top": Neumann(), "bottom": Neumann(), "right": Contact()},
        )


@pytest.mark.parametrize(
    ("part", "condition", "match"),
    [
        ("left", Dirichlet((1.0, 2.0, 3.0)), r"Dirichlet value of part 'left' must be .* 2 finite"),
        ("top", Neumann((np.nan, 0.0)), r"traction of part 'top' must be .* 2 finite"),
        ("right", Contact(gap=(0.1, 0.2)), r"gap of part 'right' must be .* 1 finite"),
        ("right", Contact(gap="far"), r"gap of part 'right' must be"),
    ],
)
def test_constant_data_of_the_wrong_size(part, condition, match):
    conditions = {"left": Dirichlet(), "top": Neumann(), "bottom": Neumann(), "right": Contact()}
    with pytest.raises(ProblemError, match=match):
        ContactProblem(_square(), MATERIAL, {**conditions, part: condition})


def test_body_force_and_exact_solution_types():
    conditions = {"left": Dirichlet(), "top": Neumann(), "bottom": Neumann(), "right": Contact()}
    with pytest.raises(ProblemError, match="body_force must be a function"):
        ContactProblem(_square(), MATERIAL, conditions, body_force=(0.0, -1.0))
    with pytest.raises(ProblemError, match="exact must be an ExactSolution"):
        ContactProblem(_square(), MATERIAL, conditions, exact=lambda x: x)
