"""η4 and η8 with friction on the faces of Γ_C (estimator/friction_faces3d.py; docs/method.md,
*Three dimensions: the frictional estimator terms on faces*): zero friction gives the
frictionless estimator, full stick gives η8 = 0, the friction stress enters η4 with the sign
that balances σ_t, η8 agrees with a dense quadrature written here from the solution's nodal
data, and on partial-slip-3d it sits on the faces of the stick–slip transition."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

import signorini.estimator.contact_faces3d as contact_faces3d
from signorini.contact.solution import INACTIVE, SLIP, STICK, solve
from signorini.estimator.friction_faces3d import eta8_parts, friction_faces
from signorini.estimator.residual import estimate
from signorini.fem.material import Material
from signorini.mesh.builders3d import box
from signorini.problem.conditions import Contact, Dirichlet, Neumann
from signorini.problem.friction_laws import Coulomb, Tresca
from signorini.problem.obstacles3d import HalfSpace
from signorini.problem.problem import ContactProblem

MATERIAL = Material.from_young(1.0, 0.3)
ETA4, ETA8 = 3, 7  # rows of Estimate.eta2_cell


def _block(law, shift=(0.004, 0.002), n: int = 2) -> ContactProblem:
    """box(n) on the half-space z ≥ 0 (condition (b), α = 0.2), its top moved by
    ``(shift, −0.01)``, the friction law ``law`` on the bottom."""
    mesh = box(n, n, n)
    cond = {p: Neumann((0.0, 0.0, 0.0)) for p in mesh.part_names}
    contact = Contact(obstacle=HalfSpace([0, 0, 0], [0, 0, 1]), friction=law, face_alpha=0.2)
    cond.update(z1=Dirichlet((shift[0], shift[1], -0.01)), z0=contact)
    return ContactProblem(mesh, MATERIAL, cond)


@cache
def _solved(law, path: bool = False):
    """The sheared block (with ``path``: pressed first, then sheared from there)."""
    previous = None
    if path:
        press = _block(law, shift=(0.0, 0.0))
        previous = solve(press, press.mesh)
    problem = _block(law)
    return previous, solve(problem, problem.mesh, previous=previous)


def test_zero_friction_gives_the_frictionless_estimator():
    _, plain = _solved(None)
    _, zero = _solved(Tresca(0.0))
    a, b = estimate(plain).eta2_cell, estimate(zero).eta2_cell
    assert not b[ETA8].any()  # b_h = p_t,h = 0: the integrand is 0 exactly
    scale = a.sum()
    np.testing.assert_allclose(b, a, rtol=1e-8, atol=1e-12 * scale)


def test_full_stick_has_no_friction_work_and_eta4_balances_sigma_t():
    _, r = _solved(Tresca(1.0))
    assert (r.state[r.active] == STICK).all()
    e = estimate(r)
    assert e.eta2_cell[ETA8].max() <= 1e-20 * e.eta2_cell.sum()
    # the friction stress with the opposite sign (or none) leaves σ_t unbalanced
    with_p = e.eta2_cell[ETA4].sum()
    original = contact_faces3d.friction_faces
    try:
        for scale, factor in ((0.0, 3.0), (-1.0, 10.0)):
            contact_faces3d.friction_faces = lambda res, unit, s=scale: original(
                res, unit
            )._replace(friction=s * original(res, unit).friction)
            assert estimate(r).eta2_cell[ETA4].sum() > factor * with_p
    finally:
        contact_faces3d.friction_faces = original


def _p2_basis(lam: np.ndarray) -> np.ndarray:
    """``(q, 6)`` the P2 basis on a triangle at barycentric points ``lam (q, 3)``: vertices
    ``λ_i (2λ_i − 1)``, then the midpoints of the sides (0, 1), (1, 2), (2, 0): ``4 λ_i λ_j``."""
    v = lam * (2.0 * lam - 1.0)
    m = 4.0 * lam * np.roll(lam, -1, axis=1)
    return np.hstack([v, m])


def _dense_barycentric(m: int) -> np.ndarray:
    """Centroids of the ``m²`` congruent sub-triangles of a triangle (each of area 1/m²)."""
    out = []
    for i in range(m):  # a loop over the rule's rows (fixed size, not the mesh)
        for j in range(m - i):
            out.append(((i + 1 / 3) / m, (j + 1 / 3) / m))
            if j < m - i - 1:
                out.append(((i + 2 / 3) / m, (j + 2 / 3) / m))
    s = np.array(out)
    return np.column_stack([1.0 - s.sum(axis=1), s])


@pytest.mark.parametrize("law", [Coulomb(0.3), Tresca(2e-3)])
def test_eta8_equals_a_dense_quadrature_of_the_nodal_data(law):
    press, r = _solved(law, path=True)
    assert (r.state == STICK).any() and (r.state == SLIP).any()
    cs = r.contact
    faces = cs.faces
    x = r.space.node_points[faces]
    np.testing.assert_allclose(x[:, 3], 0.5 * (x[:, 0] + x[:, 1]), atol=1e-14)  # order
    # nodal data from the solution: the transformed basis's stresses Λ̃ / w̃ in the node
    # frames' tangents, the slip from the pressed step's displacement
    e = estimate(r)
    frame = cs.frames[np.searchsorted(cs.frame_nodes, cs.node)]
    t = frame[:, :, 1:]  # the rows bound the z component: t_1, t_2 are the frame's others
    w = cs.transformed_integral
    p = np.einsum("kcj,kj->kc", t, r.tangential_force) / w[:, None] / e.unit
    normal = np.where(r.active, cs.edges.transformed(r.contact_force), 0.0)
    if isinstance(law, Coulomb):
        b = law.coefficient * normal / w / e.unit
    else:
        b = np.full(w.shape, law.bound) / e.unit  # a constant s: s_z = s w̃_z
    assert (np.linalg.norm(p, axis=1) <= b * (1 + 1e-9) + 1e-14).all()  # the disc law
    slip = r.u - press.u
    slip[:, 2] = 0.0  # the normal is e_z on the whole bottom
    row = cs.facet_local
    assert (row >= 0).all()  # no held node on z0
    lam = _dense_barycentric(48)
    phi = _p2_basis(lam)
    P = np.einsum("qa,fac->fqc", phi, p[row])
    U = np.einsum("qa,fac->fqc", phi, slip[faces])
    B = b[row] @ phi.T
    f = np.maximum(B, np.linalg.norm(P, axis=-1)) * np.linalg.norm(U, axis=-1)
    f -= np.einsum("fqc,fqc->fq", P, U)
    area = 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1)
    dense = f.mean(axis=1) * area  # each centroid weighs area / m²
    parts = eta8_parts(r, friction_faces(r, e.unit))
    assert dense.sum() > 0
    # the package's rule (4² triangles, degree 4) is within 1.9e-3 of the largest face's
    # integral on each face (measured against 400² centroids; this 48² rule: 1.9e-4)
    np.testing.assert_allclose(parts.sum(axis=1), dense, rtol=0, atol=5e-3 * dense.max())
    np.testing.assert_allclose(e.eta2_cell[ETA8].sum(), dense.sum(), rtol=2e-3)
    assert (parts >= 0).all()


@pytest.mark.slow
def test_eta8_lives_on_the_stick_slip_transition_of_partial_slip_3d():
    from signorini.examples.partial_slip3d import partial_slip_3d_path

    r = None
    for step in partial_slip_3d_path(h_contact=0.2):  # a loop over load steps
        r = solve(step, step.mesh, previous=r)
    e = estimate(r)
    parts = eta8_parts(r, friction_faces(r, e.unit)).sum(axis=1)
    rows = r.contact.facet_local
    state = np.where(rows >= 0, r.state[np.maximum(rows, 0)], -1)
    # the faces on the stick set's boundary: a stick row and a row that does not stick
    transition = (state == STICK).any(axis=1) & ((state == SLIP) | (state == INACTIVE)).any(axis=1)
    assert transition.any() and (~transition).sum() > 10 * transition.sum()
    # measured: 99.9 % of η8² on the 4 faces with stick and slip nodes (of 132)
    assert parts[transition].sum() >= 0.99 * parts.sum()
    assert parts[transition].max() > 100.0 * parts[~transition].max()
    np.testing.assert_allclose(e.eta2_cell[ETA8].sum(), parts.sum(), rtol=1e-12)


def test_the_3d_loop_records_eta8_of_the_frictional_estimate():
    from signorini.loop import adaptive

    law = Coulomb(0.3)
    press, pull = _block(law, shift=(0.0, 0.0)), _block(law)
    level = next(iter(adaptive(pull, path=[press], max_levels=1)))
    row = level.record.row()
    _, r = _solved(law, path=True)
    eta8 = float(np.sqrt(estimate(r).eta2_cell[ETA8].sum()))
    assert eta8 > 0
    np.testing.assert_allclose(row["eta_8"], eta8, rtol=1e-6)
