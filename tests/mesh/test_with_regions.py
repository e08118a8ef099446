"""Regions given to a mesh built without them (:func:`signorini.mesh.with_regions`)."""

import numpy as np

from signorini import Contact, ContactProblem, HalfPlane, Material, Neumann, Roller, adaptive
from signorini.examples.hertz_half import quarter_disc
from signorini.mesh import with_regions

P, R = 0.0084, 1.0


def core(x):
    return np.hypot(x[:, 0], x[:, 1] - R) < 0.5 * R


def half_model(materials):
    mesh = with_regions(quarter_disc(R), {"core": core, "shell": lambda x: ~core(x)})
    return ContactProblem(
        mesh=mesh,
        material=materials,
        conditions={
            "top": Neumann((0.0, -P / (2 * R))),
            "axis": Roller(),
            "arc": Contact(obstacle=HalfPlane((0.0, 0.0), (0.0, 1.0))),
        },
    )


def test_regions_keep_the_mesh_its_parts_and_curves():
    plain = quarter_disc(R)
    mesh = with_regions(plain, {"core": core, "shell": lambda x: ~core(x)})
    assert mesh.region_names == ("core", "shell")
    np.testing.assert_array_equal(mesh.points, plain.points)
    np.testing.assert_array_equal(mesh.cells, plain.cells)
    assert mesh.part_names == plain.part_names and mesh.curves == plain.curves
    centroids = mesh.points[mesh.cells].mean(axis=1)
    np.testing.assert_array_equal(mesh.cell_region == 0, core(centroids))


def test_a_two_material_half_model_under_force_control():
    """The README's half-model: a roller, two materials, a prescribed force. The contact
    carries the force on every level, a stiffer core makes the body stiffer (less sink), and
    the regions follow the refinement."""
    soft = Material.from_young(1.0, 0.3)
    one = list(adaptive(half_model({"core": soft, "shell": soft}), max_ndof=2_000))
    two = list(adaptive(half_model({"core": Material.from_young(10.0, 0.3), "shell": soft}),
                        max_ndof=2_000))  # fmt: skip
    for level in two:
        assert abs(2 * level.result.total_contact_force - P) <= 1e-9 * P
    sink = [-lv.result.u[:, 1].min() for lv in (one[-1], two[-1])]
    assert sink[1] < 0.9 * sink[0], sink
    # the regions follow the refinement: the core (cells of the initial mesh, away from the
    # curved arc) covers the same area on the last level as on the first
    first, last = two[0].result.mesh, two[-1].result.mesh
    areas = [m.area[m.cell_region == 0].sum() for m in (first, last)]
    assert abs(areas[1] - areas[0]) <= 1e-12 * areas[0], areas
    assert (last.cell_region == 0).sum() > (first.cell_region == 0).sum()
