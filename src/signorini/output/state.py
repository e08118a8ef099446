"""The state a run saves after each level (``resume.npz``), to continue where it stopped.

The file holds plain arrays (``numpy.load`` without pickles, read through
:func:`~signorini.output.guard.open_npz`): the index of the last finished level, whether it
was the run's last, the next level's mesh exactly as stored (points, cells in their vertex
order, which fixes the refinement edges of newest vertex bisection, boundary edges and
parts, cell regions; a tetrahedral mesh also its bisection tags, the vertex order and type of
each cell that fix the next bisections, :func:`~signorini.mesh.refine3d.tags_of`) and its warm
start; after the run's last level, that level's own mesh and solution.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..mesh.bodies import body_of_cells, validated_bodies
from ..mesh.mesh import Mesh
from ..mesh.refine3d import tagged, tags_of
from .files import replacing
from .guard import RunFolderError, open_npz

__all__ = ["STATE", "ResumeState", "read_state", "write_state"]

STATE = "resume.npz"


@dataclass
class ResumeState:
    """What :meth:`~signorini.output.run.RunFolder.restart` found: where to continue an
    interrupted run.

    Attributes
    ----------
    level : int
        Index of the last finished level (-1 when none finished).
    final : bool
        Whether that level was the run's last (only the figures may be missing).
    mesh : Mesh or None
        The next level's mesh; when ``final``, the last level's own mesh (None when no
        level finished).
    u0 : (n_nodes, 2) float array or None
        The warm start on ``mesh``: the next level's, or when ``final`` the last level's
        solution.
    history_rows : list of dict
        The history rows of levels ``0 … level``, as text.
    """

    level: int
    final: bool
    mesh: Mesh | None
    u0: np.ndarray | None
    history_rows: list[dict]


def write_state(
    folder: str | os.PathLike, level: int, mesh: Mesh | None, u0: np.ndarray | None, final: bool
) -> None:
    """Save atomically that ``level`` finished, with the next level's mesh and warm start
    (``final``: that level was the run's last; then its own mesh and solution)."""
    arrays: dict[str, np.ndarray] = {
        "level": np.array(level, dtype=np.int64),
        "final": np.array(final),
    }
    if mesh is not None:
        arrays.update(
            points=mesh.points,
            cells=mesh.cells,
            boundary=mesh.boundary,
            boundary_part=mesh.boundary_part,
            part_names=np.array(mesh.part_names, dtype=str),
            cell_region=mesh.cell_region,
            region_names=np.array(mesh.region_names, dtype=str),
            bodies=np.array(int(body_of_cells(mesh).max(initial=0)) + 1),
        )
        if mesh.dim == 3:  # without its tags a tetrahedral mesh would bisect differently
            tags = tags_of(mesh)
            arrays.update(tag_order=tags.order, tag_gamma=tags.gamma)
        if u0 is not None:
            arrays["u0"] = np.asarray(u0, dtype=np.float64)
    with replacing(Path(folder) / STATE) as tmp, open(tmp, "wb") as fh:
        np.savez(fh, **arrays)


def read_state(folder: str | os.PathLike) -> ResumeState | None:
    """The state saved in ``folder``, None if it holds none.

    Raises
    ------
    RunFolderError
        If the file is unreadable, or not a regular file of the folder
        (:func:`~signorini.output.guard.open_npz`).
    """
    file = Path(folder) / STATE
    try:
        with open_npz(file) as data:
            if data is None:
                return None
            level, final = int(data["level"]), bool(data["final"])
            options = _mesh_options(data)
            arrays = (data[k] for k in ("points", "cells", "boundary", "boundary_part"))
            mesh = Mesh(*arrays, [str(n) for n in data["part_names"]], **options)
            mesh = mesh if options["validate"] else validated_bodies(mesh)
            if "tag_order" in data:
                mesh = tagged(mesh, np.array(data["tag_order"]), np.array(data["tag_gamma"]))
            u0 = np.array(data["u0"]) if "u0" in data else None
        _check_state(file, level, mesh, u0)
    except RunFolderError as exc:
        raise RunFolderError(f"cannot resume: {exc}") from None
    except (OSError, ValueError, KeyError, EOFError, MemoryError) as exc:
        raise RunFolderError(
            f"cannot resume: {file} is unreadable ({exc}); start again with --overwrite"
        ) from None
    return ResumeState(level, final, mesh, u0, [])


def _check_state(file: Path, level: int, mesh: Mesh, u0: np.ndarray | None) -> None:
    """Refuse a saved state whose level is negative or whose warm start is not finite values
    at the nodes of its mesh (P2: vertices then edge midpoints; P1: vertices), one component
    per axis of the mesh."""
    if level < 0:
        raise RunFolderError(f"{file} says level {level} finished: not a state signorini saved")
    if u0 is None:
        return
    nodes = (mesh.n_points, mesh.n_points + mesh.n_edges)
    if u0.ndim != 2 or u0.shape[1] != mesh.dim or u0.shape[0] not in nodes:
        raise RunFolderError(
            f"{file} holds a warm start of shape {u0.shape} on a {mesh.dim}D mesh of "
            f"{nodes[0]} points and {mesh.n_edges} edges: not a state signorini saved"
        )
    if u0.dtype.kind != "f" or not np.isfinite(u0).all():
        raise RunFolderError(f"{file} holds a warm start that is not finite numbers")


def _mesh_options(data) -> dict:
    """The saved mesh's cell regions (none in a state saved before regions existed), and
    whether it is checked as one mesh (not as the union of several bodies, whose points may
    coincide where they touch: :func:`~signorini.mesh.bodies.validated_bodies`)."""
    options = {"validate": "bodies" not in data or int(data["bodies"]) == 1}
    if "cell_region" in data:
        options["cell_region"] = data["cell_region"]
        options["region_names"] = [str(n) for n in data["region_names"]]
    return options
