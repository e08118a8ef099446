"""The picture of a 3D body: one collection of boundary faces coloured by von Mises, thinned
past MAX_FACES with a note saying what was drawn."""

from __future__ import annotations

import numpy as np

from signorini.mesh.builders3d import box
from signorini.plots import body3d
from signorini.plots.body3d import plot_body_3d, shown_faces

from .figure_checks import check_written, png_size


def _surface(n: int):
    mesh = box(n, n, n)
    from signorini.fem.space import space_of

    faces = space_of(mesh, "P2").facet_nodes(mesh.boundary_facet)[:, :3]
    x = mesh.points
    u = 1e-3 * np.stack([x[:, 0] * x[:, 1], x[:, 2], -x[:, 0]], axis=1)
    stress = np.zeros((x.shape[0], 3, 3))
    stress[:, 0, 0] = x[:, 0]  # von Mises = x
    return x, faces, u, stress


def test_faces_outward_and_all_drawn_below_the_limit():
    x, faces, _, _ = _surface(2)
    corners = x[faces]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    outward = corners.mean(axis=1) - 0.5
    assert (np.einsum("ij,ij->i", normal, outward) > 0).all()
    rows, note = shown_faces(corners)
    assert rows.size == faces.shape[0] == 6 * 2 * 4 and note == ""


def test_thinned_past_the_limit_and_said():
    x, faces, _, _ = _surface(4)
    rows, note = shown_faces(x[faces], max_faces=50)
    assert 0 < rows.size <= 50
    assert note.startswith(f"drawn: {rows.size} of {faces.shape[0]} boundary faces")


def test_the_picture(tmp_path, captured, monkeypatch):
    x, faces, u, stress = _surface(2)
    written = plot_body_3d(x, faces, u, stress, tmp_path / "body", title="cube")
    check_written(written, tmp_path / "body")
    assert png_size(written[0]) == (840, 720)
    monkeypatch.setattr(body3d, "MAX_FACES", 10)
    written = plot_body_3d(x, faces, u, stress, tmp_path / "thin")
    assert written[0].stat().st_size > 5000
