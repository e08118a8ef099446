"""Files: solutions as VTU (ParaView), the convergence history as CSV, meshes from files.

Everything is written atomically (a temporary file in the same folder, then ``os.replace``),
so an interrupted run never leaves a half-written file behind.
"""

from __future__ import annotations

import contextlib
import csv
import io as _io
import math
import os
import tempfile
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from .mesh import Mesh, MeshError, signed_area

__all__ = ["atomic_write", "write_vtu", "HistoryWriter", "read_mesh"]


@contextmanager
def _replacing(path: str | os.PathLike, suffix: str = ".tmp") -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success it replaces ``path`` atomically."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=suffix)
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
    with _replacing(path) as tmp, open(tmp, "wb") as fh:
        fh.write(data)
        fh.flush()
        os.fsync(fh.fileno())
    return Path(path)


def write_vtu(path: str | os.PathLike, result, estimate=None) -> Path:
    """Write a discrete solution as a quadratic-triangle VTU file.

    Point data: ``displacement`` (3 components, z = 0, for ParaView's "Warp By Vector"),
    and on Γ_C ``pressure`` (consistent nodal pressure p_z), ``contact_force`` (Λ_z),
    ``active`` (1 where u·n = ψ is imposed) and ``contact_class`` (0 none, 1 semi, 2 full,
    −1 off Γ_C). Cell data: ``eta2`` (element indicators) and ``eta2_k`` per contribution
    when an estimate is given.

    Parameters
    ----------
    path : path of the ``.vtu`` file
    result : ContactResult
    estimate : Estimate, optional
    """
    import meshio

    space, cs = result.space, result.contact
    n = space.n_nodes
    points = np.column_stack([space.node_points, np.zeros(n)])
    disp = np.column_stack([result.u, np.zeros(n)])
    pressure = np.zeros(n)
    force = np.zeros(n)
    active = np.zeros(n, dtype=np.int32)
    klass = np.full(n, -1, dtype=np.int32)
    pressure[cs.nodes] = result.pressure
    force[cs.nodes] = result.contact_force
    active[cs.nodes] = result.active
    klass[cs.nodes] = result.classes
    cell_data = {}
    if estimate is not None:
        cell_data["eta2"] = [estimate.eta2]
        for k in range(estimate.eta2_cell.shape[0]):
            cell_data[f"eta2_{k + 1}"] = [estimate.eta2_cell[k]]
    mesh = meshio.Mesh(
        points,
        [("triangle6", space.cell_nodes)],
        point_data={"displacement": disp, "pressure": pressure, "contact_force": force,
                    "active": active, "contact_class": klass},
        cell_data=cell_data,
    )
    with _replacing(path, suffix=".vtu") as tmp:
        meshio.write(tmp, mesh, file_format="vtu")
    return Path(path)


class HistoryWriter:
    """A CSV convergence history rewritten atomically after every level.

    Parameters
    ----------
    path : path of the CSV file (replaced if it exists)
    """

    def __init__(self, path: str | os.PathLike) -> None:
        self.path = Path(path)
        self.rows: list[dict] = []

    def append(self, row: Mapping[str, object]) -> None:
        """Add one level's row and rewrite the file."""
        self.rows.append(dict(row))
        columns: list[str] = []
        for r in self.rows:
            columns += [c for c in r if c not in columns]
        out = _io.StringIO()
        writer = csv.DictWriter(out, fieldnames=columns, lineterminator="\n")
        writer.writeheader()
        for r in self.rows:
            writer.writerow({c: _fmt(r.get(c, "")) for c in columns})
        atomic_write(self.path, out.getvalue().encode())


def _fmt(value: object) -> object:
    if isinstance(value, float):
        return "nan" if math.isnan(value) else repr(value)
    return value


def read_mesh(path: str | os.PathLike, parts: Sequence[str] | None = None) -> Mesh:
    """Read a triangular mesh with named boundary parts from a file (e.g. Gmsh ``.msh``).

    Triangles (``triangle`` or ``triangle6``, whose vertices are used) make the cells; line
    elements tagged with physical groups make the boundary parts, named after the groups
    (``gmsh:physical`` / field data). Cells are oriented counter-clockwise and each cell's
    longest edge becomes its refinement edge.

    Parameters
    ----------
    path : file readable by meshio
    parts : names of the parts to keep (default: all named line groups)

    Raises
    ------
    MeshError
        If the file cannot be read as a mesh, has no triangles, or has no tagged boundary.
    """
    import meshio

    path = Path(path)
    if not path.is_file():
        raise MeshError(f"no mesh file at {path}")
    said = _io.StringIO()
    try:
        # meshio prints its diagnostics and calls sys.exit() on some foreign files
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
            m = meshio.read(path)
    except (Exception, SystemExit) as exc:  # meshio raises many types for foreign files
        detail = " ".join(said.getvalue().split()) if isinstance(exc, SystemExit) else exc
        raise MeshError(f"{path} is not a mesh file meshio can read: {detail}") from None
    tri = [(i, b) for i, b in enumerate(m.cells) if b.type in ("triangle", "triangle6")]
    if not tri:
        raise MeshError(f"{path} contains no triangles")
    cells = np.concatenate([b.data[:, :3] for _, b in tri]).astype(np.int64)
    points = np.asarray(m.points, dtype=np.float64)[:, :2]
    # drop points that no triangle uses (e.g. geometry points), renumber
    used = np.unique(cells)
    renumber = np.full(len(points), -1, dtype=np.int64)
    renumber[used] = np.arange(used.size)
    points, cells = points[used], renumber[cells]
    area = signed_area(points, cells)
    flip = area < 0
    cells[flip] = cells[flip][:, [0, 2, 1]]
    tags = m.cell_data.get("gmsh:physical")
    names = {int(v[0]): k for k, v in (m.field_data or {}).items() if len(v) > 1 and v[1] == 1}
    groups: dict[str, list[np.ndarray]] = {}
    for i, block in enumerate(m.cells):
        if block.type not in ("line", "line3") or tags is None:
            continue
        for tag in np.unique(tags[i]):
            name = names.get(int(tag), f"part{int(tag)}")
            pairs = renumber[block.data[tags[i] == tag][:, :2]]
            if np.any(pairs < 0):
                raise MeshError(f"boundary group {name!r} uses points that are not vertices "
                                "of any triangle")
            groups.setdefault(name, []).append(pairs)
    if not groups:
        raise MeshError(f"{path} has no tagged boundary lines (physical groups); the boundary "
                        "parts cannot be named")
    if parts is not None:
        missing = [p for p in parts if p not in groups]
        if missing:
            raise MeshError(f"{path} has no boundary group(s) {missing}; it has "
                            f"{sorted(groups)}")
        groups = {p: groups[p] for p in parts}
    return Mesh.from_arrays(points, cells, {k: np.concatenate(v) for k, v in groups.items()})
