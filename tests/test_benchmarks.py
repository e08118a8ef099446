"""The benchmark and example scripts run end to end on a small budget."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_adaptive_benchmark_prints_ratio_to_floor(tmp_path):
    out = subprocess.run(
        [
            sys.executable,
            str(ROOT / "benchmarks" / "adaptive.py"),
            "--max-ndof",
            "5000",
            "--out",
            str(tmp_path),
        ],
        capture_output=True,
        text=True,
        timeout=300,
        check=True,
    ).stdout
    lines = out.strip().splitlines()
    print("\n".join(lines[-8:]))
    assert lines[-1].startswith("ratio_to_floor=")
    ratio = float(lines[-1].split("=")[1])
    assert ratio > 0.5  # our level includes the floor's work: it cannot be much cheaper
    assert "PDAS linear solves per level after level 5" in out
    assert (tmp_path / "history.csv").is_file()


def test_inclined_block_example_runs(tmp_path):
    """The literate example with a non-axis contact normal runs and touches the foundation
    without penetrating it."""
    out = subprocess.run(
        [
            sys.executable,
            str(ROOT / "examples" / "inclined_block.py"),
            "--max-ndof",
            "3000",
            "--out",
            str(tmp_path),
        ],
        capture_output=True,
        text=True,
        timeout=300,
        check=True,
    ).stdout
    last = out.strip().splitlines()[-1]
    print(last)
    force = float(last.split("resultant normal force ")[1].split(";")[0])
    penetration = float(last.split("largest penetration ")[1])
    assert force > 10.0 and penetration < 1e-12
    assert (tmp_path / "solution.vtu").is_file() and (tmp_path / "deformed.png").is_file()
