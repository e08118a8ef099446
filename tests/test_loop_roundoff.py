"""The adaptive loop stops where η_h reaches its round-off level
(:mod:`signorini.estimator.roundoff`) and says so (figures of noise:
``tests/plots/test_noise.py``)."""

from __future__ import annotations

import csv
import math
import re

import numpy as np
import pytest

from signorini.cli import main
from signorini.estimator.roundoff import ROUNDOFF_FACTOR, hooke_norm, roundoff_level
from signorini.examples import example_6_2
from signorini.examples.two_bodies import stacked_blocks
from signorini.fem.material import Material
from signorini.loop import adaptive

EPS = float(np.finfo(np.float64).eps)


def test_hooke_norm_is_the_largest_eigenvalue_of_the_2d_law():
    problem = stacked_blocks()  # upper E = 1, ν = 0.3; lower E = 3, ν = 0.2 (plane strain)
    lower = Material.from_young(3.0, 0.2)
    assert lower.lam == pytest.approx(0.8333333333333334) and lower.mu == pytest.approx(1.25)
    assert hooke_norm(problem) == pytest.approx(2.0 * (0.8333333333333334 + 1.25), rel=1e-15)


def test_the_patch_test_stops_at_round_off_on_its_first_mesh(caplog):
    """stacked-blocks is exact in P2: η_h = 2.2e-14 on the first mesh, 50 times below its
    round-off level; the loop stops there (it refined 55 levels of noise before)."""
    levels = list(adaptive(stacked_blocks(), max_ndof=100_000))
    assert len(levels) == 1
    record = levels[0].record
    level = ROUNDOFF_FACTOR * EPS * (2 * (5 / 6 + 1.25)) * 0.01 * math.sqrt(148)
    print(f"eta {record.eta:.3e}, round-off level {record.eta_roundoff:.4e} ({level:.4e})")
    assert record.n_cells == 148 and record.eta_roundoff == pytest.approx(level, rel=1e-12)
    assert record.eta_roundoff == pytest.approx(1.1255e-12, rel=1e-4)
    assert record.eta < record.eta_roundoff / 10 and record.stop == "round-off"
    assert levels[0].marked is None and levels[0].next_mesh is None
    assert roundoff_level(levels[0].result) == record.eta_roundoff


def test_a_discretization_error_is_far_above_the_round_off_level():
    """Example 6.2 keeps refining: η_h is 10⁷ times its round-off level or more, and the run
    ends on its budget, as it did before the level existed."""
    levels = list(adaptive(example_6_2(), max_ndof=1500))
    records = [lv.record for lv in levels]
    ratios = [r.eta / r.eta_roundoff for r in records]
    print(f"{len(records)} levels, eta / round-off level from {min(ratios):.2e}")
    assert [r.ndof for r in records[:4]] == [144, 152, 160, 180]
    assert min(ratios) > 1e7
    assert [r.stop for r in records] == [""] * (len(records) - 1) + ["max_ndof"]


def test_the_command_line_says_it_stopped_at_round_off(tmp_path, capsys):
    out = tmp_path / "blocks"
    assert main(["run", "stacked-blocks", "--out", str(out), "--no-vtu", "--no-figures"]) == 0
    said = capsys.readouterr().out
    # η itself is round-off (its digits are the machine's): the line states it below the level
    stated = re.search(r"stopped at level 0: eta = (\S+) is at the round-off level (\S+)", said)
    assert stated is not None, said
    eta, level = float(stated.group(1)), float(stated.group(2))
    assert 0 < eta <= level
    with open(out / "history.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 1 and rows[0]["stop"] == "round-off"
    assert float(rows[0]["eta"]) == pytest.approx(eta, rel=1e-3)
    assert float(rows[0]["eta_roundoff"]) == pytest.approx(level, rel=1e-3)
    assert float(rows[0]["eta_roundoff"]) == pytest.approx(1.1255e-12, rel=1e-4)
    assert "round-off" in (out / "history.md").read_text()


def test_hooke_norm_in_3d_is_the_largest_eigenvalue_of_the_3d_law():
    """The 3D ``‖C‖`` against the eigenvalues of Hooke's law on the six symmetric strains
    (Mandel basis: the off-diagonal ones scaled by √2, so that C is a symmetric 6 × 6
    matrix): 3λ + 2μ = E / (1 − 2ν) = 2.5 for E = 1, ν = 0.3."""
    from estimator3d.cube import cube_problem, patch_fields

    problem = cube_problem(patch_fields(), 2)
    m = problem.material
    basis = []
    for i, j in [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)]:
        e = np.zeros((3, 3))
        e[i, j] = e[j, i] = 1.0 if i == j else 1.0 / math.sqrt(2.0)
        basis.append(e)
    hooke = np.array(
        [
            [np.sum((m.lam * np.trace(b) * np.eye(3) + 2 * m.mu * b) * a) for b in basis]
            for a in basis
        ]
    )
    largest = np.linalg.eigvalsh(hooke).max()
    assert hooke_norm(problem) == pytest.approx(largest, rel=1e-14)
    assert hooke_norm(problem) == pytest.approx(2.5, rel=1e-14)


def test_the_3d_patch_test_stops_at_round_off_on_its_first_mesh():
    """The constant-pressure contact patch test on the cube (u affine, exact in P2): η_h is
    5–8 times ``ε ‖C‖ max|u_h| √n_cells``, far below the level (factor 10⁴); the 3D loop stops
    there, as the 2D one does on ``stacked-blocks``."""
    from estimator3d.cube import cube_problem, patch_fields

    levels = list(adaptive(cube_problem(patch_fields(), 2), max_ndof=100_000))
    assert len(levels) == 1
    record, result = levels[0].record, levels[0].result
    level = ROUNDOFF_FACTOR * EPS * 2.5 * np.abs(result.u).max() * math.sqrt(48)
    print(f"eta {record.eta:.3e}, round-off level {record.eta_roundoff:.4e}")
    assert record.n_cells == 48 and record.eta_roundoff == pytest.approx(level, rel=1e-12)
    assert 0 < record.eta < record.eta_roundoff / 100 and record.stop == "round-off"


def test_a_3d_discretization_error_is_far_above_the_round_off_level():
    """example-6.1-3d keeps refining: its η_h is 10⁹ times its round-off level or more."""
    from signorini.examples.paper3d import example_6_1_3d

    levels = list(adaptive(example_6_1_3d(), max_ndof=700))
    ratios = [lv.record.eta / lv.record.eta_roundoff for lv in levels]
    print(f"{len(levels)} levels, eta / round-off level from {min(ratios):.2e}")
    assert len(levels) >= 3 and min(ratios) > 1e9
    assert [lv.record.stop for lv in levels] == [""] * (len(levels) - 1) + ["max_ndof"]
