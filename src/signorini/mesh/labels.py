"""The checks of a mesh's boundary labels, the same in 2D and 3D: every listed boundary
facet (an edge in 2D, a face in 3D) has a part, every part owns a facet, and the listed
facets are exactly the facets with one cell, each listed once. A failure raises a
:class:`~signorini.mesh.validation.MeshError` naming the facet by the caller's text
function (:func:`~signorini.mesh.validation.validate_mesh`,
:func:`~signorini.mesh.validation3d.validate_tetrahedra`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from .validation import MeshError

if TYPE_CHECKING:
    from .mesh import Mesh

__all__ = ["check_boundary_labelled", "check_part_labels", "edge_name", "edge_text"]

#: ``text(points, vertices)``: a facet named in an error message
Text = Callable[[np.ndarray, np.ndarray], str]


def edge_text(points: np.ndarray, edge: np.ndarray) -> str:
    """``the edge from (x, y) to (x, y) (vertices i and j)`` for a vertex pair ``edge``."""
    a, b = points[edge[0]], points[edge[1]]
    return (
        f"the edge from ({a[0]:.12g}, {a[1]:.12g}) to ({b[0]:.12g}, {b[1]:.12g}) (vertices "
        f"{edge[0]} and {edge[1]})"
    )


def edge_name(points: np.ndarray, edge: np.ndarray) -> str:
    """``edge (i, j)`` for a vertex pair ``edge`` (its coordinates left out)."""
    return f"edge ({edge[0]}, {edge[1]})"


def check_part_labels(mesh: Mesh, entity: str = "edge", text: Text = edge_text) -> None:
    """Every boundary row has a valid part index, and every part owns a facet.

    Parameters
    ----------
    mesh : Mesh
    entity : str
        What a facet is called: ``"edge"`` (2D) or ``"face"`` (3D).
    text : callable
        ``text(points (n_points, d), vertices (d,)) -> str``: a facet in a message.
    """
    if mesh.boundary_part.shape != (len(mesh.boundary),):
        raise MeshError(f"boundary_part must have one entry per boundary {entity}")
    bad_part = (mesh.boundary_part < 0) | (mesh.boundary_part >= len(mesh.part_names))
    if bad_part.any():
        first = mesh.boundary[np.flatnonzero(bad_part)[0]]
        raise MeshError(
            f"{int(bad_part.sum())} boundary {entity}(s) have no part, first "
            f"{text(mesh.points, first)}; label every boundary {entity}"
        )
    for index, name in enumerate(mesh.part_names):
        if not np.any(mesh.boundary_part == index):
            raise MeshError(f"boundary part {name!r} has no {entity}s")


def check_boundary_labelled(
    mesh: Mesh,
    is_bnd: np.ndarray,
    entity: str = "edge",
    text: Text = edge_text,
    name: Text = edge_name,
) -> None:
    """The listed boundary facets are exactly the facets with one cell, each listed once.

    Parameters
    ----------
    mesh : Mesh
    is_bnd : (n_facets,) bool array
        The facets with one cell.
    entity, text
        As :func:`check_part_labels`.
    name : callable
        As ``text``, for a listed facet shared by two cells.
    """
    listed = mesh.boundary_facet  # raises for a listed row that is not a facet
    if np.any(~is_bnd[listed]):
        bad = mesh.boundary[np.flatnonzero(~is_bnd[listed])[0]]
        raise MeshError(
            f"{name(mesh.points, bad)} is labelled as boundary but is shared by two cells"
        )
    if np.unique(listed).size != listed.size:
        raise MeshError(f"a boundary {entity} is listed twice")
    labelled = np.zeros(mesh.n_facets, dtype=bool)
    labelled[listed] = True
    missing = np.flatnonzero(is_bnd & ~labelled)
    if missing.size:
        raise MeshError(
            f"{missing.size} boundary {entity}(s) without a part, first "
            f"{text(mesh.points, mesh.facets[missing[0]])}; label every boundary {entity}"
        )
