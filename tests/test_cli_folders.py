"""The command line's run folders under hostile or unlucky use: paths through ``..``, a second
process on a folder, SIGKILL and SIGTERM, a closed stdout, a kill while drawing, a level that
fails, a truncated level file, ``figures`` with another problem; problem files with a load
path; the VTU output a ParaView user reads (stress, von Mises, pvd collections, fields.md) and
the manifest's environment."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import xml.etree.ElementTree as ET
from dataclasses import replace
from pathlib import Path

import meshio
import numpy as np
import pytest
from test_cli import (
    RUN_62,
    assert_same_history,
    history_without_timings,
    interrupt_after_level,
    read_history,
    run_in_subprocess,
    wait_for_level,
)

from signorini import Contact, ContactProblem, Dirichlet, Material, rectangle
from signorini.cli import main
from signorini.contact.solution import solve
from signorini.loop import AdaptiveOptions, adaptive
from signorini.output import write_vtu

ENV = {**os.environ, "MPLBACKEND": "Agg"}


# ---------------------------------------------------------------------- paths
def test_out_through_a_missing_folder_is_the_folder_it_names(tmp_path, capsys, monkeypatch):
    """``--out newdir/..`` is the current folder: refused, not written into."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "history.csv").write_text("my own history\n")
    assert main([*RUN_62, "--out", "newdir/.."]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"signorini: error: output folder {tmp_path} is not empty: it holds")
    assert (tmp_path / "history.csv").read_text() == "my own history\n"
    assert sorted(os.listdir(tmp_path)) == ["history.csv"]


def test_a_problem_file_named_dots_does_not_default_to_the_parent_folder(
    tmp_path, capsys, monkeypatch
):
    """``...py`` has the stem ``..``; its default folder is results/problem, not results/..
    (the current folder)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "history.csv").write_text("my own history\n")
    (tmp_path / "...py").write_text(SLIDE)
    assert main(["run", "...py", "--max-levels", "1", "--no-figures", "--quiet"]) == 0
    assert (tmp_path / "history.csv").read_text() == "my own history\n"
    assert (tmp_path / "results" / "problem" / "history.csv").is_file()


# ---------------------------------------------------------------------- lock and signals
@pytest.mark.slow
def test_a_folder_a_live_process_writes_is_refused_and_a_dead_one_is_not_running(tmp_path, capsys):
    out = tmp_path / "busy"
    proc = run_in_subprocess(out, "--max-ndof", "1000000")
    try:
        wait_for_level(proc, 2)
        pid = proc.pid
        busy = f"is being written by another process (pid {pid} on "
        assert main(["run", "example-6.2", "--resume", str(out), "--max-levels", "1"]) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"signorini: error: cannot resume: the folder {out} {busy}"), err
        again = ["run", "example-6.2", "--out", str(out), "--max-levels", "1", "--overwrite"]
        assert main([*again, "--quiet"]) == 2
        assert f"output folder {out} {busy}" in capsys.readouterr().err
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=60)
    finally:
        proc.kill()
    manifest = json.loads((out / "signorini-run.json").read_text())
    assert manifest["status"] == "running"  # SIGKILL: nobody could say otherwise
    assert main(["run", "example-6.2", "--out", str(out), "--max-levels", "1"]) == 2
    err = capsys.readouterr().err
    assert "(stopped before finishing: its process ended)" in err and "(running)" not in err
    # the lock died with the process: the folder can be taken over
    assert main([*again, "--quiet", "--no-figures"]) == 0


@pytest.mark.slow
def test_sigterm_ends_a_run_as_ctrl_c_does(tmp_path):
    out = tmp_path / "term"
    proc = run_in_subprocess(out, "--max-ndof", "1000000")
    try:
        wait_for_level(proc, 2)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    assert proc.returncode == 143, err
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("signorini: terminated (SIGTERM) at level")
    assert f"continue with: signorini run example-6.2 --resume {out}" in lines[0]
    assert json.loads((out / "signorini-run.json").read_text())["status"] == "interrupted"
    _, rows = read_history(out / "history.csv")
    assert len(rows) >= 3 and len(list(out.glob("level_*.vtu"))) == len(rows)


@pytest.mark.slow
def test_a_closed_stdout_stops_the_progress_lines_not_the_run(tmp_path):
    """``signorini run ... | head -2``: the run ends cleanly with every file."""
    out = tmp_path / "piped"
    argv = [sys.executable, "-m", "signorini.cli", "run", "example-6.2", "--out", str(out)]
    proc = subprocess.Popen(
        [*argv, "--max-ndof", "3000", "--no-figures"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=ENV,
    )
    try:
        head = [proc.stdout.readline() for _ in range(2)]
        proc.stdout.close()  # as head does after two lines
        err = proc.stderr.read().decode()
        proc.wait(timeout=300)
    finally:
        proc.kill()
    assert head[1].startswith(b"level   0")
    assert proc.returncode == 0, err
    assert "Broken pipe" not in err and "Traceback" not in err
    assert json.loads((out / "signorini-run.json").read_text())["status"] == "finished"
    _, rows = read_history(out / "history.csv")
    assert len(rows) > 5 and len(list(out.glob("level_*.vtu"))) == len(rows)


@pytest.mark.slow
def test_a_kill_while_drawing_leaves_no_empty_figure(tmp_path, capsys, monkeypatch):
    """A figure is written to a temporary file and moved into place: stopped in the middle
    of a write, no figure file is left (empty or partial), only the finished ones."""
    from matplotlib.figure import Figure

    calls = []
    savefig = Figure.savefig

    def stopped(self, fname, *args, **kwargs):
        calls.append(fname)
        if len(calls) == 3:  # the second figure's PNG
            Path(fname).write_bytes(b"")
            raise KeyboardInterrupt
        return savefig(self, fname, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", stopped)
    out = tmp_path / "f"
    assert main(["run", "example-6.2", "--max-ndof", "300", "--out", str(out), "--quiet"]) == 130
    figures = {p.name: p.stat().st_size for p in out.iterdir() if p.suffix in (".png", ".pdf")}
    assert len(figures) == 2 and min(figures.values()) > 0, figures
    assert not [p for p in os.listdir(out) if p.startswith(".")]


@pytest.mark.slow  # ~10 s of drawing
def test_a_failed_run_records_its_error_and_draws_its_finished_levels(
    tmp_path, capsys, monkeypatch
):
    """A failure in a level (here the solver's) left the manifest at "running" and drew no
    figure: now the manifest says "failed" with the error, the finished levels' figures are
    drawn, and --resume continues the run."""
    import signorini.loop as loop

    solve, calls = loop.solve, []

    def failing(*args, **kwargs):
        calls.append(1)
        if len(calls) == 4:
            raise FloatingPointError("overflow in the factorization")
        return solve(*args, **kwargs)

    monkeypatch.setattr(loop, "solve", failing)
    out = tmp_path / "crash"
    assert main(["run", "example-6.2", "--max-ndof", "3000", "--out", str(out), "--quiet"]) == 2
    error = "FloatingPointError: overflow in the factorization"
    assert capsys.readouterr().err == (
        f"signorini: error: the run failed at level 3 (levels 0-2 finished in {out}, their "
        f"figures drawn; signorini-run.json records the failure): {error}\n"
    )
    manifest = json.loads((out / "signorini-run.json").read_text())
    assert manifest["status"] == "failed" and manifest["error"] == f"at level 3: {error}"
    pictures = {p.name for p in out.glob("*.png")}
    assert {"mesh.png", "deformed.png", "example-6.2_estimator.png"} <= pictures
    assert pictures <= set(manifest["files"])
    _, rows = read_history(out / "history.csv")
    assert len(rows) == 3
    monkeypatch.undo()
    resume = ["run", "example-6.2", "--resume", str(out), "--quiet", "--no-figures"]
    assert main(resume) == 0
    manifest = json.loads((out / "signorini-run.json").read_text())
    assert manifest["status"] == "finished" and "error" not in manifest


def test_a_truncated_level_file_read_by_the_figures_is_a_recorded_failure(
    tmp_path, capsys, monkeypatch
):
    """meshio ends the process (sys.exit) on a truncated VTU file: the run ended with the
    manifest at "running" and no message naming the file."""
    import signorini.cli.run as cli_run
    import signorini.plots as plots

    draw = cli_run.draw_figures

    def truncated_then_drawn(label, folder, last, metrics, say):
        vtu = folder.path / "level_000.vtu"  # cut short (a full disk, another process)
        vtu.write_bytes(vtu.read_bytes()[:1000])
        return draw(label, folder, last, metrics, say)

    monkeypatch.setattr(cli_run, "draw_figures", truncated_then_drawn)
    monkeypatch.setattr(plots, "readable_level", lambda n_cells, most=0: 0)
    out = tmp_path / "t"
    assert main([*RUN_62[:3], "1200", "--out", str(out), "--quiet"]) == 2
    _, rows = read_history(out / "history.csv")
    fault = (
        f"{out / 'level_000.vtu'} is not a readable level file of a run (ReadError; truncated, "
        "or not a VTU file signorini wrote)"
    )
    assert capsys.readouterr().err == (
        f"signorini: error: the run failed while drawing the figures (levels 0-{len(rows) - 1} "
        f"finished in {out}; signorini-run.json records the failure): {fault}\n"
    )
    manifest = json.loads((out / "signorini-run.json").read_text())
    assert manifest["status"] == "failed"
    assert manifest["error"] == f"while drawing the figures: {fault}"


@pytest.mark.slow
def test_figures_refuses_a_problem_that_is_not_the_folders(tmp_path, capsys):
    out = tmp_path / "r"
    assert main([*RUN_62[:3], "300", "--out", str(out), "--no-figures", "--quiet"]) == 0
    assert main(["figures", "example-6.1", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"figures example-6.1 {out}: example-6.1 is not the problem of the run in" in err
    assert not list(out.glob("*.png"))
    assert main(["figures", "example-6.2", str(out)]) == 0
    assert len(list(out.glob("example-6.2_*.png"))) >= 1


# ---------------------------------------------------------------------- load paths
SLIDE = """
from signorini import Contact, ContactProblem, Coulomb, Dirichlet, Material, Neumann, rectangle


def step(dx):
    return ContactProblem(
        rectangle(0, 1, 0, 0.5, nx=4, ny=2),
        Material.from_young(1.0, 0.3),
        {
            "top": Dirichlet((dx, -0.01)),
            "left": Neumann(),
            "right": Neumann(),
            "bottom": Contact(gap=0.0, friction=Coulomb(0.3)),
        },
        name="slide",
    )


def load_path():
    return [step(0.0)]


def problem():
    return step(0.0003)
"""


@pytest.mark.slow
def test_a_problem_files_load_path_is_solved_and_resumed(tmp_path, capsys, monkeypatch):
    """A file with ``load_path()``: the history of ``adaptive(problem, path=steps)``, and
    after an interrupt and ``--resume`` the uninterrupted history."""
    source = tmp_path / "slide.py"
    source.write_text(SLIDE)
    sys.path.insert(0, str(tmp_path))
    try:
        import slide
    finally:
        sys.path.remove(str(tmp_path))
    options = AdaptiveOptions(max_ndof=800)
    records = [lv.record for lv in adaptive(slide.problem(), options, path=slide.load_path())]
    one_step = [lv.record for lv in adaptive(slide.problem(), options)]
    full, part = tmp_path / "full", tmp_path / "part"
    args = ["run", str(source), "--max-ndof", "800", "--no-figures", "--quiet"]
    assert main([*args, "--out", str(full)]) == 0
    _, rows = read_history(full / "history.csv")
    assert [int(r["ndof"]) for r in rows] == [r.ndof for r in records]
    assert [int(r["pdas_iterations"]) for r in rows] == [r.pdas_iterations for r in records]
    np.testing.assert_allclose([float(r["eta"]) for r in rows], [r.eta for r in records], 1e-9)
    # the path matters: the history is not that of the last step alone
    assert abs(one_step[0].eta / records[0].eta - 1) > 1e-5
    interrupt_after_level(monkeypatch, 2)
    assert main([*args, "--out", str(part)]) == 130
    monkeypatch.undo()
    capsys.readouterr()
    assert main(["run", str(source), "--resume", str(part), "--quiet", "--no-figures"]) == 0
    assert len(rows) > 4
    assert_same_history(
        history_without_timings(full / "history.csv"),
        history_without_timings(part / "history.csv"),
    )


@pytest.mark.parametrize(
    ("definition", "message"),
    [
        ("load_path = 3\n", "load_path in {} is a int: define it as a function load_path()"),
        ("def load_path():\n    return step(0.0)\n", "returned ContactProblem, not a list"),
        ("def load_path():\n    return [1]\n", "step 0 is a int, not a ContactProblem"),
        ("def load_path():\n    return []\n", "returned no step"),
    ],
)
def test_a_bad_load_path_is_refused_by_name(tmp_path, capsys, definition, message):
    source = tmp_path / "bad.py"
    source.write_text(
        SLIDE.split("def load_path")[0] + definition + "def problem():\n    return step(0.0)\n"
    )
    out = tmp_path / "o"
    assert main(["run", str(source), "--out", str(out), "--max-levels", "1", "--quiet"]) == 2
    assert message.format(source) in capsys.readouterr().err
    assert not out.exists()


# ---------------------------------------------------------------------- output
def uniaxial_problem(strain: float = 1e-3) -> tuple[ContactProblem, float, float]:
    """A block stretched in x, free in y (plane strain, σ_yy = σ_xy = 0): Dirichlet values
    of the exact linear field on three sides, the bottom a contact part far from its
    obstacle (free). Returns the problem, σ_xx and ε_yy."""
    material = Material.from_young(200.0, 0.3)
    lam, mu = material.lam, material.mu
    eyy = -lam * strain / (lam + 2 * mu)
    sxx = lam * (strain + eyy) + 2 * mu * strain

    def u(x):
        return np.column_stack([strain * x[:, 0], eyy * x[:, 1]])

    problem = ContactProblem(
        rectangle(0, 2, 0, 1, nx=4, ny=3),
        material,
        {
            "left": Dirichlet(u),
            "right": Dirichlet(u),
            "top": Dirichlet(u),
            "bottom": Contact(gap=1.0),
        },
    )
    return problem, sxx, eyy


def test_vtu_stress_and_von_mises_of_an_exact_linear_elastic_solution(tmp_path):
    from signorini.fem.postprocess import nodal_stress
    from signorini.output.vtu import von_mises

    problem, sxx, _ = uniaxial_problem()
    result = solve(problem)
    lam, mu = problem.material.lam, problem.material.mu
    m = meshio.read(write_vtu(tmp_path / "s.vtu", result))
    stress = m.point_data["stress"]  # xx, yy, zz, xy, yz, xz
    szz = lam * sxx / (2 * (lam + mu))
    exact = np.array([sxx, 0.0, szz, 0.0, 0.0, 0.0])
    np.testing.assert_allclose(
        stress, np.broadcast_to(exact, stress.shape), rtol=0, atol=1e-12 * sxx
    )
    vm = np.sqrt(0.5 * ((sxx - 0) ** 2 + (0 - szz) ** 2 + (szz - sxx) ** 2))
    np.testing.assert_allclose(m.point_data["von_mises"], vm, rtol=1e-12)
    # a general linear field with shear (interpolated): σ exact at every node
    g = np.array([[1e-3, 4e-4], [-2e-4, 7e-4]])
    nodes = result.space.node_points
    linear = replace(result, u=nodes @ g.T)
    eps = 0.5 * (g + g.T)
    sig = lam * np.trace(eps) * np.eye(2) + 2 * mu * eps
    got = nodal_stress(linear.space, linear.u, linear.problem.material)
    np.testing.assert_allclose(got[:, :2, :2], np.broadcast_to(sig, (len(nodes), 2, 2)), atol=1e-15)
    np.testing.assert_allclose(got[:, 2, 2], lam * np.trace(eps), rtol=1e-12)
    # von Mises by its formula, against an independent one (the deviator's norm)
    dev = got - np.trace(got, axis1=1, axis2=2)[:, None, None] * np.eye(3) / 3
    np.testing.assert_allclose(
        von_mises(got), np.sqrt(1.5 * np.einsum("nij,nij->n", dev, dev)), rtol=1e-12
    )


def test_a_run_writes_pvd_collections_fields_md_and_its_environment(tmp_path, capsys):
    from signorini.output.vtu import POINT_FIELDS

    out = tmp_path / "r"
    assert main([*RUN_62[:3], "1000", "--out", str(out), "--no-figures", "--quiet"]) == 0
    _, rows = read_history(out / "history.csv")
    for name, key in (("levels.pvd", "level"), ("levels_ndof.pvd", "ndof")):
        sets = ET.parse(out / name).getroot().find("Collection").findall("DataSet")
        assert [d.get("file") for d in sets] == [f"level_{i:03d}.vtu" for i in range(len(rows))]
        assert [d.get("timestep") for d in sets] == [r[key] for r in rows]
    fields = (out / "fields.md").read_text()
    m = meshio.read(out / "level_000.vtu")
    assert set(m.point_data) == set(POINT_FIELDS)
    for name in [*m.point_data, "eta2", "eta2_k"]:
        assert f"| `{name}` |" in fields, name
    assert {k: v.tolist() for k, v in m.field_data.items()} == {"region:body": [0]}
    assert "| `region` | region name |\n|---|---|\n| 0 | `body` |" in fields  # the run's names
    env = json.loads((out / "signorini-run.json").read_text())["environment"]
    assert set(env) >= {"signorini", "python", "numpy", "scipy", "solver_library", "date", "host"}
    assert env["numpy"] == np.__version__ and env["python"] == sys.version.split()[0]
    assert "PARDISO" in env["solver_library"] or "SuperLU" in env["solver_library"]


# ---------------------------------------------------------------------- progress
def test_the_time_left_is_the_growth_of_ndof_times_the_time_per_unknown():
    from signorini.cli.levels import Clock

    clock = Clock(AdaptiveOptions(max_ndof=10_000, max_levels=100))
    clock.ndof = [100, 400]
    # the next levels: 1600, 6400 (25600 exceeds the budget), at 1e-3 s per unknown
    assert clock.left(1, 1e-3) == pytest.approx(8.0, rel=1e-12)
    clock = Clock(AdaptiveOptions(max_ndof=10_000, max_levels=3))
    clock.ndof = [100, 400]
    assert clock.left(1, 1e-3) == pytest.approx(1.6, rel=1e-12)  # one level left
    clock.ndof = [400, 400]
    assert clock.left(1, 1e-3) is None  # no growth to go by


@pytest.mark.slow
def test_verbose_shows_the_librarys_log_lines(tmp_path):
    argv = [sys.executable, "-m", "signorini.cli", "run", "example-6.2", "--max-levels", "2"]
    for extra, expected in (([], False), (["--verbose"], True)):
        done = subprocess.run(
            [*argv, "--out", str(tmp_path / str(expected)), "--no-figures", *extra],
            capture_output=True,
            text=True,
            env=ENV,
            timeout=300,
        )
        assert done.returncode == 0, done.stderr
        assert ("INFO signorini." in done.stderr) == expected, done.stderr
