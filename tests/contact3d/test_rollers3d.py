"""Rollers on oblique planes and curved faces in 3D, the oblique contact frames, and several
materials by region: equal to the axis-aligned problem rotated, or to an exact solution that
P2 reproduces (docs/method.md, *Three dimensions: rollers, force control, regions*)."""

from __future__ import annotations

import numpy as np
import pytest
from contact3d_problems import DIRECT, MATERIAL, pressed_block, rotation

from signorini.contact.solution import solve
from signorini.fem.material import Material
from signorini.mesh.builders3d import box, eighth_ball, quarter_cylinder
from signorini.mesh.mesh import Mesh
from signorini.problem.conditions import ExactSolution, Neumann, Roller
from signorini.problem.fields import ProblemError
from signorini.problem.problem import ContactProblem


def test_oblique_rollers_and_contact_are_the_axis_aligned_ones_rotated():
    """Rollers on the rotated symmetry planes (oblique: node frames) and the tilted half-space
    (oblique contact frames) give the rotated displacement, the same active set and the same
    contact and roller forces, to round-off."""
    R = rotation()
    axis = solve(pressed_block(np.eye(3)), solver=DIRECT)
    oblique = solve(pressed_block(R), solver=DIRECT)
    assert axis.problem.rollers == {} and set(oblique.problem.rollers) == {"x0", "y0"}
    assert oblique.report.kkt.max <= 1e-12 and axis.report.kkt.max <= 1e-12
    assert axis.active.any() and np.array_equal(axis.active, oblique.active)
    scale = np.abs(axis.u).max()
    np.testing.assert_allclose(oblique.u, axis.u @ R.T, rtol=0, atol=1e-12 * scale)
    f = np.abs(axis.contact_force).max()
    np.testing.assert_allclose(oblique.contact_force, axis.contact_force, rtol=0, atol=1e-11 * f)
    np.testing.assert_array_equal(oblique.roller_nodes, axis.roller_nodes)
    np.testing.assert_allclose(oblique.roller_force, axis.roller_force, rtol=0, atol=1e-11 * f)


def _expansion(shape: str, n: int):
    """``Roller(value=δ)`` on the curved face of the quarter cylinder (rollers on x0, y0 and
    both ends) or of the eighth ball (rollers on x0, y0, z1) on the mesh of ``n``, and its
    exact solution, the uniform expansion ``u = δ x_⊥`` (R = 1) with constant stress."""
    delta = 0.01
    if shape == "cylinder":
        mesh, keep = quarter_cylinder(n, n), np.array([1.0, 1.0, 0.0])
        held = {"x0": Roller(), "y0": Roller(), "z0": Roller(), "z1": Roller()}
    else:
        mesh, keep = eighth_ball(n), np.ones(3)
        held = {"x0": Roller(), "y0": Roller(), "z1": Roller()}
    exact = ExactSolution(
        displacement=lambda x: delta * x * keep,
        gradient=lambda x: np.broadcast_to(delta * np.diag(keep), (len(x), 3, 3)),
    )
    conditions = dict(held, **{shape: Roller(value=delta)})
    return solve(ContactProblem(mesh, MATERIAL, conditions, exact=exact), solver=DIRECT)


@pytest.mark.parametrize("shape", ["cylinder", "sphere"])
def test_roller_on_a_curved_face_converges_to_the_radial_expansion(shape):
    """The curved face holds ``u(z)·n_z = δ`` with the surface's exact normal at every P2 node
    (its frame's held DOF); the nodes' normals are not the isoparametric faces' own, so the
    discrete solution is not the affine one, but its energy error falls like h² (measured
    2.01 and 2.1 for the cylinder from n = 2 to 4 to 6; P2's optimal rate)."""
    coarse, fine = _expansion(shape, 2), _expansion(shape, 4)
    for r in (coarse, fine):
        curved = r.space.part_nodes([shape])
        x = r.space.node_points[curved]
        n = r.problem.mesh.curves[r.problem.mesh.part_index(shape)].normal(x)
        np.testing.assert_allclose(np.einsum("jc,jc->j", r.u[curved], n), 0.01, atol=1e-15)
    e = [r.errors()["error_energy"] for r in (coarse, fine)]
    rate = np.log2(e[0] / e[1])
    assert rate > 1.8, f"energy error {e}, rate {rate:.3f} in h"
    assert e[1] < 1e-2 * 0.01  # 1 % of δ's energy scale on the finer mesh


def test_two_materials_by_region_give_the_piecewise_exact_bar():
    """A bar [0, 1]³ of two materials (E = 1 for x < ½, E = 4 for x > ½, ν = 0.3), rollers on
    x0 and all four sides, pulled by t = 0.1 on x1: uniaxial strain, σ_xx = t in both, u_x
    piecewise linear with slope t / (λ_i + 2μ_i), reproduced by P2 to round-off."""
    soft, stiff = Material.from_young(1.0, 0.3), Material.from_young(4.0, 0.3)
    mesh = box(4, 2, 2, regions={"soft": lambda c: c[:, 0] < 0.5, "stiff": lambda c: c[:, 0] > 0.5})
    conditions = {name: Roller() for name in ("x0", "y0", "y1", "z0", "z1")}
    conditions["x1"] = Neumann((0.1, 0.0, 0.0))
    problem = ContactProblem(mesh, {"soft": soft, "stiff": stiff}, conditions)
    result = solve(problem, solver=DIRECT)
    x = result.space.node_points[:, 0]
    k1, k2 = soft.lam + 2 * soft.mu, stiff.lam + 2 * stiff.mu
    exact = np.where(x <= 0.5, 0.1 * x / k1, 0.05 / k1 + 0.1 * (x - 0.5) / k2)
    np.testing.assert_allclose(result.u[:, 0], exact, rtol=0, atol=1e-12 * exact.max())
    np.testing.assert_allclose(result.u[:, 1:], 0.0, rtol=0, atol=1e-14)
    assert k1 != k2 and exact.max() == pytest.approx(0.05 / k1 + 0.05 / k2, rel=1e-14)


def test_a_roller_part_with_a_crease_is_refused_naming_it():
    mesh = box(1, 1, 1)
    joined = Mesh.from_arrays(
        mesh.points,
        mesh.cells,
        {
            "side": np.concatenate([mesh.facets[mesh.part_facets(p)] for p in ("x0", "y0")]),
            **{p: mesh.facets[mesh.part_facets(p)] for p in ("x1", "y1", "z0", "z1")},
        },
    )
    conditions = {name: Neumann((0.0, 0.0, 0.0)) for name in joined.part_names}
    conditions.update(side=Roller(), z0=Roller())
    with pytest.raises(ProblemError, match=r"Roller on part 'side'.* turns by 45°"):
        ContactProblem(joined, MATERIAL, conditions)
