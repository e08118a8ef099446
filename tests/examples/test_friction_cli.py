"""The friction examples through the command line: ``signorini run example-6.2-coulomb`` and
``signorini run partial-slip`` (history with the friction columns, VTU files with the friction
stress and the node states, figures with η8 and the stick and slip zones; a load-path example
resumed after an interrupt gives the uninterrupted run)."""

from __future__ import annotations

import csv
from pathlib import Path

import meshio
import numpy as np
import pytest

from signorini.cli import main

FRICTION_COLUMNS = ["eta_8", "n_stick", "n_slip", "kkt_tangential_bound"]


def rows_of(path: Path) -> list[dict[str, str]]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.mark.slow
def test_run_example_6_2_coulomb_end_to_end(tmp_path, capsys):
    out = tmp_path / "coulomb"
    assert main(["run", "example-6.2-coulomb", "--max-ndof", "1500", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "example-6.2-coulomb: adaptive" in text
    rows = rows_of(out / "history.csv")
    assert len(rows) > 5 and all(c in rows[0] for c in FRICTION_COLUMNS)
    last = rows[-1]
    print(
        f"\n{len(rows)} levels, last: ndof {last['ndof']}, eta {float(last['eta']):.3e}, "
        f"eta_8 {float(last['eta_8']):.2e}, stick {last['n_stick']}, slip {last['n_slip']}"
    )
    assert int(last["n_stick"]) > 0 and int(last["n_slip"]) > 0 and float(last["eta_8"]) > 0
    for row in rows:
        terms = np.array([float(row[f"eta_{k}"]) for k in range(1, 9)])
        assert float(row["eta"]) ** 2 == pytest.approx((terms**2).sum(), rel=1e-12)
        assert float(row["kkt_tangential_complementarity"]) < 1e-10
    vtu = meshio.read(out / f"level_{len(rows) - 1:03d}.vtu")
    state = vtu.point_data["contact_state"]
    assert {1, 2} <= set(np.unique(state).tolist())
    assert np.abs(vtu.point_data["tangential_pressure"][state == 2]).min() > 0
    figures = {p.name for p in out.glob("*.png")}
    assert {"example-6.2-coulomb_contributions.png", "deformed.png", "mesh.png"} <= figures


@pytest.mark.slow
def test_run_partial_slip_resumed_after_an_interrupt(tmp_path, capsys, monkeypatch):
    """partial-slip solves press and pull on every level; interrupted after level 2 and
    resumed, it gives the history of the uninterrupted run (counts exactly, numbers to
    round-off) with the Cattaneo–Mindlin columns."""
    import signorini.cli.levels as cli_levels

    full, part = tmp_path / "full", tmp_path / "part"
    args = ["run", "partial-slip", "--max-ndof", "2500", "--no-figures", "--quiet"]
    assert main([*args, "--out", str(full)]) == 0
    progress = cli_levels.progress

    def stop(level):
        if level.record.level == 2:
            raise KeyboardInterrupt
        return progress(level)

    monkeypatch.setattr(cli_levels, "progress", stop)
    assert main([*args, "--out", str(part)]) == 130
    assert "--resume" in capsys.readouterr().err
    monkeypatch.undo()
    resume = ["run", "partial-slip", "--resume", str(part), "--quiet", "--no-figures"]
    assert main(resume) == 0
    a, b = rows_of(full / "history.csv"), rows_of(part / "history.csv")
    print(f"\n{len(a)} levels; resumed after level 2; last c/a {a[-1]['c_over_a']}")
    assert len(a) == len(b) > 4
    for ra, rb in zip(a, b, strict=True):
        for key in ("ndof", "n_cells", "pdas_iterations", "n_stick", "n_slip"):
            assert ra[key] == rb[key], (ra["level"], key)
        for key in ("eta", "eta_8", "c_over_a", "c_over_a_theory", "q_over_fp"):
            assert float(rb[key]) == pytest.approx(float(ra[key]), rel=1e-9), key
    described = (full / "history.md").read_text()
    assert "c_over_a_theory" in described and "Cattaneo" in described


@pytest.mark.slow
def test_adaptive_benchmark_with_coulomb_friction(tmp_path):
    """benchmarks/adaptive.py --friction coulomb on a small budget: its ``iters`` column is the
    history's semismooth Newton iterations, every level has a floor, and it ends on
    ``ratio_to_floor=X``."""
    import subprocess
    import sys

    root = Path(__file__).resolve().parents[2]
    script = root / "benchmarks" / "adaptive.py"
    argv = [sys.executable, str(script), "--friction", "coulomb", "--max-ndof", "3000"]
    out = subprocess.run(
        [*argv, "--out", str(tmp_path)], capture_output=True, text=True, timeout=300, check=True
    ).stdout
    lines = out.strip().splitlines()
    header = lines[0].split()
    table = [dict(zip(header, line.split(), strict=True)) for line in lines[1 : lines.index("")]]
    history = rows_of(tmp_path / "history.csv")
    assert [row["iters"] for row in table] == [r["pdas_iterations"] for r in history]
    assert all(float(row["floor"]) > 0 for row in table)
    assert all(int(r["n_stick"]) > 0 for r in history[5:])
    iterations = next(line for line in lines if line.startswith("semismooth Newton iterations"))
    assert iterations.split(": ")[1].split() == [row["iters"] for row in table]
    assert lines[-1].startswith("ratio_to_floor=") and float(lines[-1].split("=")[1]) > 0
    print("\n" + iterations + "; " + lines[-1])
