"""Cell regions from Gmsh physical surface groups (:func:`signorini.mesh.read_mesh`)."""

from __future__ import annotations

import meshio
import numpy as np

from signorini.mesh import read_mesh
from signorini.mesh.builders import rectangle
from signorini.mesh.refine import refine_uniform

from .test_gmsh import gmsh_square


def test_physical_surfaces_become_regions(tmp_path):
    square = rectangle(0, 1, 0, 1, nx=4, ny=4)
    file = gmsh_square(square)
    centroid = square.points[square.cells].mean(axis=1)
    upper = centroid[:, 1] > 0.5
    file.cell_data["gmsh:physical"][0] = np.where(upper, 11, 10)  # "domain" and unnamed
    path = tmp_path / "layers.msh"
    meshio.write(path, file, file_format="gmsh22", binary=False)
    mesh = read_mesh(path)
    assert mesh.region_names == ("domain", "region11")
    np.testing.assert_array_equal(mesh.cell_region, upper.astype(int))
    fine = refine_uniform(mesh).mesh  # and through refinement
    c = fine.points[fine.cells].mean(axis=1)
    np.testing.assert_array_equal(fine.cell_region, (c[:, 1] > 0.5).astype(int))
