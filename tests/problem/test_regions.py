"""Materials by cell region: regions on meshes and through refinement, a material per region
in ContactProblem, and a layered block solved and estimated exactly across its interface."""

import warnings

import numpy as np
import pytest

from signorini import Contact, ContactProblem, Dirichlet, Material, Neumann, adaptive, rectangle
from signorini.algebra import FactorizationError, IllConditionedWarning
from signorini.contact.solution import solve
from signorini.estimator.residual import estimate
from signorini.fem.material import CellMaterials
from signorini.fem.space import P2Space
from signorini.mesh.mesh import Mesh, MeshError
from signorini.mesh.refine import refine_nvb, refine_uniform
from signorini.output import fitted_slope
from signorini.problem.fields import ProblemError

P = 2.0  # the compressive traction on top
BASE, COATING = Material.from_young(10.0, 0.3), Material.from_young(200.0, 0.2)
LAYERS = {"base": lambda x: x[:, 1] < 0.5, "coating": lambda x: x[:, 1] > 0.5}


def layered_block(nx=4, ny=4):
    """The unit square, base below y = 1/2 and coating above (a mesh line), its bottom on a
    rigid plane, compressed by P on top, its sides held laterally; the exact solution has
    u_x = 0 and u_y piecewise linear, ε_yy = −P/(λ_i + 2μ_i) in layer i."""
    mesh = rectangle(0, 1, 0, 1, nx=nx, ny=ny, regions=LAYERS)
    e_base = -P / (BASE.lam + 2 * BASE.mu)
    e_coat = -P / (COATING.lam + 2 * COATING.mu)

    def exact(x):
        y = x[..., 1]
        uy = np.where(y < 0.5, e_base * y, e_base * 0.5 + e_coat * (y - 0.5))
        return np.stack([0.0 * y, uy], axis=-1)

    conditions = {
        "left": Dirichlet(exact),
        "right": Dirichlet(exact),
        "top": Neumann((0.0, -P)),
        "bottom": Contact(gap=lambda x: 0.0 * x[..., 0]),
    }
    return ContactProblem(mesh, {"base": BASE, "coating": COATING}, conditions), exact


def test_regions_from_selectors_labels_and_refinement():
    mesh = rectangle(0, 1, 0, 1, nx=4, ny=4, regions=LAYERS)
    assert mesh.region_names == ("base", "coating")
    centroid = mesh.points[mesh.cells].mean(axis=1)
    np.testing.assert_array_equal(mesh.cell_region, (centroid[:, 1] > 0.5).astype(int))
    # a label array gives the same regions (int labels name the regions "0", "1")
    same = Mesh.from_arrays(
        mesh.points,
        mesh.cells,
        {"all": lambda x: x[:, 0] > -1},
        regions=np.where(mesh.cell_region == 0, "base", "coating"),
    )
    np.testing.assert_array_equal(same.cell_region, mesh.cell_region)
    assert Mesh.from_arrays(
        mesh.points, mesh.cells, {"all": lambda x: x[:, 0] > -1}, regions=3 * mesh.cell_region
    ).region_names == ("0", "3")
    # children take their parent's region: every refined cell's centroid lies in its layer
    marked = np.zeros(mesh.n_cells, dtype=bool)
    marked[::3] = True
    for fine in (refine_uniform(mesh).mesh, refine_nvb(mesh, marked).mesh):
        c = fine.points[fine.cells].mean(axis=1)
        np.testing.assert_array_equal(fine.cell_region, (c[:, 1] > 0.5).astype(int))
        assert fine.region_names == mesh.region_names


def test_region_selectors_refuse_gaps_and_overlaps():
    with pytest.raises(MeshError, match=r"belong to no region, e.g. cell \d+ \(centroid"):
        rectangle(regions={"base": lambda x: x[:, 1] < 0.5})
    with pytest.raises(MeshError, match="claimed by regions 'a' and 'b'"):
        rectangle(regions={"a": lambda x: x[:, 1] < 0.6, "b": lambda x: x[:, 1] > 0.4})
    with pytest.raises(MeshError, match="one label per cell"):
        Mesh.from_arrays(
            [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            [[0, 1, 2]],
            {"b": lambda x: x[:, 0] > -1},
            regions=[1, 2],
        )


def test_material_per_region_is_checked():
    mesh = rectangle(regions=LAYERS)
    free, fixed = Neumann((0.0, 0.0)), Dirichlet((0.0, 0.0))
    conditions = {"left": fixed, "right": free, "top": free, "bottom": free}
    with pytest.raises(ProblemError, match=r"region\(s\) \['coating'\] have none"):
        ContactProblem(mesh, {"base": BASE}, conditions)
    with pytest.raises(ProblemError, match=r"\['core'\] are not regions of the mesh"):
        ContactProblem(mesh, {"base": BASE, "coating": COATING, "core": BASE}, conditions)
    with pytest.raises(ProblemError, match="material of region 'base' must be"):
        ContactProblem(mesh, {"base": 1.0, "coating": COATING}, conditions)
    one = ContactProblem(mesh, BASE, conditions)  # one Material: every region
    assert one.material_on(mesh) is BASE
    two = ContactProblem(mesh, {"base": BASE, "coating": COATING}, conditions)
    on = two.material_on(refine_uniform(mesh).mesh)
    assert isinstance(on, CellMaterials) and len(on) == 4 * mesh.n_cells
    same = ContactProblem(mesh, {"base": BASE, "coating": BASE}, conditions)
    assert same.material_on(mesh) == BASE  # the single-material path


def test_layered_block_exact_and_interface_jump_vanishes():
    """P2 reproduces the piecewise-linear solution (the interface is a mesh line); η1…η4 —
    η2 the jump of σ(u_h)n across the interface, each side with its own material — vanish
    to round-off relative to P |Ω|^{1/2}; the contact pressure is P."""
    problem, exact = layered_block()
    result = solve(problem)
    scale = P / (BASE.lam + 2 * BASE.mu)
    error = np.abs(result.u - exact(P2Space(problem.mesh).node_points)).max()
    assert error < 1e-13 * scale
    np.testing.assert_allclose(result.pressure, P, rtol=1e-12)
    eta = np.sqrt(estimate(result).eta2_cell.sum(axis=1))
    assert eta[:4].max() < 1e-11 * P


def test_coated_block_on_an_obstacle_converges_adaptively_at_the_optimal_rate():
    """A soft block (E = 1) with a stiff coating (E = 20) below y = 1/4, pressed down onto
    the rigid parabola ψ = 0.2 (x − 1)²: singular at the ends of the contact zone and where
    the interface meets the free sides; adaptive P2 recovers η ~ Ndof^(−1) (measured
    −1.04 over the last 6 levels up to 10⁴ unknowns, −1.06 up to 3·10⁴)."""
    regions = {"coating": lambda x: x[:, 1] < 0.25, "base": lambda x: x[:, 1] > 0.25}
    mesh = rectangle(0, 2, 0, 1, nx=8, ny=4, regions=regions)
    free = Neumann((0.0, 0.0))
    materials = {"coating": Material.from_young(20.0, 0.25), "base": Material.from_young(1.0, 0.3)}
    conditions = {
        "top": Dirichlet((0.0, -0.05)),
        "left": free,
        "right": free,
        "bottom": Contact(gap=lambda x: 0.2 * (x[..., 0] - 1.0) ** 2),
    }
    problem = ContactProblem(mesh, materials, conditions)
    levels = [(lv.record.ndof, lv.record.eta) for lv in adaptive(problem, max_ndof=10_000)]
    ndof, eta = np.array(levels).T
    assert ndof[-1] > 8000
    assert -1.2 < fitted_slope(ndof, eta, 6) < -0.9


def test_vtu_has_the_cells_region(tmp_path):
    import meshio

    from signorini.output.vtu import write_vtu

    problem, _ = layered_block(nx=2, ny=2)
    result = solve(problem)
    path = write_vtu(tmp_path / "layers.vtu", result)
    region = meshio.read(path).cell_data["region"][0]
    np.testing.assert_array_equal(region, problem.mesh.cell_region)
    assert problem.mesh.region_names == ("base", "coating")


def test_one_material_for_both_layers_leaves_an_interface_jump():
    """The control of the test above: the same u_h estimated with the base's σ in the coating
    too has η2 ≈ 1.77 (P = 2): the jump vanishes only with each side's own material."""
    import dataclasses

    problem, _ = layered_block()
    result = solve(problem)
    wrong = dataclasses.replace(result, problem=dataclasses.replace(problem, material=BASE))
    eta = np.sqrt(estimate(wrong).eta2_cell.sum(axis=1))
    assert eta[1] > 0.5 * P


def test_a_region_selector_that_raises_is_named_with_its_error():
    # before: the bare ZeroDivisionError of the selector
    def coating(x):
        return x[:, 1] > 1 / 0

    with pytest.raises(
        MeshError,
        match=r"the selector of region 'coating' raised ZeroDivisionError: division by zero "
        r"\(it is called with the cell centroids x of shape \(32, 2\)\)",
    ) as info:
        rectangle(regions={"base": lambda x: x[:, 1] < 0.5, "coating": coating})
    assert isinstance(info.value.__cause__, ZeroDivisionError)


def _layers(coating: Material, base: Material = BASE, held: str = "top") -> ContactProblem:
    """The layered unit square on a rigid plane, pressed down by its top or (``held =
    "left"``) held at its left side."""
    conditions = {
        "left": Neumann(),
        "right": Neumann(),
        "top": Neumann((0.0, -P)),
        "bottom": Contact(gap=0.0),
    }
    conditions[held] = Dirichlet((0.0, -0.01) if held == "top" else (0.0, 0.0))
    mesh = rectangle(0, 1, 0, 1, nx=4, ny=4, regions=LAYERS)
    return ContactProblem(mesh, {"base": base, "coating": coating}, conditions)


def test_a_contrast_of_1e12_is_warned_about_naming_the_regions_not_a_floating_part():
    # before: no word at the problem, and a soft held coating gave "Usually a part of the body
    # is not held" from the solver, though every part is held
    with pytest.warns(
        IllConditionedWarning,
        match=r"region 'base' \(E = 10, ν = 0\.3, plane strain\) is 2\.5e\+12 times the "
        r"smallest μ = 3\.84615e-12, of region 'coating' \(E = 1e-11.*fewer than 3 digits.*"
        r"although every part is held",
    ):
        _layers(Material.from_young(1e-11, 0.3))
    with pytest.warns(IllConditionedWarning, match=r"2\.5e\+14 times"):
        problem = _layers(Material.from_young(1e-13, 0.3))
    # pivots of 1e-13 against a diagonal of 46: refused whatever the backend
    with pytest.raises(FactorizationError, match="contrast of stiffness between regions"):
        solve(problem)


def test_a_contrast_beyond_double_precision_is_refused_naming_the_regions():
    with pytest.raises(
        ProblemError,
        match=r"material: the largest modulus .* of region 'coating' \(E = 1e\+17.*is 2\.5e\+16 "
        r"times the smallest μ = 3\.84615, of region 'base'.*beyond 1/eps",
    ):
        _layers(Material.from_young(1e17, 0.3), base=Material.from_young(10.0, 0.3))


def test_a_contrast_within_double_precision_is_solved_without_a_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = solve(_layers(Material.from_young(1e7, 0.3), base=Material.from_young(10.0, 0.3)))
    assert result.report.kkt.max < 1e-6


def test_a_plane_strain_region_beside_a_plane_stress_one_is_refused_naming_both():
    # before: accepted, each region with its own 2D law
    with pytest.raises(
        ProblemError,
        match=r"region\(s\) \['base'\] are in plane strain and region\(s\) \['coating'\] in "
        r"plane stress.*same plane=",
    ):
        _layers(Material.from_young(200.0, 0.2, plane="stress"))
    plate = _layers(
        Material.from_young(200.0, 0.2, plane="stress"),
        base=Material.from_young(10.0, 0.3, plane="stress"),
    )
    assert {m.plane for m in plate.material.values()} == {"stress"}


def test_a_near_incompressible_region_beside_a_compressible_one_is_warned_about():
    # ν = 0.499999999 in the coating: its forces lose digits, and the solve's KKT residuals
    # (9e-7 on Example 6.2's square split so) stayed below the solver's warning
    with pytest.warns(
        IllConditionedWarning,
        match=r"region 'coating' \(E = 10, ν = 0\.499999999, plane strain\) is close to "
        r"incompressible beside the other regions: its \(λ\* \+ μ\) / μ = 1 / \(1 − 2ν\) is "
        r"5e\+08",
    ):
        _layers(Material.from_young(10.0, 0.499999999))
    with pytest.warns(
        IllConditionedWarning,
        match=r"3\.33333e\+10 of region 'coating' \(E = 200, ν = 0\.499999999.*8\.67e\+09 times "
        r"the smallest μ = 3\.84615, of region 'base'.*\(region 'coating' is close to "
        r"incompressible itself: its \(λ\* \+ μ\) / μ = 1 / \(1 − 2ν\) is 5e\+08\)",
    ):
        _layers(Material.from_young(200.0, 0.499999999))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # ν = 0.49: 50, far below
        _layers(Material.from_young(200.0, 0.49))
