"""Run folders: a run owns its output folder, and an interrupted run can be continued.

The rule (one for every run of the command line):

- A run writes ``signorini-run.json`` (the *manifest*) into its folder before anything else:
  the problem, the arguments that decide the numbers and the files, the run's status
  (``running``, ``interrupted``, ``failed``, ``finished``) and the name of every file the
  run writes, recorded before the file is written.
- A run starts only in a folder that does not exist or is empty. A non-empty folder is
  refused unless ``overwrite`` is given; then exactly the old run's files are removed first:
  the names the command line writes (``level_NNN.vtu``, ``history.csv``, ``history.md``,
  ``resume.npz``, ``uniform/history.csv``, the manifest, and with a manifest the figures
  named after its problem), plus those its manifest lists that are of a kind a run writes
  (:mod:`.run_files`). Any other file stays.
- Temporary files of interrupted atomic writes (:func:`~signorini.output.files.is_temporary`)
  are removed by the next run into the folder, whatever its options.
- After each finished level the run saves ``resume.npz`` atomically: that level's index, the
  next level's mesh exactly as stored (points, cells in their vertex order, which fixes the
  refinement edges of newest vertex bisection, boundary edges and parts) and its warm start
  (the solution prolongated to that mesh); after the run's last level, that level's own
  mesh and solution, from which the figures can be drawn again. :meth:`RunFolder.restart`
  reads it back, so that the loop continues where it stopped and yields the levels an
  uninterrupted run yields. A finished run removes it.
- After its first level the run saves that level's problem data in ``signorini-check.npz``
  (:mod:`.check`): a resumed run, and ``signorini figures``, rebuild the problem the user
  names and compare, so that one folder never holds the levels of two problems.
- Paths are resolved (``os.path.realpath``) before any check: ``--out newdir/..`` is the
  folder it names, and is refused if it is not empty.
- Inside the folder nothing is followed or waited for (:mod:`.guard`, :mod:`.run_files`): a
  folder where a run's file or its ``uniform`` sub-folder is a symbolic link, a named pipe
  or a device is refused before anything is read, written or removed, and what is read is
  bounded. A manifest that is not JSON is reported as such, naming the file.
- ``--resume`` checks the run's problem (:mod:`.check`) whenever the folder holds anything a
  level saved, whatever file is missing, and refuses to start again from level 0 over the
  finished levels of a history when ``resume.npz`` is missing.
- A run that fails records ``failed`` as its status and the error that stopped it.
- A run holds an OS lock on its folder (``fcntl.flock`` on the folder itself, released when
  the process ends, however it ends): a second run into a folder that a live process is
  writing, or a ``--resume`` of it, is refused; a folder whose writer died (SIGKILL) is not
  locked, and is reported as stopped, not running.
- The manifest records the environment of the run (:func:`environment`): the versions of
  signorini, Python, NumPy, SciPy and the solver library, the date and the host.
"""

from __future__ import annotations

import csv
import errno
import hashlib
import io
import json
import os
import re
from pathlib import Path

try:  # POSIX; elsewhere runs are not locked
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None

import numpy as np

from ..mesh.mesh import Mesh
from .check import CHECK
from .files import atomic_write, describe_names, folder_listing, remove_temporaries
from .guard import RunFolderError, check_not_linked, read_bounded
from .run_files import (
    MANIFEST,
    UNIFORM,
    check_entries,
    load_manifest,
    problem_text,
    read_manifest,
    remove_run_files,
)
from .state import STATE, ResumeState, read_state, write_state

__all__ = [
    "MANIFEST",
    "STATE",
    "RunFolder",
    "RunFolderError",
    "ResumeState",
    "file_digest",
    "resolved",
]


_FORMAT = 1


def resolved(path: str | os.PathLike) -> Path:
    """``path`` as the absolute folder it names, ``..`` and symbolic links resolved (a path
    through a missing folder, ``newdir/..``, is the folder it ends in)."""
    return Path(os.path.realpath(os.path.abspath(os.fspath(path))))


def _lock(path: Path) -> int | None:
    """An exclusive OS lock on the folder ``path`` (its file descriptor), None if another
    process holds it. The lock dies with the process that holds it."""
    if fcntl is None:  # pragma: no cover - Windows
        return -1
    fd = os.open(path, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as exc:
        os.close(fd)
        if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
            return None
        raise
    return fd


def _writer(manifest: dict) -> str:
    """Who holds the lock, as the manifest says (``pid 123 on host``)."""
    env = manifest.get("environment", {}) if isinstance(manifest, dict) else {}
    pid, host = manifest.get("pid"), env.get("host") if isinstance(env, dict) else None
    return f" (pid {pid}{f' on {host}' if host else ''})" if pid else ""


def _count(text: str | None) -> bool:
    """Whether a history entry is a positive integer, as the loop writes ``ndof``."""
    return text is not None and text.isascii() and text.isdigit() and int(text) > 0


def file_digest(path: str | os.PathLike) -> str:
    """SHA-256 of a file's bytes, as hex."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


class RunFolder:
    """The output folder of one run and its manifest.

    Use :meth:`create` for a new run; :meth:`open` and :meth:`restart` to continue an
    interrupted one.
    """

    def __init__(self, path: Path, manifest: dict, lock: int | None = None) -> None:
        self.path = path
        self.manifest = manifest
        self._lock = lock

    # ------------------------------------------------------------------ opening
    @classmethod
    def create(
        cls,
        path: str | os.PathLike,
        problem: dict,
        arguments: dict,
        *,
        overwrite: bool = False,
        environment: dict | None = None,
    ) -> tuple[RunFolder, list[Path]]:
        """Claim ``path`` for a new run, lock it and write its manifest.

        Parameters
        ----------
        path : folder (created if missing; resolved first, see :func:`resolved`)
        problem : dict
            How the run names its problem (JSON-serialisable; text for the user only:
            ``--resume`` checks the problem by its data, :mod:`.check`).
        arguments : dict
            The run's settings, JSON-serialisable, stored as they are: the command line
            gives the loop's options by field name (``AdaptiveOptions.to_record()``, the
            solver by its registry name) and its own file flags; ``--resume`` rebuilds the
            options from them (``AdaptiveOptions.from_record``, which also reads the keys
            ``eta5`` and ``backend`` of manifests written before).
        overwrite : bool
            Remove a previous run's files from a non-empty folder instead of refusing it.
        environment : dict, optional
            Where the run runs (:func:`~.environment.environment`), recorded as it is.

        Returns
        -------
        (RunFolder, list of Path)
            The folder (locked until :meth:`close` or the process ends), and the files
            removed (temporary files and, with ``overwrite``, the previous run's files).

        Raises
        ------
        RunFolderError
            If ``path`` is an existing file, a folder another live process is writing, a
            non-empty folder without ``overwrite``, or a folder where a file or sub-folder
            of a run is a symbolic link or not a regular file (:func:`~.run_files.check_entries`).
        """
        path = resolved(path)
        cls._check_is_folder(path)
        path.mkdir(parents=True, exist_ok=True)
        lock = cls._claim(path, "output folder")
        try:
            check_entries(path)
            removed = remove_temporaries(path) + remove_temporaries(path / UNIFORM)
            present = folder_listing(path)
            if present and not overwrite:
                try:
                    old, fault = load_manifest(path), ""
                except RunFolderError as exc:
                    old, fault = None, f" ({exc})"
                what = (
                    f"it holds a run of {problem_text(old)} ({cls._status_of(old)})"
                    if old
                    else f"it holds {len(present)} file(s): {describe_names(present)}{fault}"
                )
                raise RunFolderError(
                    f"output folder {path} is not empty: {what}. Give --overwrite to remove "
                    f"that run's files first (only the files a run writes), --resume {path} "
                    "to continue an interrupted run, or another --out folder"
                )
            if present:
                removed += remove_run_files(path)
            folder = cls(
                path,
                {
                    "format": _FORMAT,
                    "problem": problem,
                    "arguments": arguments,
                    "status": "running",
                    "files": [MANIFEST],
                    "pid": os.getpid(),
                    "environment": dict(environment or {}),
                },
                lock,
            )
            folder._write_manifest()
        except BaseException:
            cls._unlock(lock)
            raise
        return folder, removed

    @classmethod
    def open(cls, path: str | os.PathLike, purpose: str = "resume") -> RunFolder:
        """The folder of an earlier run, locked, to check it before :meth:`restart` (or to
        draw its figures: ``purpose`` is the verb of the error messages).

        Raises
        ------
        RunFolderError
            If ``path`` is not a folder with a manifest (a JSON object listing the run's
            files), another live process is writing it, or a file or sub-folder of the run
            in it is a symbolic link or not a regular file (:func:`~.run_files.check_entries`).
        """
        path = resolved(path)
        if not path.is_dir():
            raise RunFolderError(f"cannot {purpose}: {path} is not a folder")
        try:
            manifest = load_manifest(path)
            if manifest is None:
                raise RunFolderError(f"{path} holds no {MANIFEST}, so no run of signorini wrote it")
            lock = cls._claim(path, "the folder")
        except RunFolderError as exc:
            raise RunFolderError(f"cannot {purpose}: {exc}") from None
        try:
            check_entries(path)
        except RunFolderError as exc:
            cls._unlock(lock)
            raise RunFolderError(f"cannot {purpose}: {exc}") from None
        return cls(path, manifest, lock)

    @property
    def file(self) -> Path:
        """The manifest's file."""
        return self.path / MANIFEST

    def close(self) -> None:
        """Release the folder's lock (also released when the process ends)."""
        lock, self._lock = self._lock, None
        self._unlock(lock)

    @classmethod
    def _claim(cls, path: Path, what: str) -> int | None:
        lock = _lock(path)
        if lock is None:
            old = read_manifest(path) or {}
            raise RunFolderError(
                f"{what} {path} is being written by another process{_writer(old)}, a run of "
                f"{problem_text(old)}: wait until it ends (or stop it: it keeps its finished "
                "levels), then --resume or --overwrite it"
            )
        return lock

    @staticmethod
    def _unlock(lock: int | None) -> None:
        if lock is not None and lock >= 0:
            os.close(lock)  # closing the descriptor releases the flock

    @staticmethod
    def _status_of(manifest: dict) -> str:
        """The status a manifest records; "running" of a folder nobody holds (the caller
        has the lock) means its process ended without saying so (SIGKILL, power loss)."""
        status = str(manifest.get("status", "?"))
        if status == "running":
            return "stopped before finishing: its process ended"
        return status

    def restart(self, environment: dict | None = None) -> ResumeState:
        """Prepare the folder to continue the run: remove temporary files and the files of
        levels after the last one saved in ``resume.npz``, and return the saved state with
        the history rows of the saved levels.

        Raises
        ------
        RunFolderError
            If the saved state is unreadable or inconsistent with the history, or missing
            while the history holds finished levels (they would be replaced).
        """
        path = self.path
        remove_temporaries(path)
        remove_temporaries(path / UNIFORM)
        state = read_state(path)
        rows = self._history_rows()
        if state is None and rows:
            raise RunFolderError(
                f"cannot resume: {path / 'history.csv'} holds {len(rows)} finished level(s) "
                f"but {path} holds no {STATE}, the state to continue from, so resuming would "
                "replace them: start again with --overwrite (which removes them), or give "
                "another --out folder"
            )
        state = state or ResumeState(-1, False, None, None, [])
        if len(rows) < state.level + 1:
            raise RunFolderError(
                f"cannot resume: {path / 'history.csv'} has {len(rows)} level(s) but "
                f"{STATE} says level {state.level} finished; start again with --overwrite"
            )
        state.history_rows = rows[: state.level + 1]
        for i, row in enumerate(state.history_rows):
            fields = (row.get("level"), row.get("ndof"))
            if None in row or None in row.values() or fields[0] != str(i) or not _count(fields[1]):
                raise RunFolderError(
                    f"cannot resume: line {i + 2} of {path / 'history.csv'} is not the row of "
                    f"level {i} of a run (its level, its ndof or its number of fields); start "
                    "again with --overwrite"
                )
        for name in folder_listing(path):
            m = re.fullmatch(r"level_(\d{3,})\.vtu", name)
            if m and int(m.group(1)) > state.level:
                (path / name).unlink()
        self.manifest["pid"] = os.getpid()
        resumed = self.manifest.get("resumed")
        self.manifest["resumed"] = [*(resumed if isinstance(resumed, list) else ())]
        self.manifest["resumed"].append(dict(environment or {}))
        self.set_status("running")
        return state

    # ------------------------------------------------------------------ writing
    def add_files(self, *names: str) -> None:
        """Record files (relative to the folder) as the run's, before they are written."""
        files = self.manifest["files"]
        new = [n for n in names if n not in files]
        if new:
            files.extend(new)
            self._write_manifest()

    def set_status(self, status: str, error: str | None = None) -> None:
        """Record the run's status: ``running``, ``interrupted``, ``failed`` (with the
        ``error`` that stopped it, recorded as ``error``) or ``finished`` (a finished run needs
        no resume state: ``resume.npz`` is removed)."""
        self.manifest["status"] = status
        self.manifest.pop("error", None)
        if error is not None:
            self.manifest["error"] = error
        self._write_manifest()
        if status == "finished":
            (self.path / STATE).unlink(missing_ok=True)

    def sub_folder(self, name: str) -> Path:
        """The run's sub-folder ``name`` (``uniform``), created if missing.

        Raises
        ------
        RunFolderError
            If it is a symbolic link (a run never writes through one) or not a folder.
        """
        sub = self.path / name
        check_not_linked(sub)
        sub.mkdir(exist_ok=True)
        check_not_linked(sub)  # not replaced by a link meanwhile
        return sub

    def saved_work(self) -> list[str]:
        """The names in the folder that show a level was solved: the problem data, the
        resume state, the history and the level files, whatever kind of file they are."""
        return [
            name
            for name in folder_listing(self.path)
            if name in (CHECK, STATE, "history.csv") or re.fullmatch(r"level_\d{3,}\.vtu", name)
        ]

    def save_state(self, level: int, mesh: Mesh, u0: np.ndarray | None, final: bool) -> None:
        """Save atomically that ``level`` finished, with the next level's mesh and warm start
        (``final``: that level was the run's last; then its own mesh and solution)."""
        self.add_files(STATE)
        write_state(self.path, level, mesh, u0, final)

    # ------------------------------------------------------------------ internals
    @staticmethod
    def _check_is_folder(path: Path) -> None:
        if path.exists() and not path.is_dir():
            raise RunFolderError(
                f"--out {path} is an existing file, not a folder: give a folder name"
            )

    def _write_manifest(self) -> None:
        text = json.dumps(self.manifest, indent=1, sort_keys=True) + "\n"
        atomic_write(self.path / MANIFEST, text.encode())

    def _history_rows(self) -> list[dict]:
        file = self.path / "history.csv"
        data = read_bounded(file)
        if data is None:
            return []
        try:
            return list(csv.DictReader(io.StringIO(data.decode("utf-8"))))
        except (UnicodeDecodeError, csv.Error) as exc:
            raise RunFolderError(
                f"cannot resume: {file} is not a CSV history ({exc}); start again with --overwrite"
            ) from None
