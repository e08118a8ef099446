"""Before/after check of a change that touches the numerics: every built-in example, run by
the command line, compared level by level.

    python benchmarks/regression.py snapshot DIR      # run every case into DIR
    python benchmarks/regression.py compare OLD NEW   # compare two snapshots
    python benchmarks/regression.py compare OLD NEW --skip n_factorizations

``snapshot`` runs each case of :data:`CASES` with ``signorini run`` (VTU files kept, figures
off) into ``DIR/<case>``. ``compare`` reads both snapshots and prints, per case, the largest
difference of every history column (timings excluded; estimator terms relative to η, forces
relative to the largest contact force, KKT residuals absolutely) and of each level's mesh
(points and cells exactly) and nodal fields (relative to the field's largest value). Its last
line is ``regression: same`` or ``regression: DIFFERENT (...)``; the exit status is 0 or 1.
``--skip COLUMN`` (repeatable) leaves out a history column that a change alters by design,
e.g. ``n_factorizations`` where solves become low-rank updates (the change's note says so).
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
    skip = frozenset(argv[k + 1] for k in range(3, len(argv) - 1, 2) if argv[k] == "--skip")
    if len(argv) >= 3 and argv[0] == "compare" and len(argv) == 3 + 2 * len(skip):
        return 0 if compare(Path(argv[1]), Path(argv[2]), skip) else 1
    print(__doc__)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
