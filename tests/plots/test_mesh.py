"""The mesh figure (:mod:`signorini.plots.mesh`)."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.mesh.builders import rectangle
from signorini.plots import plot_mesh

from .figure_checks import check_written


def test_mesh_figure_highlights_the_given_edges(tmp_path, captured):
    mesh = rectangle(nx=6, ny=6)
    bottom = mesh.edges[mesh.part_edges("bottom")]
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
    groups = {name: mesh.edges[mesh.part_edges(name)] for name in ("left", "right")}
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
