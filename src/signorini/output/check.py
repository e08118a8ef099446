"""Which problem produced a run: the first level's data, rebuilt and compared.

A run folder may come from anywhere, so nothing read from it is trusted to say which problem
it holds (a name or a file digest in the manifest can be edited, and a helper module the
problem file imports is not in any digest). Instead, after its first level a run saves that
level's *problem data* in ``signorini-check.npz`` — the data the numbers are made of, not the
code that made them:

==============  ===========================================================================
``mesh``        the initial mesh: points, cells, boundary edges and their parts, part names
``dirichlet``   the prescribed displacements at the Dirichlet nodes (each load step)
``contact``     gap ψ(z), direction n_z and friction data at the constrained nodes (each step)
``loads``       the assembled load vector L(ψ_i): body force and tractions (each step)
``material``    the stiffness matrix applied to a fixed probe vector (each step)
``solution``    the first level's displacements and contact forces
==============  ===========================================================================

``signorini run --resume`` and ``signorini figures`` rebuild the problem the user names,
solve its first level, and compare (:func:`differences`): the mesh exactly, the rest to
``RTOL`` of each array's largest entry (the threaded sparse solvers sum in varying order).
The file is plain arrays (``numpy.load`` without pickles): reading it runs no code.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .files import replacing
from .guard import RunFolderError, open_npz

__all__ = ["CHECK", "MESH_ARRAYS", "RTOL", "differences", "read_check", "write_check"]

#: The file of a run folder holding its first level's problem data.
CHECK = "signorini-check.npz"
#: Relative tolerance (of each array's largest entry) of the comparison of computed data.
RTOL = 1e-8

#: the mesh arrays a run saves to identify its initial mesh
MESH_ARRAYS = ("points", "cells", "boundary", "boundary_part")
_WHAT = {
    "mesh": "the initial mesh (points, cells or boundary parts)",
    "dirichlet": "the Dirichlet values",
    "contact": "the contact data (gaps, normals or friction)",
    "loads": "the loads (body force or tractions)",
    "material": "the material (the stiffness matrix)",
    "solution": "the first level's solution",
    "steps": "the number of load steps",
}


def write_check(folder: str | os.PathLike, data: dict[str, np.ndarray]) -> Path:
    """Save ``data`` as the folder's ``signorini-check.npz`` (atomically)."""
    target = Path(folder) / CHECK
    with replacing(target) as tmp, open(tmp, "wb") as fh:
        np.savez(fh, **data)
    return target


def read_check(folder: str | os.PathLike) -> dict[str, np.ndarray] | None:
    """The saved problem data of a run folder, None if it has none or it is unreadable
    (plain arrays only: no pickled objects are loaded).

    Raises
    ------
    RunFolderError
        If the file is a symbolic link, not a regular file (a named pipe is never waited
        on) or holds more than its size in arrays (:func:`~.guard.open_npz`).
    """
    try:
        with open_npz(Path(folder) / CHECK) as saved:
            if saved is None:
                return None
            return {name: np.array(saved[name]) for name in saved.files}
    except (OSError, ValueError, KeyError, EOFError, MemoryError) as exc:
        if isinstance(exc, RunFolderError):
            raise
        return None


def _same(name: str, a: np.ndarray, b: np.ndarray) -> bool:
    if a.shape != b.shape or a.dtype.kind != b.dtype.kind:
        return False
    if name.startswith("mesh.") or a.dtype.kind not in "fc":
        return bool(np.array_equal(a, b))
    scale = max(float(np.abs(a).max(initial=0.0)), float(np.abs(b).max(initial=0.0)))
    return bool(np.all(np.abs(a - b) <= RTOL * scale))


def differences(saved: dict[str, np.ndarray], now: dict[str, np.ndarray]) -> list[str]:
    """What differs between the saved problem data of a run and that of a rebuilt problem.

    Returns
    -------
    list of str
        One phrase per kind of data that differs (``"the loads (body force or
        tractions)"``), in the order of the table above; empty when the problems agree.
    """
    kinds = []
    for name in sorted(set(saved) | set(now)):
        kind = name.split(".")[0]
        if kind in kinds:
            continue
        if name not in saved or name not in now or not _same(name, saved[name], now[name]):
            kinds.append(kind)
    order = list(_WHAT)
    kinds.sort(key=lambda k: order.index(k) if k in order else len(order))
    if "steps" in kinds:  # another number of steps: the per-step data differ as a consequence
        kinds = [k for k in kinds if k in ("mesh", "steps", "solution")]
    return [_WHAT.get(k, k) for k in kinds]
