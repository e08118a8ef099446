"""benchmarks/cold.py runs end to end on a small budget and reports what it measured."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_cold_benchmark_reports_agreement_iterations_and_ratio():
    out = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "cold.py"), "--max-ndof", "40000"],
        capture_output=True,
        text=True,
        timeout=300,
        check=True,
    ).stdout
    lines = out.strip().splitlines()
    ndof = int(re.search(r"mesh: (\d+) unknowns", out).group(1))
    assert 20_000 <= ndof <= 40_000, ndof
    agreement = re.search(r"agreement: u (\S+), contact force (\S+) ", out)
    assert max(float(agreement.group(1)), float(agreement.group(2).rstrip(","))) <= 1e-10
    its = [int(m) for m in re.findall(r"fine PDAS (\d+) iterations", out)]
    assert len(its) == 2 and its[0] < its[1], its  # nested, then from the empty set
    seconds, ratio = (
        float(x) for x in re.search(r"nested iteration: (\S+) s = (\S+) x floor", out).groups()
    )
    floor = float(re.search(r"^floor (\S+) s", out, re.M).group(1))
    # the printed seconds are rounded to 1 ms, the ratios to 0.001
    low, high = (seconds - 5e-4) / (floor + 5e-4), (seconds + 5e-4) / (floor - 5e-4)
    assert low - 5e-4 <= ratio <= high + 5e-4, (seconds, floor, ratio)
    assert re.fullmatch(r"cold_ratio=\d+\.\d{3}", lines[-1]), lines[-1]
    assert float(lines[-1].split("=")[1]) == ratio, (lines[-1], ratio)
