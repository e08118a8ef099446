"""The adaptive loop in 3D: SOLVE → ESTIMATE → MARK (Dörfler, θ = 0.4) → REFINE (bisection of
tetrahedra), every η column in the history, warm starts where the prolongation allows them,
and a run continued from a level giving the levels of the uninterrupted one."""

from __future__ import annotations

import math

import numpy as np
import pytest

from signorini.estimator.marking import mark_doerfler
from signorini.examples.hertz3d import hertz_3d
from signorini.loop import adaptive

from .cube import cube_problem, full_contact_fields


def _same_levels(full, rest):
    for a, b in zip(full, rest, strict=True):
        ra = {c: v for c, v in a.record.row().items() if not c.startswith("t_")}
        rb = {c: v for c, v in b.record.row().items() if not c.startswith("t_")}
        assert ra == rb
        np.testing.assert_array_equal(a.result.u, b.result.u)


def test_the_full_contact_cube_adapts_and_a_continued_run_gives_the_same_levels():
    """The full-contact cube, three adaptive levels: the records carry η and its terms, the
    efficiency index against the exact solution, the node classes (all rows in full contact
    under condition (b)); each marking is Dörfler's of the level's η_T², a proper subset; η_h
    decreases; the run continued after level 0 repeats levels 1 and 2."""
    problem = cube_problem(full_contact_fields(), 2)
    full = list(adaptive(problem, max_levels=3))
    assert [lev.record.level for lev in full] == [0, 1, 2]
    for lev in full:
        r = lev.record
        assert math.isfinite(r.eta) and r.eta > 0
        assert np.isclose(r.eta**2, sum(getattr(r, f"eta_{k}") ** 2 for k in range(1, 9)))
        assert np.isclose(r.efficiency, r.eta / r.error_energy)
        assert r.n_full_contact == r.n_constrained > 0
        if lev.marked is not None:
            np.testing.assert_array_equal(lev.marked, mark_doerfler(lev.estimate.eta2, 0.4))
            assert 0 < lev.marked.sum() < lev.marked.size
    eta = [lev.record.eta for lev in full]
    assert eta[2] < eta[1] < eta[0]
    rest = list(
        adaptive(problem, max_levels=3, mesh=full[0].next_mesh, u0=full[0].next_u0, first_level=1)
    )
    _same_levels(full[1:], rest)


@pytest.mark.slow
def test_hertz_3d_adaptive_refines_at_the_contact_zone_and_continues_exactly():
    """``adaptive(hertz_3d(h_contact=0.2))``, four levels: η_h decreases on every level, every
    marked cell is within 0.3 R of the pole (the contact radius is about 0.1 R), and the run
    continued after level 1 repeats levels 2 and 3 (curved cells on the sphere: the
    prolongation may refuse a bisection's new sphere points, and the level starts cold, as an
    uninterrupted run does)."""
    problem = hertz_3d(h_contact=0.2)
    full = list(adaptive(problem, max_levels=4))
    eta = [lev.record.eta for lev in full]
    print("hertz-3d adaptive:", [(lev.record.ndof, f"{lev.record.eta:.3e}") for lev in full])
    assert all(b < a for a, b in zip(eta, eta[1:], strict=False)), eta
    for lev in full[:-1]:
        mesh = lev.result.mesh
        centre = mesh.points[mesh.cells].mean(axis=1)
        assert np.linalg.norm(centre[lev.marked], axis=1).max() <= 0.3
    rest = list(
        adaptive(problem, max_levels=4, mesh=full[1].next_mesh, u0=full[1].next_u0, first_level=2)
    )
    _same_levels(full[2:], rest)


@pytest.mark.slow
def test_signorini_run_hertz_3d_adaptive_writes_every_eta_column(tmp_path, capsys):
    """``signorini run hertz-3d`` without ``--uniform``: the level lines show η, the history
    has every η column, the node classes, the obstacle's term beside η (0 for the plane: ψ is
    affine) and the marked cells of each level."""
    import csv

    from signorini.cli import main
    from signorini.estimator.names import TERMS

    out = tmp_path / "run"
    assert main(["run", "hertz-3d", "--max-ndof", "7000", "--out", str(out), "--no-figures"]) == 0
    lines = [line for line in capsys.readouterr().out.splitlines() if line.startswith("level ")]
    assert len(lines) >= 2 and all(" eta " in line for line in lines)
    rows = list(csv.DictReader(open(out / "history.csv")))
    assert {"eta", *TERMS, "n_semi_contact", "osc_obstacle"} <= set(rows[0])
    assert all(float(r["eta"]) > 0 and float(r["osc_obstacle"]) < 1e-6 for r in rows)
    assert int(rows[0]["n_marked"]) > 0 and int(rows[0]["n_semi_contact"]) > 0
