"""3D elasticity through the public path: ContactProblem, solve(), the loop, the command
line and the tetra10 VTU files."""

from __future__ import annotations

import csv

import meshio
import numpy as np
import pytest

from signorini.algebra.backends.selection import SOLVERS
from signorini.cli import main
from signorini.contact.rigid_modes import system_rigid_modes
from signorini.contact.solution import solve
from signorini.contact.system import assemble
from signorini.examples.elasticity3d import MATERIAL, elasticity_3d
from signorini.loop import adaptive
from signorini.mesh.builders3d import box
from signorini.mesh.mesh import Mesh
from signorini.output.vtu import write_vtu
from signorini.problem.conditions import Dirichlet, Neumann, Roller
from signorini.problem.fields import ProblemError
from signorini.problem.problem import ContactProblem


def _cantilever(mesh: Mesh, sign: float = 1.0) -> ContactProblem:
    """Clamped on x0, a traction on x1 (odd in y: the same function on the mirrored mesh),
    a body force whose y component has the sign ``sign``."""
    conditions = {name: Neumann((0.0, 0.0, 0.0)) for name in mesh.part_names}
    conditions["x0"] = Dirichlet((0.0, 0.0, 0.0))
    conditions["x1"] = Neumann(lambda x: np.stack([0 * x[:, 0], x[:, 1], -x[:, 2]], 1))
    return ContactProblem(
        mesh, MATERIAL, conditions, body_force=lambda x: np.array([0.0, 0.3 * sign, -1.0])
    )


def test_rigid_modes_are_the_kernel():
    mesh = box(2, 2, 2)
    a = assemble(_cantilever(mesh), mesh)
    R = system_rigid_modes(a)
    assert R.shape == (a.space.n_dofs, 6)
    assert np.abs(a.K @ R).max() < 1e-12 * np.abs(a.K).max() * np.abs(R).max()
    assert np.linalg.matrix_rank(R) == 6


def test_amg_equals_direct_to_cg_tolerance():
    mesh = box(3, 3, 3)
    problem = _cantilever(mesh)
    direct = solve(problem, mesh, solver=SOLVERS["scipy"])
    amg = solve(problem, mesh, solver=SOLVERS["amg"])
    assert amg.report.backend == "amg"
    assert np.abs(amg.u - direct.u).max() <= 1e-6 * np.abs(direct.u).max()


def test_mirror_invariance():
    mesh = box(2, 2, 2)
    mirrored = Mesh.from_arrays(
        mesh.points * [1.0, -1.0, 1.0],
        mesh.cells,
        {name: mesh.boundary[mesh.boundary_part == i] for i, name in enumerate(mesh.part_names)},
    )
    r = solve(_cantilever(mesh), mesh, solver=SOLVERS["scipy"])
    m = solve(_cantilever(mirrored, -1.0), mirrored, solver=SOLVERS["scipy"])
    x, y = r.space.node_points, m.space.node_points * [1.0, -1.0, 1.0]
    i, j = np.lexsort(x.T), np.lexsort(y.T)  # the same nodes, matched by position
    assert np.array_equal(x[i], y[j])
    u, v = r.u[i], m.u[j] * [1.0, -1.0, 1.0]
    assert np.abs(v - u).max() <= 1e-12 * np.abs(u).max()


def test_roller_holds_one_component():
    mesh = box(2, 2, 2)
    conditions = {name: Neumann((0.0, 0.0, 0.0)) for name in mesh.part_names}
    conditions.update(x0=Roller(), y0=Roller(), z0=Roller(), z1=Neumann((0.0, 0.0, -1.0)))
    r = solve(ContactProblem(mesh, MATERIAL, conditions), mesh)
    z0 = r.space.part_nodes(["z0"])
    assert np.abs(r.u[z0, 2]).max() == 0.0
    assert np.abs(r.u[z0, :2]).max() > 0.0  # free to slide
    # a uniaxial compression: σ_zz = −1 everywhere
    assert np.allclose(r.nodal_stress[:, 2, 2], -1.0, atol=1e-10)


@pytest.mark.parametrize(
    ("conditions", "message"),
    [
        ({"x0": Dirichlet((0.0, 0.0))}, "give 3"),
        ({"x0": Dirichlet((0.0, None, 0.0))}, "rigid motion"),
    ],
)
def test_refused_at_the_boundary(conditions, message):
    mesh = box(1, 1, 1)
    full = {name: Neumann((0.0, 0.0, 0.0)) for name in mesh.part_names}
    full.update(conditions)
    with pytest.raises(ProblemError, match=message):
        ContactProblem(mesh, MATERIAL, full)


def test_adaptive_3d_runs_with_the_estimator():
    """Without ``uniform`` a 3D problem is refined where the estimator marks (Dörfler,
    tests/estimator3d has the estimator's own tests)."""
    levels = list(adaptive(elasticity_3d(2), max_levels=2))
    assert levels[0].estimate is not None and levels[0].record.eta > 0
    assert 0 < levels[0].marked.sum() < levels[0].marked.size
    assert levels[1].result.mesh.n_cells > levels[0].result.mesh.n_cells


def test_vtu_tetra10_read_back(tmp_path):
    problem = elasticity_3d(2)
    result = solve(problem)
    path = write_vtu(tmp_path / "level.vtu", result)
    data = meshio.read(path)
    tet, faces = data.cells_dict["tetra10"], data.cells_dict["triangle6"]
    assert tet.shape == (problem.mesh.n_cells, 10)
    edges = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]  # VTK's quadratic tetra
    p = data.points
    for k, (a, b) in enumerate(edges):
        assert np.abs(p[tet[:, 4 + k]] - 0.5 * (p[tet[:, a]] + p[tet[:, b]])).max() < 1e-14
    for k, (a, b) in enumerate([(0, 1), (1, 2), (2, 0)]):
        assert np.abs(p[faces[:, 3 + k]] - 0.5 * (p[faces[:, a]] + p[faces[:, b]])).max() < 1e-14
    assert np.array_equal(data.point_data["displacement"], result.u)
    assert data.point_data["stress"].shape == (result.space.n_nodes, 6)
    parts = data.cell_data_dict["part"]["triangle6"]
    assert sorted(set(parts.tolist())) == list(range(6))


def test_cli_uniform_rates(tmp_path):
    out = tmp_path / "run"
    assert main(["run", "elasticity-3d", "--uniform", "--max-ndof", "20000", "--out",
                 str(out), "--no-figures", "--quiet"]) == 0  # fmt: skip
    rows = list(csv.DictReader(open(out / "history.csv")))
    assert len(rows) == 3
    n = np.array([float(r["ndof"]) for r in rows])
    e = np.array([float(r["error_energy"]) for r in rows])
    l2 = np.array([float(r["error_l2"]) for r in rows])
    slope = np.log(e[-1] / e[-2]) / np.log(n[-1] / n[-2])
    assert -0.75 < slope < -0.55  # h² ~ N^{−2/3}, pre-asymptotic from above
    assert float(rows[-1]["rate_energy"]) == pytest.approx(slope, rel=1e-12)
    assert np.log(l2[-1] / l2[-2]) / np.log(n[-1] / n[-2]) < -0.8  # h³ ~ N^{−1}
    assert (out / "level_002.vtu").is_file() and (out / "levels.pvd").is_file()
