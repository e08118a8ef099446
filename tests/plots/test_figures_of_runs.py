"""Every figure of the paper's two examples and of ``examples/inclined_block.py``, drawn by
the command line: no text leaves the canvas, no two labels overlap, no wide empty band
(checked by the ``captured`` fixture as each figure is saved), and what each shows."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from signorini import plots
from signorini.cli import main
from signorini.plots import READABLE_CELLS, readable_level
from signorini.plots.mesh import read_level_mesh

EXAMPLE_FILE = Path(__file__).parents[2] / "examples" / "inclined_block.py"


def run(out: Path, problem: str, *options: str) -> None:
    assert main(["run", problem, "--out", str(out), "--quiet", *options]) == 0


def by_name(captured: list[dict]) -> dict[str, dict]:
    return {Path(info["file"]).stem: info for info in captured}


@pytest.mark.slow  # three short runs, 14 figures
def test_every_figure_of_the_examples_is_readable(tmp_path, captured, monkeypatch):
    # a low readability limit, so that Example 6.1's mesh figure shows an earlier level,
    # read back from its VTU file
    with monkeypatch.context() as m:
        m.setattr(plots, "readable_level", lambda n: readable_level(n, most=200))
        run(tmp_path / "e1", "example-6.1", "--max-ndof", "3000")
    run(tmp_path / "e2", "example-6.2", "--max-ndof", "3000", "--compare-uniform")
    run(tmp_path / "ib", str(EXAMPLE_FILE), "--max-ndof", "3000")
    figures = by_name(captured)
    print(sorted(figures))
    assert len(captured) == 14 and len(figures) == 10  # mesh and deformed: one per run
    # every slope's range is stated: in the legend's title, or in a caption under the axes
    for stem in ("example-6.1_contributions", "example-6.2_contributions"):
        assert figures[stem]["legend_title"].startswith("slopes: least squares on $N_")
    for stem in (
        "example-6.1_error_estimator",
        "example-6.2_estimator",
        "inclined_block_estimator",
    ):
        assert figures[stem]["caption"].startswith("slopes: least squares on $N_")
    assert figures["adaptive_vs_uniform"]["caption"] == (
        "slopes: least squares on the finer half of each run"
    )
    # Example 6.1: |u| up to 0.88 on the unit square is drawn shrunk, the obstacle's gaps
    # with it (where the drawn body touches it), and the title says so
    e1 = [i for i in captured if i["titles"][0].startswith("example-6.1: deformed")]
    assert e1[0]["titles"][0] == (
        "example-6.1: deformed body\ndisplacement and obstacle gaps \u00d70.1"
    )
    assert "obstacle, gaps \u00d70.1" in e1[0]["legend"]
    # Example 6.2 (|u| <= 0.2) at true scale, the inclined block (|u| <= 0.03 on 2) magnified
    titles = [i["titles"][0] for i in captured if "deformed body" in i["titles"][0]]
    assert titles[1:] == [
        "example-6.2: deformed body\ndisplacement at true scale",
        "inclined block: deformed body\ndisplacement and obstacle gaps \u00d75",
    ]
    # the mesh figures: a readable level, the three kinds of boundary marked
    meshes = [i for i in captured if ": mesh, level" in i["titles"][0]]
    assert len(meshes) == 3
    for info in meshes:
        assert info["legend"] == [
            r"Dirichlet $\Gamma_D$",
            r"Neumann $\Gamma_N$",
            r"contact $\Gamma_C$",
        ]
        n_cells = int(info["titles"][0].split(" cells")[0].rsplit(", ", 1)[1])
        assert n_cells <= READABLE_CELLS
    assert np.all([len(i["segments"]) == 3 for i in meshes])
    # where the contact zone ends inside Γ_C (6.2, the block), a zoom panel shows it
    assert [len(i["titles"]) for i in meshes] == [1, 2, 2]
    assert [i["titles"][1] for i in meshes[1:]] == ["end of the contact zone"] * 2
    # Example 6.1: the mesh of level 6 (the last with <= 200 cells), from level_006.vtu
    history = np.genfromtxt(tmp_path / "e1" / "history.csv", delimiter=",", names=True)
    k = int(np.flatnonzero(history["n_cells"] <= 200)[-1])
    assert k < history.size - 1
    # ... and its title says that it is not the last level, which the others are
    last = int(history["level"][-1])
    assert " ".join(meshes[0]["titles"][0].split()) == (
        f"example-6.1: mesh, level {k}, {int(history['n_cells'][k])} cells (an earlier level, "
        f"readable; the run ends at level {last})"
    )
    assert all(" ".join(i["titles"][0].split()).endswith("(last level)") for i in meshes[1:])
    points, cells = read_level_mesh(tmp_path / "e1" / f"level_{k:03d}.vtu")
    contact = np.array(meshes[0]["segments"][r"contact $\Gamma_C$"])
    assert np.all(contact[:, :, 1] == 0.0)  # Γ_C is the bottom y = 0 ...
    assert np.isclose(np.abs(contact[:, 1, 0] - contact[:, 0, 0]).sum(), 1.0)  # ... all of it
    assert len(contact) == np.count_nonzero(np.isclose(points[:, 1], 0.0)) - 1
