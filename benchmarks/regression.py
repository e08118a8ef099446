"""Before/after check of a change that touches the numerics: every built-in example, run by
the command line, compared level by level.

    python benchmarks/regression.py snapshot DIR      # run every case into DIR
    python benchmarks/regression.py compare OLD NEW   # compare two snapshots
    python benchmarks/regression.py compare OLD NEW --skip n_factorizations
    python benchmarks/regression.py compare OLD NEW --exact    # bit for bit

``snapshot`` runs each case of :data:`CASES` with ``signorini run`` (VTU files kept, figures
off) into ``DIR/<case>``. ``compare`` reads both snapshots and prints, per case, the largest
difference of every history column (timings excluded; estimator terms relative to η, forces
relative to the largest contact force, KKT residuals absolutely) and of each level's mesh
(points and cells exactly) and nodal fields (relative to the field's largest value). Its last
line is ``regression: same`` or ``regression: DIFFERENT (...)``; the exit status is 0 or 1.
``--skip COLUMN`` (repeatable) leaves out a history column that a change alters by design,
e.g. ``n_factorizations`` where solves become low-rank updates (the change's note says so).
``--exact`` is the check of a change that moves tables and names but no arithmetic: every
history column (timings excluded), every level's mesh and every nodal field must then be
equal bit for bit, and the last line names the first difference found.
"""

from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path

import numpy as np

#: name -> command line arguments of ``signorini run`` (the budgets keep a snapshot near 2 min)
CASES: dict[str, list[str]] = {
    "6.1": ["example-6.1", "--max-ndof", "30000"],
    "6.1-uniform": ["example-6.1", "--uniform", "--max-ndof", "30000"],
    "6.1-eta5-paper": ["example-6.1", "--eta5", "paper", "--max-ndof", "15000"],
    "6.2": ["example-6.2", "--max-ndof", "60000"],
    "6.2-scipy": ["example-6.2", "--backend", "scipy", "--max-ndof", "8000"],
    "6.2-tresca": ["example-6.2-tresca", "--max-ndof", "20000"],
    "6.2-coulomb": ["example-6.2-coulomb", "--max-ndof", "20000"],
    "hertz": ["hertz", "--max-ndof", "20000"],
    "punch": ["punch", "--max-ndof", "20000"],
    "partial-slip": ["partial-slip", "--max-ndof", "12000"],
}

#: columns that are not numbers of the solution
SKIP = {"backend"}
#: a difference above this (in the units of :func:`_scale`) counts
RTOL = 1e-8


def snapshot(folder: Path) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    for name, args in CASES.items():
        out = folder / name
        cmd = ["signorini", "run", *args, "--out", str(out), "--no-figures", "--quiet"]
        cmd += ["--overwrite"]
        print(" ".join(cmd), flush=True)
        subprocess.run(cmd, check=True)


def _history(path: Path) -> list[dict[str, str]]:
    with open(path / "history.csv", newline="") as f:
        return list(csv.DictReader(f))


def _number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return float("nan")


def _scale(column: str, old: list[dict[str, str]]) -> float:
    """What a column's differences are measured against."""
    values = np.array([_number(r[column]) for r in old])
    finite = np.abs(values[np.isfinite(values)])
    if column.startswith("eta") or column.startswith("error"):
        etas = np.array([_number(r["eta"]) for r in old])
        return float(np.nanmax(np.abs(etas)))
    if column.startswith("kkt"):
        return 1.0
    return float(finite.max()) if finite.size and finite.max() > 0 else 1.0


def _compare_history(
    old: Path, new: Path, skip: frozenset[str] = frozenset()
) -> tuple[float, str, list[str]]:
    a, b = _history(old), _history(new)
    faults = []
    if len(a) != len(b):
        faults.append(f"{len(a)} levels against {len(b)}")
    if a and b and list(a[0]) != list(b[0]):
        faults.append(f"columns differ: {sorted(set(a[0]) ^ set(b[0]))}")
    worst, where = 0.0, ""
    for column in a[0] if a else []:
        if column in SKIP | skip or column.startswith("t_") or column not in (b[0] if b else {}):
            continue
        scale = _scale(column, a)
        for r, s in zip(a, b, strict=False):
            x, y = _number(r[column]), _number(s[column])
            if np.isnan(x) and np.isnan(y):
                continue
            d = abs(x - y) / scale if np.isfinite(x) and np.isfinite(y) else np.inf
            if d > worst:
                worst, where = d, f"{column} at level {r['level']}"
    return worst, where, faults


def _compare_meshes(old: Path, new: Path) -> tuple[float, str, list[str]]:
    import meshio

    faults, worst, where = [], 0.0, ""
    files = sorted(p.name for p in old.glob("*.vtu"))
    if files != sorted(p.name for p in new.glob("*.vtu")):
        faults.append("other VTU files")
    for name in files:
        if not (new / name).exists():
            continue
        m, n = meshio.read(old / name), meshio.read(new / name)
        if m.points.shape != n.points.shape or not np.array_equal(m.points, n.points):
            faults.append(f"{name}: points differ")
            continue
        ca, cb = m.cells[0].data, n.cells[0].data
        if ca.shape != cb.shape or not np.array_equal(ca, cb):
            faults.append(f"{name}: cells differ")
            continue
        for field, x in m.point_data.items():
            y = n.point_data.get(field)
            if y is None or y.shape != x.shape:
                faults.append(f"{name}: field {field} missing or reshaped")
                continue
            scale = float(np.abs(x).max()) or 1.0
            d = float(np.abs(x - y).max()) / scale
            if d > worst:
                worst, where = d, f"{field} in {name}"
    return worst, where, faults


def _bits_differ(x: np.ndarray, y: np.ndarray) -> bool:
    """Whether two arrays differ in dtype, shape or any bit (NaNs alike, -0.0 is not 0.0)."""
    x, y = np.ascontiguousarray(x), np.ascontiguousarray(y)
    return x.dtype != y.dtype or x.shape != y.shape or x.tobytes() != y.tobytes()


def _exact_history(old: Path, new: Path, skip: frozenset[str]) -> str | None:
    """The first history entry (level by level, column by column) whose text differs."""
    a, b = _history(old), _history(new)
    if len(a) != len(b):
        return f"{len(a)} levels against {len(b)}"
    if a and list(a[0]) != list(b[0]):
        return f"columns differ: {sorted(set(a[0]) ^ set(b[0]))}"
    for r, s in zip(a, b, strict=True):
        for column in r:
            if column in skip or column.startswith("t_"):
                continue
            if r[column] != s[column]:
                return f"{column} at level {r['level']}: {r[column]} against {s[column]}"
    return None


def _exact_meshes(old: Path, new: Path) -> str | None:
    """The first VTU file whose points, cells, nodal or cell fields differ in any bit."""
    import meshio

    files = sorted(p.name for p in old.glob("*.vtu"))
    if files != sorted(p.name for p in new.glob("*.vtu")):
        return "other VTU files"
    for name in files:
        m, n = meshio.read(old / name), meshio.read(new / name)
        if _bits_differ(m.points, n.points):
            return f"{name}: points differ"
        if [c.type for c in m.cells] != [c.type for c in n.cells]:
            return f"{name}: cell types differ"
        for ca, cb in zip(m.cells, n.cells, strict=True):
            if _bits_differ(ca.data, cb.data):
                return f"{name}: {ca.type} cells differ"
        for kind, x_data, y_data in (
            ("field", m.point_data, n.point_data),
            ("cell field", m.cell_data, n.cell_data),
        ):
            if sorted(x_data) != sorted(y_data):
                return f"{name}: {kind}s {sorted(set(x_data) ^ set(y_data))} in one only"
        for field, x in m.point_data.items():
            if _bits_differ(x, n.point_data[field]):
                return f"{name}: field {field} differs"
        for field, blocks in m.cell_data.items():
            other = n.cell_data[field]
            if len(blocks) != len(other) or any(map(_bits_differ, blocks, other)):
                return f"{name}: cell field {field} differs"
    return None


def compare_exact(old: Path, new: Path, skip: frozenset[str] = frozenset()) -> bool:
    """Every case bit for bit; the last line names the first difference found."""
    first = None
    if skip:
        print(f"history columns left out: {', '.join(sorted(skip))}")
    for name in CASES:
        fault = _exact_history(old / name, new / name, skip)
        fault = fault or _exact_meshes(old / name, new / name)
        print(f"{name:16s} " + ("bit-identical" if fault is None else f"differs: {fault}"))
        first = first or (fault and f"{name}: {fault}")
    print("regression: same" if first is None else f"regression: DIFFERENT ({first})")
    return first is None


def compare(old: Path, new: Path, skip: frozenset[str] = frozenset()) -> bool:
    same = True
    if skip:
        print(f"history columns left out: {', '.join(sorted(skip))}")
    for name in CASES:
        h, hw, hf = _compare_history(old / name, new / name, skip)
        f, fw, ff = _compare_meshes(old / name, new / name)
        ok = not hf and not ff and h <= RTOL and f <= RTOL
        same &= ok
        print(
            f"{name:16s} history {h:.1e} ({hw or '-'}); fields {f:.1e} ({fw or '-'})"
            + ("" if ok else "  <-- " + "; ".join(hf + ff or ["above tolerance"]))
        )
    print("regression: same" if same else "regression: DIFFERENT (see the marked cases)")
    return same


def main(argv: list[str]) -> int:
    if len(argv) == 2 and argv[0] == "snapshot":
        snapshot(Path(argv[1]))
        return 0
    exact = "--exact" in argv[3:]
    argv = argv[:3] + [a for a in argv[3:] if a != "--exact"]
    skip = frozenset(argv[k + 1] for k in range(3, len(argv) - 1, 2) if argv[k] == "--skip")
    if len(argv) >= 3 and argv[0] == "compare" and len(argv) == 3 + 2 * len(skip):
        check = compare_exact if exact else compare
        return 0 if check(Path(argv[1]), Path(argv[2]), skip) else 1
    print(__doc__)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
