"""Atomic file replacement: an interrupted run never leaves a half-written file behind.

Each file is written to a temporary file in the same folder, then moved over the target with
``os.replace``. A temporary file is named ``.<target name>.<8 random characters>.signorini-tmp``
(with ``same_name``, a file of the target's own name in a temporary folder of that name, for
writers that read the format from the name: matplotlib's ``savefig``); if the process is
killed before the move, :func:`remove_temporaries` recognises and removes it (the command
line does so at the start of every run into a folder).
"""

from __future__ import annotations

import os
import re
import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = [
    "TEMP_SUFFIX",
    "atomic_write",
    "describe_names",
    "folder_listing",
    "remove_temporaries",
    "replacing",
]

#: Ending of every temporary file the atomic writers create.
TEMP_SUFFIX = ".signorini-tmp"

# ".<name>.<mkstemp's 8 characters><suffix>"; ".tmp" and ".vtu" were the suffixes of
# earlier versions, whose leftovers are removed too
_TEMPORARY = re.compile(r"^\..+\.[a-z0-9_]{8}(\.signorini-tmp|\.tmp|\.vtu)$")


@contextmanager
def replacing(path: str | os.PathLike, same_name: bool = False) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success it replaces ``path`` atomically.

    On any exception (KeyboardInterrupt included) the temporary file is removed and ``path``
    is left as it was. With ``same_name`` the temporary path has the name of ``path`` (in a
    temporary folder beside it).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if same_name:
        folder = tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}.", suffix=TEMP_SUFFIX)
        try:
            tmp = Path(folder) / path.name  # created by the writer, with open()'s mode
            yield tmp
            os.replace(tmp, path)
        finally:
            shutil.rmtree(folder, ignore_errors=True)
        return
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=TEMP_SUFFIX)
    os.close(fd)
    try:
        yield Path(tmp)
        # mkstemp makes the file private (0o600); give it the mode open() would
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_write(path: str | os.PathLike, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically."""
    with replacing(path) as tmp, open(tmp, "wb") as fh:
        fh.write(data)
        fh.flush()
        os.fsync(fh.fileno())
    return Path(path)


def is_temporary(name: str) -> bool:
    """Whether a file name is that of a temporary file left by an atomic writer."""
    return _TEMPORARY.match(name) is not None


def remove_temporaries(folder: str | os.PathLike) -> list[Path]:
    """Remove the temporary files an interrupted atomic write left in ``folder``.

    Returns
    -------
    list of Path
        The files removed (none if ``folder`` does not exist).
    """
    folder = Path(folder)
    if not folder.is_dir():
        return []
    removed = []
    for entry in os.scandir(folder):
        if not is_temporary(entry.name):
            continue
        if entry.is_file(follow_symlinks=False):
            Path(entry.path).unlink(missing_ok=True)
            removed.append(Path(entry.path))
        elif entry.is_dir(follow_symlinks=False) and entry.name.endswith(TEMP_SUFFIX):
            shutil.rmtree(entry.path, ignore_errors=True)  # a same-name write's folder
            removed.append(Path(entry.path))
    return removed


def folder_listing(folder: Path) -> list[str]:
    """The names in ``folder``, sorted (none if it is not a folder)."""
    return sorted(os.listdir(folder)) if folder.is_dir() else []


def describe_names(names: list[str]) -> str:
    """The first four of ``names`` and how many more, for a message."""
    shown = ", ".join(names[:4])
    return shown + (f" and {len(names) - 4} more" if len(names) > 4 else "")
