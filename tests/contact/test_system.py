"""The algebraic problem of one mesh (:mod:`signorini.contact.system`): the assembly trusts the
validated problem and gives the matrix and load of the checked building blocks, and user data
that is not numbers is reported by part."""

from __future__ import annotations

import numpy as np
import pytest
from contact_problems import independent_system, patch_problem, random_quadratic

from signorini.contact.node_frames import rotate_frames
from signorini.contact.system import assemble
from signorini.fem.material import Material
from signorini.mesh.builders import rectangle
from signorini.mesh.refine import refine_nvb
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann, ProblemError

MATERIAL = Material.from_young(10.0, 0.3)


def square_problem(**conditions) -> ContactProblem:
    base = {"left": Dirichlet(), "top": Neumann(), "bottom": Neumann(), "right": Contact()}
    return ContactProblem(rectangle(nx=2, ny=2), MATERIAL, {**base, **conditions})


def test_assembly_equals_the_checked_building_blocks():
    rng = np.random.default_rng(4)
    mesh = rectangle(0, 2, 0, 1, nx=4, ny=2)
    mesh = refine_nvb(mesh, rng.random(mesh.n_cells) < 0.4).mesh
    u = random_quadratic(rng)
    normal = np.array([0.0, -1.0])
    pb = patch_problem(
        mesh, MATERIAL, u, {"top": "D", "left": "N", "right": "N", "bottom": "C"}, normal=normal
    )
    a = assemble(pb, mesh)
    # the same system from the validating entry points, in Cartesian DOFs, then rotated
    ref = independent_system(pb, mesh)
    assert np.array_equal(ref.nodes, a.contact.nodes)
    K, F = rotate_frames(ref.K, ref.F, ref.nodes, ref.normal)
    assert np.array_equal(K.indptr, a.K.indptr) and np.array_equal(K.indices, a.K.indices)
    scale = np.abs(K.data).max()
    assert np.abs(K.data - a.K.data).max() <= 1e-15 * scale
    assert np.abs(F - a.F).max() <= 1e-13 * np.abs(F).max()
    assert np.array_equal(np.sort(ref.dirichlet), np.sort(a.dirichlet))
    assert a.seconds > 0


def test_dirichlet_value_returning_nan():
    pb = square_problem(left=Dirichlet(lambda x: np.full(x.shape, np.nan)))
    with pytest.raises(ProblemError, match="Dirichlet value of part 'left' returned NaN"):
        assemble(pb, pb.mesh)


def test_traction_of_the_wrong_shape():
    pb = square_problem(top=Neumann(lambda x, normal: x[..., 0]))
    with pytest.raises(
        ProblemError, match=r"traction of Neumann part 'top' must return shape \(\d+, 2\)"
    ):
        assemble(pb, pb.mesh)


def test_body_force_returning_inf():
    base = square_problem()
    pb = ContactProblem(
        base.mesh, MATERIAL, base.conditions, body_force=lambda x: np.full(x.shape, np.inf)
    )
    with pytest.raises(ProblemError, match="body_force returned NaN or inf"):
        assemble(pb, pb.mesh)
