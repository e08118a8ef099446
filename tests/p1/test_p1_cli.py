"""``signorini run ... --element p1``: the element in the manifest, linear triangles in the
VTU files, and --resume keeping the element."""

from __future__ import annotations

import csv
import json

import meshio
import numpy as np
import pytest

from signorini.cli import main
from signorini.plots import read_level_mesh
from tests.test_cli import (
    assert_same_history,
    assert_same_vtu,
    history_without_timings,
    interrupt_after_level,
)


@pytest.mark.slow
def test_a_p1_run_records_its_element_and_resumes_with_it(tmp_path, capsys, monkeypatch):
    full, part = tmp_path / "full", tmp_path / "part"
    args = ["run", "example-6.2", "--element", "p1", "--max-ndof", "1500", "--no-figures"]
    assert main([*args, "--out", str(full), "--quiet"]) == 0
    manifest = json.loads((full / "signorini-run.json").read_text())
    assert manifest["arguments"]["element"] == "P1"
    vtu = meshio.read(full / "level_002.vtu")
    assert [c.type for c in vtu.cells] == ["triangle"]
    with open(full / "history.csv") as f:
        rows = list(csv.DictReader(f))
    ndof = np.array([float(r["ndof"]) for r in rows])
    eta = np.array([float(r["eta"]) for r in rows])
    slope = np.polyfit(np.log(ndof[len(ndof) // 2 :]), np.log(eta[len(eta) // 2 :]), 1)[0]
    print(f"P1 run: {len(rows)} levels to {int(ndof[-1])} unknowns, eta slope {slope:.3f}")
    assert -0.65 <= slope <= -0.4
    interrupt_after_level(monkeypatch, 4)
    assert main([*args, "--out", str(part)]) == 130
    capsys.readouterr()
    monkeypatch.undo()
    resume = ["run", "example-6.2", "--resume", str(part)]
    assert main([*resume, "--element", "p2"]) == 2
    assert "--element P2 (the run has P1)" in capsys.readouterr().err
    assert main([*resume, "--quiet", "--no-figures"]) == 0
    a, b = (
        history_without_timings(full / "history.csv"),
        history_without_timings(part / "history.csv"),
    )
    assert_same_history(a, b)
    names = sorted(p.name for p in full.glob("level_*.vtu"))
    assert names == sorted(p.name for p in part.glob("level_*.vtu"))
    for name in names[4:]:
        assert_same_vtu(full / name, part / name)
    # the mesh figure of a long run reads a readable level's mesh back from its VTU file
    points, cells = read_level_mesh(full / "level_002.vtu")
    assert cells.shape == (int(rows[2]["n_cells"]), 3) and points.shape == (len(vtu.points), 2)
    assert main(["figures", "example-6.2", str(full)]) == 0


def test_an_unknown_element_flag_is_refused(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["run", "example-6.2", "--element", "p3"])
    assert exit_.value.code == 2
    assert "argument --element: invalid choice: 'P3'" in capsys.readouterr().err
