"""VTU output and the CSV history (:mod:`signorini.output`), reading Gmsh meshes
(:mod:`signorini.mesh.gmsh`)."""

from __future__ import annotations

import csv
import dataclasses
import math
import os
import stat

import meshio
import numpy as np
import pytest

import signorini.output.files as sio
from signorini.contact.contact_set import FULL_CONTACT, NO_CONTACT, SEMI_CONTACT
from signorini.contact.solution import solve
from signorini.estimator.residual import estimate
from signorini.examples import example_6_2
from signorini.fem.space import P2Space
from signorini.mesh import read_mesh
from signorini.mesh.mesh import MeshError
from signorini.mesh.refine import refine_uniform
from signorini.output import HistoryWriter, write_vtu


@pytest.fixture(scope="module")
def solved():
    """Example 6.2 on the initial mesh: full, semi and no contact nodes all occur."""
    result = solve(example_6_2())
    return result, estimate(result)


def files_in(folder) -> list[str]:
    return sorted(os.listdir(folder))


# ---------------------------------------------------------------------------- VTU
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
    assert not first.cell_data
    fine = solve(example_6_2(), refine_uniform(result.mesh).mesh)
    write_vtu(path, fine)  # replaced in place
    assert len(meshio.read(path).cells[0].data) == fine.mesh.n_cells
    assert files_in(tmp_path) == ["a.vtu"]


def test_written_files_follow_the_umask(tmp_path, solved):
    """Results are ordinary files: mode 0o666 minus the umask, like ``open(..., "w")``."""
    old = os.umask(0o022)
    try:
        write_vtu(tmp_path / "s.vtu", solved[0])
        history = HistoryWriter(tmp_path / "h.csv")
        history.append({"level": 0})
        with open(tmp_path / "plain.txt", "w") as fh:
            fh.write("x")
    finally:
        os.umask(old)
    modes = {
        name: stat.S_IMODE(os.stat(tmp_path / name).st_mode)
        for name in ("s.vtu", "h.csv", "plain.txt")
    }
    print({k: oct(v) for k, v in modes.items()})
    assert modes == {"s.vtu": 0o644, "h.csv": 0o644, "plain.txt": 0o644}


# ---------------------------------------------------------------------------- history
def read_rows(path) -> tuple[list[str], list[dict]]:
    with open(path, newline="") as fh:
        reader = csv.DictReader(fh)
        rows = list(reader)
        return list(reader.fieldnames or []), rows


def test_history_writer_rewrites_a_parsable_file_after_each_append(tmp_path):
    path = tmp_path / "history.csv"
    history = HistoryWriter(path)
    rows = [
        {
            "level": 0,
            "ndof": 144,
            "eta": 310.85036363636,
            "error_energy": math.nan,
            "backend": "pardiso",
        },
        {
            "level": 1,
            "ndof": 152,
            "eta": 1.2345678901234567e-300,
            "error_energy": 0.1 + 0.2,
            "backend": "scipy",
        },
        {
            "level": 2,
            "ndof": 10**12,
            "eta": 2.0**0.5,
            "error_energy": 7.0,
            "backend": "a,b",
            "extra_column": 3.5,
        },
    ]
    for i, row in enumerate(rows):
        history.append(row)
        assert files_in(tmp_path) == ["history.csv"]
        columns, back = read_rows(path)
        assert len(back) == i + 1
        expected_columns = ["level", "ndof", "eta", "error_energy", "backend"]
        if i == 2:
            expected_columns.append("extra_column")
        assert columns == expected_columns
        for want, got in zip(rows[: i + 1], back, strict=True):
            assert int(got["level"]) == want["level"] and int(got["ndof"]) == want["ndof"]
            assert float(got["eta"]) == want["eta"]  # floats round-trip exactly
            if math.isnan(want["error_energy"]):
                assert got["error_energy"] == "nan"
            else:
                assert float(got["error_energy"]) == want["error_energy"]
            assert got["backend"] == want["backend"]
        if i == 2:
            assert [r["extra_column"] for r in back] == ["", "", "3.5"]


def test_history_writer_keeps_the_old_file_when_writing_fails(tmp_path, monkeypatch):
    path = tmp_path / "history.csv"
    history = HistoryWriter(path)
    history.append({"level": 0, "eta": 1.5})
    before = path.read_bytes()

    def fail(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(sio.os, "replace", fail)
    with pytest.raises(OSError, match="disk full"):
        history.append({"level": 1, "eta": 0.75})
    monkeypatch.undo()
    assert path.read_bytes() == before
    assert files_in(tmp_path) == ["history.csv"]


# ---------------------------------------------------------------------------- reading meshes
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
        edges = [mesh.part_edges(n) for n in mesh.part_names]
        lines = np.vstack([space.edge_nodes(e)[:, : order + 1] for e in edges])
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
        pts = mesh.points[mesh.edges[mesh.part_edges(name)]]
        np.testing.assert_array_equal(pts[..., axis], value)
        assert mesh.part_length(name) == pytest.approx(1.0, rel=1e-14)
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
