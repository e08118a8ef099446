"""The discrete frictional contact problem in node frames: its data, checks and KKT residuals.

At every frictional contact node ``i`` the system has a normal DOF ``normal[i]`` (``x = u·n``)
and ``d − 1`` tangential DOFs ``tangent[i]`` (``x = u·t_j``, the node frame
``[n t_1 … t_{d−1}]``); in 2D one, ``tangent (m, 1)``, the DOF the 2D kernel reads as
:attr:`FrictionProblem.tangent_2d` ``(m,)``. The multipliers are the residuals of these
rows, ``Λ = F − K x`` (``Λ_n ≥ 0`` is the contact force; the obstacle acts on the body with
``−Λ``). The laws (docs/method.md, *Friction: the algebraic problem and its solver*):

- normal: ``x_n ≤ g``, ``Λ_n ≥ 0``, ``Λ_n (x_n − g) = 0``;
- tangential: ``|Λ_t| ≤ s``; ``|Λ_t| < s ⇒ x_t = x_ref`` (stick); ``|Λ_t| = s ⇒
  x_t − x_ref = α Λ_t`` with ``α ≥ 0`` (slip), where the slip bound ``s`` is that of each
  node's friction law (:mod:`.laws`: e.g. the Tresca bound, on every node or only on nodes in
  contact, or ``F Λ_n`` for Coulomb); laws may differ from node to node.

:func:`check_friction` turns the problem's arrays and laws into the :class:`FrictionProblem`
that :func:`~.newton.solve_friction` solves, or raises a :class:`ValueError` naming the
argument;
:func:`friction_kkt` measures how far a point is from satisfying both laws.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..kkt import contact_scale, force_scale, normal_law_columns
from ..qp import BoundQP, _index_array, check_qp, check_vector
from ..ranks import Ranks
from ..sparse import as_csr
from .laws import LawGroups, check_laws

__all__ = ["FrictionKKT", "FrictionProblem", "check_friction", "friction_kkt"]


@dataclass(frozen=True)
class FrictionProblem:
    """Checked data of the frictional contact problem.

    Attributes
    ----------
    qp : BoundQP
        ``K``, ``F`` and the Dirichlet data; its constrained DOFs are ``normal`` then
        ``tangent``, its bounds ``gap`` then ``reference`` (the values these DOFs take when
        held: in contact, and in stick).
    normal : (m,) int64 array
        The normal DOF of each frictional contact node.
    tangent : (m, d − 1) int64 array
        Its tangential DOFs, one per tangent ``t_j`` of the node frame (in 2D ``(m, 1)``).
    gap : (m,) float array
        ``g``: the bound ``x_n ≤ g``.
    reference : (m,) float array
        ``x_ref``: the tangential displacement of no slip (the previous load step's).
    friction : LawGroups
        The friction law of each node and its weight (:mod:`.laws`).
    """

    qp: BoundQP
    normal: np.ndarray
    tangent: np.ndarray
    gap: np.ndarray
    reference: np.ndarray
    friction: LawGroups

    @property
    def tangent_2d(self) -> np.ndarray:
        """``(m,)`` the one tangential DOF of each node, ``tangent[:, 0]``: the door of the 2D
        kernel (the Tresca and Coulomb laws on a line, docs/method.md, *Friction: the
        algebraic problem and its solver*)."""
        return self.tangent[:, 0]

    @property
    def m(self) -> int:
        """Number of frictional contact nodes."""
        return self.normal.size

    @property
    def symmetric(self) -> bool:
        """Whether every law in play has a bound independent of ``Λ_n`` (symmetric
        systems)."""
        return self.friction.symmetric

    def slip_bound(self, normal_force: np.ndarray, in_contact: np.ndarray) -> np.ndarray:
        """The slip bound ``s (m,)`` of each node's law at ``Λ_n = normal_force``."""
        return self.friction.slip_bound(normal_force, in_contact)

    def on_ranks(self, ranks: Ranks) -> FrictionProblem:
        """The same problem with ``K`` split by rows over ``ranks`` (each rank's ``K`` holds
        its own rows, the other rows empty; :meth:`.BoundQP.on_ranks` checks it)."""
        return replace(self, qp=self.qp.on_ranks(ranks))


def check_friction(
    K: object,
    F: object,
    normal: object,
    tangent: object,
    gap: object,
    dirichlet: object = None,
    dirichlet_values: object = None,
    *,
    laws: object,
    weight: object,
    law_index: object = None,
    reference: object = None,
) -> FrictionProblem:
    """Check and normalise the data of the frictional contact problem.

    Parameters
    ----------
    K : scipy sparse matrix, shape (n, n)
        Symmetric, positive definite on the non-Dirichlet DOFs, with the contact nodes'
        DOFs rotated into their (normal, tangential) frames.
    F : (n,) float array
        Load vector (force units).
    normal : (m,) int array or (n,) bool mask
        The normal DOF of each frictional contact node (as a mask, nodes in increasing DOF
        order).
    tangent : (m, d − 1) int array, or (m,) int array or (n,) bool mask (d = 2)
        Its tangential DOFs, one column per tangent of the node frame ``[n t_1 … t_{d−1}]``;
        a 1-D tangent is the one column of 2D. Only ``d = 2`` is solved today.
    gap : float or (m,) float array
        ``g``: the bound ``x_n ≤ g`` (length units).
    dirichlet : (n_d,) int array or (n,) bool mask, optional
    dirichlet_values : float, (n_d,) or (n,) float array, optional
        Default 0.
    laws : FrictionLaw or sequence of FrictionLaw
        The friction laws (:class:`~.laws.FrictionLaw`, e.g.
        :class:`signorini.problem.friction.Tresca`, :class:`~signorini.problem.friction.Coulomb`).
    weight : float or (m,) float array
        Each node's weight for its law (Tresca: the slip bound ``s ≥ 0`` in force units, e.g.
        ``∫ s ψ_z ds``; Coulomb: the coefficient ``F ≥ 0``).
    law_index : (m,) int array, optional
        The law of each node, an index into ``laws``, ``-1`` for none (no friction force);
        default the first law at every node.
    reference : float or (m,) float array, optional
        ``x_ref``: the tangential displacement of no slip (default 0; the previous load step's
        in a quasi-static path, so that the law acts on the slip increment).

    Raises
    ------
    ValueError
        Naming the argument: wrong shape or type, non-finite values, indices out of range or
        repeated, a DOF both normal and tangential or both contact and Dirichlet, a negative
        weight, something else than friction laws, a law index out of range, a tangent
        that is not ``(m, d − 1)``.
    NotImplementedError
        For ``d − 1 > 1`` tangential DOFs per node (3D friction).
    """
    K = as_csr(K, "K")
    n = K.shape[0]
    normal = _index_array(normal, n, "normal")
    tangent = _tangent_basis(tangent, n, normal.size)
    _disjoint(normal, tangent.ravel(), "normal", "tangent")
    if dirichlet is not None:
        d = _index_array(dirichlet, n, "dirichlet")
        _disjoint(normal, d, "normal", "dirichlet")
        _disjoint(tangent.ravel(), d, "tangent", "dirichlet")
    m = normal.size
    g = check_vector(gap, m, "gap", allow_scalar=True)
    ref = (
        np.zeros(m)
        if reference is None
        else check_vector(reference, m, "reference", allow_scalar=True)
    )
    friction = check_laws(laws, law_index, weight, m)
    constrained = np.concatenate([normal, tangent[:, 0]])
    qp = check_qp(K, F, constrained, np.concatenate([g, ref]), dirichlet, dirichlet_values)
    return FrictionProblem(qp, normal, tangent, g, ref, friction)


def _tangent_basis(tangent: object, n: int, m: int) -> np.ndarray:
    """The tangential DOFs ``(m, d − 1)`` of :func:`check_friction`: a 1-D ``tangent`` (indices
    or a mask) is the one column of ``d = 2``; a 2-D one is taken as it is."""
    if np.ndim(tangent) == 2:
        tangent = np.asarray(tangent)
        if tangent.shape[0] != m or tangent.shape[1] < 1:
            raise ValueError(
                f"tangent must be (m, d - 1) = ({m}, d - 1), one row of tangential DOFs per "
                f"contact node, got {tangent.shape}"
            )
        columns = tangent.shape[1]
        if columns > 1:
            raise NotImplementedError(
                f"tangent has {columns} tangential DOFs per node (d = {columns + 1}): the "
                "frictional solver handles d = 2, one tangential DOF per node"
            )
        tangent = tangent[:, 0]
    elif np.ndim(tangent) > 2:
        raise ValueError(f"tangent must be (m,) or (m, d - 1), got shape {np.shape(tangent)}")
    tangent = _index_array(tangent, n, "tangent")
    if tangent.size != m:
        raise ValueError(
            f"tangent must name one DOF per contact node: {tangent.size} DOFs for {m} normal DOFs"
        )
    return tangent[:, None]


def _disjoint(a: np.ndarray, b: np.ndarray, name_a: str, name_b: str) -> None:
    common = np.intersect1d(a, b)
    if common.size:
        raise ValueError(
            f"{name_a} and {name_b} share {common.size} DOFs (first: {common[0]}); a DOF is "
            "either normal, tangential or Dirichlet"
        )


@dataclass(frozen=True)
class FrictionKKT:
    """Relative residuals of both laws at a point (see :func:`friction_kkt`).

    The scales are those of :class:`~.kkt.KKTResiduals`: displacements relative to
    ``disp_scale``, contact forces (normal and tangential) to ``contact_force_scale``.

    Attributes
    ----------
    primal, dual, complementarity : float
        The normal law: the largest penetration, wrong-signed contact force, and
        ``max min(|Λ_n|, |x_n − g|)``, as in :class:`~.kkt.KKTResiduals`.
    tangential_bound : float
        ``max (|Λ_t| − s)^+``: the friction force beyond its bound.
    tangential_complementarity : float
        ``max min(stick, slip)`` over the nodes, with the stick residual ``|x_t − x_ref|`` and
        the slip residual ``max(| |Λ_t| − s |, (−Λ_t (x_t − x_ref))^+)`` (the force at its
        bound and the slip along ``Λ_t``, the latter relative to both scales).
    stationarity : float
        ``max |F − K x|`` over the free rows without a contact DOF, over ``force_scale``.
    dirichlet : float
    force_scale, disp_scale, contact_force_scale : float
    """

    primal: float
    dual: float
    complementarity: float
    tangential_bound: float
    tangential_complementarity: float
    stationarity: float
    dirichlet: float
    force_scale: float
    disp_scale: float
    contact_force_scale: float

    @property
    def max(self) -> float:
        """The largest of the seven relative residuals."""
        return max(
            self.primal,
            self.dual,
            self.complementarity,
            self.tangential_bound,
            self.tangential_complementarity,
            self.stationarity,
            self.dirichlet,
        )

    def columns(self) -> dict[str, float]:
        """The seven relative residuals as history columns: those of
        :meth:`~.kkt.KKTResiduals.columns` and ``kkt_tangential_bound``,
        ``kkt_tangential_complementarity``."""
        return {
            **normal_law_columns(self),
            "kkt_tangential_bound": self.tangential_bound,
            "kkt_tangential_complementarity": self.tangential_complementarity,
        }


def friction_kkt(
    problem: FrictionProblem, x: np.ndarray, in_contact: np.ndarray | None = None
) -> FrictionKKT:
    """Relative KKT residuals of ``x`` for both laws (checked data, no checks).

    Parameters
    ----------
    problem : FrictionProblem
    x : (n,) float array
    in_contact : (m,) bool array, optional
        The nodes in contact for laws that act only there (the solver's final contact set);
        default ``Λ_n > 0``.

    Returns
    -------
    FrictionKKT
    """
    qp = problem.qp
    K, F, n_dof, t_dof = qp.K, qp.F, problem.normal, problem.tangent_2d
    Kx = qp.matvec(x)
    r = F - Kx
    force = force_scale(K, F, x, Kx, ranks=qp.ranks)
    lam_n, lam_t = r[n_dof], r[t_dof]
    slack = x[n_dof] - problem.gap
    slide = x[t_dof] - problem.reference
    disp = max(
        np.abs(x).max(initial=0.0),
        np.abs(qp.dirichlet_values).max(initial=0.0),
        np.abs(problem.gap[slack >= 0]).max(initial=0.0),
        np.abs(problem.reference).max(initial=0.0),
    )
    disp = disp if disp > 0 else 1.0
    total = float(np.maximum(lam_n, 0.0).sum())
    fc = contact_scale(K, F, x, n_dof, total, force, qp.ranks)
    s = problem.slip_bound(lam_n, lam_n > 0 if in_contact is None else in_contact)
    stick = np.abs(slide) / disp
    wrong_way = np.maximum(-lam_t * slide, 0.0) / (fc * disp)
    slip = np.maximum(np.abs(np.abs(lam_t) - s) / fc, wrong_way)
    other = np.ones(x.size, dtype=bool)
    other[qp.constrained] = False
    other[qp.dirichlet] = False
    return FrictionKKT(
        primal=float(np.maximum(slack, 0.0).max(initial=0.0) / disp),
        dual=float(np.maximum(-lam_n, 0.0).max(initial=0.0) / fc),
        complementarity=float(np.minimum(np.abs(lam_n) / fc, np.abs(slack) / disp).max(initial=0)),
        tangential_bound=float(np.maximum(np.abs(lam_t) - s, 0.0).max(initial=0.0) / fc),
        tangential_complementarity=float(np.minimum(stick, slip).max(initial=0.0)),
        stationarity=float(np.abs(r[other]).max(initial=0.0) / force),
        dirichlet=float(np.abs(x[qp.dirichlet] - qp.dirichlet_values).max(initial=0.0) / disp),
        force_scale=float(force),
        disp_scale=float(disp),
        contact_force_scale=float(fc),
    )
