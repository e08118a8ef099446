"""Shared 3D contact problems of tests/contact3d: a rotation about no axis, the block
pressed onto a half-space on two symmetry rollers (force control), a mesh joined to its
mirror image, and a problem's system with its contact made traction-free."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from signorini.algebra.backends.selection import SOLVERS
from signorini.contact.system import Assembled, assemble
from signorini.fem.material import Material
from signorini.mesh.builders3d import box
from signorini.mesh.mesh import Mesh
from signorini.problem.conditions import Contact, Neumann, Roller
from signorini.problem.obstacles3d import HalfSpace
from signorini.problem.problem import ContactProblem

MATERIAL = Material.from_young(1.0, 0.3)
DIRECT = SOLVERS["scipy"]


def rotation() -> np.ndarray:
    """A rotation about no coordinate axis (0.7 rad about z after 0.7 rad about x)."""
    c, s = np.cos(0.7), np.sin(0.7)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ np.array(
        [[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]]
    )


def pressed_block(R: np.ndarray, load: float = -0.1) -> ContactProblem:
    """The unit cube of box(2) rotated by ``R``: symmetry rollers on x0 and y0, pressed by
    the traction ``(0.01, 0, load)`` on z1 and a body force onto the half-space below z0 (a
    gap of 10⁻³): held along its normal by its contact alone (force control)."""
    base = box(2, 2, 2)
    parts = {p: base.facets[base.part_facets(p)] for p in base.part_names}
    mesh = Mesh.from_arrays(base.points @ R.T, base.cells, parts)
    traction = R @ np.array([0.01, 0.0, load])
    conditions = {name: Neumann((0.0, 0.0, 0.0)) for name in mesh.part_names}
    conditions.update(
        x0=Roller(),
        y0=Roller(),
        z1=Neumann(tuple(traction.tolist())),
        z0=Contact(obstacle=HalfSpace(R @ [0.0, 0.0, -1e-3], R @ [0.0, 0.0, 1.0])),
    )
    force = R @ np.array([0.0, 0.02, -0.05])
    return ContactProblem(mesh, MATERIAL, conditions, body_force=lambda x: force)


def mirrored(mesh: Mesh, axis: int) -> tuple[Mesh, np.ndarray]:
    """``mesh`` and its mirror image in the plane ``x_axis = 0`` (its vertices there kept
    once): the image's cells with vertices 1 and 2 swapped (positive again), each part the
    union of its faces and their images except a part on the plane (now inside), curved
    parts carrying their (symmetric) surfaces; and each vertex's image."""
    p = mesh.points
    off = p[:, axis] != 0.0
    image = np.arange(mesh.n_points)
    image[off] = mesh.n_points + np.arange(off.sum())
    flipped = p[off].copy()
    flipped[:, axis] *= -1.0
    parts = {}
    for name in mesh.part_names:  # a loop over parts
        faces = mesh.facets[mesh.part_facets(name)]
        if off[faces].any():
            parts[name] = np.vstack([faces, image[faces]])
    whole = Mesh.from_arrays(
        np.vstack([p, flipped]), np.vstack([mesh.cells, image[mesh.cells][:, [0, 2, 1, 3]]]), parts
    )
    for name, curve in zip(mesh.part_names, mesh.curves, strict=True):
        if curve is not None and name in parts:
            whole = whole.with_curve(name, curve)
    return whole, image


def without_contact(problem: ContactProblem) -> Assembled:
    """The assembled Cartesian system of ``problem`` with its contact parts and their
    masters traction-free (an independent solve's K, F and held DOFs)."""
    free = Neumann((0.0, 0.0, 0.0))
    conditions = {k: free if isinstance(c, Contact) else c for k, c in problem.conditions.items()}
    conditions |= dict.fromkeys(problem.pairs.values(), free)
    return assemble(replace(problem, conditions=conditions), problem.mesh)
