"""A level of the loop as plain arrays, for the leaves that draw it (``plots.run_figures``):
they take arrays and part names, never the solver's objects, as :meth:`LevelRecord.row
<signorini.loop.record.LevelRecord.row>` gives the history writer a plain row."""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from ..contact.contact_set import ContactSet
from ..contact.solution import SLIP, STICK
from ..fem.element import P1
from .arrays3d import surface_arrays

if TYPE_CHECKING:
    from . import Level

__all__ = ["arc_lengths", "body_arrays", "level_arrays", "obstacle_offset", "obstacle_outline"]

#: Points sampled along each contact edge where the obstacle's outline is drawn.
OUTLINE_SAMPLES = 9
#: The outline is left out where the obstacle is farther than this fraction of the body's size
#: from the contact part (a shape far from most of a curved part, e.g. the plane under a disc).
OUTLINE_REACH = 0.25


def body_arrays(level: Level) -> dict[str, Any]:
    """What the picture of a 3D level's body needs (``plots.run_figures.body_figures``), as
    plain arrays at the mesh's vertices.

    Returns
    -------
    dict
        ``level`` (int); ``points (n, 3)``, the vertices; ``faces (k, 3)``, the boundary
        faces' vertices in outward order (the space's
        :meth:`~signorini.fem.space3d.P2TetSpace.facet_nodes`); ``displacement (n, 3)`` and
        the nodal Cauchy stress ``stress (n, 3, 3)`` at the vertices; ``name``, the
        problem's; ``degree``, the element's; ``dim`` 3; with contact ``contact``, the
        contact surface (:func:`~.arrays3d.surface_arrays`).
    """
    res = level.result
    mesh, n = res.mesh, res.mesh.points.shape[0]
    contact = {"contact": surface_arrays(res)} if res.contact.size else {}
    return {
        "level": level.record.level,
        "points": mesh.points,
        "faces": res.space.facet_nodes(mesh.boundary_facet)[:, :3],
        "displacement": res.u[:n],
        "stress": res.nodal_stress[:n],
        "name": res.problem.name,
        "degree": res.space.element.degree,
        "dim": mesh.dim,
        **contact,
    }


def level_arrays(level: Level) -> dict[str, Any]:
    """The mesh, displacement and contact quantities of ``level``, as plain arrays.

    Returns
    -------
    dict
        ``level`` (int); ``points (n, 2)``, ``cells (m, 3)`` of the level's mesh;
        ``displacement (n_nodes, 2)`` at the P2 nodes (vertices first); ``initial``, the
        problem's initial mesh, and ``parts``, the names of its ``"dirichlet"``,
        ``"neumann"`` and ``"contact"`` parts; per constraint (k of them)
        ``contact_points (k, 2)``, ``active (k,)``, ``pressure (k,)`` p_z, ``gap (k,)`` ψ(z)
        and ``normal (k, 2)`` n_z; ``obstacle``, each contact part's obstacle outline near
        it (:func:`obstacle_outline`), and ``obstacle_offset``, the gap vector ``ψ n`` from
        the body's point to each point of the outline (:func:`obstacle_offset`: a drawing of
        the displacement magnified by s draws the obstacle at ``obstacle + (s − 1)
        obstacle_offset``, where the magnified body touches it); ``along``, each contact
        part's constraints and their arc length (:func:`arc_lengths`); ``pairs``, the
        contact pairs between bodies (slave part -> master part; docs/method.md, *Two
        bodies*); ``name``, the problem's name (figure titles), and ``degree``, the element's
        (2 for P2, 1 for P1); with friction on some
        contact part also ``state (k,)`` as the labels ``"inactive"``, ``"stick"``,
        ``"slip"``, ``contact_displacement (k, 2)`` and ``tangential_pressure (k,)`` p_t,z.
    """
    res = level.result
    mesh, problem, cs = res.mesh, res.problem, res.contact
    arrays = {
        "level": level.record.level,
        "points": mesh.points,
        "cells": mesh.cells,
        "displacement": res.u,
        "initial": problem.mesh,
        "parts": {
            "dirichlet": problem.dirichlet_parts,
            "neumann": problem.neumann_parts,
            "contact": problem.contact_parts,
        },
        "contact_points": res.space.node_points[cs.nodes],
        "active": res.active,
        "pressure": res.pressure,
        "gap": cs.gap,
        "normal": cs.normal,
        **_obstacle_arrays(cs, res.space.node_points, problem.conditions),
        "along": arc_lengths(cs, res.space.node_points),
        "pairs": dict(problem.pairs),
        "name": problem.name,
        "degree": res.space.element.degree,
    }
    if cs.has_friction:
        arrays["state"] = np.where(
            res.state == STICK, "stick", np.where(res.state == SLIP, "slip", "inactive")
        )
        arrays["contact_displacement"] = cs.relative(res.u)[cs.nodes]  # relative, two bodies
        arrays["tangential_pressure"] = res.tangential_pressure
    return arrays


def _p2_facet(values: np.ndarray) -> np.ndarray:
    """Per-edge nodal data ``(e, 3, ...)`` at ``[start, end, midpoint]``; a P1 edge's ``(e, 2,
    ...)`` with the mean of its ends at the midpoint (:meth:`~signorini.fem.facet_element.
    FacetElement.facet_values`)."""
    return values if values.shape[1] == 3 else P1.facet.facet_values(values)


def _on_facets(ends: np.ndarray, m: int) -> np.ndarray:
    """``(e, m, ...)`` values at ``m`` equispaced points of each edge, interpolated
    quadratically from ``ends (e, 3, ...)`` at ``[start, end, midpoint]`` (the P2 edge)."""
    t = np.linspace(0.0, 1.0, m)
    basis = np.stack([2 * (t - 0.5) * (t - 1), 2 * t * (t - 0.5), 4 * t * (1 - t)], axis=1)
    return np.einsum("mj,ej...->em...", basis, ends)


def obstacle_outline(
    cs: ContactSet, node_points: np.ndarray, conditions: Mapping[str, Any]
) -> dict[str, np.ndarray]:
    """Each contact part's obstacle near the part at true scale (the outline of
    :func:`obstacle_offset`)."""
    both = obstacle_offset(cs, node_points, conditions)
    return {name: outline for name, (outline, _) in both.items()}


def _obstacle_arrays(
    cs: ContactSet, node_points: np.ndarray, conditions: Mapping[str, Any]
) -> dict[str, dict[str, np.ndarray]]:
    """``obstacle`` and ``obstacle_offset`` of :func:`level_arrays`."""
    both = obstacle_offset(cs, node_points, conditions)
    return {
        "obstacle": {name: outline for name, (outline, _) in both.items()},
        "obstacle_offset": {name: offset for name, (_, offset) in both.items()},
    }


def obstacle_offset(
    cs: ContactSet, node_points: np.ndarray, conditions: Mapping[str, Any]
) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each contact part's obstacle near the part at true scale, as a polyline broken by NaN
    rows, and the gap vector from the part to each of its points.

    Along each contact edge, :data:`OUTLINE_SAMPLES` points ``x`` of the (P2) edge are mapped
    to the obstacle: against a shape (:mod:`signorini.problem.obstacles`, a user's
    ``Obstacle`` subclass) to their closest point ``x + ψ(x) n(x)`` from its
    ``gap_and_direction``, which lies on the shape's boundary; for a gap function given along
    the body's normal the nodes' ``z + ψ(z) n_z``, interpolated quadratically along the edge
    (the obstacle surface of the small-deformation model, docs/method.md). Points whose gap
    exceeds :data:`OUTLINE_REACH` times the body's size are left out (NaN).

    Parameters
    ----------
    cs : ContactSet
        The contact data of the level.
    node_points : (n_nodes, 2) float array
        The P2 nodes.
    conditions : mapping
        The problem's conditions by part name (``Contact`` for the contact parts).

    Returns
    -------
    dict
        Part name -> ``(outline, offset)``, two ``(e * (OUTLINE_SAMPLES + 1), 2)`` float
        arrays, ``e`` the part's contact edges: the outline, one run of points per edge with
        a NaN row after each, and ``offset = outline − x``, the gap vector ``ψ n`` from the
        point ``x`` of the edge each outline point belongs to. A drawing that magnifies the
        displacement by ``s`` draws the body's ``x`` at ``x + s u`` and must draw the
        obstacle at ``x + s ψ n = outline + (s − 1) offset``: there the magnified body
        touches it (u·n = ψ), as the true body touches the true obstacle.
    """
    m = OUTLINE_SAMPLES
    size = float(np.ptp(node_points, axis=0).max()) if node_points.size else 0.0
    outline = {}
    for i, name in enumerate(cs.parts):  # a loop over the contact parts
        if getattr(conditions[name], "master", None) is not None:
            continue  # the other body is drawn itself
        sel = cs.facet_part == i
        out = np.full((int(sel.sum()), m + 1, 2), np.nan)
        obstacle = conditions[name].obstacle
        x = _on_facets(_p2_facet(node_points[cs.facet_nodes[sel]]), m).reshape(-1, 2)
        if obstacle is not None:
            g, n = obstacle.gap_and_direction(x)
            out[:, :m] = (x + g[:, None] * n).reshape(-1, m, 2)
            psi = g.reshape(-1, m)
        else:
            ends = node_points[cs.facet_nodes[sel]]
            ends = _p2_facet(ends + cs.facet_gap[sel][..., None] * cs.facet_direction[sel])
            out[:, :m] = _on_facets(ends, m)
            psi = _on_facets(_p2_facet(cs.facet_gap[sel]), m)
        out[:, :m][np.abs(psi) > OUTLINE_REACH * size] = np.nan
        offset = out.copy()
        offset[:, :m] -= x.reshape(-1, m, 2)
        outline[name] = (out.reshape(-1, 2), offset.reshape(-1, 2))
    return outline


def arc_lengths(
    cs: ContactSet, node_points: np.ndarray
) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each contact part's constraints and their arc length along the part.

    The part's edges (oriented counter-clockwise, ``cs.facet_nodes``) form chains; the arc
    length of a vertex is its distance along the chain from the chain's first vertex
    (shortest paths on the directed chain graph, each edge weighted by its length through its
    midpoint), a midpoint's that of its edge's start plus the half-edge.

    Returns
    -------
    dict
        Part name -> ``(rows (j,), s (j,))``: the rows of the part's constraints (indices of
        ``cs.nodes``; a corner node's row for this part) in increasing ``s``, and ``s``
        (length units, from 0).
    """
    along = {}
    for i, name in enumerate(cs.parts):  # a loop over the contact parts
        sel = cs.facet_part == i
        en, local = cs.facet_nodes[sel], cs.facet_local[sel]
        if en.shape[0] == 0:
            along[name] = (np.zeros(0, np.int64), np.zeros(0))
            continue
        x = _p2_facet(node_points[en])
        half = np.hypot(*(x[:, 2] - x[:, 0]).T), np.hypot(*(x[:, 1] - x[:, 2]).T)
        vertices, ends = np.unique(en[:, :2], return_inverse=True)
        ends = ends.reshape(-1, 2)
        n_v = vertices.size
        graph = coo_matrix((half[0] + half[1], (ends[:, 0], ends[:, 1])), shape=(n_v, n_v))
        roots = np.setdiff1d(ends[:, 0], ends[:, 1])
        if roots.size == 0:  # a closed part: from the first edge's start
            roots = ends[:1, 0]
        dist = dijkstra(graph.tocsr(), directed=True, indices=roots, min_only=True)
        s = np.stack([dist[ends[:, 0]], dist[ends[:, 1]], dist[ends[:, 0]] + half[0]], axis=1)
        s = s[:, : en.shape[1]]  # P1: no midpoint node
        rows, first = np.unique(local.ravel(), return_index=True)
        s = s.ravel()[first][rows >= 0]
        rows = rows[rows >= 0]
        order = np.argsort(s, kind="stable")
        along[name] = (rows[order], s[order])
    return along
