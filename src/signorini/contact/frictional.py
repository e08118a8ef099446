"""SOLVE with friction: the assembled system of a problem whose contact parts carry Tresca or
Coulomb friction, handed to the semismooth Newton method of :mod:`signorini.algebra.friction`
(docs/method.md, *Friction: the algebraic problem and its solver*).

Every constraint is one contact node with its normal DOF ``2z`` and tangential DOF ``2z + 1``
in the node frame ``[n t]``; frictionless parts of the same problem take the bound 0 (Tresca)
or the coefficient 0 (Coulomb). Tresca is the classical problem, the bound acting on every
node of Γ_C (the minimiser of ``½ a(u, u) − L(u) + Σ_z s_z |u_t(z)|`` subject to
``u(z)·n_z ≤ ψ(z)``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..algebra.friction import INACTIVE, SLIP, solve_friction
from ..algebra.friction_result import FrictionResult
from ..problem.fields import ProblemError
from .contact_set import COULOMB, TRESCA, ContactSet
from .node_frames import to_frames
from .system import Assembled

__all__ = ["FrictionSolve", "check_friction_set", "solve_frictional"]


@dataclass(frozen=True)
class FrictionSolve:
    """What the frictional solve gives per constraint (k of them) and its report."""

    x: np.ndarray
    normal_force: np.ndarray
    tangential_force: np.ndarray
    state: np.ndarray
    report: FrictionResult


def check_friction_set(cs: ContactSet) -> str:
    """The law (``"tresca"`` or ``"coulomb"``) of a contact set with friction.

    Raises
    ------
    ProblemError
        If Tresca and Coulomb parts are mixed, or a node where two contact parts meet at an
        angle (two constraints) lies on a part with friction.
    """
    laws = set(cs.friction_law[cs.friction_law > 0].tolist())
    if laws == {TRESCA, COULOMB}:
        raise ProblemError(
            "contact parts with Tresca and with Coulomb friction in one problem are not "
            "supported; give all frictional parts the same law"
        )
    friction_parts = np.unique(cs.part[cs.friction_law > 0])
    corner = np.isin(cs.nodes, cs.nodes[cs.second])
    at_corner = corner & np.isin(cs.part, friction_parts)
    if at_corner.any():
        k = int(np.flatnonzero(at_corner)[0])
        raise ProblemError(
            f"node {cs.nodes[k]} is a corner of contact parts {cs.parts[cs.part[k]]!r} and "
            "another part (two constraint directions): friction at such a corner is not "
            "supported; end the frictional part before the corner (e.g. a frictionless part "
            "for the last edge) or join the parts"
        )
    return "tresca" if TRESCA in laws else "coulomb"


def solve_frictional(
    assembled: Assembled,
    K,
    F: np.ndarray,
    *,
    u0: np.ndarray | None,
    backend: str,
    max_iter: int,
) -> FrictionSolve:
    """Solve the frictional contact problem of an assembled system (``K``, ``F`` possibly
    divided by the stiffness unit: the forces returned are in that unit).

    Parameters
    ----------
    assembled : Assembled
    K, F : the system to solve, in node frames
    u0 : (n_nodes, 2) float array or None
        Warm start: the update rule evaluated at it.
    backend : str
    max_iter : int
    """
    cs = assembled.contact
    law = check_friction_set(cs)
    x0 = None
    if u0 is not None:
        x0 = to_frames(u0.ravel(), cs.frame_nodes, cs.frames)
    common = {
        "dirichlet": assembled.dirichlet,
        "dirichlet_values": assembled.dirichlet_values,
        "x0": x0,
        "max_iter": max_iter,
        "backend": backend,
    }
    nodes = cs.nodes
    if law == "tresca":
        res = solve_friction(
            K, F, 2 * nodes, 2 * nodes + 1, cs.gap, bound=cs.friction_bound,
            tresca_everywhere=True, **common,
        )  # fmt: skip
    else:
        res = solve_friction(
            K, F, 2 * nodes, 2 * nodes + 1, cs.gap, coefficient=cs.friction_coefficient,
            **common,
        )  # fmt: skip
    state = res.state.astype(np.int64)
    # a frictionless node in contact slides freely: its friction force (0) is at its bound
    state[(state != INACTIVE) & (cs.friction_law == 0)] = SLIP
    return FrictionSolve(res.x, res.multiplier_n, res.multiplier_t, state, res)
