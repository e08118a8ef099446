"""The problem a user states (:mod:`signorini.problem.problem`): one condition per part, a
Dirichlet part, straight contact parts with their outward normals, the Dirichlet nodes and
the paper's Ndof."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from signorini.fem.material import Material
from signorini.fem.space import P2Space
from signorini.mesh.builders import rectangle
from signorini.mesh.mesh import Mesh
from signorini.mesh.refine import refine_uniform
from signorini.problem import (
    Contact,
    ContactProblem,
    Dirichlet,
    Neumann,
    ProblemError,
    SlenderBodyWarning,
)

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
    with pytest.raises(ProblemError, match="must be Dirichlet, Roller, Neumann or Contact"):
        ContactProblem(
            _square(),
            MATERIAL,
            {"top": Dirichlet(), "right": Neumann(), "left": Neumann(), "bottom": (0.0, 0.0)},
        )


def test_polygonal_contact_part():
    """A contact part that is not straight has no single normal (its directions are per
    node); a normal given for it is refused."""
    m = _square()
    mesh = Mesh.from_arrays(
        m.points,
        m.cells,
        {
            "corner": lambda x: (np.abs(x[:, 1]) < 1e-12) | (np.abs(x[:, 0] - 1) < 1e-12),
            "rest": lambda x: (np.abs(x[:, 1] - 1) < 1e-12) | (np.abs(x[:, 0]) < 1e-12),
        },
    )
    pb = ContactProblem(mesh, MATERIAL, {"rest": Dirichlet(), "corner": Contact()})
    assert "corner" not in pb.contact_normals
    with pytest.raises(ProblemError, match="normal is given for contact part 'corner'"):
        ContactProblem(mesh, MATERIAL, {"rest": Dirichlet(), "corner": Contact(normal=(1, 0))})


@pytest.mark.parametrize("normal", [(-1.0, 0.0), (0.0, -1.0), (1.0, 0.1)])
def test_normal_that_is_not_the_outward_normal(normal):
    with pytest.raises(ProblemError, match="is not its outward normal"):
        right_contact(normal=normal)


def test_zero_normal():
    with pytest.raises(ProblemError, match=r"Contact\(normal=...\) must be None or two finite"):
        right_contact(normal=(0.0, 0.0))
    with pytest.raises(ProblemError, match=r"Contact\(normal=...\) must be None or two finite"):
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


def test_body_force_and_exact_solution_types():
    conditions = {"left": Dirichlet(), "top": Neumann(), "bottom": Neumann(), "right": Contact()}
    with pytest.raises(
        ProblemError,
        match=r"^ContactProblem\(body_force=...\) must be None or a function f\(x\) of points "
        r"x \(n, 2\); got \(0.0, -1.0\)$",
    ):
        ContactProblem(_square(), MATERIAL, conditions, body_force=(0.0, -1.0))
    with pytest.raises(ProblemError, match=r"got a function with signature \(x, y\)$"):
        ContactProblem(_square(), MATERIAL, conditions, body_force=lambda x, y: x)
    with pytest.raises(ProblemError, match="^conditions must be a mapping part name"):
        ContactProblem(_square(), MATERIAL, list(conditions.values()))
    with pytest.raises(ProblemError, match="exact must be an ExactSolution"):
        ContactProblem(_square(), MATERIAL, conditions, exact=lambda x: x)


# ---------------------------------------------------------------- components of the body


def _union(*meshes_and_parts) -> Mesh:
    """One mesh from several, each given as ``(mesh, shift, {new part: old part})``; points
    that coincide after the shift are merged (so meshes may share vertices)."""
    points, cells, parts = [], [], {}
    offset = 0
    for mesh, shift, names in meshes_and_parts:
        points.append(mesh.points + np.asarray(shift, dtype=float))
        cells.append(mesh.cells + offset)
        for new, old in names.items():
            pairs = mesh.oriented_boundary(mesh.part_facets(old)) + offset
            parts[new] = np.concatenate([parts[new], pairs]) if new in parts else pairs
        offset += mesh.n_points
    p = np.concatenate(points)
    _, first, inverse = np.unique(p.round(12), axis=0, return_index=True, return_inverse=True)
    keep = np.sort(first)
    renumber = np.empty(len(first), dtype=np.int64)
    renumber[np.argsort(first)] = np.arange(len(first))
    new_index = renumber[inverse.ravel()]
    return Mesh.from_arrays(
        p[keep], new_index[np.concatenate(cells)], {k: new_index[v] for k, v in parts.items()}
    )


SIDES = {"left": "left", "top": "top", "right": "right", "bottom": "bottom"}


def _two_squares():
    """The unit square (parts left, top, right, bottom) and a second one at x in [2, 3] (parts
    left2, top2, right2, bottom2), not touching."""
    sq = rectangle(nx=2, ny=2)
    return _union((sq, (0, 0), SIDES), (sq, (2, 0), {f"{k}2": v for k, v in SIDES.items()}))


def test_a_floating_component_is_named():
    mesh = _two_squares()
    conditions = {p: Neumann() for p in mesh.part_names}
    conditions["left"] = Dirichlet()
    conditions["top2"] = Neumann((0.0, -1.0))
    with pytest.raises(ProblemError) as info:
        ContactProblem(mesh, MATERIAL, conditions)
    assert str(info.value) == (
        "the body falls into 2 components (cells joined through shared edges; cells that "
        "share only a vertex are not joined), and 1 of them has no Dirichlet part, so nothing "
        "rules out their rigid body motions: component 2 (8 cells in [2, 3] × [0, 1], "
        "boundary parts ['left2', 'top2', 'right2', 'bottom2']). Give each component a "
        "Dirichlet part or join it to the body along an edge; contact alone does not hold a "
        "component (docs/method.md, *The continuous problem*)"
    )
    # held on both: accepted
    ContactProblem(mesh, MATERIAL, {**conditions, "left2": Dirichlet()})


def test_a_bow_tie_is_two_components():
    # a triangle joined to the clamped square at its corner (1, 1) only
    sq = rectangle(nx=2, ny=2)
    points = np.concatenate([sq.points, [[2.0, 1.0], [2.0, 2.0]]])
    corner = int(np.flatnonzero((sq.points == 1.0).all(axis=1))[0])
    n = sq.n_points
    wing = [[corner, n], [n, n + 1], [n + 1, corner]]
    parts = {name: sq.oriented_boundary(sq.part_facets(name)) for name in sq.part_names}
    mesh = Mesh.from_arrays(
        points, np.vstack([sq.cells, [[corner, n, n + 1]]]), {**parts, "wing": np.array(wing)}
    )
    conditions = {"left": Dirichlet(), "top": Neumann(), "right": Neumann(), "bottom": Neumann()}
    with pytest.raises(
        ProblemError,
        match=r"component 2 \(1 cell in \[1, 2\] × \[1, 2\], "
        r"boundary parts \['wing'\]\)",
    ):
        ContactProblem(mesh, MATERIAL, {**conditions, "wing": Neumann((0.0, 1.0))})


def test_a_component_held_only_by_contact_is_refused():
    mesh = _two_squares()
    conditions = {p: Neumann() for p in mesh.part_names}
    conditions.update(left=Dirichlet(), bottom2=Contact(0.0), right2=Contact(0.0))
    with pytest.raises(
        ProblemError,
        match=r"component 2 \(8 cells in \[2, 3\] × \[0, 1\], boundary parts \['left2', "
        r"'top2', 'right2', 'bottom2'\]\) is held only by contact parts \['right2', "
        r"'bottom2'\]\. .*contact alone does not hold a component",
    ):
        ContactProblem(mesh, MATERIAL, conditions)


def test_many_floating_components_are_counted():
    sq = rectangle(nx=1, ny=1)
    free = {f"free_{side}": side for side in ("top", "right", "bottom")}
    pieces = [(sq, (0, 0), {"clamp": "left", **free})]
    pieces += [(sq, (2 * i, 0), {"free_left": "left", **free}) for i in range(1, 8)]
    mesh = _union(*pieces)
    conditions = {p: Neumann() for p in mesh.part_names}
    conditions["clamp"] = Dirichlet()
    with pytest.raises(
        ProblemError,
        match=r"and 7 of them have no Dirichlet part.*component 6 \(2 cells in \[10, 11\] .*"
        r"; and 2 more\. Give",
    ):
        ContactProblem(mesh, MATERIAL, conditions)


# ---------------------------------------------------------------- user functions end to end


def test_user_functions_written_for_flat_points_solve():
    # x[:, 0] and np.column_stack: functions written for points (n, 2)
    from signorini import solve

    def traction(x, normal):
        return np.column_stack([0.0 * x[:, 0], -0.1 * x[:, 0]])

    pb = ContactProblem(
        rectangle(nx=2, ny=2),
        MATERIAL,
        {
            "left": Dirichlet(lambda x: np.column_stack([0.01 * x[:, 1], 0 * x[:, 1]])),
            "top": Neumann(traction),
            "bottom": Neumann(),
            "right": Contact(gap=lambda x: 0.01 + 0.0 * x[:, 1]),
        },
        body_force=lambda x: np.column_stack([x[:, 0], x[:, 1]]),
    )
    result = solve(pb)
    assert np.isfinite(result.u).all() and np.abs(result.u).max() > 0


def test_the_traction_forms_give_the_same_solution():
    from signorini import solve

    def named(x, normal):
        return -0.3 * normal * (1 + x[:, :1])

    def old(x, n):
        return -0.3 * n * (1 + x[:, :1])

    def one(x):
        return np.column_stack([0 * x[:, 0], 0.3 * (1 + x[:, 0])])  # top: normal (0, 1)

    base = {"left": Dirichlet(), "bottom": Neumann(), "right": Contact(0.001)}
    with pytest.warns(DeprecationWarning):
        old_form = Neumann(old)
    u = [
        solve(ContactProblem(rectangle(nx=2, ny=2), MATERIAL, {**base, "top": cond})).u
        for cond in (Neumann(named), old_form, Neumann(lambda x: -one(x)))
    ]
    assert np.abs(u[0]).max() > 1e-3
    assert np.array_equal(u[0], u[1])
    assert np.allclose(u[0], u[2], rtol=0, atol=1e-15 * np.abs(u[0]).max())


def test_a_raising_user_function_is_named_from_the_public_call():
    from signorini import solve

    def traction(x, normal):
        return 1.0 / 0

    pb = ContactProblem(
        rectangle(nx=2, ny=2),
        MATERIAL,
        {"left": Dirichlet(), "top": Neumann(traction), "bottom": Neumann(), "right": Contact()},
    )
    with pytest.raises(
        ProblemError, match="^the traction of Neumann part 'top' raised ZeroDivisionError: "
    ):
        solve(pb)


def test_docstrings_state_units_and_shapes():
    for obj in (Dirichlet, Neumann, Contact, ContactProblem):
        assert "(n, 2)" in obj.__doc__, obj
    for obj in (ContactProblem, Material):
        assert "consistent: if E is in MPa" in " ".join(obj.__doc__.split()), obj


@pytest.mark.parametrize(("height", "warns"), [(1.0, False), (0.05, False), (2e-3, True)])
def test_a_slender_body_is_warned_about(height, warns):
    """A cantilever strip of aspect 1/height: its stiffness condition number grows like the
    aspect to the fourth, so above 100 the user is told, with the measured ratio."""
    mesh = rectangle(0.0, 1.0, 0.0, height, nx=8, ny=1)
    conditions = {"left": Dirichlet(), "right": Neumann((0.0, -1.0)), "top": Neumann()}
    conditions["bottom"] = Neumann()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ContactProblem(mesh, Material.from_young(1.0, 0.3), conditions)
    slender = [w for w in caught if issubclass(w.category, SlenderBodyWarning)]
    assert len(slender) == int(warns), [str(w.message) for w in caught]
    if warns:
        ratio = (1.0 + height**2) / height
        assert f"{ratio:.3g}" in str(slender[0].message)
        assert slender[0].filename == __file__  # points at the user's line


def test_ndof_has_one_definition_shared_by_the_problem_and_the_result():
    """The paper's Ndof, 2 n_nodes − 2 n_D, from ``free_ndof``: the budget the loop checks
    before solving and the ``ndof`` of the solved result agree."""
    from signorini.contact import solve
    from signorini.examples import example_6_1
    from signorini.problem.problem import free_ndof

    pb = example_6_1()
    space = P2Space(pb.mesh)
    n_d = pb.dirichlet_nodes(space).size
    assert n_d > 0
    assert free_ndof(space, pb.dirichlet_nodes(space)) == 2 * space.n_nodes - 2 * n_d
    assert pb.free_ndof(pb.mesh) == solve(pb).ndof == 2 * space.n_nodes - 2 * n_d
