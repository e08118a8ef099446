"""SOLVE with friction on faces: the assembled system of a 3D problem whose contact parts
carry friction laws, handed to the semismooth Newton method of the disc law
(:mod:`signorini.algebra.friction.disc`; docs/method.md, *Friction in three dimensions: the
disc law*).

Each row of the face contact set is one node with its normal DOF (the row's) and its two
tangential DOFs in the node frame, both in the transformed basis (:mod:`.face_friction`). A
load step of a quasi-static path gets the previous step's result: its tangential
displacements in this step's variables are the reference ``x_t,ref`` (the law acts on the
slip increment) and its displacement is the starting point.
"""

from __future__ import annotations

import time

import numpy as np

from ..algebra.friction.disc import check_disc, solve_disc
from ..algebra.friction.result import INACTIVE, SLIP, FrictionResult
from .frictional import Solved, check_previous
from .frictional import solve_frictional as solve_frictional_2d
from .system import Assembled

__all__ = ["Solved", "check_previous", "solve_frictional", "solve_frictional_3d"]


def solve_frictional_3d(
    assembled: Assembled,
    K,
    F: np.ndarray,
    *,
    u0: np.ndarray | None,
    max_iter: int,
    previous: object = None,
) -> Solved:
    """Solve the frictional problem of an assembled 3D system (``K``, ``F`` possibly divided
    by the stiffness unit: the forces returned are in that unit).

    ``u0 (n_nodes, 3)`` (or, without it, ``previous.u``) is the starting point; with
    ``previous`` the reference of the slip is its tangential displacement. Returns the
    :class:`~.frictional.Solved` of the rows, with ``tangential_force``, ``reference``
    ``(k, 2)`` in ``[t_1 t_2]`` and ``direction (k, 2)`` the unit slip direction
    ``Λ_t / ‖Λ_t‖`` of slipping nodes (0 elsewhere).
    """
    t0 = time.perf_counter()
    cs = assembled.contact
    friction = cs.friction
    tangent = friction.solver_tangent()
    held = tangent < 0
    reference = np.zeros((cs.n_rows, 2))
    if previous is not None:
        y = cs.unknowns(np.asarray(previous.u, dtype=np.float64).ravel())
        reference = np.where(held, 0.0, y[friction.tangent])
        u0 = previous.u if u0 is None else u0
    x0 = None if u0 is None else cs.unknowns(np.asarray(u0, dtype=np.float64).ravel())
    law = friction.laws
    problem = check_disc(
        K, F, cs.dof, tangent, cs.gap, assembled.dirichlet, assembled.dirichlet_values,
        laws=law.laws, weight=law.weight, law_index=law.index, reference=reference,
    )  # fmt: skip
    res = solve_disc(problem, x0=x0, max_iter=max(max_iter, 60))
    state = res.state.astype(np.int64)
    # a frictionless node in contact slides freely: its friction force (0) is at its bound
    state[(res.normal_force > 0) & (law.index < 0)] = SLIP
    norm = np.linalg.norm(res.tangential_force, axis=1)
    direction = np.where(
        (state == SLIP)[:, None] & (norm > 0)[:, None],
        res.tangential_force / np.where(norm > 0, norm, 1.0)[:, None],
        0.0,
    )
    report = FrictionResult(
        x=res.x,
        iterations=res.iterations,
        n_solves=res.iterations,
        n_factorizations=res.iterations,
        n_analyses=res.n_analyses,
        history=[],
        kkt=res.kkt,
        backend=res.backend,
        c_scale=float(np.mean(problem.qp.diagonal()[cs.dof])) if cs.n_rows else 1.0,
        times={"total": time.perf_counter() - t0},
        multiplier_n=res.normal_force,
        multiplier_t=res.tangential_force,
        state=res.state,
        direction=direction,
        symmetric=law.symmetric,
    )
    state[(state == INACTIVE) & (res.normal_force > 0)] = SLIP
    return Solved(
        res.x, res.normal_force, res.tangential_force, state, direction, reference, report
    )


def solve_frictional(assembled: Assembled, K, F: np.ndarray, **options) -> Solved:
    """:func:`solve_frictional_3d` on a tetrahedral mesh (``u0``, ``max_iter``,
    ``previous`` of ``options``), else :func:`~.frictional.solve_frictional` itself."""
    if assembled.space.mesh.dim == 3:
        keep = {name: options.get(name) for name in ("u0", "previous")}
        return solve_frictional_3d(assembled, K, F, max_iter=options["max_iter"], **keep)
    return solve_frictional_2d(assembled, K, F, **options)
