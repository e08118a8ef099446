"""A resumed run's mesh keeps its cell regions (one material per region)."""

import numpy as np

from signorini.mesh.builders import rectangle
from signorini.output.run import RunFolder
from signorini.output.state import read_state

from .test_run import PROBLEM


def test_saved_state_keeps_the_cell_regions(tmp_path):
    regions = {"base": lambda x: x[:, 1] < 0.5, "coating": lambda x: x[:, 1] > 0.5}
    mesh = rectangle(0, 1, 0, 1, nx=4, ny=4, regions=regions)
    folder, _ = RunFolder.create(tmp_path / "r", PROBLEM, {})
    folder.save_state(0, mesh, None, final=False)
    folder.close()  # the folder is locked per open descriptor
    saved = read_state(tmp_path / "r").mesh
    assert saved.region_names == ("base", "coating")
    np.testing.assert_array_equal(saved.cell_region, mesh.cell_region)
