"""Every figure of a run is titled with its problem's ``name=``, not with the file's stem."""

from __future__ import annotations

from pathlib import Path

from signorini.cli import main

EXAMPLE_FILE = Path(__file__).parents[2] / "examples" / "inclined_block.py"


def test_figures_are_titled_with_the_problems_name(tmp_path, captured, capsys):
    out = tmp_path / "block"
    argv = ["run", str(EXAMPLE_FILE), "--max-ndof", "400", "--out", str(out), "--no-vtu"]
    assert main([*argv, "--quiet"]) == 0  # the file says name="inclined block"
    titles = {Path(i["file"]).stem: i["titles"][0].split("\n")[0] for i in captured}
    print(titles)
    assert sorted(titles) == [
        "deformed",
        "inclined_block_contributions",
        "inclined_block_estimator",
        "mesh",
    ]  # file names keep the file's stem
    assert titles["inclined_block_estimator"] == "inclined block"
    assert titles["inclined_block_contributions"] == "inclined block"
    assert titles["deformed"] == "inclined block: deformed body"
    assert titles["mesh"].startswith("inclined block: mesh, level ")
    captured.clear()
    assert main(["figures", str(EXAMPLE_FILE), str(out)]) == 0
    assert [i["titles"][0] for i in captured] == ["inclined block"] * 2
