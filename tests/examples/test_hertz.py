"""The Hertz example (signorini.examples.hertz): an elastic half-disc on a rigid plane.

The adaptive loop must reproduce Hertz's half-width a and peak pressure p0 (of each level's
own total force) within 1 %, and his pressure profile within 2 % of p0 away from the ends;
η_h must decay like Ndof⁻¹ with the refinement at the two ends of the contact zone. The
problem rotated by any angle gives the rotated solution, and on coarse meshes straight
chords put the peak pressure several percent off where isoparametric cells do not.
"""

from __future__ import annotations

import numpy as np
import pytest

from signorini import adaptive, solve
from signorini.examples.hertz import DEPTH, hertz, hertz_contact, hertz_metrics, hertz_solution
from signorini.output import fitted_slope

#: about 25 levels, one to two seconds in all
BUDGET = 30_000


@pytest.fixture(scope="module")
def levels():
    return list(adaptive(hertz(), max_ndof=BUDGET, metrics=hertz_metrics))


@pytest.mark.slow
def test_a_and_p0_within_one_percent_of_hertz_at_the_final_level(levels):
    print("\nlevel   ndof   a/R       a error   p0 error")
    for level in levels:
        r, e = level.record, level.record.extra
        print(
            f"{r.level:5d} {r.ndof:6d} {e['a']:.5f} "
            f"{100 * e['a_rel_error']:+8.3f} % {100 * e['p0_rel_error']:+8.3f} %"
        )
    final = levels[-1].record.extra
    assert 0.09 < final["a"] < 0.11, f"a/R = {final['a']}, the example is meant for a/R ≈ 0.1"
    assert abs(final["a_rel_error"]) < 0.01, f"a differs from Hertz by {final['a_rel_error']:.3%}"
    assert abs(final["p0_rel_error"]) < 0.01, (
        f"p0 differs from Hertz by {final['p0_rel_error']:.3%}"
    )


@pytest.mark.slow
def test_pressure_profile_within_two_percent_of_p0_away_from_the_ends(levels):
    result = levels[-1].result
    zone = hertz_contact(result)
    a, p0 = hertz_solution(zone["force"], zone["radius"], result.problem.material)
    x = zone["x"]
    inner = np.abs(x) < 0.8 * a
    hertz_p = p0 * np.sqrt(1 - (x[inner] / a) ** 2)
    misfit = np.abs(result.pressure[inner] - hertz_p).max() / p0
    print(f"\n{inner.sum()} nodes with |x| < 0.8 a: largest |p_z − p_Hertz| = {misfit:.3%} of p0")
    assert inner.sum() > 20
    assert misfit < 0.02, f"pressure off the Hertz profile by {misfit:.3%} of p0"


@pytest.mark.slow
def test_estimator_decays_like_one_over_ndof(levels):
    ndof = [level.record.ndof for level in levels]
    eta = [level.record.eta for level in levels]
    slope = fitted_slope(ndof, eta, last=6)
    print(f"\nη_h slope over the last 6 levels ({ndof[-6]} to {ndof[-1]} unknowns): {slope:.3f}")
    assert slope <= -0.9, f"η_h decays like Ndof^{slope:.3f}"


@pytest.mark.slow
def test_refinement_concentrates_at_the_two_ends_of_the_contact_zone(levels):
    result = levels[-1].result
    mesh = result.mesh
    zone = hertz_contact(result)
    a = zone["a"]
    smallest = np.argsort(mesh.h, kind="stable")[:20]
    centres = mesh.points[mesh.cells[smallest]].mean(axis=1)
    x = (centres - zone["centre"]) @ zone["tangent"]
    print(
        f"\nthe 20 smallest cells (h = {mesh.h[smallest].min():.2e} … "
        f"{mesh.h[smallest].max():.2e}) lie at x / a = {np.sort(x / a).round(3)}"
    )
    assert np.all(np.abs(np.abs(x) - a) < 0.05 * a), np.sort(x / a)
    assert (x < 0).sum() >= 5 and (x > 0).sum() >= 5, "refined at one end only"
    assert mesh.h.max() > 50 * mesh.h[smallest].max()  # graded, not uniform


@pytest.mark.slow
def test_every_level_meets_kkt_to_1e_10(levels):
    worst = max(level.result.report.kkt.max for level in levels)
    print(f"\nlargest relative KKT residual over {len(levels)} levels: {worst:.2e}")
    assert worst <= 1e-10


def test_rotated_problem_gives_the_rotated_solution():
    angle = 0.7317
    c, s = np.cos(angle), np.sin(angle)
    rotation = np.array([[c, -s], [s, c]])
    upright = solve(hertz(h_bottom=0.02))
    turned = solve(hertz(h_bottom=0.02, angle=angle))
    assert np.array_equal(upright.contact.nodes, turned.contact.nodes)
    scale_u = np.abs(upright.u).max()
    du = np.abs(turned.u - upright.u @ rotation.T).max() / scale_u
    dl = np.abs(turned.contact_force - upright.contact_force).max() / upright.total_contact_force
    print(f"\nrotated by {angle} rad: max |u' − Q u| / max |u| = {du:.1e}, max |ΔΛ| / P = {dl:.1e}")
    assert np.array_equal(upright.active, turned.active)
    assert du < 1e-10 and dl < 1e-10
    m0, m1 = hertz_metrics(upright), hertz_metrics(turned)
    assert m1 == pytest.approx(m0, rel=1e-9, abs=1e-12)


@pytest.mark.slow
def test_straight_chords_put_the_peak_pressure_percents_off_on_coarse_meshes():
    a = 0.099  # the default example's half-width, a / R
    errors = {}
    for fraction in (5, 10):
        for curved in (False, True):
            problem = hertz(h_bottom=a / fraction, grading=0.1, curved=curved)
            errors[fraction, curved] = hertz_metrics(solve(problem))["p0_rel_error"]
    print(
        "\npeak pressure against Hertz:"
        + "".join(
            f"\n  h = a/{f:<2d}: straight chords {100 * errors[f, False]:+.2f} %, "
            f"isoparametric {100 * errors[f, True]:+.2f} %"
            for f in (5, 10)
        )
    )
    assert errors[5, False] > 0.05 and errors[10, False] > 0.025, errors
    assert 1.6 < errors[5, False] / errors[10, False] < 2.4, errors  # first order in h
    assert abs(errors[5, True]) < 0.005 and abs(errors[10, True]) < 0.005, errors


@pytest.mark.slow
def test_default_depth_gives_a_over_r_about_one_tenth(levels):
    assert DEPTH == 0.015
    assert levels[-1].record.extra["a"] == pytest.approx(0.099, abs=0.002)


def test_scaled_problem_gives_the_same_relative_errors():
    """R = 2 with the default δ = DEPTH·R and the mesh scaled alike: u and a double, the
    pressures stay, so the relative errors are the same to round-off."""
    small = solve(hertz(h_bottom=0.02))
    large = solve(hertz(radius=2.0, h_bottom=0.04))
    assert np.abs(large.u - 2 * small.u).max() < 1e-12 * np.abs(large.u).max()
    m1, m2 = hertz_metrics(small), hertz_metrics(large)
    assert m2["a"] == pytest.approx(2 * m1["a"], rel=1e-10)
    assert m2["p0"] == pytest.approx(m1["p0"], rel=1e-10)
    for key in ("a_rel_error", "p0_rel_error"):
        assert m2[key] == pytest.approx(m1[key], rel=1e-8, abs=1e-12)


@pytest.mark.slow
def test_command_line_writes_the_hertz_columns_and_the_pressure_figure(tmp_path):
    from signorini.cli import main
    from signorini.output import read_history

    out = tmp_path / "hertz"
    argv = ["run", "hertz", "--max-ndof", "1500", "--no-vtu", "--quiet", "--out", str(out)]
    assert main(argv) == 0
    history = read_history(out / "history.csv")
    levels = list(adaptive(hertz(), max_ndof=1500))
    assert history["ndof"].tolist() == [level.record.ndof for level in levels]
    for column in ("a", "p0", "a_rel_error", "p0_rel_error"):
        expected = [hertz_metrics(level.result)[column] for level in levels]
        assert np.array_equal(history[column], expected, equal_nan=True), column
        assert f"| `{column}` |" in (out / "history.md").read_text()
    assert (out / "hertz_pressure.png").stat().st_size > 5000


def test_without_contact_the_measurements_are_nan():
    result = solve(hertz(depth=-0.01, h_bottom=0.05))  # lifted off the plane
    assert result.total_contact_force == 0.0
    values = hertz_metrics(result)
    assert set(values) == {"a", "p0", "a_rel_error", "p0_rel_error"}
    assert all(np.isnan(v) for v in values.values())
    with pytest.raises(ValueError, match="does not touch the plane"):
        hertz_contact(result)


def test_mesh_figure_finds_the_arc_of_a_refined_mesh():
    """The mesh figure marks Γ_C on the arc, whose refined edges lie on the circle, not on the
    initial mesh's chords."""
    from signorini.mesh.refine import refine_nvb, refine_uniform
    from signorini.plots.run_figures import part_segments

    initial = hertz().mesh
    mesh = refine_uniform(refine_nvb(initial, initial.h > 0.3).mesh).mesh
    mesh = refine_nvb(mesh, np.arange(0, mesh.n_cells, 3)).mesh
    arc = mesh.points[mesh.boundary[mesh.boundary_part == mesh.part_index("arc")]]
    found = part_segments(initial, "arc", mesh.points, mesh.cells)

    def key(segments):
        return sorted(tuple(sorted(map(tuple, np.round(s, 12)))) for s in segments)

    assert len(arc) > 2 * initial.part_facets("arc").size
    assert key(found) == key(arc)
    top = part_segments(initial, "top", mesh.points, mesh.cells)
    assert np.array_equal(top, initial.points[initial.facets[initial.part_facets("top")]])


def test_resumed_run_gives_the_hertz_columns_of_the_uninterrupted_run(tmp_path, monkeypatch):
    from signorini.cli import main
    from tests.test_cli import assert_same_history, history_without_timings, interrupt_after_level

    full, part = tmp_path / "full", tmp_path / "part"
    args = ["run", "hertz", "--max-ndof", "1500", "--no-figures", "--no-vtu", "--quiet"]
    assert main([*args, "--out", str(full)]) == 0
    interrupt_after_level(monkeypatch, 4)
    assert main([*args, "--out", str(part)]) == 130
    monkeypatch.undo()
    assert main(["run", "hertz", "--resume", str(part), "--quiet", "--no-figures"]) == 0
    a = history_without_timings(full / "history.csv")
    b = history_without_timings(part / "history.csv")
    assert len(a) > 6 and "p0_rel_error" in a[-1]
    assert_same_history(a, b)
