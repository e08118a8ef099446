"""Run folders (:mod:`signorini.output.run`): ownership, overwrite, resume state."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

from signorini.examples import example_6_2
from signorini.loop import adaptive
from signorini.output.run import MANIFEST, STATE, RunFolder, RunFolderError

PROBLEM = {"name": "example-6.2", "label": "example-6.2", "file": None, "sha256": None}


def test_a_new_run_claims_an_empty_or_missing_folder_and_records_its_files(tmp_path):
    folder, removed = RunFolder.create(tmp_path / "new", PROBLEM, {"theta": 0.4})
    assert removed == []
    folder.add_files("history.csv", "level_000.vtu")
    folder.add_files("history.csv")
    manifest = json.loads((tmp_path / "new" / MANIFEST).read_text())
    assert manifest["files"] == [MANIFEST, "history.csv", "level_000.vtu"]
    assert manifest["status"] == "running" and manifest["arguments"] == {"theta": 0.4}
    assert manifest["problem"] == PROBLEM


def test_a_non_empty_folder_is_refused(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(RunFolderError, match=r"is not empty: it holds 1 file\(s\): notes.txt"):
        RunFolder.create(tmp_path, PROBLEM, {})
    folder, _ = RunFolder.create(tmp_path / "run", PROBLEM, {})
    folder.set_status("finished")
    folder.close()
    with pytest.raises(
        RunFolderError, match=r"it holds a run of example-6.2 \(finished\). Give --overwrite"
    ):
        RunFolder.create(tmp_path / "run", PROBLEM, {})
    (tmp_path / "file").write_text("x")
    with pytest.raises(RunFolderError, match="is an existing file, not a folder"):
        RunFolder.create(tmp_path / "file", PROBLEM, {})


def test_overwrite_removes_exactly_the_old_runs_files(tmp_path):
    out = tmp_path / "run"
    folder, _ = RunFolder.create(out, PROBLEM, {})
    ours = [
        *(f"level_{i:03d}.vtu" for i in range(34)),
        "history.csv",
        "history.md",
        STATE,
        "example-6.2_estimator.png",
        "mesh.pdf",
        "listed.png",
        "uniform/history.csv",
        ".level_029.vtu.ab_12xyz.vtu",
    ]
    (out / "uniform").mkdir()
    for name in ours:
        (out / name).write_bytes(b"")
    folder.add_files("listed.png", "listed.dat")  # a manifest may list any name
    folder.close()
    theirs = ["notes.txt", "level_1.vtu", "photo.png", "uniform/mine.csv", "sub/level_000.vtu"]
    theirs += ["listed.dat"]  # not of a kind a run writes
    (out / "sub").mkdir()
    for name in theirs:
        (out / name).write_text("keep")
    new, removed = RunFolder.create(out, PROBLEM, {"uniform": True}, overwrite=True)
    assert sorted(str(p.relative_to(out)) for p in removed) == sorted([*ours, MANIFEST])
    left = sorted(os.path.relpath(os.path.join(d, f), out) for d, _, fs in os.walk(out) for f in fs)
    assert left == sorted([*theirs, MANIFEST])
    assert new.manifest["arguments"] == {"uniform": True}


def test_saved_state_rebuilds_the_mesh_and_warm_start_exactly(tmp_path):
    levels = list(adaptive(example_6_2(), max_ndof=700))
    folder, _ = RunFolder.create(tmp_path / "r", PROBLEM, {})
    rows = "level,ndof,eta\n" + "".join(f"{i},{10 + i},{i / 3!r}\n" for i in range(len(levels)))
    (tmp_path / "r" / "history.csv").write_text(rows)
    for name in ("level_000.vtu", "level_003.vtu", "level_004.vtu"):
        (tmp_path / "r" / name).write_bytes(b"")
    k = 3
    lv = levels[k]
    folder.save_state(k, lv.next_mesh, lv.next_u0, final=False)
    folder.close()
    state = RunFolder.open(tmp_path / "r").restart()
    assert (state.level, state.final) == (k, False)
    for name in ("points", "cells", "boundary", "boundary_part"):
        np.testing.assert_array_equal(getattr(state.mesh, name), getattr(lv.next_mesh, name))
    assert state.mesh.part_names == lv.next_mesh.part_names
    np.testing.assert_array_equal(state.u0, lv.next_u0)
    assert [r["level"] for r in state.history_rows] == ["0", "1", "2", "3"]
    assert state.history_rows[1]["eta"] == repr(1 / 3)
    # the files of later levels are gone, the earlier ones kept
    assert sorted(p.name for p in (tmp_path / "r").glob("*.vtu")) == [
        "level_000.vtu",
        "level_003.vtu",
    ]


def test_resume_refuses_what_it_cannot_continue(tmp_path):
    with pytest.raises(RunFolderError, match="cannot resume: .* is not a folder"):
        RunFolder.open(tmp_path / "none")
    with pytest.raises(RunFolderError, match=f"holds no {MANIFEST}"):
        RunFolder.open(tmp_path)
    folder, _ = RunFolder.create(tmp_path / "r", PROBLEM, {})
    folder.close()
    (tmp_path / "r" / STATE).write_bytes(b"garbage")
    with pytest.raises(RunFolderError, match="is unreadable"):
        reopened = RunFolder.open(tmp_path / "r")
        try:
            reopened.restart()
        finally:
            reopened.close()
    mesh = example_6_2().mesh
    folder.save_state(2, mesh, None, final=False)
    with pytest.raises(RunFolderError, match="has 0 level"):
        RunFolder.open(tmp_path / "r").restart()
