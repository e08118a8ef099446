"""Which files of a folder are a run's, and its manifest, read as if the folder came from
anyone (:mod:`.guard`): a link or a pipe among them is refused before anything is read,
written or removed.

A run's files are the names the command line writes (``level_NNN.vtu``, ``history.csv``,
``history.md``, ``fields.md``, ``resume.npz``, ``signorini-check.npz``, the ``.pvd``
collections, ``uniform/history.csv``, the manifest), the figures named after the run's
problem, and those its manifest (``signorini-run.json``) lists that are of a kind a run
writes (VTU, CSV, Markdown, JSON, NPZ, PNG, PDF); ``uniform`` is its one sub-folder.
"""

from __future__ import annotations

import json
import os
import re
import shutil
from pathlib import Path

from .files import folder_listing
from .guard import RunFolderError, check_not_linked, read_bounded, regular_file

__all__ = [
    "MANIFEST",
    "UNIFORM",
    "check_entries",
    "load_manifest",
    "problem_text",
    "read_manifest",
    "remove_run_files",
]

MANIFEST = "signorini-run.json"
# files of a run, by name, in the run's folder and in its "uniform" sub-folder
_RUN_FILE = re.compile(
    r"^(level_\d{3,}\.vtu|history\.csv|history\.md|fields\.md|resume\.npz|signorini-run\.json"
    r"|signorini-check\.npz|levels\.pvd|levels_ndof\.pvd)$"
)
_FIGURE_NAMES = ("mesh", "deformed", "adaptive_vs_uniform")
# the kinds of file a run writes: a name its manifest lists is its only with one of these
_RUN_SUFFIXES = (".vtu", ".pvd", ".csv", ".md", ".json", ".npz", ".png", ".pdf")
UNIFORM = "uniform"


def problem_text(manifest: dict | None, key: str = "name", default: str = "?") -> str:
    """The problem's ``name`` (or ``label``) a manifest records, as text only."""
    problem = manifest.get("problem") if isinstance(manifest, dict) else None
    value = problem.get(key) if isinstance(problem, dict) else None
    return str(value) if value else default


def load_manifest(path: Path) -> dict | None:
    """The manifest of the folder ``path``, None if it has none.

    Raises
    ------
    RunFolderError
        If it is a symbolic link, not a regular file, larger than
        :data:`~.guard.MAX_TEXT_BYTES`, not JSON, or not a JSON object listing files.
    """
    file = path / MANIFEST
    data = read_bounded(file)
    if data is None:
        return None
    try:
        manifest = json.loads(data.decode("utf-8"))
    except UnicodeDecodeError:
        raise RunFolderError(f"{file} is not JSON (not UTF-8 text)") from None
    except json.JSONDecodeError as exc:
        raise RunFolderError(
            f"{file} is not JSON ({exc.msg}: line {exc.lineno} column {exc.colno})"
        ) from None
    files = manifest.get("files") if isinstance(manifest, dict) else None
    if not isinstance(files, list) or not all(isinstance(n, str) for n in files):
        raise RunFolderError(
            f"{file} is JSON but not the manifest of a run (an object whose 'files' lists "
            "the names of the run's files)"
        )
    return manifest


def read_manifest(path: Path) -> dict | None:
    """The manifest of ``path``, None if it has none or none that can be used (for the
    messages about a folder; never blocks, never follows a link)."""
    try:
        return load_manifest(path)
    except RunFolderError:
        return None


def _run_entries(path: Path) -> list[Path]:
    """The files in ``path`` and its ``uniform`` sub-folder that a run writes: the names the
    command line writes, the figures named after the run's problem, and those its manifest
    lists if they are of a kind a run writes (a manifest may come from anyone: listing
    ``notes.txt`` does not make it the run's)."""
    manifest = read_manifest(path) or {}
    listed = {n for n in manifest.get("files", []) if n.endswith(_RUN_SUFFIXES)}
    label = problem_text(manifest, "label", "")
    stems = "|".join(re.escape(n) for n in (*_FIGURE_NAMES, *([label] if label else [])))
    figure = re.compile(rf"^({stems})[\w.-]*\.(png|pdf)$")
    entries = []
    for sub in ("", UNIFORM):
        folder = path / sub if sub else path
        for name in folder_listing(folder):
            rel = f"{sub}/{name}" if sub else name
            if rel in listed or _RUN_FILE.match(name) or (not sub and figure.match(name)):
                entries.append(folder / name)
    return entries


def check_entries(path: Path) -> None:
    """Refuse the folder ``path`` if a file or sub-folder a run reads, writes or removes
    there is a symbolic link or not a regular file (a named pipe, a device, a folder):
    a run never acts outside its folder, and never waits on a pipe."""
    check_not_linked(path / UNIFORM)  # before anything is listed through it
    regular_file(path / MANIFEST)  # before it is read
    for target in _run_entries(path):
        regular_file(target)


def remove_run_files(path: Path) -> list[Path]:
    """Remove what a previous run wrote into ``path`` (its entries checked by
    :func:`check_entries`), never any other file."""
    removed = []
    for target in _run_entries(path):
        target.unlink()
        removed.append(target)
    uniform = path / UNIFORM
    if uniform.is_dir() and not os.listdir(uniform):
        shutil.rmtree(uniform)
    return removed
