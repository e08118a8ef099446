"""Reading tetrahedral Gmsh meshes (:mod:`signorini.mesh.gmsh3d`)."""

from __future__ import annotations

import meshio
import numpy as np
import pytest

from signorini.mesh import MeshError, read_mesh
from signorini.mesh.builders3d import box, eighth_ball
from signorini.mesh.surfaces import Sphere
from signorini.mesh.tetrahedra import facet_edges


def gmsh_file(mesh, path, *, order=1, midpoints=None, groups=True, extra=()):
    """Write ``mesh`` as a Gmsh 2.2 file: tetrahedra in one physical volume per region,
    boundary triangles in one physical surface per part (tetra10/triangle6 for order 2, the
    midpoints ``midpoints (n_edges, 3)``, by default the chord midpoints)."""
    faces = mesh.oriented_boundary(mesh.boundary_facet)
    points, cells = mesh.points, mesh.cells
    if order == 2:
        mid = mesh.edge_midpoints if midpoints is None else midpoints
        points = np.vstack([points, mid])
        cells = np.hstack([cells, mesh.n_points + mesh.cell2edge])
        faces = np.hstack([faces, mesh.n_points + facet_edges(mesh.edges, faces, mesh.n_points)])
    kinds = ("tetra", "triangle") if order == 1 else ("tetra10", "triangle6")
    field = {name: np.array([i + 1, 2]) for i, name in enumerate(mesh.part_names)}
    field.update({name: np.array([100 + i, 3]) for i, name in enumerate(mesh.region_names)})
    blocks = [(kinds[0], cells), (kinds[1], faces), *[(t, d) for t, d, _ in extra]]
    physical = [
        100 + mesh.cell_region,
        (mesh.boundary_part + 1) if groups else 0 * mesh.boundary_part,
    ]
    physical += [np.full(len(d), tag) for _, d, tag in extra]
    meshio.write(
        path,
        meshio.Mesh(
            points,
            blocks,
            cell_data={"gmsh:physical": physical, "gmsh:geometrical": [p.copy() for p in physical]},
            field_data=field,
        ),
        file_format="gmsh22",
        binary=False,
    )
    return path


def test_read_a_first_order_box(tmp_path):
    original = box(
        2, 2, 3, regions={"low": lambda x: x[:, 2] < 0.5, "high": lambda x: x[:, 2] >= 0.5}
    )
    mesh = read_mesh(gmsh_file(original, tmp_path / "box.msh"))
    assert mesh.dim == 3 and mesh.n_cells == original.n_cells
    assert set(mesh.part_names) == set(original.part_names)
    assert set(mesh.region_names) == {"low", "high"}
    for name in original.part_names:
        assert np.isclose(mesh.part_measure(name), original.part_measure(name))
    low = original.volume[original.region_cells("low")].sum()
    assert np.isclose(mesh.volume[mesh.region_cells("low")].sum(), low)
    assert read_mesh(tmp_path / "box.msh", parts=["x0", "x1", "y0", "y1", "z0", "z1"]).dim == 3


def test_read_a_second_order_ball_with_its_sphere(tmp_path):
    original = eighth_ball(2)
    path = gmsh_file(original, tmp_path / "ball.msh", order=2, midpoints=original.curved_midpoints)
    sphere = Sphere((0, 0, 0), 1.0)
    mesh = read_mesh(path, surfaces={"sphere": sphere})
    assert mesh.curves[mesh.part_index("sphere")] is sphere
    np.testing.assert_allclose(mesh.curved_midpoints, original.curved_midpoints, atol=1e-15)
    with pytest.raises(MeshError, match=r"midpoint\(s\) lie off their edge's chord on no part"):
        read_mesh(path)
    with pytest.raises(MeshError, match=r"vertex \d+ .* of part 'sphere' lies .* from Sphere"):
        read_mesh(path, surfaces={"sphere": Sphere((0, 0, 0), 1.01)})
    off = original.curved_midpoints.copy()
    e = original.part_edge_indices(original.part_index("sphere"))
    off[e] *= 1.01
    path = gmsh_file(original, tmp_path / "off.msh", order=2, midpoints=off)
    with pytest.raises(MeshError, match=r"midpoint .* of part 'sphere' lies 0.01 off Sphere"):
        read_mesh(path, surfaces={"sphere": sphere})


def test_a_straight_second_order_file_reads_as_the_first_order_one(tmp_path):
    mesh = read_mesh(gmsh_file(box(1, 1, 2), tmp_path / "box2.msh", order=2))
    assert mesh.n_points == box(1, 1, 2).n_points
    assert all(c is None for c in mesh.curves)


def test_files_refused(tmp_path):
    with pytest.raises(MeshError, match="no tagged boundary faces"):
        read_mesh(gmsh_file(box(1, 1, 1), tmp_path / "a.msh", groups=False))
    mesh = box(1, 1, 1)
    path = gmsh_file(mesh, tmp_path / "b.msh", extra=[("triangle", np.array([[0, 1, 6]]), 0)])
    assert read_mesh(path).n_cells == 6  # in no physical group: ignored
    gmsh_file(mesh, tmp_path / "c.msh", extra=[("triangle", np.array([[0, 1, 6]]), 1)])
    with pytest.raises(MeshError, match=r"mixes 2D and 3D cells: 1 triangle\(s\) of group 'x0'"):
        read_mesh(tmp_path / "c.msh")
    with pytest.raises(MeshError, match=r"has no boundary group\(s\) \['top'\]"):
        read_mesh(tmp_path / "b.msh", parts=["top"])
