"""Smoke test of the independent 3D face-contact study (studies/faces3d), n = 2."""

from __future__ import annotations

import sys
from functools import cache
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "studies"))

from faces3d.contact import assemble, solve_dual_nnls, solve_pdas  # noqa: E402
from faces3d.elasticity import energy_error  # noqa: E402
from faces3d.manufactured import full_contact, patch, transition  # noqa: E402
from faces3d.measures import recovered_pressure  # noqa: E402
from faces3d.mesh import cube_mesh  # noqa: E402


@cache
def built(make):
    """The manufactured solution and its assembled problem on n = 2 (once per module)."""
    exact = make()
    return exact, assemble(cube_mesh(2), exact)


@pytest.mark.parametrize("alpha", [0.0, 0.2], ids=["nodal", "transformed"])
def test_patch_test_is_exact(alpha):
    exact, problem = built(patch)
    mesh = problem.mesh
    sol = solve_pdas(problem, alpha)
    assert max(sol.kkt.values()) <= 1e-10
    assert energy_error(mesh, sol.u, exact.grad_u, exact.lam, exact.mu) <= 1e-13
    assert np.abs(sol.u - exact.u(mesh.points)).max() <= 1e-14
    p = recovered_pressure(problem, sol.force, 0.5 if alpha == 0 else alpha)
    assert np.nanmax(np.abs(p - 0.1)) <= 1e-13


@pytest.mark.parametrize("alpha", [0.0, 0.2], ids=["nodal", "transformed"])
@pytest.mark.parametrize("make", [full_contact, transition], ids=["full", "transition"])
def test_kkt_and_independent_solve(make, alpha):
    _, problem = built(make)
    sol = solve_pdas(problem, alpha)
    assert max(sol.kkt.values()) <= 1e-10, sol.kkt
    assert np.abs(sol.u - solve_dual_nnls(problem, alpha)).max() <= 1e-12
