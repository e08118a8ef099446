"""Frictional contact in three dimensions: the disc law and its semismooth Newton method.

At every frictional contact node ``i`` a normal DOF ``normal[i]`` and two tangential DOFs
``tangent[i] = (t_1, t_2)``, the node frame ``[n t_1 t_2]`` of
:mod:`signorini.contact.node_frames3d`; ``Λ = F − K x`` on these rows (as in :mod:`.kkt`).
The laws (docs/method.md, *Friction in three dimensions: the disc law*):

- normal: ``x_n ≤ g``, ``Λ_n ≥ 0``, ``Λ_n (x_n − g) = 0``;
- tangential: ``‖Λ_t‖ ≤ s``; ``‖Λ_t‖ < s ⇒ x_t = x_ref`` (stick); ``‖Λ_t‖ = s ⇒
  x_t − x_ref = α Λ_t``, ``α ≥ 0`` (slip), with ``s`` the node's law's bound
  (:mod:`.laws`: Tresca's given bound, Coulomb's ``F Λ_n``).

They are the equations ``Λ_n = max(0, μ)``, ``max(s, ‖ξ‖) Λ_t = s ξ`` with ``μ = Λ_n +
c (x_n − g)``, ``ξ = Λ_t + c (x_t − x_ref)`` and ``s`` the bound at ``μ``, i.e. ``Λ_t`` the
projection of ``ξ`` onto the ball of radius ``s`` (Hüeber, Stadler, Wohlmuth [1]_, (3.7)).
:func:`solve_disc` applies the semismooth Newton method to them: a node is inactive
(``μ ≤ 0`` and a law acting in contact only, or ``s = 0``: ``Λ_t = 0``), sticks (``‖ξ‖ < s``:
``x_t = x_ref``) or slips (``‖ξ‖ ≥ s``), where the generalised derivative of the ball's
projection is linearised with ``Λ_t`` replaced by ``Λ̃_t = s Λ_t / max(s, ‖Λ_t‖)``, the
damping of [1]_ (section 4) that keeps the slip block's symmetric part positive. The 2D
solver (:mod:`.newton`) is untouched: this module shares with it the law protocol and the
scales of the KKT residuals only.

References
----------
.. [1] S. Hüeber, G. Stadler, B. I. Wohlmuth, A primal-dual active set algorithm for
   three-dimensional contact problems with Coulomb friction, SIAM J. Sci. Comput. 30 (2008)
   572-596.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..backends.selection import make_solver
from ..backends.solvers import SolverFactory
from ..kkt import contact_scale, force_scale
from ..qp import BoundQP, _index_array, check_qp, check_vector
from ..sparse import as_csr
from .kkt import FrictionKKT, _disjoint
from .laws import LawGroups, check_laws
from .result import INACTIVE, SLIP, STICK

__all__ = ["DiscProblem", "DiscResult", "check_disc", "disc_kkt", "solve_disc"]

#: a Newton step below this times ``max |x|`` is round-off: the iteration has converged
ROUND_OFF = 1e-13
#: the largest relative KKT residual accepted at a round-off step (that of the 2D solver,
#: :class:`~.newton.FrictionOptions`)
ACCEPT = 1e-8


@dataclass(frozen=True)
class DiscProblem:
    """Checked data of the 3D frictional contact problem (module docstring).

    Attributes
    ----------
    qp : BoundQP
        ``K``, ``F``, the Dirichlet data; its constrained DOFs the normal ones, bounds ``gap``.
    normal : (m,) int64 array
    tangent : (m, 2) int64 array
        ``-1`` where the tangent is held (a roller through the node): the law then acts on
        the other component alone, this one's force and slip are 0.
    gap : (m,) float array
    reference : (m, 2) float array
        ``x_ref`` per node and tangent.
    friction : LawGroups
    """

    qp: BoundQP
    normal: np.ndarray
    tangent: np.ndarray
    gap: np.ndarray
    reference: np.ndarray
    friction: LawGroups

    @property
    def m(self) -> int:
        """Number of frictional contact nodes."""
        return self.normal.size


def check_disc(
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
) -> DiscProblem:
    """Check the data of the 3D frictional problem (as :func:`.kkt.check_friction`, with
    ``tangent (m, 2)`` and ``reference`` a scalar or ``(m, 2)``).

    Raises
    ------
    ValueError
        Naming the argument: shapes, non-finite values, indices out of range or shared
        between normal, tangential and Dirichlet DOFs, bad laws or weights.
    """
    K = as_csr(K, "K")
    n = K.shape[0]
    normal = _index_array(normal, n, "normal")
    m = normal.size
    if np.shape(tangent) != (m, 2):
        raise ValueError(
            f"tangent must be (m, 2) = ({m}, 2), the DOFs of t_1 and t_2 per contact node, "
            f"got shape {np.shape(tangent)}"
        )
    tangent = np.asarray(tangent)
    if tangent.size and (not np.issubdtype(tangent.dtype, np.integer) or tangent.min() < -1):
        raise ValueError("tangent must hold DOF indices, or -1 for a held tangent")
    tangent = tangent.astype(np.int64)
    present = tangent[tangent >= 0]
    _index_array(present, n, "tangent")
    _disjoint(normal, present, "normal", "tangent")
    if dirichlet is not None:
        d = _index_array(dirichlet, n, "dirichlet")
        _disjoint(normal, d, "normal", "dirichlet")
        _disjoint(present, d, "tangent", "dirichlet")
    g = check_vector(gap, m, "gap", allow_scalar=True)
    if reference is None:
        ref = np.zeros((m, 2))
    elif np.ndim(reference) == 0:
        ref = np.full((m, 2), float(reference))
    else:
        ref = check_vector(np.ravel(reference), 2 * m, "reference").reshape(m, 2)
        if np.shape(reference) != (m, 2):
            raise ValueError(f"reference must be (m, 2) = ({m}, 2), got {np.shape(reference)}")
    if not np.isfinite(ref).all():
        raise ValueError("reference must be finite")
    friction = check_laws(laws, law_index, weight, m)
    qp = check_qp(K, F, normal, g, dirichlet, dirichlet_values)
    return DiscProblem(qp, normal, tangent, g, ref, friction)


def _tangential(v: np.ndarray, tangent: np.ndarray) -> np.ndarray:
    """``(m, 2)`` the entries of ``v (n,)`` at the tangential DOFs, 0 where held (-1)."""
    return np.where(tangent >= 0, v[np.maximum(tangent, 0)], 0.0)


def disc_kkt(
    problem: DiscProblem, x: np.ndarray, in_contact: np.ndarray | None = None
) -> FrictionKKT:
    """Relative KKT residuals of ``x`` for both laws, scaled as :func:`.kkt.friction_kkt`
    (the tangential ones with ``‖·‖`` of the vectors in ``[t_1 t_2]``; the slip residual's
    wrong way is ``(‖Λ_t‖ ‖x_t − x_ref‖ − Λ_t·(x_t − x_ref))``, zero when they are parallel).
    """
    qp = problem.qp
    Kx = qp.matvec(x)
    r = qp.F - Kx
    force = force_scale(qp.K, qp.F, x, Kx, ranks=qp.ranks)
    lam_n, lam_t = r[problem.normal], _tangential(r, problem.tangent)
    slack = x[problem.normal] - problem.gap
    slide = _tangential(x, problem.tangent) - problem.reference * (problem.tangent >= 0)
    disp = max(
        np.abs(x).max(initial=0.0),
        np.abs(qp.dirichlet_values).max(initial=0.0),
        np.abs(problem.gap[slack >= 0]).max(initial=0.0),
        np.abs(problem.reference).max(initial=0.0),
    )
    disp = disp if disp > 0 else 1.0
    total = float(np.maximum(lam_n, 0.0).sum())
    fc = contact_scale(qp.K, qp.F, x, problem.normal, total, force, qp.ranks)
    s = problem.friction.slip_bound(lam_n, lam_n > 0 if in_contact is None else in_contact)
    norm_lam, norm_slide = np.linalg.norm(lam_t, axis=1), np.linalg.norm(slide, axis=1)
    stick = norm_slide / disp
    wrong_way = (norm_lam * norm_slide - np.sum(lam_t * slide, axis=1)) / (fc * disp)
    slip = np.maximum(np.abs(norm_lam - s) / fc, np.maximum(wrong_way, 0.0))
    other = np.ones(x.size, dtype=bool)
    other[problem.normal] = False
    other[problem.tangent[problem.tangent >= 0]] = False
    other[qp.dirichlet] = False
    return FrictionKKT(
        primal=float(np.maximum(slack, 0.0).max(initial=0.0) / disp),
        dual=float(np.maximum(-lam_n, 0.0).max(initial=0.0) / fc),
        complementarity=float(np.minimum(np.abs(lam_n) / fc, np.abs(slack) / disp).max(initial=0)),
        tangential_bound=float(np.maximum(norm_lam - s, 0.0).max(initial=0.0) / fc),
        tangential_complementarity=float(np.minimum(stick, slip).max(initial=0.0)),
        stationarity=float(np.abs(r[other]).max(initial=0.0) / force),
        dirichlet=float(np.abs(x[qp.dirichlet] - qp.dirichlet_values).max(initial=0.0) / disp),
        force_scale=float(force),
        disp_scale=float(disp),
        contact_force_scale=float(fc),
    )


@dataclass(frozen=True)
class DiscResult:
    """The answer of :func:`solve_disc`.

    Attributes
    ----------
    x : (n,) float array
    normal_force : (m,) float array
        ``Λ_n``.
    tangential_force : (m, 2) float array
        ``Λ_t`` in ``[t_1 t_2]``.
    state : (m,) int8 array
        :data:`~.result.INACTIVE`, :data:`~.result.STICK` or :data:`~.result.SLIP`.
    iterations : int
        Newton steps (linear solves).
    kkt : FrictionKKT
    backend : str
        The LU factorization's backend (``"pardiso"`` or ``"superlu"``).
    n_analyses : int
        Its symbolic analyses: 1, the steps' matrices sharing one pattern.
    """

    x: np.ndarray
    normal_force: np.ndarray
    tangential_force: np.ndarray
    state: np.ndarray
    iterations: int
    kkt: FrictionKKT
    backend: str = "superlu"
    n_analyses: int = 0


def solve_disc(
    problem: DiscProblem,
    *,
    x0: np.ndarray | None = None,
    c: float | None = None,
    max_iter: int = 60,
    kkt_tol: float = 1e-12,
    solver: SolverFactory | None = None,
) -> DiscResult:
    """Semismooth Newton for the disc law (module docstring; docs/method.md, *Friction in
    three dimensions*): each step solves the linearised equations of the current node
    states with the equilibrium ``K x + E Λ = F`` in ``(x_free, Λ_n, Λ_t)`` by sparse LU
    (``solver``'s general factorization, default PARDISO's where it loads, else SuperLU's;
    the analysis reused while the pattern repeats);
    it stops when the states repeat and the KKT residuals are at most ``kkt_tol``, or the
    step is round-off (:data:`ROUND_OFF`) with residuals at most :data:`ACCEPT`.

    ``c`` defaults to the mean diagonal of ``K`` over the normal DOFs.

    Raises
    ------
    ValueError
        For ``max_iter < 1``, ``kkt_tol`` or ``c`` not positive, a bad ``x0``.
    RuntimeError
        If the KKT residuals are above ``kkt_tol`` after ``max_iter`` steps.
    """
    if isinstance(max_iter, bool) or not isinstance(max_iter, (int, np.integer)) or max_iter < 1:
        raise ValueError(f"max_iter must be a positive integer, got {max_iter!r}")
    if not kkt_tol > 0:
        raise ValueError(f"kkt_tol must be positive, got {kkt_tol!r}")
    qp, m = problem.qp, problem.m
    n = qp.n
    c = float(np.mean(qp.diagonal()[problem.normal])) if c is None and m else (c or 1.0)
    if not c > 0:
        raise ValueError(f"c must be positive, got {c!r}")
    x = np.zeros(n) if x0 is None else check_vector(x0, n, "x0").copy()
    x[qp.dirichlet] = qp.dirichlet_values
    free = np.ones(n, dtype=bool)
    free[qp.dirichlet] = False
    K_ff = qp.K[free][:, free].tocsr()
    b = qp.F[free] - qp.K[free][:, qp.dirichlet] @ qp.dirichlet_values
    r = qp.F - qp.matvec(x)
    lam_n, lam_t = r[problem.normal].copy(), _tangential(r, problem.tangent)
    lu = make_solver(solver, symmetric=False)
    try:
        return _newton(problem, (x, lam_n, lam_t), (K_ff, b, free), (c, max_iter, kkt_tol), lu)
    finally:
        lu.close()


def _newton(problem, start, system, settings, lu) -> DiscResult:
    """The iteration of :func:`solve_disc` from ``start = (x, Λ_n, Λ_t)`` on ``system =
    (K_ff, b, free)``, ``settings = (c, max_iter, kkt_tol)``, each step's LU by ``lu``."""
    (x, lam_n, lam_t), (K_ff, b, free), (c, max_iter, kkt_tol) = start, system, settings
    law, m, nf = problem.friction, problem.m, K_ff.shape[0]
    where = np.full(x.size, -1, dtype=np.int64)
    where[free] = np.arange(nf)
    jn = where[problem.normal]  # (m,) free indices
    jt = np.where(problem.tangent >= 0, where[np.maximum(problem.tangent, 0)], -1)  # (m, 2)
    # the contact forces as unknowns: E places Λ_n, Λ_t on their rows (held tangents: none)
    cols = np.concatenate([jn, jt.ravel()])
    on = cols >= 0
    E = sp.csr_matrix((np.ones(on.sum()), (cols[on], np.arange(3 * m)[on])), shape=(nf, 3 * m))
    reference = problem.reference * (problem.tangent >= 0)
    states_seen = None
    for it in range(1, max_iter + 1):
        xf = x[free]
        mu = lam_n + c * (x[problem.normal] - problem.gap)
        contact = mu > 0
        s = law.slip_bound(np.maximum(mu, 0.0), contact)
        ds = np.where(contact, law.bound_derivative(contact), 0.0)
        xi = lam_t + c * (_tangential(x, problem.tangent) - reference)
        norm_xi = np.linalg.norm(xi, axis=1)
        rubs = (s > 0) & (contact | law.everywhere)
        stick = rubs & (norm_xi < s)
        slip = rubs & ~stick
        state = np.where(stick, STICK, np.where(slip, SLIP, INACTIVE)).astype(np.int8)
        A, R = _linearised(
            problem, x, (lam_n, lam_t), c, (contact, stick, slip), (s, ds, xi), (jn, jt), nf
        )
        J = sp.bmat([[K_ff, E], [A[:, :nf], A[:, nf:]]], format="csr")
        res = np.concatenate([K_ff @ xf + E @ np.concatenate([lam_n, lam_t.ravel()]) - b, R])
        step = _lu_step(lu, J, -res)
        x[free] = xf + step[:nf]
        lam_n = lam_n + step[nf : nf + m]
        lam_t = lam_t + step[nf + m :].reshape(m, 2)
        key = (contact.tobytes(), state.tobytes())
        kkt = disc_kkt(problem, x, contact)
        # converged: the states repeat, and the residuals are at kkt_tol or the step at
        # round-off (a system whose round-off floor is above kkt_tol)
        still = np.abs(step[:nf]).max(initial=0.0) <= ROUND_OFF * np.abs(x).max(initial=1.0)
        if key == states_seen and (kkt.max <= kkt_tol or (still and kkt.max <= ACCEPT)):
            return DiscResult(x, lam_n, lam_t, state, it, kkt, lu.backend, lu.n_analyses)
        states_seen = key
    raise RuntimeError(
        f"the 3D frictional Newton iteration did not reach kkt_tol = {kkt_tol:.1e} in "
        f"{max_iter} steps (largest relative KKT residual {kkt.max:.2e})"
    )


#: the largest relative residual of a Newton step's linear solve before a refinement step
STEP_RTOL = 1e-10


def _lu_step(lu, J: sp.csr_matrix, rhs: np.ndarray) -> np.ndarray:
    """``J⁻¹ rhs`` by the LU solver ``lu``, up to two steps of iterative refinement where the
    residual is above :data:`STEP_RTOL` of ``rhs`` (a perturbed pivot). ``J`` stores its
    whole diagonal, zeros on the rows of a contact node's constraint ``x_n = g`` included:
    :func:`_linearised` stores every entry a state may set, the ``Λ`` columns of the
    contact rows among them."""
    J.sum_duplicates()
    lu.factorize(J)
    step = lu.solve(rhs)
    scale = np.abs(rhs).max(initial=0.0)
    for _ in range(2):  # refinement steps
        r = rhs - J @ step
        if np.abs(r).max(initial=0.0) <= STEP_RTOL * scale:
            break
        step = step + lu.solve(r)
    return step


def _linearised(problem, x, lam, c, states, bound, columns, nf):
    """The rows ``A (3m, nf + 3m)`` and residuals ``R (3m,)`` of the linearised contact
    equations of the current states (rows: the normal ones, then ``t_1, t_2`` per node;
    columns: ``x_free``, then ``Λ_n``, then ``Λ_t`` node by node)."""
    (lam_n, lam_t), (contact, stick, slip), (s, ds, xi), (jn, jt) = lam, states, bound, columns
    m = problem.m
    absent = (jt < 0).ravel()  # held tangents: Λ_t = 0 on their rows, nothing else
    rows, cols, vals = [], [], []
    R = np.zeros(3 * m)
    nodes = np.arange(m)
    # normal: in contact x_n = g, else Λ_n = 0
    rows.append(nodes)
    cols.append(np.where(contact, jn, nf + nodes))
    vals.append(np.ones(m))
    R[:m] = np.where(contact, x[problem.normal] - problem.gap, lam_n)
    # tangential rows 3·: m + 2 i + k
    t_rows = m + 2 * nodes[:, None] + np.arange(2)  # (m, 2)
    lt_cols = nf + m + 2 * nodes[:, None] + np.arange(2)
    free_t = ~(stick | slip)
    for k in range(2):  # the two tangents
        rows.append(t_rows[:, k])
        cols.append(np.where(stick & (jt[:, k] >= 0), jt[:, k], lt_cols[:, k]))
        vals.append(np.where(stick | free_t, 1.0, 0.0))
    slide = _tangential(x, problem.tangent) - problem.reference * (jt >= 0)
    R[m:] = np.where(stick[:, None], slide, np.where(free_t[:, None], lam_t, 0.0)).ravel()
    # slip: C = ‖ξ‖ Λ_t − s ξ, dC = (‖ξ‖ − s) dΛ_t + Λ̃ vᵀ dξ − s c dx_t − ξ ds
    i = np.flatnonzero(slip)
    if i.size:
        xi_i, s_i = xi[i], s[i]
        norm = np.linalg.norm(xi_i, axis=1)
        v = xi_i / norm[:, None]
        lt = lam_t[i]
        damped = lt * (s_i / np.maximum(s_i, np.linalg.norm(lt, axis=1)))[:, None]
        outer = damped[:, :, None] * v[:, None, :]  # (k, 2, 2) Λ̃ vᵀ
        eye = np.eye(2)[None]
        d_lam = (norm - s_i)[:, None, None] * eye + outer
        d_x = c * (outer - s_i[:, None, None] * eye)
        r_rows = np.repeat(t_rows[i], 2, axis=1)  # (k, 4): rows a,a,b,b
        lam_cols = np.tile(lt_cols[i], 2)
        x_cols = np.tile(jt[i], 2)
        rows += [r_rows.ravel(), r_rows.ravel()]
        cols += [lam_cols.ravel(), x_cols.ravel()]
        vals += [d_lam.reshape(-1, 4).ravel(), d_x.reshape(-1, 4).ravel()]
        # the bound's derivative: s = s(μ), dμ = dΛ_n + c dx_n
        g_rows = t_rows[i].ravel()
        coef = -(xi_i * ds[i][:, None]).ravel()
        rows += [g_rows, g_rows]
        cols += [np.repeat(nf + i, 2), np.repeat(jn[i], 2)]
        vals += [coef, c * coef]
        R[t_rows[i].ravel()] = (norm[:, None] * lt - s_i[:, None] * xi_i).ravel()
    # every entry a state may set, as explicit zeros: the matrix of each step has one
    # pattern, so that the factorization's analysis is reused (docs/method.md, *Two bodies
    # in three dimensions: friction*, "The linear solves")
    every = np.column_stack([lt_cols, jt, nf + nodes, jn])  # (m, 6) columns of a row
    rows += [np.r_[nodes, nodes], np.repeat(t_rows, 6, axis=1).ravel()]
    cols += [np.r_[jn, nf + nodes], np.tile(every, (1, 2)).ravel()]
    vals += [np.zeros(2 * m), np.zeros(12 * m)]
    rows, cols, vals = (np.concatenate(a) for a in (rows, cols, vals))
    keep = (cols >= 0) & ~(absent[np.maximum(rows - m, 0)] & (rows >= m))
    held_rows = m + np.flatnonzero(absent)
    rows = np.concatenate([rows[keep], held_rows])
    cols = np.concatenate([cols[keep], nf + held_rows])
    vals = np.concatenate([vals[keep], np.ones(held_rows.size)])
    keep = np.ones(rows.size, dtype=bool)
    R[held_rows] = lam_t.ravel()[held_rows - m]
    A = sp.csr_matrix((vals[keep], (rows[keep], cols[keep])), shape=(3 * m, nf + 3 * m))
    return A, R
