"""Force control of a semi-coercive body: the load must press it onto its contacts along
the rigid motions its Dirichlet and Roller parts leave free (docs/method.md, *Force control*).

For a free rigid motion r (``K r = 0`` on the free DOFs), equilibrium of the discrete problem
``K u = F − Σ_z Λ_z n_z`` (contact forces ``Λ_z ≥ 0`` pushing the body off the obstacle)
tested with r gives ``Σ_z Λ_z r(z)·n_z = F·r``: the load's work along every free motion must
be a non-negative combination of the contact directions' ``r(z)·n_z``. If it is not (a load
that pulls the body away from the obstacle), no solution exists; if it is only on the edge of
that cone (no load along a motion the contacts resist one way only), the body's position
along it is not determined. Both are refused before the solve, naming the motion, instead of
a singular matrix.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import nnls

from ..problem.fields import DATA_MAX, ProblemError
from ..problem.rigid import describe_motion
from .face_contact import FaceContactSet
from .node_frames import to_frames
from .system import Assembled

__all__ = ["check_load_carried", "initial_active_set", "motion_fields"]

#: relative size below which the load's work along a free motion, or the misfit of its
#: balance by contact forces, is zero (the load's own scale: Σ |F_i| |r_i|)
LOAD_RTOL = 1e-10
#: the load must stay balanced by contact forces when moved by this much (relative to its
#: scale) along each free motion: strictly inside the cone of contact forces
STRICT_RTOL = 1e-6


def motion_fields(assembled: Assembled) -> np.ndarray:
    """The free rigid motions of the problem of ``assembled`` at its P2 nodes, ``(k,
    n_nodes, 2)``, as the unknowns the constraints bound: each zero off its body where the
    problem has contact pairs
    (:attr:`~.discrete_conditions.DiscreteConditions.rigid_field`), and then the relative
    displacement ``ũ = (I − T_d) u`` of the pairs (docs/method.md, *Two bodies*), so that
    ``r̃(z)·n_z`` is the motion's normal component at constraint ``z``, a master's motion
    included, and the load's work ``F̃·r̃ = F·r``."""
    r, cs = assembled.conditions.rigid_field, assembled.contact
    if cs.transfer is None:
        return r
    return np.stack([cs.relative(ri) for ri in r])  # k ≤ 3 per body


def check_load_carried(assembled: Assembled) -> None:
    """Refuse a load the contacts cannot carry along the free rigid motions of the problem
    of ``assembled``.

    Parameters
    ----------
    assembled : Assembled
        The algebraic problem on one mesh (rotated frames at the constrained nodes), whose
        conditions have free rigid motions (``conditions.rigid_motions (k, 3)``, ``k ≥ 1``).

    Raises
    ------
    ProblemError
        If the load along the free motions cannot be balanced by contact forces
        ``Λ_z ≥ 0``, or only just (on the edge of their cone: no load along a motion the
        contacts hold one way only), naming the motion, the contact parts and the load.
    """
    space, cs = assembled.space, assembled.contact
    motions = assembled.conditions.rigid_motions
    r = motion_fields(assembled)  # (k, n_nodes, d)
    nodes, frames = assembled.frame_nodes, assembled.frames
    if isinstance(cs, FaceContactSet):  # the solver's variables (k ≤ 6)
        y = np.stack([cs.unknowns(ri.ravel()) for ri in r])
    else:
        y = np.stack([to_frames(ri.ravel(), nodes, frames) for ri in r])  # k ≤ 3
    # a load beyond DATA_MAX (E extreme, the loads with it) is divided by a power of 2 near
    # its size (exact), so that the norms below do not overflow
    big = np.abs(assembled.F).max(initial=0.0)
    e = int(np.frexp(big)[1]) if big > DATA_MAX else 0
    F = np.ldexp(assembled.F, -e)
    work = y @ F  # (k,)
    scale = np.abs(y) @ np.abs(F)  # (k,)
    along = _along(cs, r, y)  # (k, n_constraints)
    parts = list(cs.parts)
    size = float(np.linalg.norm(scale))

    def misfit(w: np.ndarray) -> float:
        return float(nnls(along, w)[1])

    if misfit(work) > LOAD_RTOL * size:
        # the motion along which the contact forces cannot balance the load
        lam = nnls(along, work)[0]
        residual = work - along @ lam
        i = int(np.argmax(np.abs(residual)))
        m = np.asarray(residual) @ motions
        m = m if np.abs(m).max() > 0 else motions[i]
        raise ProblemError(
            f"the load pulls the body away from its contacts: along the free rigid motion "
            f"{describe_motion(space.mesh, m)} (held by no Dirichlet part or Roller) the "
            f"contact parts {parts} can only push, and no contact forces Λ_z ≥ 0 balance "
            f"the load's work {np.ldexp(work, e)[i]:.6g} along it. Reverse the load, or hold "
            "the motion with a Dirichlet part or a Roller (docs/method.md, *Force control*)"
        )
    # the load must lie inside the cone of contact forces, not on its edge: a motion the
    # contacts resist one way only, with no load along it, leaves the position undetermined
    step = STRICT_RTOL * size
    for i in range(motions.shape[0]):  # k ≤ 3 free motions
        for sign in (1.0, -1.0):
            moved = work + sign * step * np.eye(motions.shape[0])[i]
            if size == 0.0 or misfit(moved) > LOAD_RTOL * size:
                raise ProblemError(
                    f"the load does not press the body onto its contacts along the rigid "
                    f"motion {describe_motion(space.mesh, motions[i])}, which only the "
                    f"contact parts {parts} hold, and only one way (load along it "
                    f"{np.ldexp(work, e)[i]:.6g}): the body's position along it is not "
                    "determined. Hold it with a Dirichlet part or a Roller, or load the body "
                    "towards the obstacle (docs/method.md, *Force control*)"
                )


def initial_active_set(assembled: Assembled) -> np.ndarray:
    """The first active set of PDAS for a semi-coercive body: the constraints of least gap
    (the first points of contact) if their directions hold every free rigid motion, else
    every constraint (the contact closed). Either makes the first system regular where
    the empty set leaves the free motions singular (docs/method.md, *Force control*).

    Returns
    -------
    (k,) bool array over the constraints of ``assembled.contact``.
    """
    cs = assembled.contact
    gap = cs.gap
    first = gap <= gap.min() + 1e-12 * max(np.abs(gap).max(), np.finfo(float).tiny)
    motions = assembled.conditions.rigid_motions
    if isinstance(cs, FaceContactSet):
        along = _along(
            cs, None, np.stack([cs.unknowns(ri.ravel()) for ri in motion_fields(assembled)])
        )[:, first]
    else:
        r = motion_fields(assembled)[:, cs.nodes[first]]
        along = np.einsum("knc,nc->kn", r, cs.normal[first])
    s = np.linalg.svd(along, compute_uv=False)
    if s.size == motions.shape[0] and s.min() > 1e-9 * max(s.max(), 1.0):
        return first
    return np.ones(cs.size, dtype=bool)


def _along(cs, r: np.ndarray | None, y: np.ndarray) -> np.ndarray:
    """``(k, n_constraints)`` each free motion's component along each constraint: ``r(z)·n_z``
    of the motions at the nodes ``r (k, n_nodes, 2)``; on faces the bounded unknowns of the
    motions in the solver's variables ``y (k, n_dofs)`` (``ỹ_dof``: the transformed basis's
    coefficients of ``r·n_z``, against which the multipliers ``Λ̃ ≥ 0`` work)."""
    if isinstance(cs, FaceContactSet):
        return y[:, cs.dof]
    return np.einsum("knc,nc->kn", r[:, cs.nodes], cs.normal)
