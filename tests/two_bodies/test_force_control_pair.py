"""Force control in a contact pair (docs/method.md, *Force control*, "In a contact pair"): a
block loaded by a traction on its top rests on a deformable support; its vertical motion is
held only by the pair. Checked against equilibrium (the contact forces carry the load to
round-off), the KKT residuals, and an independent solve of the same problem under
displacement control (the block's top prescribed the force-controlled displacement): the
same discrete solution, and its reaction at the top is the load's nodal force vector.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from signorini.contact import solve
from signorini.fem.loads import assemble_facet_load
from signorini.fem.material import Material
from signorini.fem.stiffness import assemble_stiffness
from signorini.mesh.bodies import union
from signorini.mesh.builders import rectangle
from signorini.mesh.mesh import Mesh
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann, ProblemError
from signorini.problem.friction_laws import Coulomb

X0, X1 = 0.2, 0.8  # the block's width; the support is [0, 1] x [0, 1]
MATERIALS = {"a": Material.from_young(1.0, 0.3), "b": Material.from_young(4.0, 0.25)}


def load(x):
    """The traction on the block's top: downward, growing to the right, and along +x."""
    q = 0.1 + 0.2 * (x[..., 0] - X0)
    return np.stack([0.25 * q, -q], axis=-1)


#: ∫ q over the top: the downward load the contact carries
LOAD_Y = 0.1 * (X1 - X0) + 0.1 * (X1 - X0) ** 2


def block() -> Mesh:
    """[0.2, 0.8] x [1, 1.5], 4 x 3 squares; parts top, bottom, guide (the left side above
    y = 1.1, off the contact part's end: a roller there leaves the bottom's tangential
    displacement to the friction law) and sides (the rest)."""
    m = rectangle(X0, X1, 1.0, 1.5, 4, 3)
    left = np.isclose(m.points[m.boundary, 0], X0).all(axis=1)
    above = m.points[m.boundary, 1].min(axis=1) > 1.1
    parts = {name: m.boundary[m.boundary_part == m.part_index(name)] for name in ("top", "bottom")}
    parts["guide"] = m.boundary[left & above]
    return Mesh.from_arrays(m.points, m.cells, {**parts, "sides": lambda x: np.ones(len(x), bool)})


def block_on_support(friction=None, top=None) -> ContactProblem:
    """The block [0.2, 0.8] x [1, 1.5] (4 edges along its bottom) on [0, 1] x [0, 1] (5):
    support's bottom fixed, the block's guide on a roller (u_x = 0, which holds its
    horizontal motion and its rotation), its top under :func:`load` (or ``top``)."""
    mesh = union({"a": block(), "b": rectangle(0.0, 1.0, 0.0, 1.0, 5, 5)})
    conditions = {p: Neumann() for p in mesh.part_names if p != "b.top"}
    conditions.update({
        "a.top": Neumann(load) if top is None else top,
        "a.guide": Dirichlet((0.0, None)),
        "a.bottom": Contact(master="b.top", friction=friction),
        "b.bottom": Dirichlet((0.0, 0.0)),
    })  # fmt: skip
    return ContactProblem(mesh=mesh, material=MATERIALS, conditions=conditions)


def cartesian_system(problem):
    """K (Cartesian, both bodies, from the element routines) and the nodal load of a.top."""
    mesh = problem.mesh
    n_points = mesh.n_points
    cell_nodes = np.hstack([mesh.cells, n_points + mesh.cell2edge])
    n_dofs = 2 * (n_points + mesh.n_edges)
    cell_dofs = (2 * cell_nodes[:, :, None] + np.arange(2)).reshape(-1, 12)
    K = assemble_stiffness(mesh.points[mesh.cells], cell_dofs, n_dofs, problem.material_on(mesh))
    edges = mesh.part_facets("a.top")
    ab = mesh.oriented_boundary(edges)
    nodes = np.column_stack([ab, n_points + edges])
    dofs = (2 * nodes[:, :, None] + np.arange(2)).reshape(-1, 6)
    g = problem.conditions["a.top"].field()
    F = assemble_facet_load(mesh.points[nodes[:, :2]], dofs, n_dofs, g, degree=8)
    return K, F


def displacement_controlled(result, friction=None):
    """The same problem with the block's top prescribed ``result``'s displacement."""
    space = result.space
    top = space.part_nodes(["a.top"])
    tree = cKDTree(space.node_points[top])

    def u_top(x):
        distance, i = tree.query(x)
        assert distance.max() < 1e-12
        return result.u[top[i]]

    return solve(block_on_support(friction, top=Dirichlet(u_top)))


@pytest.mark.parametrize("friction", [None, Coulomb(0.3)])
def test_a_loaded_block_on_a_deformable_support_carries_its_load(friction):
    problem = block_on_support(friction)
    assert problem.rigid_motions.shape == (1, 3) and problem.rigid_parts[0].startswith("a.")
    assert np.allclose(np.abs(problem.rigid_motions[0]), [0.0, 1.0, 0.0])  # along y
    r = solve(problem)
    assert r.report.kkt.max < 1e-10, r.report.kkt
    # equilibrium of the block along its free motion: the contact carries the load
    assert r.contact_force_vector[1] == pytest.approx(LOAD_Y, rel=1e-12)
    assert r.total_contact_force == pytest.approx(LOAD_Y, rel=1e-12)
    # the support feels the opposite resultant
    on, traction, _ = r.master_side
    K, F = cartesian_system(problem)
    assert F[1::2].sum() == pytest.approx(-LOAD_Y, rel=1e-12)
    # an independent solve: displacement control with the computed top displacement
    d = displacement_controlled(r, friction)
    scale = np.abs(r.u).max()
    assert np.abs(d.u - r.u).max() < 1e-9 * scale, np.abs(d.u - r.u).max() / scale
    assert np.array_equal(d.state, r.state)
    # whose reaction at the top is the load's nodal force vector
    top = d.space.part_nodes(["a.top"])
    reaction = (K @ d.u.ravel()).reshape(-1, 2)[top]
    corner = np.isclose(d.space.node_points[top, 0], X0)  # held in x by the guide too
    force = F.reshape(-1, 2)[top]
    assert np.abs(reaction[:, 1] - force[:, 1]).max() < 1e-9 * np.abs(force).max()
    assert np.abs(reaction[~corner, 0] - force[~corner, 0]).max() < 1e-9 * np.abs(force).max()
    if friction is not None:
        counts = np.bincount(r.state, minlength=3)
        assert counts[1] > 0, counts  # some nodes stick


def test_a_load_that_lifts_the_block_off_its_support_is_refused():
    with pytest.raises(ProblemError, match="pulls the body away from its contacts"):
        solve(block_on_support(top=Neumann((0.0, 0.1))))


def test_two_bodies_held_only_by_each_other_are_refused():
    mesh = union({"a": block(), "b": rectangle(0.0, 1.0, 0.0, 1.0, 5, 5)})
    conditions = {p: Neumann() for p in mesh.part_names if p != "b.top"}
    conditions.update({
        "a.top": Neumann((0.0, -0.1)),
        "a.guide": Dirichlet((0.0, None)),
        "b.left": Dirichlet((0.0, None)),
        "a.bottom": Contact(master="b.top"),
    })  # fmt: skip
    with pytest.raises(ProblemError, match="neither is held in all its rigid motions"):
        ContactProblem(mesh=mesh, material=MATERIALS, conditions=conditions)


def test_the_loaded_block_may_be_the_master_of_the_pair():
    """The support [0.3, 0.7] x [0, 1] narrower than the block: it is the slave, the free
    block the master; the free motion's normal component at a constraint is then the
    master's transferred motion (−r·n through T_d)."""
    mesh = union({"a": block(), "b": rectangle(0.3, 0.7, 0.0, 1.0, 3, 5)})
    conditions = {p: Neumann() for p in mesh.part_names if p != "a.bottom"}
    conditions.update({
        "a.top": Neumann(load),
        "a.guide": Dirichlet((0.0, None)),
        "b.top": Contact(master="a.bottom"),
        "b.bottom": Dirichlet((0.0, 0.0)),
    })  # fmt: skip
    problem = ContactProblem(mesh=mesh, material=MATERIALS, conditions=conditions)
    assert problem.rigid_parts == ("a.top",)
    r = solve(problem)
    assert r.report.kkt.max < 1e-10, r.report.kkt
    assert r.total_contact_force == pytest.approx(LOAD_Y, rel=1e-12)
    assert r.active.all()
