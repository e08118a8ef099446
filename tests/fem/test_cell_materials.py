"""One material per cell (CellMaterials): assembly and stresses equal the sums and values of
each material on its own cells, on affine and isoparametric cells alike."""

import numpy as np

from signorini.fem.material import CellMaterials, Material, on_cells, stress
from signorini.fem.postprocess import cell_stress
from signorini.fem.space import P2Space
from signorini.fem.stiffness import assemble_stiffness
from signorini.mesh import with_regions
from signorini.mesh.builders import half_disc
from signorini.mesh.mesh import Mesh

SOFT = Material.from_young(1.0, 0.3)
STIFF = Material.from_young(30.0, 0.2, plane="stress")
VOID = Material(lam=0.0, mu=1e-300)


def two_region_half_disc() -> Mesh:
    """The curved half-disc, its cells below y = 0.4 (on the arc, isoparametric) stiff."""
    return with_regions(
        half_disc(rings=4), {"upper": lambda x: x[:, 1] >= 0.4, "lower": lambda x: x[:, 1] < 0.4}
    )


def test_assembly_with_two_materials_is_the_sum_of_each_on_its_cells():
    mesh = two_region_half_disc()
    space = P2Space(mesh)
    assert len(space.mapping.groups) == 2  # affine and isoparametric cells
    both = CellMaterials((SOFT, STIFF), mesh.cell_region)
    K = assemble_stiffness(space.mapping, space.cell_dofs, space.n_dofs, both)
    # each material on its own cells, the others given a negligible one (mu = 1e-300)
    lower = mesh.cell_region == 1
    parts = []
    for material, mask in ((SOFT, ~lower), (STIFF, lower)):
        only = CellMaterials((material, VOID), (~mask).astype(int))
        parts.append(assemble_stiffness(space.mapping, space.cell_dofs, space.n_dofs, only))
    diff = abs(K - parts[0] - parts[1]).max()
    assert diff < 1e-13 * abs(K).max()


def test_stress_per_cell_is_each_cells_own_material():
    mesh = two_region_half_disc()
    space = P2Space(mesh)
    rng = np.random.default_rng(0)
    u_cell = space.cell_values(rng.standard_normal((space.n_nodes, 2)))
    both = CellMaterials((SOFT, STIFF), mesh.cell_region)
    xi = np.array([[0.2, 0.3], [0.5, 0.1]])
    sig = cell_stress(space.mapping, u_cell, both, xi)
    for k, material in enumerate((SOFT, STIFF)):
        rows = mesh.cell_region == k
        alone = cell_stress(space.mapping, u_cell, material, xi)
        np.testing.assert_array_equal(sig[rows], alone[rows])
    grad = rng.standard_normal((3, 2, 2))
    three = CellMaterials((SOFT, STIFF), [1, 0, 1])
    np.testing.assert_allclose(stress(three, grad)[1], stress(SOFT, grad[1]), rtol=1e-15)
    np.testing.assert_allclose(stress(on_cells(three, [2]), grad[2:]), stress(STIFF, grad[2:]))
