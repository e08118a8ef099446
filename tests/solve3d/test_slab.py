"""The plane-strain slab: a box in z with rollers on its two z faces and a load independent
of z is the 2D package's plane-strain problem on its cross-section; under uniform
refinement its compliance per unit thickness converges to the 2D answer (on a fine mesh) at
the 2D package's own rate on the same problem: the energy error squared."""

from __future__ import annotations

import numpy as np

from signorini.contact.solution import solve
from signorini.contact.system import assemble
from signorini.fem.material import Material
from signorini.mesh.builders import rectangle
from signorini.mesh.builders3d import box
from signorini.problem.conditions import Dirichlet, Roller
from signorini.problem.problem import ContactProblem

MATERIAL = Material(lam=1.7, mu=0.9)  # plane strain in 2D; the same Lamé parameters in 3D
THICKNESS = 0.5


def load(x: np.ndarray) -> np.ndarray:
    """The in-plane body force ``(n, 2)`` at points ``x (n, ≥ 2)``, independent of z."""
    X, Y = x[:, 0], x[:, 1]
    return np.stack([np.sin(np.pi * X) * np.sin(np.pi * Y), X * Y + 0.5], axis=1)


def compliance(problem: ContactProblem) -> float:
    """``F · u_h``, the work of the load on the discrete solution (twice its energy)."""
    result = solve(problem)
    return float(assemble(problem, problem.mesh).F @ result.u.ravel())


def slab(n: int) -> ContactProblem:
    """The slab ``[0, 1]² × [0, THICKNESS]`` on ``n × n × n/2`` Kuhn cubes: clamped on its
    four sides (all three components: ``u_z = 0`` as in plane strain), rollers on z0, z1."""
    mesh = box(n, n, max(1, round(n * THICKNESS)), upper=(1.0, 1.0, THICKNESS))
    conditions = {name: Dirichlet((0.0, 0.0, 0.0)) for name in ("x0", "x1", "y0", "y1")}
    conditions.update(z0=Roller(), z1=Roller())

    def force(x: np.ndarray) -> np.ndarray:
        return np.concatenate([load(x), np.zeros((x.shape[0], 1))], axis=1)

    return ContactProblem(mesh, MATERIAL, conditions, body_force=force)


def plane_strain(n: int) -> ContactProblem:
    mesh = rectangle(nx=n, ny=n)
    conditions = {name: Dirichlet((0.0, 0.0)) for name in mesh.part_names}
    return ContactProblem(mesh, MATERIAL, conditions, body_force=load)


def test_the_slab_converges_to_plane_strain():
    reference = compliance(plane_strain(96))  # 2D error ~ 1e-8 (96 against 48), far below
    sizes = np.array([2, 4, 8])
    slabs = np.array([compliance(slab(n)) for n in sizes]) / THICKNESS
    planes = np.array([compliance(plane_strain(n)) for n in sizes])

    def rates(values: np.ndarray) -> np.ndarray:
        """Observed rates in h of ``|values − reference|``."""
        difference = np.abs(values - reference)
        return np.log(difference[:-1] / difference[1:]) / np.log(sizes[1:] / sizes[:-1])

    # the discrete energy lies below the exact one (a minimum principle): from below
    assert (slabs < reference).all() and (planes < reference).all()
    # the rate is the 2D package's own on the same meshes (measured 3.0 and 3.2: the energy
    # error squared, h⁴ less the clamped corners' singularity), within half an order
    slab_rate, plane_rate = rates(slabs)[-1], rates(planes)[-1]
    assert 2.5 < plane_rate < 4.5
    assert abs(slab_rate - plane_rate) < 0.5, (slab_rate, plane_rate)
    assert rates(slabs)[-1] > rates(slabs)[0]  # towards it from the pre-asymptotic side
    assert abs(slabs[-1] - reference) < 1e-3 * reference
