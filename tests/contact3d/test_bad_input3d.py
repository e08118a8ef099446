"""Bad input of a 3D contact problem, each refused before any work with an error naming the
part, node or motion (issue 38, "Bad input")."""

from __future__ import annotations

import numpy as np
import pytest
from contact3d_problems import MATERIAL

from signorini.contact.solution import solve
from signorini.contact.system import assemble
from signorini.mesh.builders import rectangle
from signorini.mesh.builders3d import box
from signorini.mesh.mesh import Mesh
from signorini.mesh.validation import MeshError
from signorini.problem.conditions import Contact, Dirichlet, Neumann, Roller
from signorini.problem.fields import ProblemError
from signorini.problem.obstacles3d import HalfSpace
from signorini.problem.problem import ContactProblem


def _conditions(mesh: Mesh, **changes) -> dict:
    conditions = {name: Neumann((0.0, 0.0, 0.0)) for name in mesh.part_names}
    conditions.update(z1=Dirichlet((0.0, 0.0, -0.01)), **changes)
    return conditions


def _refused(conditions: dict, match: str, mesh: Mesh | None = None) -> None:
    """Refused by the problem or by the assembly, which evaluates the user's functions
    before the stiffness matrix."""
    mesh = box(2, 2, 2) if mesh is None else mesh
    with pytest.raises(ProblemError, match=match):
        assemble(ContactProblem(mesh, MATERIAL, conditions), mesh)


def test_a_contact_part_the_mesh_does_not_have():
    mesh = box(1, 1, 1)
    with pytest.raises(ProblemError, match=r"do(es)? not have: \['floor'\]"):
        ContactProblem(mesh, MATERIAL, _conditions(mesh, floor=Contact()))


def test_a_part_off_the_boundary():
    mesh = box(2, 2, 2)
    parts = {p: mesh.facets[mesh.part_facets(p)] for p in mesh.part_names}
    parts["inside"] = mesh.facets[np.flatnonzero(mesh.facet2cell[:, 1] >= 0)[:1]]
    with pytest.raises(MeshError, match="boundary part 'inside'.* not a boundary face"):
        Mesh.from_arrays(mesh.points, mesh.cells, parts)


def test_a_body_that_starts_deep_inside_the_obstacle():
    """The plane at z = 0.5 puts the bottom 0.5 deep into it, more than a quarter of the
    body's diagonal √3 (0.43), with the top held."""
    plane = HalfSpace([0.0, 0.0, 0.5], [0.0, 0.0, 1.0])
    _refused(_conditions(box(1, 1, 1), z0=Contact(obstacle=plane)),
             r"contact part 'z0' starts 0\.5 deep inside the body at \(", box(1, 1, 1))  # fmt: skip


def test_a_body_held_by_nothing_along_some_rigid_motions():
    """A roller on z0 alone leaves the translations in x and y and the rotation about z
    free, and no contact part holds them: all three are named."""
    mesh = box(1, 1, 1)
    conditions = {name: Neumann((0.0, 0.0, 0.0)) for name in mesh.part_names}
    conditions["z0"] = Roller()
    with pytest.raises(ProblemError, match="leave 3 rigid motion") as err:
        ContactProblem(mesh, MATERIAL, conditions)
    text = str(err.value)
    assert "rotation about the axis (0.0, 0.0, 1.0) through" in text
    assert text.count("translation along") == 2
    # a contact on x0 holds the translation along x and the rotation about z (its normal
    # component changes sign over the face), not the translation along y
    conditions["x0"] = Contact(obstacle=HalfSpace([-0.1, 0, 0], [1.0, 0, 0]))
    with pytest.raises(ProblemError, match="leave 1 rigid motion") as err:
        ContactProblem(mesh, MATERIAL, conditions)
    assert "translation along (0.0, 1.0, 0.0)" in str(err.value)


@pytest.mark.parametrize(
    ("normal", "match"),
    [
        ((0.0, -1.0), r"contact part 'z0' gives normal=\(0\.0, -1\.0\) \(2 numbers\) on a 3D"),
        (lambda x: np.zeros((len(x), 2)), r"the normal of contact part 'z0' must return shape"),
        (lambda x: np.tile([0.0, 0.0, -2.0], (len(x), 1)), r"contact part 'z0' has length 2"),
        ((0.0, 0.0, 1.0), r"given for contact part 'z0' at the node .* points into the body"),
        (lambda x: np.tile([1.0, 0.0, 0.0], (len(x), 1)), r"'z0' at the node .* or along it"),
    ],
    ids=["two-numbers", "shape", "length", "inward", "tangent"],
)
def test_a_given_normal_of_the_wrong_shape_length_or_side(normal, match):
    _refused(_conditions(box(2, 2, 2), z0=Contact(gap=0.01, normal=normal)), match)


def test_three_numbers_or_a_direction_field_on_a_2d_mesh():
    mesh = rectangle(nx=2, ny=2)
    conditions = {name: Neumann((0.0, 0.0)) for name in mesh.part_names}
    conditions.update(top=Dirichlet((0.0, 0.0)), bottom=Contact(normal=(0.0, 0.0, -1.0)))
    with pytest.raises(ProblemError, match="contact part 'bottom' gives normal=.* on a 2D mesh"):
        ContactProblem(mesh, MATERIAL, conditions)


def test_a_gap_function_that_returns_nan_names_the_part_and_the_point():
    def gap(x):
        return np.where(x[:, 0] > 0.7, np.nan, 0.01)

    where = r"returned NaN or inf at x = \(1\.0, 0\.0, 0\.0\)"
    _refused(_conditions(box(2, 2, 2), z0=Contact(gap=gap)), "contact part 'z0' " + where)


def test_a_problem_handed_a_mesh_of_the_other_dimension():
    cube = box(1, 1, 1)
    problem3d = ContactProblem(cube, MATERIAL, _conditions(cube))
    square = rectangle(nx=1, ny=1)
    conditions = {name: Neumann((0.0, 0.0)) for name in square.part_names}
    conditions["bottom"] = Dirichlet((0.0, 0.0))
    problem2d = ContactProblem(square, MATERIAL, conditions)
    with pytest.raises(ValueError, match="stated on a 3D mesh and was handed a 2D mesh"):
        solve(problem3d, square)
    with pytest.raises(ValueError, match="stated on a 2D mesh and was handed a 3D mesh"):
        solve(problem2d, cube)


def test_a_refinement_handed_as_the_mesh_is_refused_naming_its_mesh():
    """``solve(problem, refine_uniform(mesh))`` (the refinement's record, not its mesh): a
    TypeError naming ``mesh`` and the remedy, before any assembly; 2D alike."""
    from signorini.mesh.refine import refine_uniform

    cube = box(1, 1, 1)
    problem = ContactProblem(cube, MATERIAL, _conditions(cube))
    with pytest.raises(TypeError, match=r"mesh must be a Mesh, got Refinement: pass its \.mesh"):
        solve(problem, refine_uniform(cube))
    with pytest.raises(TypeError, match="mesh must be a Mesh, got ndarray$"):
        solve(problem, cube.points)
