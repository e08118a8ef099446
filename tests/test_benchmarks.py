"""The benchmark scripts run end to end on a small budget and print their ratios."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from signorini.tuning import retain_freed_memory

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_adaptive_benchmark_prints_ratio_to_floor(tmp_path):
    out = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "adaptive.py"), "--max-ndof", "5000",
         "--out", str(tmp_path)],
        capture_output=True, text=True, timeout=300, check=True,
    ).stdout
    lines = out.strip().splitlines()
    print("\n".join(lines[-8:]))
    assert lines[-1].startswith("ratio_to_floor=")
    ratio = float(lines[-1].split("=")[1])
    assert ratio > 0.5  # our level includes the floor's work: it cannot be much cheaper
    assert "PDAS linear solves per level after level 5" in out
    assert (tmp_path / "history.csv").is_file()


def test_retain_freed_memory_on_linux():
    if not sys.platform.startswith("linux"):
        pytest.skip("glibc only")
    assert retain_freed_memory() is True
