"""The mesh figure (:mod:`signorini.plots.mesh`)."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.mesh.builders import rectangle
from signorini.mesh.refine import refine_uniform
from signorini.plots import boundary_groups, plot_mesh, read_level_mesh, readable_level
from signorini.plots.style import DPI

from .figure_checks import check_written, png_size


def test_mesh_figure_highlights_the_given_edges(tmp_path, captured):
    mesh = rectangle(nx=6, ny=6)
    bottom = mesh.facets[mesh.part_facets("bottom")]
    written = plot_mesh(mesh.points, mesh.cells, tmp_path / "mesh", title="mesh", highlight=bottom)
    check_written(written, tmp_path / "mesh")
    (info,) = captured
    # one group, labelled as the contact boundary by default, drawn on the given edges
    (label,) = info["segments"]
    assert info["legend"] == [label] and "Gamma_C" in label
    np.testing.assert_array_equal(np.array(info["segments"][label]), mesh.points[bottom])
    assert info["titles"] == ["mesh"]
    # the whole mesh is in view
    lim = info["data_lim"][0]
    assert (lim.x0, lim.y0, lim.x1, lim.y1) == pytest.approx((0.0, 0.0, 1.0, 1.0))


def test_mesh_figure_with_several_groups(tmp_path, captured):
    mesh = rectangle(nx=3, ny=3)
    groups = {name: mesh.facets[mesh.part_facets(name)] for name in ("left", "right")}
    groups["none"] = np.zeros((0, 2), dtype=int)  # empty groups are left out
    plot_mesh(mesh.points, mesh.cells, tmp_path / "m", highlight=groups)
    (info,) = captured
    assert info["legend"] == ["left", "right"]
    for name in ("left", "right"):
        np.testing.assert_array_equal(info["segments"][name], mesh.points[groups[name]])


def test_mesh_figure_rejects_bad_arrays(tmp_path):
    mesh = rectangle(nx=2, ny=2)
    p, c = mesh.points, mesh.cells
    with pytest.raises(ValueError, match="points must have shape"):
        plot_mesh(p[:, :1], c, tmp_path / "x")
    with pytest.raises(ValueError, match="integer"):
        plot_mesh(p, c.astype(float), tmp_path / "x")
    with pytest.raises(ValueError, match="range"):
        plot_mesh(p, c + 100, tmp_path / "x")
    with pytest.raises(ValueError, match="highlight"):
        plot_mesh(p, c, tmp_path / "x", highlight=np.array([[0, 1, 2]]))
    assert not any(tmp_path.iterdir())


def test_readable_level_is_the_finest_with_few_cells():
    assert readable_level([32, 400, 2900, 3000, 3001, 9000]) == 3
    assert readable_level([32, 400, 900], most=500) == 1
    assert readable_level([5000, 9000]) == 0  # none is small: the first
    with pytest.raises(ValueError, match="no level"):
        readable_level([])


def test_boundary_groups_of_a_refined_mesh_follow_the_coarse_parts():
    coarse = rectangle(nx=2, ny=2)
    fine = refine_uniform(refine_uniform(coarse).mesh).mesh
    segments = {
        "D": coarse.points[coarse.facets[coarse.part_facets("top")]],
        "C": np.concatenate(
            [coarse.points[coarse.facets[coarse.part_facets(n)]] for n in ("bottom", "right")]
        ),
        "none": np.zeros((0, 2, 2)),
    }
    groups = boundary_groups(fine.points, fine.cells, segments)
    assert list(groups) == ["D", "C", "none"] and groups["none"].shape == (0, 2)
    for name, parts in (("D", ["top"]), ("C", ["bottom", "right"])):
        expected = np.concatenate([fine.facets[fine.part_facets(n)] for n in parts])
        assert sorted(map(tuple, np.sort(groups[name], axis=1))) == sorted(map(tuple, expected))


def test_read_level_mesh_gives_back_the_triangulation(tmp_path):
    from signorini import solve, write_vtu
    from signorini.examples import example_6_2

    result = solve(example_6_2())
    write_vtu(tmp_path / "level_000.vtu", result)
    points, cells = read_level_mesh(tmp_path / "level_000.vtu")
    np.testing.assert_array_equal(points, result.mesh.points)
    np.testing.assert_array_equal(cells, result.mesh.cells)
    # a truncated file is named (meshio.read would end the process with sys.exit)
    vtu = tmp_path / "level_000.vtu"
    vtu.write_bytes(vtu.read_bytes()[:1000])
    with pytest.raises(ValueError, match=f"^{vtu} is not a readable level file of a run"):
        read_level_mesh(vtu)


def test_mesh_figure_height_follows_a_wide_body(tmp_path, captured):
    mesh = rectangle(0.0, 4.0, 0.0, 0.5, nx=16, ny=2)
    written = plot_mesh(mesh.points, mesh.cells, tmp_path / "m", title="a wide block")
    # the figure is as low as the body needs (the layout checks allow no wide empty band)
    height = png_size(written[0])[1] / DPI
    print(f"figure height {height:.2f} in")
    assert height < 2.2


def test_mesh_figure_with_a_zoom(tmp_path, captured):
    mesh = refine_uniform(rectangle(nx=4, ny=4)).mesh
    right = mesh.facets[mesh.part_facets("right")]
    plot_mesh(
        mesh.points,
        mesh.cells,
        tmp_path / "z",
        highlight={"C": right},
        zoom=(0.9, 0.5, 0.1),
        zoom_title="end of the contact zone",
    )
    (info,) = captured
    assert info["titles"] == ["", "end of the contact zone"]
    assert info["ylim"][1] == pytest.approx((0.4, 0.6)) and info["legend"] == ["C"]
    (frame,) = [p for p in info["patches"] if p.get_width() == pytest.approx(0.2)]
    assert frame.get_xy() == pytest.approx((0.8, 0.4))
    with pytest.raises(ValueError, match="zoom must be"):
        plot_mesh(mesh.points, mesh.cells, tmp_path / "x", zoom=(0.5, 0.5, 0.0))
