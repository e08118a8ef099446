"""Where an adaptive 3D run refines, and what it saves against uniform refinement (issue 39,
"How it is verified"): measurements on the levels of ``adaptive()``, shared by the tests and
the tables of docs/method.md, *Three dimensions: the adaptive loop on the built-ins*.

- :func:`zone_boundary_vertices`: the vertices of the contact faces whose vertices are not all
  in contact (the discrete contact zone's boundary on Γ_C);
- :func:`dirichlet_neumann_vertices`: the vertices on both a Dirichlet face and a face of a
  Neumann part (the Dirichlet–Neumann edges);
- :func:`ridge_vertices`: example-6.2-3d's vertices on the pyramid's ridges (the diagonals of
  the face x = 1, where the obstacle has its kinks);
- :func:`marking_concentration`: P(marked | cell touches the set) / P(marked | cell far from
  it): above 1 where Dörfler's marking gathers at the set, whatever the local mesh size;
- :func:`ndof_ratio`: N_adaptive / N_uniform at the same η, both histories interpolated
  log-log.
"""

from __future__ import annotations

import numpy as np

from signorini.problem import Contact, Dirichlet, Neumann


def _part_vertices(mesh, names) -> np.ndarray:
    facets = [mesh.part_facets(n) for n in names]
    if not facets:
        return np.zeros(0, dtype=np.int64)
    return np.unique(mesh.facets[np.concatenate(facets)])


def zone_boundary_vertices(result) -> np.ndarray:
    """Vertices of the contact faces whose three vertices are partly in contact (a vertex is
    in contact when one of its rows is active)."""
    mesh, cs = result.mesh, result.contact
    in_contact = np.zeros(mesh.n_points, dtype=bool)
    rows = cs.node < mesh.n_points
    in_contact[cs.node[rows & result.active]] = True
    names = [n for n, c in result.problem.conditions.items() if isinstance(c, Contact)]
    faces = mesh.facets[np.concatenate([mesh.part_facets(n) for n in names])]
    flags = in_contact[faces]
    mixed = flags.any(axis=1) & ~flags.all(axis=1)
    return np.unique(faces[mixed])


def dirichlet_neumann_vertices(result) -> np.ndarray:
    """Vertices on a Dirichlet face (all components held) and on a Neumann part's face."""
    conditions, mesh = result.problem.conditions, result.mesh
    held = [n for n, c in conditions.items() if isinstance(c, Dirichlet)]
    free = [n for n, c in conditions.items() if isinstance(c, Neumann)]
    return np.intersect1d(_part_vertices(mesh, held), _part_vertices(mesh, free))


def ridge_vertices(result) -> np.ndarray:
    """example-6.2-3d: the vertices of the face x = 1 on its diagonals y = z, y + z = 1 (mesh
    edges of the mirrored Kuhn mesh and of its bisections: the pyramid's kinks)."""
    x = result.mesh.points
    on_face = np.abs(x[:, 0] - 1.0) < 1e-12
    diagonal = (np.abs(x[:, 1] - x[:, 2]) < 1e-12) | (np.abs(x[:, 1] + x[:, 2] - 1.0) < 1e-12)
    return np.flatnonzero(on_face & diagonal)


def near_cells(mesh, vertices: np.ndarray) -> np.ndarray:
    """``(n_cells,)`` bool: the cells with a vertex among ``vertices``."""
    flag = np.zeros(mesh.n_points, dtype=bool)
    flag[vertices] = True
    return flag[mesh.cells].any(axis=1)


def marking_concentration(mesh, marked: np.ndarray, vertices: np.ndarray) -> float:
    """P(marked | the cell touches ``vertices``) / P(marked | it does not); NaN without
    cells on one side or nothing marked away from the set (then ``inf``)."""
    near = near_cells(mesh, vertices)
    if not near.any() or near.all():
        return float("nan")
    far = marked[~near].mean()
    return float(marked[near].mean() / far) if far > 0 else float("inf")


def ndof_ratio(adaptive_history, uniform_history, eta: float) -> float:
    """``N_adaptive(η) / N_uniform(η)``: each run's ``log N`` interpolated linearly in
    ``log η`` (histories as mappings with ``ndof`` and ``eta``, η decreasing); NaN where
    ``eta`` is outside either run's range."""

    def n_at(history) -> float:
        log_eta = np.log(np.asarray(history["eta"], dtype=float))[::-1]
        log_n = np.log(np.asarray(history["ndof"], dtype=float))[::-1]
        x = np.log(eta)
        if not log_eta[0] <= x <= log_eta[-1]:
            return float("nan")
        return float(np.exp(np.interp(x, log_eta, log_n)))

    return n_at(adaptive_history) / n_at(uniform_history)
