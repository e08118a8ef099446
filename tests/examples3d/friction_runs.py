"""What a frictional 3D run writes, read back (tests of ``partial-slip-3d`` and
``partial-slip-spheres``): :func:`checked_run` runs ``signorini run`` for one level and checks
that the history's friction columns agree with the example's own counts and with the level's
VTU file, and that the tangential KKT residuals meet 1e-12."""

from __future__ import annotations

import csv
from pathlib import Path

from signorini.cli import main
from signorini.contact.solution import SLIP, STICK


def checked_run(args: list[str], out: Path) -> tuple[dict[str, str], dict]:
    """Run ``signorini run *args --out out`` (one level), check its stick and slip rows
    (module docstring) and return the history's row and the VTU file's point data."""
    import meshio

    assert main(["run", *args, "--out", str(out)]) == 0
    (row,) = list(csv.DictReader(open(out / "history.csv")))
    assert int(row["n_stick"]) == float(row["stick_nodes"]) > 0
    assert int(row["n_slip"]) == float(row["slip_nodes"]) > 0
    for name in ("kkt_tangential_bound", "kkt_tangential_complementarity"):
        assert float(row[name]) <= 1e-12, name
    data = meshio.read(out / "level_000.vtu").point_data
    state = data["contact_state"]
    assert int((state == STICK).sum()) == int(row["n_stick"])
    assert int((state == SLIP).sum()) == int(row["n_slip"])
    return row, data
