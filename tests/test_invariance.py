r"""Scale and translation invariance of the whole pipeline (mesh, SOLVE, ESTIMATE).

Example 6.2's data on the image of its geometry under ``Φ(x) = s x + t``: the same material,
Dirichlet data ``s u_D``, gap ``ψ_s(Φ(x)) = s ψ(x)``, the same normal, ``f = 0``, ``g = 0``.
The mesh is built through :meth:`Mesh.from_arrays` from the mapped points and refined by
newest vertex bisection with the cells that the unscaled run marks (refinement works on
indices, so every run has the same meshes up to ``Φ``).

The scaling law. ``u_s ∘ Φ = s u`` solves the mapped problem: the strain ``ε(u_s)`` and the
stress ``σ(u_s)`` are unchanged at mapped points and the contact conditions scale with ψ. The
same holds for the discrete problem (3.2): in 2D the stiffness matrix is invariant
(gradients ``~ 1/s``, area ``~ s²``) and the load vector scales like ``s``, so
``u_h,s ∘ Φ = s u_h``, the same active set, and the nodal contact forces Λ_z (3.17),
stress times length, scale like ``s`` (the density s_z = Λ_z/m_z and the pressure are
invariant). In (5.1), with ``h ~ s``, ``‖·‖²_T ~ s²``, ``‖·‖²_E ~ s`` and σ invariant:
``η1² = h² ‖f + div σ‖²_ω ~ s² s⁻² s²``; η2…η5: ``h ‖·‖²_γ ~ s²``; ``η6² = s_p d_p ~ 1 · s²``
(``d_p = ∫ (ψ − u_h·n)⁺ φ_p ~ s · s``). So ``η_k(s) = s η_k(1)`` for k = 1…6. η7 is the full
``H^{1/2}(Γ_C)`` norm of the penetration ``w ~ s``: its L² part scales like ``s³`` and its
seminorm (kernel ``|x − y|⁻²``, scale-free in 1D) like ``s²``, so
``η7(s)² = s³ A + s² B`` with ``A``, ``B`` the two parts at ``s = 1``; they are found from the
runs at ``s = 1`` and ``s = 2`` (scaling by 2 is exact in floating point).
Translation changes nothing.

The tolerance. Scaling alone costs the round-off of the linear solve and of the estimator's
sums: observed ≤ 5e-14 for all scales here; the bound is ``1e-12``. A shift ``t`` stores
each coordinate with an absolute rounding error up to ``eps |t| / 2``, which perturbs the
cells (of diameter ≥ ``s h_min``) by a relative ``eps |t| / (s h_min)``; the solution and
the estimator depend smoothly on the geometry, with a constant observed up to 6.3 (η6 and
η7, small differences of nearly equal quantities). The bound is
``1e-12 + 100 eps |t| / (s h_min)``.
"""

from __future__ import annotations

import numpy as np
import pytest

from signorini.contact.solution import solve
from signorini.estimator.marking import mark_doerfler
from signorini.estimator.residual import estimate
from signorini.examples import example_6_2
from signorini.mesh import Mesh, refine_nvb
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann

STEPS = 4  # NVB steps after the initial mesh: η7 > 0 on the final mesh (penetration)
EPS = np.finfo(np.float64).eps


def mapped_problem(mesh: Mesh, s: float, t: np.ndarray) -> ContactProblem:
    base = example_6_2()

    def gap(x):
        return s * (-0.2 + 0.5 * np.abs((x[..., 1] - t[1]) / s - 0.5))

    return ContactProblem(
        mesh=mesh,
        material=base.material,
        conditions={
            "left": Dirichlet((0.1 * s, 0.0)),
            "top": Neumann((0.0, 0.0)),
            "bottom": Neumann((0.0, 0.0)),
            "right": Contact(gap=gap, normal=(1.0, 0.0)),
        },
    )


def run(s: float, t, marks: list[np.ndarray] | None = None):
    """Solve and estimate on the mapped meshes; returns the last result and estimate, and the
    marked cells of each step (taken from ``marks`` when given)."""
    t = np.asarray(t, dtype=float)
    m0 = example_6_2().mesh
    parts = {name: m0.facets[m0.part_facets(name)] for name in m0.part_names}
    mesh = Mesh.from_arrays(m0.points * s + t, m0.cells, parts)
    used = []
    for step in range(STEPS + 1):
        result = solve(mapped_problem(mesh, s, t))
        est = estimate(result)
        if step == STEPS:
            return result, est, used
        marked = marks[step] if marks is not None else mark_doerfler(est.eta2, 0.4)
        used.append(marked)
        mesh = refine_nvb(mesh, marked).mesh


@pytest.fixture(scope="module")
def unscaled():
    result, est, marks = run(1.0, (0.0, 0.0))
    _, est2, _ = run(2.0, (0.0, 0.0), marks)
    # η7(s)² = s³ A + s² B from s = 1 and s = 2
    e1, e2 = est.eta_terms[6] ** 2, est2.eta_terms[6] ** 2
    A = (e2 - 4 * e1) / 4
    B = e1 - A
    assert est.eta_terms[6] > 1e-4 and A > 0 and B > 0  # both parts present
    return result, est, marks, (A, B)


CASES = [
    (1e-12, (0.0, 0.0)),
    (1e-6, (0.0, 0.0)),
    (1e-3, (1e3, 0.0)),
    (0.1, (1e9, 1e9)),
    (1.0, (1e9, -1e9)),
    (3.7, (-1e9, 2.5e8)),
    (1e6, (1e9, -1e9)),
    (1e12, (0.0, 0.0)),
    (1e12, (1e9, 0.0)),
]


@pytest.mark.parametrize(("s", "t"), CASES)
def test_pipeline_is_scale_and_translation_invariant(unscaled, s, t) -> None:
    r0, e0, marks, (A, B) = unscaled
    r, e, _ = run(s, t, marks)
    tol = 1e-12 + 100 * EPS * np.abs(t).max() / (s * r0.mesh.h.min())

    def rel(a, b):
        return float(np.abs(a - b).max() / np.abs(b).max())

    print(f"s = {s:g}, t = {t}: tolerance {tol:.1e}")
    assert r.mesh.n_cells == r0.mesh.n_cells
    np.testing.assert_array_equal(r.active, r0.active)
    assert rel(r.u / s, r0.u) <= tol
    assert rel(r.contact_force / s, r0.contact_force) <= tol
    for k in range(6):
        assert abs(e.eta_terms[k] / s - e0.eta_terms[k]) <= tol * e0.eta_terms[k], f"eta_{k + 1}"
    eta7 = np.sqrt(s**3 * A + s**2 * B)
    assert abs(e.eta_terms[6] - eta7) <= tol * eta7
    eta = np.sqrt(s**2 * (e0.eta**2 - e0.eta_terms[6] ** 2) + eta7**2)
    assert abs(e.eta - eta) <= tol * eta
