"""The body's outward unit normal at the P2 nodes of a boundary part: one definition for the
directions of contact parts (docs/method.md, *Contact directions*) and of rollers
(docs/method.md, *Rollers and components*).

At a node ``z`` of a part's facet the normal ``n_z`` is

- the part's normal on a straight part;
- the exact normal of the part's curve where the mesh carries a curve that has one
  (:meth:`~signorini.mesh.mesh.Mesh.with_curve`), oriented outwards;
- otherwise the facet chord's normal at a midpoint, and the normalised mean of the normals of
  the part's (one or two) facets at a vertex (edges in 2D).
"""

from __future__ import annotations

import numpy as np

from ..mesh.curves import Line
from ..mesh.geometry import facet_normals
from ..mesh.mesh import Mesh
from ..mesh.validation import MeshError
from .fields import ProblemError

__all__ = [
    "CURVE_NORMAL_ANGLE",
    "STRAIGHT_RTOL",
    "face_node_normals",
    "node_normals",
    "straight_normal",
]

#: a curve's normal at a node of a part's facet may differ from the facet chord's normal by at
#: most this angle (radians, 60°): the curve turns by about h / R over a facet, far less on
#: any mesh that resolves it; a normal along the boundary (the tangent) is 90° off
CURVE_NORMAL_ANGLE = np.pi / 3
#: a part is straight when its facets' outward unit normals differ from their mean by at most
#: this much (and it carries no curve other than a line)
STRAIGHT_RTOL = 1e-8


def straight_normal(mesh: Mesh, name: str) -> np.ndarray | None:
    """``(2,)`` the outward unit normal of part ``name`` if it is straight (its facets'
    normals agree within :data:`STRAIGHT_RTOL` and it carries no curve other than a
    :class:`~signorini.mesh.curves.Line`), else ``None``."""
    ab = mesh.oriented_boundary(mesh.part_facets(name))
    _, n = facet_normals(mesh.points[ab])
    mean = n.mean(axis=0)
    mean /= np.linalg.norm(mean)
    curve = mesh.curves[mesh.part_index(name)]
    if np.abs(n - mean).max() > STRAIGHT_RTOL or not (curve is None or isinstance(curve, Line)):
        return None
    return mean


def node_normals(
    mesh: Mesh,
    name: str,
    nodes: np.ndarray,
    points: np.ndarray,
    chord: np.ndarray,
    *,
    straight: np.ndarray | None = None,
    what: str = "contact part",
) -> np.ndarray:
    """The outward unit normal at the nodes ``[start, end, midpoint]`` of one part's facets.

    Parameters
    ----------
    mesh : Mesh
    name : str
        The part.
    nodes : (e, 3) int array
        Global P2 nodes ``[start, end, midpoint]`` of the part's facets (vertices first in
        the P2 numbering, so ``nodes[:, :2]`` are mesh vertices).
    points : (e, 3, 2) float array
        Their coordinates (the midpoint on the part's curve).
    chord : (e, 2) float array
        The outward unit normal of each facet's chord.
    straight : (2,) float array, optional
        The part's normal where it is straight (:func:`straight_normal`): every node takes it.
    what : str
        The kind of part, for messages (``"contact part"``, ``"roller part"``).

    Returns
    -------
    (e, 3, 2) float array

    Raises
    ------
    ProblemError
        If the part's curve cannot give its normal at a node, or gives one more than
        :data:`CURVE_NORMAL_ANGLE` away from the facet's normal (a tangent, not a normal).
    """
    if straight is not None:
        return np.broadcast_to(straight, nodes.shape + (2,)).copy()
    curve = mesh.curves[mesh.part_index(name)]
    if curve is not None and curve.has_normal:
        x = points.reshape(-1, 2)
        try:
            n = curve.normal(x).reshape(nodes.shape + (2,))
        except MeshError as err:
            raise ProblemError(f"the curve of {what} {name!r}: {err}") from err
        cos = np.einsum("ejc,ec->ej", n, chord)
        _check_across(f"{what} {name!r}", cos, x)
        return n * np.where(cos < 0, -1.0, 1.0)[..., None]
    total = np.zeros((int(nodes[:, :2].max(initial=0)) + 1, 2))
    np.add.at(total, nodes[:, :2].ravel(), np.repeat(chord, 2, axis=0))
    out = np.repeat(chord[:, None, :], nodes.shape[1], axis=1)
    mean = total[nodes[:, :2]]
    out[:, :2] = mean / np.hypot(mean[..., 0], mean[..., 1])[..., None]
    return out


def _check_across(part: str, cos: np.ndarray, x: np.ndarray) -> None:
    """Refuse a curve normal that runs along the boundary rather than across it: ``cos (e, 3)``
    of its angle to the chord's normal at the nodes ``x (3 e, 2)`` of a part's facets."""
    bad = np.flatnonzero(np.abs(cos).ravel() < np.cos(CURVE_NORMAL_ANGLE))
    if bad.size:
        i = bad[0]
        angle = np.degrees(np.arccos(min(abs(float(cos.ravel()[i])), 1.0)))
        raise ProblemError(
            f"the curve of {part} gives at the node ({x[i, 0]:.12g}, "
            f"{x[i, 1]:.12g}) a normal {angle:.3g}° away from the normal of the boundary edge "
            f"there (more than {np.degrees(CURVE_NORMAL_ANGLE):.0f}°; {bad.size} node(s)): it "
            "runs along the boundary, not across it. ProjectedCurve(normal=...) must return "
            "the curve's normal, not its tangent"
        )


def face_node_normals(space, name: str, z: np.ndarray) -> np.ndarray:
    """``(j, 3)`` the body's outward unit normals at the P2 nodes ``z (j,)`` of part
    ``name``'s faces on a tetrahedral mesh (docs/method.md, *Three dimensions: contact on
    faces*): the surface's exact normal on a part carrying a :class:`~signorini.mesh.surfaces.
    Surface` with a normal (oriented as the faces), else the normalised mean of the unit
    normals of the part's faces at each node (on a flat part: its normal).

    Parameters
    ----------
    space : P2TetSpace
    name : str
        The boundary part.
    z : (j,) int array
        Nodes of the part's faces.
    """
    mesh = space.mesh
    nodes = space.facet_nodes(mesh.part_facets(name))
    _, normal = facet_normals(mesh.points[nodes[:, :3]])
    total = np.zeros((space.n_nodes, 3))
    np.add.at(total, nodes.ravel(), np.repeat(normal, nodes.shape[1], axis=0))
    n = total[z] / np.linalg.norm(total[z], axis=1)[:, None]
    surface = mesh.curves[mesh.part_index(name)]
    if surface is not None and getattr(surface, "has_normal", False):
        m = surface.normal(space.node_points[z])
        return m * np.where(np.einsum("jc,jc->j", m, n) < 0, -1.0, 1.0)[:, None]
    return n
