"""Results folders under hostile use, as a shared results directory invites: links named like a
run's files or its ``uniform`` sub-folder, named pipes, a history linked to ``/dev/zero``, an
edited manifest, a missing resume state. A run never acts outside its folder, never waits on
a pipe, never reads without bound and never replaces finished levels of another problem.

A test that meets a named pipe would block forever if the code opened it: the code checks
each file with ``os.lstat`` and opens with ``O_NONBLOCK``, and :func:`no_blocking` turns a
regression into a failure (an alarm interrupts the blocked ``open``) instead of a hang."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from test_cli import interrupt_after_level

from signorini.cli import main

PART = ["run", "example-6.2", "--max-ndof", "3000", "--no-figures", "--quiet"]


@pytest.fixture(scope="module")
def interrupted(tmp_path_factory) -> Path:
    """A run of example-6.2 interrupted after level 2 (levels 0-2 finished)."""
    out = tmp_path_factory.mktemp("template") / "part"
    with pytest.MonkeyPatch.context() as mp:
        interrupt_after_level(mp, 2)
        assert main([*PART, "--out", str(out)]) == 130
    return out


@pytest.fixture
def part(interrupted, tmp_path) -> Path:
    """A copy of the interrupted run, to spoil."""
    return Path(shutil.copytree(interrupted, tmp_path / "part"))


def snapshot(folder: Path) -> dict[str, bytes]:
    """Every regular file under ``folder`` (links not followed) and its bytes."""
    files = {}
    for root, _, names in os.walk(folder):
        for name in names:
            path = Path(root) / name
            if path.is_file() and not path.is_symlink():
                files[str(path.relative_to(folder))] = path.read_bytes()
    return files


def resume(problem: str, folder: Path) -> list[str]:
    return ["run", problem, "--resume", str(folder), "--quiet", "--no-figures"]


# ---------------------------------------------------------------------- links out of the folder
def elsewhere_with_a_runs_names(tmp_path: Path) -> Path:
    """A folder outside the run holding files named like a run's, and the user's notes."""
    other = tmp_path / "elsewhere"
    other.mkdir()
    for name in ("history.csv", "history.md", "level_000.vtu", "notes.txt"):
        (other / name).write_text(f"the user's {name}")
    return other


def test_a_uniform_link_out_of_the_folder_is_refused_and_nothing_outside_is_touched(
    part, tmp_path, capsys
):
    """``uniform -> elsewhere/`` with a manifest listing ``uniform/notes.txt``: --overwrite
    removed history.csv, history.md, level_000.vtu and notes.txt outside the folder, and
    --compare-uniform wrote through the link."""
    other = elsewhere_with_a_runs_names(tmp_path)
    manifest = json.loads((part / "signorini-run.json").read_text())
    manifest["files"].append("uniform/notes.txt")
    (part / "signorini-run.json").write_text(json.dumps(manifest))
    (part / "uniform").symlink_to(other, target_is_directory=True)
    outside, inside = snapshot(other), snapshot(part)
    capsys.readouterr()
    refused = (
        f"{part / 'uniform'} is a symbolic link (to {other}): a run folder's files and "
        "sub-folders are its own, and signorini never follows a link out of them. Remove the "
        "link, or give another --out folder\n"
    )
    again = [*PART, "--max-levels", "1", "--out", str(part)]
    for argv in ([*again, "--overwrite"], [*again, "--overwrite", "--compare-uniform"]):
        assert main(argv) == 2
        assert capsys.readouterr().err == f"signorini: error: {refused}"
    assert main(resume("example-6.2", part)) == 2
    assert capsys.readouterr().err == f"signorini: error: cannot resume: {refused}"
    assert main(["figures", "example-6.2", str(part)]) == 2
    assert capsys.readouterr().err == f"signorini: error: cannot draw the figures: {refused}"
    assert snapshot(other) == outside and snapshot(part) == inside


def test_a_link_named_like_a_runs_file_is_refused(part, tmp_path, capsys):
    other = elsewhere_with_a_runs_names(tmp_path)
    (part / "history.md").unlink()
    (part / "history.md").symlink_to(other / "history.md")
    inside = snapshot(part)
    assert main([*PART, "--out", str(part), "--overwrite"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"signorini: error: {part / 'history.md'} is a symbolic link (to ")
    assert snapshot(part) == inside and (other / "history.md").read_text() == (
        "the user's history.md"
    )


def test_a_manifest_listing_a_users_file_does_not_make_overwrite_remove_it(part, capsys):
    file = part / "signorini-run.json"
    manifest = json.loads(file.read_text())
    manifest["files"] += ["notes.txt", "uniform/notes.txt"]
    file.write_text(json.dumps(manifest))
    (part / "uniform").mkdir()
    for notes in (part / "notes.txt", part / "uniform" / "notes.txt"):
        notes.write_text("the user's notes")
    assert main([*PART, "--max-levels", "1", "--out", str(part), "--overwrite"]) == 0
    assert (part / "notes.txt").read_text() == "the user's notes"
    assert (part / "uniform" / "notes.txt").read_text() == "the user's notes"
    assert len(list(part.glob("level_*.vtu"))) == 1


def test_a_history_linked_to_dev_zero_is_not_read(part, capsys):
    """Read, it would fill the memory."""
    (part / "history.csv").unlink()
    (part / "history.csv").symlink_to("/dev/zero")
    assert main(resume("example-6.2", part)) == 2
    err = capsys.readouterr().err
    assert err.startswith(
        f"signorini: error: cannot resume: {part / 'history.csv'} is a symbolic link (to /dev/zero)"
    )
    assert main(["figures", "example-6.2", str(part)]) == 2
    assert "is a symbolic link (to /dev/zero)" in capsys.readouterr().err


# ---------------------------------------------------------------------- named pipes
@pytest.mark.parametrize("name", ["signorini-run.json", "signorini-check.npz", "resume.npz"])
def test_a_named_pipe_among_a_runs_files_is_refused_without_waiting(
    part, capsys, no_blocking, name
):
    (part / name).unlink()
    os.mkfifo(part / name)
    refused = f"{part / name} is a named pipe, not a regular file: refused\n"
    # another problem: the identity check is never skipped for a pipe as the resume state
    for problem in ("example-6.2", "example-6.1"):
        assert main(resume(problem, part)) == 2
        assert capsys.readouterr().err == f"signorini: error: cannot resume: {refused}"
    assert main([*PART, "--out", str(part), "--overwrite"]) == 2
    assert capsys.readouterr().err == f"signorini: error: {refused}"
    assert main(["figures", "example-6.2", str(part)]) == 2
    assert capsys.readouterr().err == f"signorini: error: cannot draw the figures: {refused}"
    assert (part / "history.csv").is_file() and len(list(part.glob("level_*.vtu"))) == 3


# ---------------------------------------------------------------------- a missing resume state
def test_resume_without_resume_npz_checks_the_problem_and_keeps_the_levels(part, capsys):
    """With resume.npz missing, --resume of another problem skipped the identity check and
    replaced the finished levels."""
    (part / "resume.npz").unlink()
    before = snapshot(part)
    assert main(resume("example-6.1", part)) == 2
    err = capsys.readouterr().err
    assert f"--resume {part}: example-6.1 is not the problem of the run in {part}" in err
    assert main(resume("example-6.2", part)) == 2
    assert capsys.readouterr().err == (
        f"signorini: error: cannot resume: {part / 'history.csv'} holds 3 finished level(s) "
        f"but {part} holds no resume.npz, the state to continue from, so resuming would "
        "replace them: start again with --overwrite (which removes them), or give another "
        "--out folder\n"
    )
    (part / "signorini-check.npz").unlink()
    assert main(resume("example-6.1", part)) == 2
    assert f"{part} holds no readable signorini-check.npz" in capsys.readouterr().err
    before.pop("signorini-check.npz")
    assert snapshot(part) == before  # the levels, their history and the manifest as they were


# ---------------------------------------------------------------------- an edited manifest
@pytest.mark.parametrize(
    "key, value, text",
    [
        (
            "max_ndof",
            float("inf"),
            "records max_ndof = Infinity, which --max-ndof never takes (an integer)",
        ),
        (
            "max_ndof",
            3000.5,
            "records max_ndof = 3000.5, which --max-ndof never takes (an integer)",
        ),
        (
            "max_levels",
            True,
            "records max_levels = true, which --max-levels never takes (an integer)",
        ),
        ("theta", "0.4", 'records theta = "0.4", which --theta never takes (a number)'),
        ("no_vtu", "yes", 'records no_vtu = "yes", which --no-vtu never takes (true or false)'),
        ("shell", "rm -rf", "records an unknown argument 'shell'"),
    ],
)
def test_a_manifests_options_are_checked_as_strictly_as_the_command_lines(
    part, capsys, key, value, text
):
    """``"max_ndof": Infinity`` made --resume refine without a budget."""
    file = part / "signorini-run.json"
    manifest = json.loads(file.read_text())
    manifest["arguments"][key] = value
    if key == "max_ndof":
        manifest["arguments"]["max_levels"] = 5  # a regression ends, without a budget too
    file.write_text(json.dumps(manifest))
    levels = sorted(p.name for p in part.glob("level_*.vtu"))
    assert main(resume("example-6.2", part)) == 2
    assert capsys.readouterr().err == (
        f"signorini: error: {file} {text}; it was edited or not written by signorini: start "
        "a new run (--overwrite)\n"
    )
    assert sorted(p.name for p in part.glob("level_*.vtu")) == levels


def test_a_manifest_that_is_not_json_is_reported_as_such(part, capsys):
    """It was reported as missing ("holds no signorini-run.json")."""
    file = part / "signorini-run.json"
    file.write_text('{"files": [')
    fault = f"{file} is not JSON (Expecting value: line 1 column 12)"
    assert main(resume("example-6.2", part)) == 2
    assert capsys.readouterr().err == f"signorini: error: cannot resume: {fault}\n"
    assert main(["figures", "example-6.2", str(part)]) == 2
    assert capsys.readouterr().err == f"signorini: error: cannot draw the figures: {fault}\n"
    assert main([*PART, "--out", str(part)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"signorini: error: output folder {part} is not empty: it holds ")
    assert f"({fault}). Give --overwrite" in err
    file.write_text('["a list"]')
    assert main(resume("example-6.2", part)) == 2
    assert capsys.readouterr().err == (
        f"signorini: error: cannot resume: {file} is JSON but not the manifest of a run (an "
        "object whose 'files' lists the names of the run's files)\n"
    )


# ---------------------------------------------------------------------- an edited state or history
@pytest.mark.parametrize(
    "change, fault",
    [
        ({"level": np.array(-1)}, "says level -1 finished: not a state signorini saved"),
        ({"u0": np.zeros((7, 2))}, "holds a warm start of shape (7, 2) on a 2D mesh of"),
        ({"u0": np.full((1, 1), np.nan)}, "holds a warm start of shape (1, 1)"),
    ],
)
def test_an_edited_resume_state_is_refused_naming_the_file(part, capsys, change, fault):
    file = part / "resume.npz"
    with np.load(file) as data:
        arrays = {name: data[name] for name in data.files}
    np.savez(file, **{**arrays, **change})
    assert main(resume("example-6.2", part)) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"signorini: error: cannot resume: {file} {fault}"), err


def test_an_edited_history_is_refused_before_the_run_goes_on(part, capsys):
    file = part / "history.csv"
    lines = file.read_text().splitlines()
    lines[2] = "x" + lines[2][1:]  # level 1's index
    file.write_text("\n".join(lines) + "\n")
    assert main(resume("example-6.2", part)) == 2
    assert capsys.readouterr().err == (
        f"signorini: error: cannot resume: line 3 of {file} is not the row of level 1 of a "
        "run (its level, its ndof or its number of fields); start again with --overwrite\n"
    )
    assert json.loads((part / "signorini-run.json").read_text())["status"] == "interrupted"
