"""The adaptive loop on the 3D built-ins (issue 39, "How it is verified"): every level equals an
independent solve on its mesh, example-6.1-3d's error and η decay like N^{-2/3} with a steady
efficiency index, adaptive refinement reaches a given η with fewer unknowns than uniform
refinement, the marking gathers at the contact zone's boundary, and a 3D ``signorini run``
continued after an interruption gives the uninterrupted run's history."""

from __future__ import annotations

import numpy as np
import pytest
from examples3d.adaptive_measures import (
    marking_concentration,
    ndof_ratio,
    near_cells,
    zone_boundary_vertices,
)
from examples3d.independent_qp import solve_independent

from signorini.examples.hertz3d import hertz_3d
from signorini.examples.paper3d import example_6_1_3d, example_6_2_3d
from signorini.loop import adaptive
from signorini.output import fitted_slope


def _history(levels) -> dict[str, np.ndarray]:
    keys = ("ndof", "eta", "error_energy", "efficiency")
    levels = list(levels)
    return {k: np.array([getattr(lev.record, k) for lev in levels]) for k in keys}


@pytest.mark.parametrize("make", [example_6_1_3d, example_6_2_3d], ids=["6.1-3d", "6.2-3d"])
def test_every_adaptive_level_equals_the_independent_dual_nnls(make):
    """The first three adaptive levels (300 to about 500 unknowns, meshes of the bisection's
    closure): u, the active set and the multipliers of ``solve()`` equal the dual NNLS of
    :mod:`.independent_qp` to 10⁻¹² relative, whose KKT residuals are ≤ 10⁻¹²."""
    levels = list(adaptive(make(), max_levels=3))
    assert len(levels) == 3 and levels[2].record.ndof > levels[0].record.ndof
    for lev in levels:
        result = lev.result
        _, other = solve_independent(result)
        assert max(other.kkt.values()) <= 1e-12, other.kkt
        scale = np.abs(other.u).max()
        np.testing.assert_allclose(result.u, other.u, rtol=0, atol=1e-12 * scale)
        np.testing.assert_array_equal(result.active, other.lam > 0)
        force = np.abs(other.lam).max()
        np.testing.assert_allclose(result.report.multiplier, other.lam, atol=1e-12 * force)


@pytest.mark.slow
def test_example_6_1_3d_adaptive_rates_and_a_steady_efficiency_index():
    """example-6.1-3d, θ = 0.4, to 8 000 unknowns (13 levels): the energy error and η_h decay
    at least like N^{-0.6} over the last four levels (optimal: −2/3), and the efficiency index
    η_h / ‖u − u_h‖_a stays within ±30 % of its mean on every level (no drift)."""
    h = _history(adaptive(example_6_1_3d(), max_ndof=8000))
    error_slope = fitted_slope(h["ndof"], h["error_energy"], 4)
    eta_slope = fitted_slope(h["ndof"], h["eta"], 4)
    mean = h["efficiency"].mean()
    band = np.abs(h["efficiency"] / mean - 1).max()
    print(
        f"{h['ndof'].size} levels to N = {h['ndof'][-1]}: slopes error {error_slope:.3f}, "
        f"eta {eta_slope:.3f}; efficiency mean {mean:.2f}, band ±{100 * band:.1f} %"
    )
    assert h["ndof"].size >= 8
    assert error_slope <= -0.6 and eta_slope <= -0.6
    assert band <= 0.3


@pytest.mark.slow
def test_a_3d_run_resumed_after_an_interrupt_gives_the_uninterrupted_history(
    tmp_path, capsys, monkeypatch
):
    """``signorini run example-6.1-3d`` interrupted after level 2 and continued with --resume:
    the same levels, every column but the timings equal to round-off (η and its terms, the
    error, the efficiency index, the counts), the run finished."""
    from test_cli import assert_same_history, history_without_timings, interrupt_after_level

    from signorini.cli import main

    full, part = tmp_path / "full", tmp_path / "part"
    args = ["run", "example-6.1-3d", "--max-ndof", "1500", "--no-figures", "--no-vtu"]
    assert main([*args, "--out", str(full), "--quiet"]) == 0
    interrupt_after_level(monkeypatch, 2)
    assert main([*args, "--out", str(part)]) == 130
    assert "interrupted at level 3; levels 0-2 finished" in capsys.readouterr().err
    monkeypatch.undo()
    assert main(["run", "example-6.1-3d", "--resume", str(part), "--quiet", "--no-figures"]) == 0
    a = history_without_timings(full / "history.csv")
    b = history_without_timings(part / "history.csv")
    print(f"{len(a)} levels; resumed after level 2")
    assert len(a) >= 5 and a[-1]["stop"] == "max_ndof"
    assert_same_history(a, b)


@pytest.mark.slow
def test_example_6_2_3d_adaptive_needs_fewer_unknowns_than_uniform_for_the_same_eta():
    """example-6.2-3d: uniform refinement reaches η_h = 217.0 at 13 872 unknowns; adaptive
    refinement (θ = 0.4) reaches it with 0.43 times as many (log-log interpolation of η(N))."""
    adapted = _history(adaptive(example_6_2_3d(), max_ndof=7000))
    uniform = _history(adaptive(example_6_2_3d(), max_ndof=14_000, uniform=True))
    assert uniform["ndof"].tolist() == [300, 1944, 13872]
    ratio = ndof_ratio(adapted, uniform, uniform["eta"][-1])
    print(f"eta {uniform['eta'][-1]:.4e}: N_adaptive / N_uniform = {ratio:.3f}")
    assert ratio < 0.6


@pytest.mark.slow
def test_hertz_3d_marks_at_the_contact_zone_boundary():
    """hertz-3d, the first five adaptive levels: a cell with a vertex on the boundary of the
    discrete contact zone (a contact face whose vertices are partly in contact) is marked far
    more often than any other — on every level at least 5 times as often, pooled over the
    levels more than 10 times (``marking_concentration``)."""
    levels = list(adaptive(hertz_3d(), max_levels=6))
    near_marked = near_all = far_marked = far_all = 0
    per_level = []
    for lev in levels[:5]:
        zone = zone_boundary_vertices(lev.result)
        per_level.append(marking_concentration(lev.result.mesh, lev.marked, zone))
        near = near_cells(lev.result.mesh, zone)
        near_marked += lev.marked[near].sum()
        near_all += near.sum()
        far_marked += lev.marked[~near].sum()
        far_all += (~near).sum()
    pooled = (near_marked / near_all) / (far_marked / far_all)
    print("concentration per level", np.round(per_level, 2), f"pooled {pooled:.1f}")
    assert min(per_level) >= 5 and pooled > 10


@pytest.mark.slow
def test_compare_uniform_draws_the_3d_optimal_slope(tmp_path, monkeypatch):
    """``signorini run example-6.1-3d --compare-uniform``: both comparison figures (η and the
    error) carry the reference triangle of P2 in 3D, slope −2/3 (not 2D's −1)."""
    from signorini import plots
    from signorini.cli import main

    drawn = []
    plot = plots.plot_adaptive_vs_uniform

    def record(histories, path, **kwargs):
        drawn.append((kwargs["key"], kwargs["reference_slope"]))
        return plot(histories, path, **kwargs)

    monkeypatch.setattr(plots, "plot_adaptive_vs_uniform", record)
    out = tmp_path / "run"
    args = ["run", "example-6.1-3d", "--max-ndof", "700", "--compare-uniform", "--no-vtu"]
    assert main([*args, "--quiet", "--out", str(out)]) == 0
    assert drawn == [("eta", pytest.approx(-2 / 3)), ("error_energy", pytest.approx(-2 / 3))]
    assert (out / "adaptive_vs_uniform.png").stat().st_size > 0
