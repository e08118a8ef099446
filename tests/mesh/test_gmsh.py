"""Reading Gmsh meshes (:mod:`signorini.mesh.gmsh`)."""

from __future__ import annotations

import dataclasses

import meshio
import numpy as np
import pytest

from signorini.contact.solution import solve
from signorini.estimator.residual import estimate
from signorini.examples import example_6_2
from signorini.fem.space import P2Space
from signorini.mesh import read_mesh
from signorini.mesh.mesh import MeshError


def gmsh_square(mesh, *, order: int = 1, with_lines: bool = True):
    """A meshio Mesh of ``mesh`` with named physical line groups, as Gmsh writes it: an extra
    geometry point no triangle uses, every other triangle clockwise, a physical surface;
    ``order=2`` gives quadratic triangles and lines (midpoint nodes)."""
    names = {name: i + 1 for i, name in enumerate(mesh.part_names)}
    space = P2Space(mesh)
    if order == 1:
        points, cells, flip, kinds = mesh.points, mesh.cells.copy(), [0, 2, 1], ("triangle", "line")
    else:
        points, cells = space.node_points, space.cell_nodes.copy()
        flip, kinds = [0, 2, 1, 5, 4, 3], ("triangle6", "line3")
    cells[::2] = cells[::2][:, flip]
    points = np.vstack([points, [[2.0, 2.0]]])
    blocks = [(kinds[0], cells)]
    physical = [np.full(len(cells), 10)]
    if with_lines:
        edges = [mesh.part_facets(n) for n in mesh.part_names]
        lines = np.vstack([space.facet_nodes(e)[:, : order + 1] for e in edges])
        tags = np.concatenate(
            [np.full(e.size, names[n]) for n, e in zip(mesh.part_names, edges, strict=True)]
        )
        blocks.append((kinds[1], lines))
        physical.append(tags)
    field_data = {n: np.array([t, 1]) for n, t in names.items()}
    field_data["domain"] = np.array([10, 2])
    return meshio.Mesh(
        np.column_stack([points, np.zeros(len(points))]),
        blocks,
        cell_data={"gmsh:physical": physical, "gmsh:geometrical": [p.copy() for p in physical]},
        field_data=field_data,
    )


@pytest.mark.parametrize(("order", "binary"), [(1, False), (1, True), (2, False)])
def test_read_mesh_from_gmsh_file(tmp_path, order, binary):
    problem = example_6_2()
    original = problem.mesh
    path = tmp_path / "square.msh"
    meshio.write(path, gmsh_square(original, order=order), file_format="gmsh22", binary=binary)
    mesh = read_mesh(path)
    assert set(mesh.part_names) == {"bottom", "right", "top", "left"}
    assert mesh.n_points == original.n_points and mesh.n_cells == original.n_cells
    assert np.all(mesh.area > 0) and mesh.area.sum() == pytest.approx(1.0, rel=1e-14)
    side = {"bottom": (1, 0.0), "right": (0, 1.0), "top": (1, 1.0), "left": (0, 0.0)}
    for name, (axis, value) in side.items():
        pts = mesh.points[mesh.facets[mesh.part_facets(name)]]
        np.testing.assert_array_equal(pts[..., axis], value)
        assert mesh.part_measure(name) == pytest.approx(1.0, rel=1e-14)
    # the same problem on the mesh read back gives the same discrete solution
    again = dataclasses.replace(problem, mesh=mesh)
    eta_file, eta_orig = estimate(solve(again)).eta, estimate(solve(problem)).eta
    print(f"eta on the mesh read back {eta_file:.12e}, on the built-in mesh {eta_orig:.12e}")
    assert eta_file == pytest.approx(eta_orig, rel=1e-10)
    # the parts can be requested by name; an absent one is named in the error
    assert set(read_mesh(path, parts=["bottom", "right", "top", "left"]).part_names) == set(side)
    with pytest.raises(MeshError, match="contact"):
        read_mesh(path, parts=["bottom", "contact"])


def test_read_mesh_without_physical_lines_raises(tmp_path):
    path = tmp_path / "bare.msh"
    meshio.write(
        path, gmsh_square(example_6_2().mesh, with_lines=False), file_format="gmsh22", binary=False
    )
    with pytest.raises(MeshError, match="no tagged boundary"):
        read_mesh(path)


@pytest.mark.parametrize("name", ["notes.txt", "fake.msh", "fake.vtu"])
def test_read_mesh_rejects_a_text_file(tmp_path, name):
    path = tmp_path / name
    path.write_text("this is not a mesh\n1 2 3\n")
    with pytest.raises(MeshError, match="not a mesh file") as info:
        read_mesh(path)
    assert name in str(info.value)


def test_read_mesh_missing_file(tmp_path):
    with pytest.raises(MeshError, match="no mesh file"):
        read_mesh(tmp_path / "absent.msh")


def write(tmp_path, mesh: meshio.Mesh, name: str = "m.msh"):
    path = tmp_path / name
    meshio.write(path, mesh, file_format="gmsh22", binary=False)
    return path


@pytest.mark.parametrize("z", [lambda p: p[:, 1], lambda p: 1e-3 * p[:, 0] * p[:, 1]])
def test_read_mesh_refuses_a_mesh_that_is_not_flat(tmp_path, z):
    m = gmsh_square(example_6_2().mesh)
    m.points[:, 2] = z(m.points)
    with pytest.raises(MeshError, match=r"m\.msh is not flat in the xy-plane: z ranges over "):
        read_mesh(write(tmp_path, m))


def test_read_mesh_accepts_a_constant_z(tmp_path):
    m = gmsh_square(example_6_2().mesh)
    m.points[:, 2] = 7.5
    mesh = read_mesh(write(tmp_path, m))
    assert mesh.n_cells == 32 and mesh.area.sum() == pytest.approx(1.0, rel=1e-14)


def test_read_mesh_without_any_physical_group(tmp_path):
    # triangles and lines, no physical group at all (Gmsh writes physical tag 0)
    m = gmsh_square(example_6_2().mesh)
    for blocks in m.cell_data.values():
        for tags in blocks:
            tags[:] = 0
    m.field_data = {}
    with pytest.raises(MeshError, match=r"m\.msh has no tagged boundary lines .*Physical Curve"):
        read_mesh(write(tmp_path, m))


def test_physical_tag_0_names_no_part(tmp_path):
    # the left side in no physical group: its lines name no part, so its edges are unlabelled
    base = example_6_2().mesh
    m = gmsh_square(base)
    tags = m.cell_data["gmsh:physical"][1]
    tags[tags == 1 + base.part_names.index("left")] = 0
    with pytest.raises(
        MeshError,
        match=r"m\.msh: 4 boundary edge\(s\) have no part, first the edge from \(0, [0-9.]+\) to "
        r"\(0, [0-9.]+\) \(vertices",
    ):
        read_mesh(write(tmp_path, m))
    # keeping the named parts only still leaves the left side unlabelled
    with pytest.raises(MeshError, match="have no part"):
        read_mesh(write(tmp_path, m), parts=["bottom", "right", "top"])


def test_read_mesh_with_line_groups_only(tmp_path):
    m = gmsh_square(example_6_2().mesh)
    m = meshio.Mesh(
        m.points,
        [m.cells[1]],
        cell_data={k: [v[1]] for k, v in m.cell_data.items()},
        field_data=m.field_data,
    )
    with pytest.raises(
        MeshError,
        match=r"contains no triangles \(it has \['line'\]\): only line elements were saved; add "
        r"a physical surface group .* or save all elements",
    ):
        read_mesh(write(tmp_path, m))


def test_read_mesh_mixed_orientation_is_reported(tmp_path):
    # gmsh_square lists every other triangle clockwise
    mesh = read_mesh(write(tmp_path, gmsh_square(example_6_2().mesh)))
    np.testing.assert_array_equal(mesh.reoriented, np.arange(0, 32, 2))


@pytest.mark.parametrize(
    ("order", "node", "axis"),
    [(1, 3, 2), (2, 3, 2), (2, 27, 1), (1, 3, 0)],
    ids=["z", "z-second-order", "midpoint", "x"],
)
def test_a_nan_coordinate_is_refused_naming_the_node(tmp_path, order, node, axis):
    # before: a NaN in z (the flatness test compares NaN: False) or in a second-order
    # midpoint (its offset from the chord compares the same) was read as if it were not there
    m = gmsh_square(example_6_2().mesh, order=order)
    points = m.points.copy()
    points[node, axis] = np.nan
    m.points = points
    path = tmp_path / "nan.msh"
    meshio.write(path, m, file_format="gmsh22", binary=False)
    with pytest.raises(
        MeshError, match=rf"nan\.msh: node {node + 1} of the file .* non-finite coordinate, \("
    ):
        read_mesh(path)
