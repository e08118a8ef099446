"""Atomic file replacement (:mod:`signorini.output.files`)."""

from __future__ import annotations

import os
import stat

import pytest

import signorini.output.files as files
from signorini.output.files import atomic_write, replacing


@pytest.mark.parametrize("umask", [0o022, 0o077])
def test_written_files_follow_the_umask(tmp_path, umask):
    """Results are ordinary files: mode 0o666 minus the umask, like ``open(..., "w")``."""
    old = os.umask(umask)
    try:
        atomic_write(tmp_path / "a.bin", b"data")
        with open(tmp_path / "plain.txt", "w") as fh:
            fh.write("x")
    finally:
        os.umask(old)
    modes = {n: stat.S_IMODE(os.stat(tmp_path / n).st_mode) for n in ("a.bin", "plain.txt")}
    print({k: oct(v) for k, v in modes.items()})
    assert modes["a.bin"] == modes["plain.txt"] == 0o666 & ~umask


def test_replaces_and_leaves_no_temporary_file(tmp_path):
    path = tmp_path / "sub" / "f.txt"
    assert atomic_write(path, b"one") == path
    atomic_write(path, b"two")
    assert path.read_bytes() == b"two"
    assert os.listdir(tmp_path / "sub") == ["f.txt"]


def test_a_failed_write_keeps_the_old_file(tmp_path, monkeypatch):
    path = tmp_path / "f.txt"
    atomic_write(path, b"old")

    def fail(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(files.os, "replace", fail)
    with pytest.raises(OSError, match="disk full"):
        atomic_write(path, b"new")
    monkeypatch.undo()
    with pytest.raises(RuntimeError, match="interrupted"), replacing(path) as tmp:
        tmp.write_bytes(b"partial")
        raise RuntimeError("interrupted")
    assert path.read_bytes() == b"old"
    assert os.listdir(tmp_path) == ["f.txt"]
