"""Reading a run folder that may come from anyone: its own files, and nothing beyond them.

A results folder may be shared, so any name in it may be a symbolic link to somewhere else,
a named pipe (which blocks whoever opens it for reading), a device (``/dev/zero`` never
ends) or a file far larger than a run writes. The rule, for every file a run owns:

- a run's file or sub-folder that is a symbolic link is refused, never followed (it could
  make a run read, write or delete outside its folder);
- only regular files are opened, checked with ``os.lstat`` before and ``os.fstat`` after an
  ``open`` that neither follows a link nor waits for a writer (``O_NOFOLLOW | O_NONBLOCK``);
- what is read is bounded: a text file (manifest, history) by :data:`MAX_TEXT_BYTES`, an
  ``.npz`` archive by its own size on disk (each array it holds is stored, not compressed,
  so none can be larger than the file).

Each refusal is a :class:`RunFolderError` naming the file and what it is.
"""

from __future__ import annotations

import os
import stat
import zipfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

__all__ = [
    "MAX_TEXT_BYTES",
    "RunFolderError",
    "check_not_linked",
    "open_npz",
    "read_bounded",
    "regular_file",
]

#: the largest manifest or history a run folder may hold (a run writes a few kilobytes per
#: level; 64 MiB is tens of thousands of levels)
MAX_TEXT_BYTES = 64 * 2**20

_NOT_REGULAR = {
    stat.S_IFIFO: "a named pipe",
    stat.S_IFCHR: "a character device",
    stat.S_IFBLK: "a block device",
    stat.S_IFSOCK: "a socket",
    stat.S_IFDIR: "a folder",
    stat.S_IFREG: "a file",
}


class RunFolderError(ValueError):
    """An output folder that cannot be used as asked (the message says why and what to do)."""


def _kind(mode: int) -> str:
    return _NOT_REGULAR.get(stat.S_IFMT(mode), "not a regular file")


def _link_error(path: Path) -> RunFolderError:
    try:
        target = f" (to {os.readlink(path)})"
    except OSError:
        target = ""
    return RunFolderError(
        f"{path} is a symbolic link{target}: a run folder's files and sub-folders are its "
        "own, and signorini never follows a link out of them. Remove the link, or give "
        "another --out folder"
    )


def regular_file(path: str | os.PathLike, follow_links: bool = False) -> os.stat_result | None:
    """The status of ``path`` if it is a regular file, None if it does not exist.

    Raises
    ------
    RunFolderError
        If ``path`` is a symbolic link (unless ``follow_links``) or not a regular file (a
        named pipe, a device, a socket, a folder), naming it and what it is.
    """
    path = Path(path)
    try:
        st = os.stat(path) if follow_links else os.lstat(path)
    except FileNotFoundError:
        return None
    if stat.S_ISLNK(st.st_mode):
        raise _link_error(path)
    if not stat.S_ISREG(st.st_mode):
        raise RunFolderError(f"{path} is {_kind(st.st_mode)}, not a regular file: refused")
    return st


def check_not_linked(path: str | os.PathLike) -> None:
    """Refuse ``path`` if it is a symbolic link (a sub-folder of a run: ``uniform``).

    Raises
    ------
    RunFolderError
        If ``path`` is a symbolic link, or exists and is not a folder.
    """
    path = Path(path)
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return
    if stat.S_ISLNK(st.st_mode):
        raise _link_error(path)
    if not stat.S_ISDIR(st.st_mode):
        raise RunFolderError(f"{path} is {_kind(st.st_mode)}, not a folder: refused")


@contextmanager
def _opened(path: Path, follow_links: bool) -> Iterator[tuple[int, os.stat_result]]:
    """A descriptor of the regular file ``path``, opened without waiting for a writer."""
    flags = os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0)
    if not follow_links:
        flags |= getattr(os, "O_NOFOLLOW", 0)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        if os.path.islink(path):
            raise _link_error(path) from None
        raise RunFolderError(f"cannot read {path}: {exc.strerror}") from None
    try:
        st = os.fstat(fd)  # what was opened, whatever the name points to now
        if not stat.S_ISREG(st.st_mode):
            raise RunFolderError(f"{path} is {_kind(st.st_mode)}, not a regular file: refused")
        os.set_blocking(fd, True)
        yield fd, st
    finally:
        os.close(fd)


def read_bounded(
    path: str | os.PathLike, limit: int = MAX_TEXT_BYTES, follow_links: bool = False
) -> bytes | None:
    """The bytes of the regular file ``path`` (None if it does not exist), at most ``limit``.

    Raises
    ------
    RunFolderError
        If ``path`` is a symbolic link (unless ``follow_links``), not a regular file, or
        larger than ``limit`` bytes.
    """
    path = Path(path)
    if regular_file(path, follow_links) is None:
        return None
    with _opened(path, follow_links) as (fd, st):
        if st.st_size > limit:
            raise RunFolderError(_too_large(path, st.st_size, limit))
        chunks, size = [], 0
        while size <= limit:
            chunk = os.read(fd, min(limit + 1 - size, 2**20))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    if size > limit:  # grew while read
        raise RunFolderError(_too_large(path, size, limit))
    return b"".join(chunks)


def _too_large(path: Path, size: int, limit: int) -> str:
    return (
        f"{path} is {size} bytes, more than the {limit} bytes such a file of a run can be: "
        "refused (not a file signorini wrote)"
    )


@contextmanager
def open_npz(path: str | os.PathLike) -> Iterator[np.lib.npyio.NpzFile | None]:
    """``numpy.load`` of the regular file ``path`` without pickles (None if it does not
    exist), refused if an array it holds claims more bytes than the file has.

    Raises
    ------
    RunFolderError
        If ``path`` is a symbolic link, not a regular file, or an archive whose arrays are
        larger than the file (a compressed archive: signorini writes stored arrays only).
    OSError, ValueError, KeyError, EOFError
        If the archive is unreadable (the caller says what that means).
    """
    path = Path(path)
    if regular_file(path) is None:
        yield None
        return
    with _opened(path, follow_links=False) as (fd, st), open(fd, "rb", closefd=False) as fh:
        try:
            members = zipfile.ZipFile(fh).infolist()
        except zipfile.BadZipFile as exc:
            raise ValueError(f"not an .npz archive ({exc})") from None
        claimed = sum(m.file_size for m in members)
        if claimed > st.st_size:
            raise RunFolderError(
                f"{path} holds {claimed} bytes of arrays in a file of {st.st_size}: refused "
                "(signorini stores its arrays uncompressed)"
            )
        fh.seek(0)
        with np.load(fh, allow_pickle=False) as data:
            yield data
