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


def test_a_killed_write_leaves_a_recognisable_temporary_that_is_removed(tmp_path):
    """A process killed inside a write (here: ``os._exit``, as SIGKILL would) leaves its
    temporary file; its name marks it, and :func:`remove_temporaries` removes exactly it."""
    import subprocess
    import sys

    code = (
        "import os, sys\n"
        "from signorini.output.files import replacing\n"
        "with replacing(sys.argv[1]) as tmp:\n"
        "    tmp.write_bytes(b'half')\n"
        "    os._exit(9)\n"
    )
    target = tmp_path / "level_029.vtu"
    proc = subprocess.run([sys.executable, "-c", code, str(target)], timeout=60)
    assert proc.returncode == 9
    left = os.listdir(tmp_path)
    print(left)
    assert len(left) == 1 and left[0].startswith(".level_029.vtu.")
    assert left[0].endswith(files.TEMP_SUFFIX) and files.is_temporary(left[0])
    # a leftover of earlier versions, and files that only look alike, which stay
    (tmp_path / ".level_029.vtu.k2x_9abc.vtu").write_bytes(b"")
    keep = ["level_029.vtu", "notes.vtu", ".hidden.vtu", ".a.b.signorini-tmp.txt"]
    for name in keep:
        (tmp_path / name).write_bytes(b"x")
    removed = files.remove_temporaries(tmp_path)
    assert sorted(p.name for p in removed) == sorted([left[0], ".level_029.vtu.k2x_9abc.vtu"])
    assert sorted(os.listdir(tmp_path)) == sorted(keep)
    assert files.remove_temporaries(tmp_path / "missing") == []


def test_a_same_name_write_killed_leaves_a_folder_that_is_removed(tmp_path):
    """``replacing(path, same_name=True)`` (figures: matplotlib reads the format from the
    name) writes ``NAME`` inside a temporary folder; killed, that folder is what is left, and
    :func:`remove_temporaries` removes it; done, only the target is left."""
    import subprocess
    import sys

    target = tmp_path / "mesh.png"
    with files.replacing(target, same_name=True) as tmp:
        assert tmp.name == "mesh.png" and tmp.parent != tmp_path
        tmp.write_bytes(b"png")
    assert os.listdir(tmp_path) == ["mesh.png"] and target.read_bytes() == b"png"
    code = (
        "import os, sys\n"
        "from signorini.output.files import replacing\n"
        "with replacing(sys.argv[1], same_name=True) as tmp:\n"
        "    tmp.write_bytes(b'')\n"
        "    os._exit(9)\n"
    )
    proc = subprocess.run([sys.executable, "-c", code, str(target)], timeout=60)
    assert proc.returncode == 9
    left = sorted(set(os.listdir(tmp_path)) - {"mesh.png"})
    assert len(left) == 1 and files.is_temporary(left[0]) and (tmp_path / left[0]).is_dir()
    assert target.read_bytes() == b"png"  # the finished figure untouched
    removed = files.remove_temporaries(tmp_path)
    assert [p.name for p in removed] == left and os.listdir(tmp_path) == ["mesh.png"]
