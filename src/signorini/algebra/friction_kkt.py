"""The discrete frictional contact problem in node frames: its data, checks and KKT residuals.

At every frictional contact node ``i`` the system has a normal DOF ``normal[i]`` (``x = u·n``)
and a tangential DOF ``tangent[i]`` (``x = u·t``). The multipliers are the residuals of these
rows, ``Λ = F − K x`` (``Λ_n ≥ 0`` is the contact force; the obstacle acts on the body with
``−Λ``). The laws (docs/method.md, *Friction: the algebraic problem and its solver*):

- normal: ``x_n ≤ g``, ``Λ_n ≥ 0``, ``Λ_n (x_n − g) = 0``;
- tangential: ``|Λ_t| ≤ s``; ``|Λ_t| < s ⇒ x_t = x_ref`` (stick); ``|Λ_t| = s ⇒
  x_t − x_ref = α Λ_t`` with ``α ≥ 0`` (slip), where the slip bound ``s`` is the Tresca bound
  (on every node, or only on nodes in contact), or ``F Λ_n`` (Coulomb).

:func:`check_friction` turns the arguments of :func:`~.friction.solve_friction` into a
:class:`FrictionProblem` or raises a :class:`ValueError` naming the argument;
:func:`friction_kkt` measures how far a point is from satisfying both laws.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .kkt import force_scale
from .qp import BoundQP, _index_array, check_qp, check_vector
from .sparse import as_csr

__all__ = ["FrictionKKT", "FrictionProblem", "check_friction", "friction_kkt", "slip_bound"]

_SQRT_EPS = float(np.sqrt(np.finfo(np.float64).eps))

#: The friction laws :func:`check_friction` knows.
LAWS = ("tresca", "coulomb")


@dataclass(frozen=True)
class FrictionProblem:
    """Checked data of the frictional contact problem.

    Attributes
    ----------
    qp : BoundQP
        ``K``, ``F`` and the Dirichlet data; its constrained DOFs are ``normal`` then
        ``tangent``, its bounds ``gap`` then ``reference`` (the values these DOFs take when
        held: in contact, and in stick).
    normal, tangent : (m,) int64 arrays
        The normal and tangential DOF of each frictional contact node.
    gap : (m,) float array
        ``g``: the bound ``x_n ≤ g``.
    reference : (m,) float array
        ``x_ref``: the tangential displacement of no slip (the previous load step's).
    law : {"tresca", "coulomb"}
    weight : (m,) float array
        The Tresca bound ``s ≥ 0`` (force units) or the Coulomb coefficient ``F ≥ 0``.
    everywhere : bool
        Tresca only: the bound acts on every node, in contact or not (the classical problem).
    """

    qp: BoundQP
    normal: np.ndarray
    tangent: np.ndarray
    gap: np.ndarray
    reference: np.ndarray
    law: str
    weight: np.ndarray
    everywhere: bool = False

    @property
    def m(self) -> int:
        """Number of frictional contact nodes."""
        return self.normal.size


def check_friction(
    K: object,
    F: object,
    normal: object,
    tangent: object,
    gap: object,
    dirichlet: object,
    dirichlet_values: object,
    bound: object,
    coefficient: object,
    reference: object,
    everywhere: bool,
) -> FrictionProblem:
    """Check and normalise the data of the frictional contact problem.

    Exactly one of ``bound`` (Tresca) and ``coefficient`` (Coulomb) is given.

    Raises
    ------
    ValueError
        Naming the argument: wrong shape or type, non-finite values, indices out of range or
        repeated, a DOF both normal and tangential or both contact and Dirichlet, a negative
        bound or coefficient, both or neither law, ``everywhere`` with Coulomb.
    """
    K = as_csr(K, "K")
    n = K.shape[0]
    normal = _index_array(normal, n, "normal")
    tangent = _index_array(tangent, n, "tangent")
    if tangent.size != normal.size:
        raise ValueError(
            f"tangent must name one DOF per contact node: {tangent.size} DOFs for "
            f"{normal.size} normal DOFs"
        )
    _disjoint(normal, tangent, "normal", "tangent")
    if dirichlet is not None:
        d = _index_array(dirichlet, n, "dirichlet")
        _disjoint(normal, d, "normal", "dirichlet")
        _disjoint(tangent, d, "tangent", "dirichlet")
    m = normal.size
    g = check_vector(gap, m, "gap", allow_scalar=True)
    ref = (
        np.zeros(m)
        if reference is None
        else check_vector(reference, m, "reference", allow_scalar=True)
    )
    if (bound is None) == (coefficient is None):
        raise ValueError("give exactly one of bound (Tresca) and coefficient (Coulomb)")
    law, name = ("tresca", "bound") if coefficient is None else ("coulomb", "coefficient")
    weight = check_vector(bound if law == "tresca" else coefficient, m, name, allow_scalar=True)
    if (weight < 0).any():
        raise ValueError(f"{name} must be non-negative, got min {weight.min():.3g}")
    if everywhere and law == "coulomb":
        raise ValueError("tresca_everywhere applies to the Tresca law only")
    constrained = np.concatenate([normal, tangent])
    qp = check_qp(K, F, constrained, np.concatenate([g, ref]), dirichlet, dirichlet_values)
    return FrictionProblem(qp, normal, tangent, g, ref, law, weight, bool(everywhere))


def _disjoint(a: np.ndarray, b: np.ndarray, name_a: str, name_b: str) -> None:
    common = np.intersect1d(a, b)
    if common.size:
        raise ValueError(
            f"{name_a} and {name_b} share {common.size} DOFs (first: {common[0]}); a DOF is "
            "either normal, tangential or Dirichlet"
        )


def slip_bound(
    problem: FrictionProblem, multiplier_n: np.ndarray, in_contact: np.ndarray
) -> np.ndarray:
    """The slip bound ``s (m,)`` of each node: Tresca's ``s`` (times ``in_contact`` unless
    ``everywhere``), or Coulomb's ``F max(Λ_n, 0)``."""
    if problem.law == "coulomb":
        return problem.weight * np.maximum(multiplier_n, 0.0)
    return problem.weight if problem.everywhere else problem.weight * in_contact


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


def friction_kkt(
    problem: FrictionProblem, x: np.ndarray, in_contact: np.ndarray | None = None
) -> FrictionKKT:
    """Relative KKT residuals of ``x`` for both laws (checked data, no checks).

    Parameters
    ----------
    problem : FrictionProblem
    x : (n,) float array
    in_contact : (m,) bool array, optional
        The nodes where the Tresca bound acts when it does not act everywhere (the solver's
        final contact set); default ``Λ_n > 0``. Not used by Coulomb.

    Returns
    -------
    FrictionKKT
    """
    qp = problem.qp
    K, F, n_dof, t_dof = qp.K, qp.F, problem.normal, problem.tangent
    r = F - K @ x
    force = force_scale(K, F, x)
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
    fc = total if total > _SQRT_EPS * force else force
    s = slip_bound(problem, lam_n, lam_n > 0 if in_contact is None else in_contact)
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
