"""Reading a run folder's files (:mod:`signorini.output.guard`): regular files only, links
never followed, named pipes never waited on, reads bounded."""

from __future__ import annotations

import os

import numpy as np
import pytest

from signorini.output import read_history
from signorini.output.check import read_check
from signorini.output.guard import (
    MAX_TEXT_BYTES,
    RunFolderError,
    check_not_linked,
    open_npz,
    read_bounded,
)
from signorini.output.run import RunFolder

from .test_run import PROBLEM


def test_a_named_pipe_is_refused_without_being_waited_on(tmp_path, no_blocking):
    pipe = tmp_path / "history.csv"
    os.mkfifo(pipe)
    with pytest.raises(RunFolderError, match=f"^{pipe} is a named pipe, not a regular file"):
        read_bounded(pipe)
    with pytest.raises(ValueError, match="is a named pipe"):
        read_history(pipe)
    os.mkfifo(tmp_path / "signorini-check.npz")
    with pytest.raises(RunFolderError, match="signorini-check.npz is a named pipe"):
        read_check(tmp_path)


def test_a_link_is_not_followed_and_a_device_not_read(tmp_path):
    link = tmp_path / "history.csv"
    link.symlink_to("/dev/zero")
    with pytest.raises(RunFolderError, match=r"is a symbolic link \(to /dev/zero\)"):
        read_bounded(link)
    # a history named by the user may be a link, but not to a device read without end
    with pytest.raises(ValueError, match="is a character device, not a regular file"):
        read_history(link)
    (tmp_path / "uniform").symlink_to(tmp_path, target_is_directory=True)
    with pytest.raises(RunFolderError, match="uniform is a symbolic link"):
        check_not_linked(tmp_path / "uniform")
    assert read_bounded(tmp_path / "missing") is None
    (tmp_path / "sub").write_text("")
    with pytest.raises(RunFolderError, match="sub is a file, not a folder: refused"):
        check_not_linked(tmp_path / "sub")


def test_a_file_larger_than_a_run_writes_is_refused_before_it_is_read(tmp_path):
    big = tmp_path / "history.csv"
    with open(big, "wb") as fh:
        fh.truncate(MAX_TEXT_BYTES + 1)  # sparse: nothing is written, nor read
    with pytest.raises(ValueError, match=f"is {MAX_TEXT_BYTES + 1} bytes, more than the"):
        read_history(big)
    small = tmp_path / "small.txt"
    small.write_bytes(b"12345")
    assert read_bounded(small, limit=5) == b"12345"
    with pytest.raises(RunFolderError, match="is 5 bytes, more than the 4 bytes"):
        read_bounded(small, limit=4)


def test_an_archive_claiming_more_than_its_size_is_refused(tmp_path):
    """signorini stores its arrays; a compressed archive could hold gigabytes of zeros."""
    np.savez(tmp_path / "stored.npz", a=np.zeros(10_000))
    with open_npz(tmp_path / "stored.npz") as data:
        assert data["a"].shape == (10_000,)
    np.savez_compressed(tmp_path / "bomb.npz", a=np.zeros(10_000))
    with pytest.raises(RunFolderError, match=r"holds 80\d+ bytes of arrays in a file of"):
        with open_npz(tmp_path / "bomb.npz"):
            pass
    with open_npz(tmp_path / "none.npz") as data:
        assert data is None


def test_the_uniform_sub_folder_is_never_a_link(tmp_path):
    """A link made while the run writes is refused before the comparison writes into it."""
    other = tmp_path / "elsewhere"
    other.mkdir()
    folder, _ = RunFolder.create(tmp_path / "r", PROBLEM, {})
    assert folder.sub_folder("uniform") == tmp_path / "r" / "uniform"
    (tmp_path / "r" / "uniform").rmdir()
    (tmp_path / "r" / "uniform").symlink_to(other, target_is_directory=True)
    with pytest.raises(RunFolderError, match=f"uniform is a symbolic link \\(to {other}\\)"):
        folder.sub_folder("uniform")
    folder.close()
    assert os.listdir(other) == []
