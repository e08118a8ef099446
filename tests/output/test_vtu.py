"""Discrete solutions as quadratic-triangle VTU files (:mod:`signorini.output.vtu`)."""

from __future__ import annotations

import os
import stat

import meshio
import numpy as np
import pytest
from contact_problems import corner_problem

from signorini.contact.contact_set import FULL_CONTACT, NO_CONTACT, SEMI_CONTACT
from signorini.contact.solution import INACTIVE, SLIP, STICK, solve
from signorini.estimator.residual import estimate
from signorini.examples import example_6_2
from signorini.examples.two_bodies import two_cylinders
from signorini.fem.material import Material
from signorini.mesh.bodies import union
from signorini.mesh.builders import rectangle
from signorini.mesh.refine import refine_nvb, refine_uniform
from signorini.output import write_vtu
from signorini.output.vtu import write_fields
from signorini.problem import Contact, ContactProblem, Coulomb, Dirichlet, Neumann
from signorini.problem.obstacles import Disc


@pytest.fixture(scope="module")
def solved():
    """Example 6.2 on the initial mesh: full, semi and no contact nodes all occur."""
    result = solve(example_6_2())
    return result, estimate(result)


def files_in(folder) -> list[str]:
    return sorted(os.listdir(folder))


def test_write_vtu_reads_back(tmp_path, solved):
    result, est = solved
    path = write_vtu(tmp_path / "out" / "solution.vtu", result, est)
    assert path == tmp_path / "out" / "solution.vtu"
    assert files_in(tmp_path / "out") == ["solution.vtu"]  # no temporary file left behind
    m = meshio.read(path)
    space = result.space
    # one block of quadratic triangles, P2 local order = VTK order: vertices, then the
    # midpoints of v0-v1, v1-v2, v2-v0 (checked on the coordinates read back)
    assert [b.type for b in m.cells] == ["triangle6"]
    tri = m.cells[0].data
    np.testing.assert_array_equal(tri, space.cell_nodes)
    xy = m.points[:, :2]
    np.testing.assert_array_equal(m.points[:, 2], 0.0)
    for k in range(3):
        np.testing.assert_allclose(
            xy[tri[:, 3 + k]], 0.5 * (xy[tri[:, k]] + xy[tri[:, (k + 1) % 3]]), atol=1e-15
        )
    np.testing.assert_array_equal(xy, space.node_points)
    # point data
    pd = m.point_data
    np.testing.assert_array_equal(pd["displacement"][:, :2], result.u)
    np.testing.assert_array_equal(pd["displacement"][:, 2], 0.0)
    cs = result.contact
    off = np.setdiff1d(np.arange(space.n_nodes), cs.nodes)
    np.testing.assert_array_equal(pd["pressure"][cs.nodes], result.pressure)
    np.testing.assert_array_equal(pd["pressure"][off], 0.0)
    np.testing.assert_array_equal(pd["contact_force"][cs.nodes], result.contact_force)
    np.testing.assert_array_equal(
        pd["contact_traction"][cs.nodes, :2], -result.pressure[:, None] * cs.normal
    )
    np.testing.assert_array_equal(pd["contact_traction"][off], 0.0)
    np.testing.assert_array_equal(pd["active"][cs.nodes], result.active.astype(int))
    np.testing.assert_array_equal(pd["active"][off], 0)
    np.testing.assert_array_equal(pd["contact_class"][cs.nodes], result.classes)
    np.testing.assert_array_equal(pd["contact_class"][off], -1)
    assert set(pd["contact_class"][cs.nodes]) == {NO_CONTACT, SEMI_CONTACT, FULL_CONTACT}
    assert pd["pressure"].max() > 0
    # cell data: indicators summing to η², term by term
    eta2 = m.cell_data["eta2"][0]
    assert eta2.shape == (result.mesh.n_cells,)
    assert eta2.sum() == pytest.approx(est.eta**2, rel=1e-13)
    for k in range(7):
        assert m.cell_data[f"eta2_{k + 1}"][0].sum() == pytest.approx(
            est.eta2_terms[k], rel=1e-13, abs=1e-300
        )
    print(
        f"VTU: {len(xy)} nodes, {len(tri)} triangle6 cells, sum eta2 = {eta2.sum():.10e}, "
        f"eta^2 = {est.eta**2:.10e}"
    )


def test_write_vtu_without_estimate_and_overwrite(tmp_path, solved):
    result, _ = solved
    path = tmp_path / "a.vtu"
    write_vtu(path, result)
    first = meshio.read(path)
    assert list(first.cell_data) == ["region"]  # no estimate: the regions only
    fine = solve(example_6_2(), refine_uniform(result.mesh).mesh)
    write_vtu(path, fine)  # replaced in place
    assert len(meshio.read(path).cells[0].data) == fine.mesh.n_cells
    assert files_in(tmp_path) == ["a.vtu"]


def test_vtu_file_follows_the_umask(tmp_path, solved):
    """A VTU file is an ordinary file: mode 0o666 minus the umask, like ``open(..., "w")``."""
    old = os.umask(0o027)
    try:
        write_vtu(tmp_path / "s.vtu", solved[0])
    finally:
        os.umask(old)
    mode = stat.S_IMODE(os.stat(tmp_path / "s.vtu").st_mode)
    assert mode == 0o640, oct(mode)


def test_corner_node_gets_the_larger_scalars_and_the_sum_of_tractions(tmp_path):
    """A node with two constraints (a block in a rigid corner) in the VTU file."""
    result = solve(corner_problem())
    cs = result.contact
    corner = cs.nodes[cs.second]
    assert corner.size == 1
    rows = np.flatnonzero(cs.nodes == corner[0])
    pd = meshio.read(write_vtu(tmp_path / "corner.vtu", result)).point_data
    assert pd["pressure"][corner[0]] == result.pressure[rows].max()
    assert pd["contact_force"][corner[0]] == result.contact_force[rows].max()
    expected = -(result.pressure[rows, None] * cs.normal[rows]).sum(axis=0)
    np.testing.assert_allclose(pd["contact_traction"][corner[0], :2], expected, rtol=1e-15)
    assert pd["active"][corner[0]] == 1


def test_friction_fields(tmp_path):
    """A block pressed and pulled onto a rigid cylinder with Coulomb friction: the VTU file
    holds p_t and the node states (stick and slip both occur), and the traction
    ``−p n − p_t t`` sums, times the weights w_z, to the resultant of the obstacle's forces;
    without friction p_t is 0 and a node in contact is stated as slipping."""
    mesh = rectangle(0.0, 2.0, 0.0, 1.0, nx=16, ny=8)

    def block(friction):
        return ContactProblem(
            mesh,
            Material.from_young(1.0, 0.3),
            {
                "left": Neumann(),
                "right": Neumann(),
                "top": Dirichlet((0.012, -0.02)),
                "bottom": Contact(obstacle=Disc((1.0, -12.5), 12.5), friction=friction),
            },
        )

    result = solve(block(Coulomb(0.3)))
    cs = result.contact
    off = np.setdiff1d(np.arange(result.space.n_nodes), cs.nodes)
    pd = meshio.read(write_vtu(tmp_path / "friction.vtu", result)).point_data
    np.testing.assert_array_equal(pd["tangential_pressure"][cs.nodes], result.tangential_pressure)
    np.testing.assert_array_equal(pd["tangential_pressure"][off], 0.0)
    np.testing.assert_array_equal(pd["contact_state"][cs.nodes], result.state)
    np.testing.assert_array_equal(pd["contact_state"][off], -1)
    assert set(pd["contact_state"][cs.nodes]) == {INACTIVE, STICK, SLIP}
    assert np.abs(pd["tangential_pressure"]).max() > 0.1 * pd["pressure"].max()
    resultant = (pd["contact_traction"][cs.nodes, :2] * cs.basis_integral[:, None]).sum(axis=0)
    print(
        f"\nresultant from the traction {resultant}, from the forces {result.contact_force_vector}"
    )
    np.testing.assert_allclose(resultant, result.contact_force_vector, rtol=1e-13)
    assert abs(resultant[0]) > 0.1 * abs(resultant[1])
    frictionless = solve(block(None))
    pd = meshio.read(write_vtu(tmp_path / "frictionless.vtu", frictionless)).point_data
    np.testing.assert_array_equal(pd["tangential_pressure"], 0.0)
    np.testing.assert_array_equal(
        pd["contact_state"][cs.nodes], np.where(frictionless.active, SLIP, INACTIVE)
    )


def test_body_field_is_the_unions_body_after_refinement(tmp_path):
    """Two cylinders with the upper one refined all over: the refined mesh starts with lower
    cells, and the ``body`` field still says 0 for the upper cells (the union's first body,
    whose regions come first), 1 for the lower ones."""
    problem = two_cylinders()
    upper = problem.mesh.cell_region == problem.mesh.region_names.index("upper")
    mesh = refine_nvb(problem.mesh, upper).mesh
    assert mesh.region_names[mesh.cell_region[0]] == "lower"  # the cells' order changed
    cell_data = meshio.read(write_vtu(tmp_path / "pair.vtu", solve(problem, mesh))).cell_data
    np.testing.assert_array_equal(cell_data["region"][0], mesh.cell_region)
    np.testing.assert_array_equal(cell_data["body"][0], mesh.cell_region)  # one region a body


def test_region_and_body_names_round_trip_as_field_data(tmp_path, solved):
    """The names of the regions and bodies are the VTU file's field data, ``region:<name>``
    and ``body:<name>`` -> the index in the cell field, read back by meshio; one body has
    its region only."""
    pair = solve(two_cylinders())
    m = meshio.read(write_vtu(tmp_path / "pair.vtu", pair))
    assert {k: v.tolist() for k, v in m.field_data.items()} == {
        "region:upper": [0],
        "region:lower": [1],
        "body:upper": [0],
        "body:lower": [1],
    }
    one = meshio.read(write_vtu(tmp_path / "one.vtu", solved[0]))
    assert {k: v.tolist() for k, v in one.field_data.items()} == {"region:body": [0]}
    assert "body" not in one.cell_data


def test_region_names_that_xml_must_escape(tmp_path):
    """A region name with XML's special characters reads back as it was."""
    odd = 'steel & "rubber" <soft>'
    halves = {odd: lambda x: x[:, 0] < 0.5, "b": lambda x: x[:, 0] > 0.5}
    mesh = rectangle(0, 1, 0, 1, nx=2, ny=2, regions=halves)
    problem = ContactProblem(
        mesh,
        {odd: Material.from_young(1.0, 0.3), "b": Material.from_young(2.0, 0.3)},
        {
            "top": Dirichlet((0.0, -0.01)),
            "bottom": Dirichlet((0.0, 0.0)),
            "left": Neumann(),
            "right": Neumann(),
        },
    )
    m = meshio.read(write_vtu(tmp_path / "odd.vtu", solve(problem)))
    names = {k: int(v[0]) for k, v in m.field_data.items()}
    assert names == {f"region:{r}": k for k, r in enumerate(mesh.region_names)}
    assert f"region:{odd}" in names


def test_fields_md_says_which_index_is_which_name(tmp_path):
    """fields.md lists the field data and, for the run's mesh, each region index and body
    number with its name (a body with two regions is named once)."""
    halves = {"a": lambda x: x[:, 0] < 0.5, "b": lambda x: x[:, 0] > 0.5}
    mesh = union(
        {
            "upper": rectangle(0, 1, 1, 2, 2, 2, regions=halves),
            "lower": rectangle(0, 1, 0, 1, 2, 2),
        }
    )
    text = write_fields(tmp_path / "fields.md", mesh).read_text()
    for line in (
        "| `region:<name>` |",
        "| `body:<name>` |",
        "| 0 | `upper.a` |",
        "| 1 | `upper.b` |",
        "| 2 | `lower` |",
        "| `body` | body name |",
        "| 0 | `upper` |",
        "| 1 | `lower` |",
    ):
        assert line in text, line
    one = write_fields(tmp_path / "one.md", rectangle(0, 1, 0, 1, 2, 2)).read_text()
    assert "| 0 | `body` |" in one and "| `body` | body name |" not in one
