"""End-to-end tests of the ``signorini`` command line (:mod:`signorini.cli`)."""

from __future__ import annotations

import csv
import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import meshio
import numpy as np
import pytest

from signorini.cli import main
from signorini.contact.solution import solve
from signorini.estimator.residual import estimate
from signorini.examples import example_6_1
from signorini.output import fitted_slope

REQUIRED = [
    "level",
    "ndof",
    "n_cells",
    "eta",
    *[f"eta_{k}" for k in range(1, 8)],
    "pdas_iterations",
    "n_active",
    "error_energy",
    "efficiency",
    "t_output",
]


def read_history(path: Path) -> tuple[list[str], list[dict[str, str]]]:
    with open(path, newline="") as fh:
        reader = csv.DictReader(fh)
        rows = list(reader)
    return list(reader.fieldnames or []), rows


def check_history_and_vtu(out: Path) -> list[dict[str, str]]:
    """history.csv has the required columns and one VTU per level that matches its row."""
    columns, rows = read_history(out / "history.csv")
    missing = [c for c in REQUIRED if c not in columns]
    assert not missing, f"history.csv lacks {missing}"
    assert [int(r["level"]) for r in rows] == list(range(len(rows)))
    vtu = sorted(p.name for p in out.glob("*.vtu"))
    assert vtu == [f"level_{i:03d}.vtu" for i in range(len(rows))]
    for row in rows:
        eta = float(row["eta"])
        terms = np.array([float(row[f"eta_{k}"]) for k in range(1, 8)])
        assert float(row["t_output"]) > 0  # the VTU file took time to write
        assert eta**2 == pytest.approx((terms**2).sum(), rel=1e-12)
        m = meshio.read(out / f"level_{int(row['level']):03d}.vtu")
        assert len(m.cells[0].data) == int(row["n_cells"])
        assert m.cell_data["eta2"][0].sum() == pytest.approx(eta**2, rel=1e-12)
    assert not [p for p in os.listdir(out) if p.endswith(".tmp")]
    return rows


def test_run_example_6_1_uniform(tmp_path, capsys):
    out = tmp_path / "u61"
    code = main(
        ["run", "example-6.1", "--uniform", "--max-ndof", "3000", "--out", str(out), "--no-figures"]
    )
    printed = capsys.readouterr()
    assert code == 0, printed.err
    rows = check_history_and_vtu(out)
    ndof = np.array([int(r["ndof"]) for r in rows])
    err = np.array([float(r["error_energy"]) for r in rows])
    eta = np.array([float(r["eta"]) for r in rows])
    eff = np.array([float(r["efficiency"]) for r in rows])
    print(printed.out)
    print(f"ndof {ndof.tolist()}, error {err}, efficiency {eff}")
    assert ndof.tolist() == [144, 544, 2112]
    assert [int(r["n_cells"]) for r in rows] == [32, 128, 512]
    np.testing.assert_allclose(eff, eta / err, rtol=1e-14)
    slope = fitted_slope(ndof, err, last=2)
    assert slope <= -0.9, f"observed rate {slope:.3f}, expected -1 (P2: error ~ h^2 ~ Ndof^-1)"
    assert all(int(r["pdas_iterations"]) >= 1 for r in rows)
    assert all(int(r["n_active"]) == int(r["n_constrained"]) for r in rows)  # full contact
    # the first row is the package's answer on the example's initial mesh
    assert eta[0] == estimate(solve(example_6_1())).eta
    assert printed.out.count("level ") == 3 and "Traceback" not in printed.err
    assert not list(out.glob("*.png"))


@pytest.mark.slow  # ~10 s of drawing
def test_run_draws_figures_and_figures_command_redraws_them(tmp_path, capsys):
    out = tmp_path / "f61"
    assert (
        main(
            [
                "run",
                "example-6.1",
                "--uniform",
                "--max-ndof",
                "600",
                "--out",
                str(out),
                "--no-vtu",
                "--quiet",
            ]
        )
        == 0
    )
    pictures = sorted(p.name for p in out.glob("*.png"))
    print(pictures)
    # an exact error in the history: error and estimator, efficiency, contributions
    convergence = [f"example-6.1_{f}" for f in ("error_estimator", "efficiency", "contributions")]
    assert pictures == sorted([*(f"{f}.png" for f in convergence), "deformed.png", "mesh.png"])
    _, rows = read_history(out / "history.csv")
    assert len(rows) > 1 and not list(out.glob("*.vtu"))  # --no-vtu: no level written
    capsys.readouterr()
    assert main(["figures", "example-6.1", str(out)]) == 0
    listed = capsys.readouterr().out.split()
    assert listed == [str(out / f"{f}.{ext}") for f in convergence for ext in ("png", "pdf")]


def test_run_example_6_2_adaptive(tmp_path, capsys):
    out = tmp_path / "a62"
    code = main(
        [
            "run",
            "example-6.2",
            "--max-ndof",
            "1500",
            "--theta",
            "0.5",
            "--out",
            str(out),
            "--no-figures",
        ]
    )
    printed = capsys.readouterr()
    assert code == 0, printed.err
    rows = check_history_and_vtu(out)
    ndof = [int(r["ndof"]) for r in rows]
    eta = [float(r["eta"]) for r in rows]
    print(f"ndof {ndof}\neta {np.round(eta, 3)}")
    assert len(rows) >= 4 and max(ndof) <= 1500
    assert all(b > a for a, b in zip(ndof, ndof[1:], strict=False))
    assert eta[-1] < eta[0] / 3
    assert all(r["error_energy"] == "nan" and r["efficiency"] == "nan" for r in rows)
    assert not list(out.glob("*.png"))


def test_run_options_eta5_no_vtu_quiet(tmp_path, capsys):
    out = tmp_path / "p61"
    code = main(
        [
            "run",
            "example-6.1",
            "--uniform",
            "--max-ndof",
            "600",
            "--eta5",
            "paper",
            "--no-vtu",
            "--no-figures",
            "--quiet",
            "--out",
            str(out),
        ]
    )
    printed = capsys.readouterr()
    assert code == 0 and printed.out == ""
    # the run's files: its history, the columns' description, its manifest and its first
    # level's problem data (the resume state is removed once the run finished)
    assert sorted(os.listdir(out)) == [
        "history.csv",
        "history.md",
        "signorini-check.npz",
        "signorini-run.json",
    ]
    _, rows = read_history(out / "history.csv")
    assert len(rows) == 2
    paper = estimate(solve(example_6_1()), eta5_variant="paper").eta_terms[4]
    assert float(rows[0]["eta_5"]) == paper
    assert not math.isclose(paper, estimate(solve(example_6_1())).eta_terms[4], rel_tol=0.5)


@pytest.mark.slow
def test_bad_theta_exits_with_a_message_and_no_traceback(tmp_path):
    out = tmp_path / "bad"
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "signorini.cli",
            "run",
            "example-6.2",
            "--theta",
            "2",
            "--out",
            str(out),
            "--no-figures",
        ],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )
    print(f"exit {proc.returncode}; stderr: {proc.stderr.strip()}")
    assert proc.returncode != 0
    assert "theta" in proc.stderr and "2" in proc.stderr
    assert "Traceback" not in proc.stderr + proc.stdout
    assert not (out / "history.csv").exists()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["run", "example-6.2", "--theta", "abc"], "invalid float value"),
        (["run", "example-6.2", "--eta5", "other"], "invalid choice"),
        (["run", "example-6.2", "--max-ndof", "many"], "invalid int value"),
        ([], "required"),
    ],
)
def test_argument_errors_exit_2(argv, message, capsys):
    with pytest.raises(SystemExit) as info:
        main(argv)
    err = capsys.readouterr().err
    assert info.value.code == 2
    assert message in err and "Traceback" not in err


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--theta", "0"], "theta"),
        (["--theta", "nan"], "theta"),
        (["--max-ndof", "10"], "max[-_]ndof"),
        (["--max-ndof", "-5"], "max[-_]ndof"),
    ],
)
def test_invalid_values_exit_nonzero(tmp_path, capsys, argv, message):
    code = main(["run", "example-6.2", "--out", str(tmp_path / "x"), "--no-figures", *argv])
    err = capsys.readouterr().err
    assert code != 0
    assert err.startswith("signorini: error:") and re.search(message, err)


@pytest.mark.parametrize(
    ("name", "message"),
    [
        (
            "example-9.9",
            r"unknown problem 'example-9.9': give one of \['elasticity-3d', 'example-6.1', ",
        ),
        ("missing.py", "no problem file at missing.py"),
    ],
)
def test_unknown_problem_exits_2(tmp_path, capsys, name, message):
    code = main(["run", name, "--out", str(tmp_path / "x"), "--no-figures"])
    err = capsys.readouterr().err
    assert code == 2 and re.search(message, err) and "Traceback" not in err


@pytest.mark.slow
def test_run_a_problem_file(tmp_path, capsys):
    """A user's Python file defining problem() runs through the same pipeline."""
    source = tmp_path / "wedge.py"
    source.write_text(
        "import numpy as np\n"
        "from signorini import Contact, ContactProblem, Dirichlet, Material, Neumann, "
        "rectangle\n"
        "def problem():\n"
        "    return ContactProblem(rectangle(nx=2, ny=2), Material.from_young(100.0, 0.25), {\n"
        "        'top': Dirichlet((0.0, -0.02)), 'left': Neumann(), 'right': Neumann(),\n"
        "        'bottom': Contact(gap=lambda x: 0.01 * x[..., 0])}, name='wedge')\n"
    )
    out = tmp_path / "out"
    assert main(["run", str(source), "--max-ndof", "1500", "--out", str(out), "--quiet"]) == 0
    rows = check_history_and_vtu(out)
    assert float(rows[-1]["contact_force"]) > 0 and int(rows[-1]["n_active"]) > 0
    assert (out / "wedge_estimator.png").is_file() and (out / "deformed.png").is_file()


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("x = 1\n", "must define a function problem()"),
        ("def problem():\n    return 42\n", "returned int, not a ContactProblem"),
    ],
)
def test_bad_problem_file(tmp_path, capsys, text, message):
    source = tmp_path / "bad.py"
    source.write_text(text)
    code = main(["run", str(source), "--out", str(tmp_path / "o"), "--no-figures"])
    err = capsys.readouterr().err
    assert code == 2 and message in err


# ---------------------------------------------------------------------- run folders
def history_without_timings(path: Path) -> list[dict[str, str]]:
    _, rows = read_history(path)
    return [{k: v for k, v in r.items() if not k.startswith("t_")} for r in rows]


def assert_same_history(a: list[dict[str, str]], b: list[dict[str, str]]) -> None:
    """Equal histories: counts and names exactly, numbers to round-off (two uninterrupted
    runs differ at round-off too: the threaded sparse solver sums in varying order)."""
    assert len(a) == len(b) and [list(r) for r in a] == [list(r) for r in b]
    for ra, rb in zip(a, b, strict=True):
        for key, va in ra.items():
            vb = rb[key]
            try:
                int(va)
            except ValueError:
                try:
                    number = float(va)
                except ValueError:  # text, e.g. the backend
                    assert va == vb, (ra["level"], key)
                else:
                    assert float(vb) == pytest.approx(number, rel=1e-9, nan_ok=True), key
            else:
                assert va == vb, (ra["level"], key)


def assert_same_vtu(a: Path, b: Path) -> None:
    ma, mb = meshio.read(a), meshio.read(b)
    np.testing.assert_array_equal(ma.points, mb.points)
    np.testing.assert_array_equal(ma.cells[0].data, mb.cells[0].data)
    for key in ma.point_data:
        x, y = ma.point_data[key], mb.point_data[key]
        np.testing.assert_allclose(x, y, rtol=0, atol=1e-9 * np.abs(x).max(), err_msg=key)
    for key in ma.cell_data:
        x, y = ma.cell_data[key][0], mb.cell_data[key][0]
        np.testing.assert_allclose(x, y, rtol=0, atol=1e-9 * np.abs(x).max(), err_msg=key)


RUN_62 = ["run", "example-6.2", "--max-ndof", "1200", "--no-figures", "--quiet"]


def test_a_folder_holding_a_run_is_refused_and_overwrite_clears_only_that_run(tmp_path, capsys):
    """A shorter rerun never leaves the longer run's levels beside its own history."""
    out = tmp_path / "r"
    assert main([*RUN_62, "--out", str(out)]) == 0
    n_long = len(list(out.glob("level_*.vtu")))
    (out / "notes.txt").write_text("my notes")
    (out / ".level_029.vtu.a1b2c3d4.vtu").write_bytes(b"")  # left by a killed write
    before = sorted(os.listdir(out))
    capsys.readouterr()
    short = ["run", "example-6.2", "--uniform", "--max-ndof", "600", "--out", str(out)]
    assert main([*short, "--no-figures"]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"signorini: error: output folder {out} is not empty: it holds a run of example-6.2 "
        "(finished). Give --overwrite to remove that run's files first (only the files a run "
        f"writes), --resume {out} to continue an interrupted run, or another --out folder\n"
    )
    # the refused run removed its temporaries only
    assert sorted(os.listdir(out)) == [n for n in before if not n.startswith(".level")]
    assert main([*short, "--no-figures", "--overwrite"]) == 0
    assert "removed" in capsys.readouterr().out
    rows = check_history_and_vtu(out)
    assert len(rows) == 2 < n_long
    assert (out / "notes.txt").read_text() == "my notes"
    assert sorted(os.listdir(out)) == sorted(
        ["history.csv", "history.md", "level_000.vtu", "level_001.vtu", "notes.txt"]
        + ["signorini-run.json", "signorini-check.npz", "fields.md"]
        + ["levels.pvd", "levels_ndof.pvd"]
    )


def test_out_naming_a_file_or_a_foreign_folder(tmp_path, capsys):
    path = tmp_path / "results.txt"
    path.write_text("x")
    assert main([*RUN_62, "--out", str(path)]) == 2
    err = capsys.readouterr().err
    assert (
        err == f"signorini: error: --out {path} is an existing file, not a folder: give a "
        "folder name\n"
    )
    assert "Errno" not in err
    (tmp_path / "photos").mkdir()
    (tmp_path / "photos" / "a.jpg").write_bytes(b"")
    assert main([*RUN_62, "--out", str(tmp_path / "photos")]) == 2
    assert "it holds 1 file(s): a.jpg" in capsys.readouterr().err


def interrupt_after_level(monkeypatch, k: int) -> None:
    """Make the command line receive Ctrl-C right after level ``k`` is written."""
    import signorini.cli.levels as cli_levels

    progress = cli_levels.progress

    def stop(level):
        if level.record.level == k:
            raise KeyboardInterrupt
        return progress(level)

    monkeypatch.setattr(cli_levels, "progress", stop)


@pytest.mark.slow
def test_resume_after_an_interrupt_gives_the_uninterrupted_run(tmp_path, capsys, monkeypatch):
    full, part = tmp_path / "full", tmp_path / "part"
    args = ["run", "example-6.2", "--max-ndof", "2500", "--theta", "0.5", "--no-figures"]
    assert main([*args, "--out", str(full), "--quiet"]) == 0
    interrupt_after_level(monkeypatch, 5)
    assert main([*args, "--out", str(part)]) == 130
    err = capsys.readouterr().err
    assert err == (
        f"signorini: interrupted at level 6; levels 0-5 finished in {part}; continue with: "
        f"signorini run example-6.2 --resume {part}\n"
    )
    assert json.loads((part / "signorini-run.json").read_text())["status"] == "interrupted"
    monkeypatch.undo()
    # options given again must agree with the run's
    assert main(["run", "example-6.2", "--resume", str(part), "--max-ndof", "3000"]) == 2
    assert "--max-ndof 3000 (the run has 2500)" in capsys.readouterr().err
    assert main(["run", "example-6.1", "--resume", str(part)]) == 2
    assert "example-6.1 is not the problem of the run in" in capsys.readouterr().err
    assert len(list(part.glob("level_*.vtu"))) == 6
    resume = ["run", "example-6.2", "--resume", str(part)]
    assert main([*resume, "--theta", "0.5", "--quiet", "--no-figures"]) == 0
    a, b = (
        history_without_timings(full / "history.csv"),
        history_without_timings(part / "history.csv"),
    )
    print(f"{len(a)} levels; resumed after level 5")
    assert len(a) > 9
    assert_same_history(a, b)  # every column but the timings
    names = sorted(p.name for p in full.glob("level_*.vtu"))
    assert names == sorted(p.name for p in part.glob("level_*.vtu"))
    for name in names[5:]:
        assert_same_vtu(full / name, part / name)
    assert sorted(os.listdir(full)) == sorted(os.listdir(part))
    assert main(resume) == 0
    assert "is finished: nothing to resume" in capsys.readouterr().out


def test_resume_of_a_run_whose_manifest_has_the_old_option_names(tmp_path, capsys, monkeypatch):
    """Runs written before the options were one object recorded the η5 variant as ``eta5``
    and the solver as ``backend``: --resume reads them, checks flags given again against
    them, and continues the run as it was."""
    full, part = tmp_path / "full", tmp_path / "part"
    args = ["run", "example-6.2", "--max-ndof", "1500", "--eta5", "paper", "--no-figures"]
    assert main([*args, "--backend", "scipy", "--out", str(full), "--quiet"]) == 0
    interrupt_after_level(monkeypatch, 3)
    assert main([*args, "--backend", "scipy", "--out", str(part)]) == 130
    monkeypatch.undo()
    capsys.readouterr()
    manifest = json.loads((part / "signorini-run.json").read_text())
    assert manifest["arguments"]["eta5_variant"] == "paper"
    assert manifest["arguments"]["solver"] == "scipy"
    manifest["arguments"] = {
        "uniform": False,
        "theta": 0.4,
        "max_ndof": 1500,
        "tol": 0.0,
        "max_levels": 100,
        "eta5": "paper",
        "backend": "scipy",
        "fallback": False,
        "no_vtu": False,
        "compare_uniform": False,
    }
    (part / "signorini-run.json").write_text(json.dumps(manifest))
    resume = ["run", "example-6.2", "--resume", str(part)]
    assert main([*resume, "--eta5", "consistent"]) == 2
    assert "--eta5 consistent (the run has paper)" in capsys.readouterr().err
    assert main([*resume, "--backend", "auto"]) == 2
    assert "--backend auto (the run has scipy)" in capsys.readouterr().err
    assert main([*resume, "--eta5", "paper", "--quiet", "--no-figures"]) == 0
    a = history_without_timings(full / "history.csv")
    b = history_without_timings(part / "history.csv")
    assert len(a) > 5 and {r["backend"] for r in b} == {"scipy"}
    assert_same_history(a, b)


def test_resume_refuses_a_folder_that_is_not_a_run(tmp_path, capsys):
    assert main(["run", "--resume", str(tmp_path)]) == 2
    assert "holds no signorini-run.json" in capsys.readouterr().err
    assert main(["run", "--out", str(tmp_path / "x")]) == 2  # no PROBLEM, no --resume
    err = capsys.readouterr().err
    assert err == "signorini: error: give a PROBLEM (an example's name or a problem file)\n"


#: The command line as a shell starts it, whatever the test process does with SIGINT: a signal
#: mask and an ignored signal are inherited across exec, and a worker of the test runner may
#: hold either (a run here once went to its end through the SIGINT sent to it), so the child
#: unblocks SIGINT and takes Python's own handler before ``python -m signorini.cli`` runs.
AS_FROM_A_SHELL = (
    "import runpy, signal, sys; "
    "signal.pthread_sigmask(signal.SIG_UNBLOCK, [signal.SIGINT]); "
    "signal.signal(signal.SIGINT, signal.default_int_handler); "
    "sys.argv[0] = 'signorini'; runpy.run_module('signorini.cli', run_name='__main__')"
)


def run_in_subprocess(out: Path, *extra: str):
    return subprocess.Popen(
        [sys.executable, "-c", AS_FROM_A_SHELL, "run", "example-6.2", "--out", str(out)]
        + ["--no-figures", *extra],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )


def wait_for_level(proc, k: int, timeout: float = 120) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        line = proc.stdout.readline()
        if line.startswith(f"level {k:3d}"):
            return
        assert line, f"the run ended before level {k}: {proc.stderr.read()}"
    proc.kill()
    raise AssertionError(f"no level {k} within {timeout} s")


@pytest.mark.slow
def test_ctrl_c_prints_one_line_and_exits_130(tmp_path):
    out = tmp_path / "big"
    proc = run_in_subprocess(out, "--max-ndof", "1000000")
    try:
        wait_for_level(proc, 3)
        running = proc.poll() is None
        proc.send_signal(signal.SIGINT)
        printed, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    print(f"exit {proc.returncode}; stderr: {err!r}")
    assert running, "the run had ended when level 3 was read"
    assert proc.returncode == 130, printed[-3000:]
    assert "Traceback" not in err and "KeyboardInterrupt" not in err
    lines = err.splitlines()
    assert len(lines) == 1 and re.fullmatch(
        rf"signorini: interrupted at level (\d+); levels 0-(\d+) finished in {re.escape(str(out))}"
        rf"; continue with: signorini run example-6\.2 --resume {re.escape(str(out))}",
        lines[0],
    )
    done = int(re.search(r"levels 0-(\d+)", lines[0]).group(1))
    assert done >= 3 and len(list(out.glob("level_*.vtu"))) == done + 1
    assert not [n for n in os.listdir(out) if n.startswith(".")]


@pytest.mark.slow
def test_sigkill_then_resume_gives_the_uninterrupted_run(tmp_path, capsys):
    """Killed at any moment (possibly inside a VTU write), the run is continued by
    --resume: temporaries removed, the same history and files as an uninterrupted run."""
    args = ["--max-ndof", "6000"]
    full, part = tmp_path / "full", tmp_path / "part"
    proc = run_in_subprocess(part, *args)
    try:
        wait_for_level(proc, 8)
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=60)
    finally:
        proc.kill()
    assert main(["run", "example-6.2", *args, "--out", str(full), "--no-figures", "--quiet"]) == 0
    before = len(list(part.glob("level_*.vtu")))
    (part / ".level_029.vtu.zz_9q7w3.vtu").write_bytes(b"")  # as SIGKILL in a write leaves
    resume = ["run", "example-6.2", "--resume", str(part), "--quiet", "--no-figures"]
    assert main(resume) == 0
    a = history_without_timings(full / "history.csv")
    b = history_without_timings(part / "history.csv")
    print(f"killed with {before} VTU files; {len(a)} levels")
    assert len(a) > before
    assert_same_history(a, b)
    assert sorted(os.listdir(full)) == sorted(os.listdir(part))
    assert_same_vtu(full / f"level_{len(a) - 1:03d}.vtu", part / f"level_{len(a) - 1:03d}.vtu")


# ---------------------------------------------------------------------- options
@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--max-levels", "0"], "--max-levels must be an integer >= 1, got 0"),
        (["--max-levels", "-2"], "--max-levels must be an integer >= 1, got -2"),
        (["--tol", "nan"], "--tol must be a number >= 0, got nan"),
        (["--resume", "x", "--overwrite"], "--resume and --overwrite exclude each other"),
    ],
)
def test_bad_run_options_fail_before_the_run(tmp_path, capsys, argv, message):
    out = tmp_path / "x"
    code = main(["run", "example-6.2", "--out", str(out), "--no-figures", *argv])
    err = capsys.readouterr().err
    assert code == 2 and err == f"signorini: error: {message}\n"
    assert not out.exists()


def test_unknown_backend_is_rejected_by_the_parser(tmp_path, capsys):
    with pytest.raises(SystemExit) as info:
        main(["run", "example-6.2", "--backend", "foo", "--out", str(tmp_path / "x")])
    err = capsys.readouterr().err
    assert info.value.code == 2
    assert "argument --backend: invalid choice: 'foo' (choose from" in err
    assert "pardiso" in err and "scipy" in err and not (tmp_path / "x").exists()


def test_version_and_help(capsys):
    from signorini import __version__

    with pytest.raises(SystemExit) as info:
        main(["--version"])
    assert info.value.code == 0 and capsys.readouterr().out == f"signorini {__version__}\n"
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "A problem file is Python code: signorini executes it with your rights" in text
    assert re.search(r"--max-levels MAX_LEVELS\s+stop after this many levels", text)
    assert "--resume DIR" in text and "--overwrite" in text
    assert re.search(r"--fallback\s+where the active set iteration cycles", text)


def test_history_md_describes_every_column(tmp_path):
    out = tmp_path / "h"
    assert main([*RUN_62, "--out", str(out), "--max-levels", "2"]) == 0
    columns, _ = read_history(out / "history.csv")
    text = (out / "history.md").read_text()
    described = re.findall(r"^\| `(\w+)` \|", text, flags=re.M)
    assert described == columns
    ndof = next(line for line in text.splitlines() if line.startswith("| `ndof` |"))
    assert "free scalar unknowns" in ndof and "Dirichlet" in ndof and "excluded" in ndof


def test_figures_are_announced_before_they_are_drawn(tmp_path, capsys, monkeypatch):
    import signorini.cli.figures as cli_figures

    def figures(example, out, last=None):
        print("DRAWING")
        return []

    monkeypatch.setattr(cli_figures, "figures", figures)
    argv = ["run", "example-6.1", "--uniform", "--max-ndof", "600", "--no-vtu"]
    assert main([*argv, "--out", str(tmp_path / "a")]) == 0
    out = capsys.readouterr().out.splitlines()
    i = out.index("DRAWING")
    assert out[i - 1].startswith("drawing the figures of example-6.1")
    assert main([*argv, "--out", str(tmp_path / "b"), "--quiet"]) == 0
    assert capsys.readouterr().out == "DRAWING\n"


# ---------------------------------------------------------------------- problem files
GOOD = (
    "from signorini import Contact, ContactProblem, Dirichlet, Material, Neumann, rectangle\n"
    "def make(gap=0.01):\n"
    "    return ContactProblem(rectangle(nx=2, ny=2), Material.from_young(100.0, 0.25), {\n"
    "        'top': Dirichlet((0.0, -0.02)), 'left': Neumann(), 'right': Neumann(),\n"
    "        'bottom': Contact(gap=lambda x: gap * x[..., 0])}, name='user')\n"
)


def run_file(tmp_path, text: str, *extra: str, name: str = "user.py") -> int:
    source = tmp_path / name
    source.write_text(text)
    out = tmp_path / "out"
    argv = ["run", str(source), "--max-ndof", "300", "--out", str(out), "--no-figures"]
    return main([*argv, "--quiet", *extra])


def test_a_problem_file_that_raises_shows_its_own_file_and_line(tmp_path, capsys):
    text = "import math\n\nscale = 1 / 0\n\ndef problem():\n    pass\n"
    assert run_file(tmp_path, text) == 2
    err = capsys.readouterr().err
    print(err)
    source = tmp_path / "user.py"
    lines = [x for x in err.splitlines() if not re.fullmatch(r"\s*[~^]+\s*", x)]  # 3.11 carets
    assert lines == [
        f"signorini: error: the problem file {source} raised ZeroDivisionError:",
        f'  File "{source}", line 3, in <module>',
        "    scale = 1 / 0",
        "ZeroDivisionError: division by zero",
    ]
    # raised inside problem(), through a helper of the file: the user's two frames only
    text = "def helper():\n    return {}['gap']\n\ndef problem():\n    return helper()\n"
    assert run_file(tmp_path, text) == 2
    err = capsys.readouterr().err
    assert re.findall(r'File "(.*)", line (\d+)', err) == [(str(source), "5"), (str(source), "2")]
    assert err.endswith("KeyError: 'gap'\n") and "cli.py" not in err
    # frames of installed packages (a virtual environment beside the file) are left out
    lib = tmp_path / "venv" / "lib" / "site-packages"
    lib.mkdir(parents=True)
    (lib / "somelib.py").write_text("def load(name):\n    raise OSError(f'no {name}')\n")
    text = f"import sys\nsys.path.append({str(lib)!r})\nimport somelib\nsomelib.load('x')\n"
    assert run_file(tmp_path, text) == 2
    err = capsys.readouterr().err
    assert re.findall(r'File "(.*)", line (\d+)', err) == [(str(source), "4")]
    assert err.endswith("OSError: no x\n")
    # a syntax error points at its line too
    assert run_file(tmp_path, "def problem(:\n    pass\n") == 2
    err = capsys.readouterr().err
    assert f'File "{source}", line 1' in err and "SyntaxError" in err


def test_a_problem_file_with_future_annotations_dataclass_and_a_helper(tmp_path, capsys):
    (tmp_path / "helpers_for_user.py").write_text(GOOD)
    text = (
        "from __future__ import annotations\n"
        "from dataclasses import dataclass\n"
        "from helpers_for_user import make\n"
        "@dataclass\n"
        "class Data:\n"
        "    gap: float = 0.01\n"
        "def problem():\n"
        "    return make(Data().gap)\n"
    )
    assert run_file(tmp_path, text) == 0, capsys.readouterr().err
    assert str(tmp_path) not in sys.path  # the folder is on the path only while loading
    _, rows = read_history(tmp_path / "out" / "history.csv")
    assert len(rows) >= 2


def test_compare_uniform_executes_the_problem_file_once(tmp_path, capsys):
    counter = tmp_path / "count.txt"
    text = f"from pathlib import Path\nPath({str(counter)!r}).open('a').write('x')\n" + GOOD
    text += "def problem():\n    return make()\n"
    assert run_file(tmp_path, text, "--compare-uniform") == 0, capsys.readouterr().err
    assert counter.read_text() == "x"
    assert (tmp_path / "out" / "uniform" / "history.csv").is_file()


def test_a_file_that_is_not_a_problem_file(tmp_path, capsys):
    mesh = tmp_path / "part.msh"
    mesh.write_text("$MeshFormat\n")
    assert main(["run", str(mesh), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"signorini: error: {mesh} is not a problem file: a problem file is a Python file "
        "(.py) that defines a function problem() taking no arguments and returning a "
        "ContactProblem (see examples/inclined_block.py)\n"
    )
    assert run_file(tmp_path, "def make():\n    pass\n") == 2
    assert "is not a problem file: it must define a function problem()" in (capsys.readouterr().err)


def interrupted_file_run(tmp_path, monkeypatch, text: str, k: int = 1) -> tuple[Path, Path]:
    """A run of the problem file ``text`` (user.py) interrupted after level ``k``."""
    interrupt_after_level(monkeypatch, k)
    assert run_file(tmp_path, text) == 130
    monkeypatch.undo()
    return tmp_path / "user.py", tmp_path / "out"


def test_resume_never_executes_a_file_the_results_folder_names(tmp_path, capsys, monkeypatch):
    """A results folder may come from anyone: --resume without PROBLEM executes nothing the
    manifest names, and says how to write the command."""
    source, out = interrupted_file_run(
        tmp_path, monkeypatch, GOOD + "def problem():\n    return make()\n"
    )
    capsys.readouterr()
    marker = tmp_path / "executed"
    evil = tmp_path / "evil.py"
    evil.write_text(
        f"open({str(marker)!r}, 'w').close()\n" + GOOD + "def problem():\n    return make()\n"
    )
    manifest = json.loads((out / "signorini-run.json").read_text())
    manifest["problem"] = {"name": str(evil), "label": "evil", "file": str(evil), "sha256": None}
    (out / "signorini-run.json").write_text(json.dumps(manifest))
    assert main(["run", "--resume", str(out)]) == 2
    err = capsys.readouterr().err
    assert not marker.exists()
    assert err.startswith(
        f"signorini: error: name the problem: signorini run PROBLEM --resume {out} (an "
        "example's name or your problem file, as for a new run). A run folder may come from "
        "anyone, so signorini never executes a file that it names. The run recorded its "
        f"problem as {str(evil)!r}"
    )
    # named on the command line, the right file resumes; the interrupt line says so
    assert main(["run", str(source), "--resume", str(out), "--quiet", "--no-figures"]) == 0
    assert not marker.exists()


def test_the_interrupt_line_gives_a_complete_command(tmp_path, capsys, monkeypatch):
    source = tmp_path / "my problem.py"
    source.write_text(GOOD + "def problem():\n    return make()\n")
    interrupt_after_level(monkeypatch, 0)
    out = tmp_path / "out dir"
    assert main(["run", str(source), "--out", str(out), "--max-ndof", "300", "--quiet"]) == 130
    err = capsys.readouterr().err
    command = err.strip().split("continue with: ")[1]
    assert command == f"signorini run '{source}' --resume '{out}'"
    monkeypatch.undo()
    import shlex

    assert main([*shlex.split(command)[1:], "--quiet", "--no-figures"]) == 0
    assert json.loads((out / "signorini-run.json").read_text())["status"] == "finished"


def test_resume_refuses_a_problem_whose_helper_module_changed(tmp_path, capsys, monkeypatch):
    """Only the data decide: the problem file is unchanged, the helper module it imports is
    edited (the gap), and the rebuilt problem's contact data differ from the run's."""
    (tmp_path / "helper.py").write_text("GAP = 0.01\n")
    text = "import helper\n" + GOOD + "def problem():\n    return make(helper.GAP)\n"
    source, out = interrupted_file_run(tmp_path, monkeypatch, text)
    capsys.readouterr()
    before = sorted(os.listdir(out))
    (tmp_path / "helper.py").write_text("GAP = 0.02\n")
    sys.modules.pop("helper", None)
    assert main(["run", str(source), "--resume", str(out), "--quiet"]) == 2
    assert capsys.readouterr().err == (
        f"signorini: error: --resume {out}: {source} is not the problem of the run in {out}: "
        "rebuilt, it differs from the run's first level in the contact data (gaps, normals "
        "or friction) and the first level's solution. Name the problem the run solved, or "
        "start a new run (another --out, or --overwrite)\n"
    )
    assert sorted(os.listdir(out)) == before  # nothing touched
    (tmp_path / "helper.py").write_text("GAP = 0.01\n")
    sys.modules.pop("helper", None)
    assert main(["run", str(source), "--resume", str(out), "--quiet", "--no-figures"]) == 0


def test_resume_refuses_a_manifest_whose_problem_name_was_edited(tmp_path, capsys, monkeypatch):
    out = tmp_path / "r"
    interrupt_after_level(monkeypatch, 1)
    assert main([*RUN_62, "--out", str(out)]) == 130
    monkeypatch.undo()
    capsys.readouterr()
    manifest = json.loads((out / "signorini-run.json").read_text())
    manifest["problem"]["name"] = manifest["problem"]["label"] = "example-6.1"
    (out / "signorini-run.json").write_text(json.dumps(manifest))
    assert main(["run", "example-6.1", "--resume", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"example-6.1 is not the problem of the run in {out}: rebuilt, it differs" in err
    assert "first level in the Dirichlet values, the contact data" in err
    assert main(["run", "example-6.2", "--resume", str(out), "--quiet", "--no-figures"]) == 0


def test_resume_after_an_interrupt_while_drawing_redraws_from_the_last_level(
    tmp_path, capsys, monkeypatch
):
    """Every level finished, the figures did not: --resume solves the last level again
    (warm started from its saved solution) only to draw them, and writes no new level."""
    import signorini.cli.figures as cli_figures

    drawn = []

    def figures(example, out, last=None):
        if not drawn:
            drawn.append(None)
            raise KeyboardInterrupt
        drawn.append(last)
        return []

    monkeypatch.setattr(cli_figures, "figures", figures)
    out = tmp_path / "d"
    argv = ["run", "example-6.2", "--max-ndof", "700", "--out", str(out), "--no-vtu"]
    assert main(argv) == 130
    err = capsys.readouterr().err
    assert err.startswith("signorini: interrupted while drawing the figures; levels 0-")
    before = history_without_timings(out / "history.csv")
    assert main(["run", "example-6.2", "--resume", str(out)]) == 0
    assert "were finished; drawing what is missing" in capsys.readouterr().out
    last = drawn[-1]
    assert last.record.level == len(before) - 1 and last.record.ndof == int(before[-1]["ndof"])
    assert last.record.eta == pytest.approx(float(before[-1]["eta"]), rel=1e-9)
    assert history_without_timings(out / "history.csv") == before
    assert json.loads((out / "signorini-run.json").read_text())["status"] == "finished"
    assert not (out / "resume.npz").exists()


@pytest.mark.slow
def test_a_problem_file_in_an_old_form_is_told_so(tmp_path):
    """Python hides DeprecationWarnings outside __main__; those raised at the problem file's
    own lines (here a traction g(x, n)) are shown, pointing at the file."""
    source = tmp_path / "old_form.py"
    source.write_text(
        "from signorini import ContactProblem, Dirichlet, Material, Neumann, rectangle\n"
        "\n"
        "def problem():\n"
        "    return ContactProblem(\n"
        "        rectangle(0, 1, 0, 1, nx=2, ny=2),\n"
        "        Material.from_young(1.0, 0.3),\n"
        "        {'left': Dirichlet(), 'right': Neumann(lambda x, n: 0.1 * n),\n"
        "         'top': Neumann(), 'bottom': Neumann()},\n"
        "    )\n"
    )
    argv = [str(source), "--max-levels", "1", "--no-vtu", "--no-figures", "--quiet"]
    done = subprocess.run(
        [sys.executable, "-c", "from signorini.cli import main; raise SystemExit(main())", "run"]
        + argv
        + ["--out", str(tmp_path / "out")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert f"{source}:7: DeprecationWarning" in done.stderr, done.stderr
    assert "name the parameter `normal`" in done.stderr


QUARTER_DISC = """
import numpy as np
from signorini import Contact, ContactProblem, Dirichlet, Material, Mesh, Neumann
from signorini.mesh import Circle

def problem():
    t = np.linspace(0, np.pi / 2, 5)
    p = np.vstack([[0, 0], np.column_stack([np.cos(t), np.sin(t)])])
    p[-1] = [0.0, 1.0]
    cells = np.array([[0, 1 + j, 2 + j] for j in range(4)])
    parts = {
        "bottom": lambda x: np.abs(x[:, 1]) < 1e-12,
        "left": lambda x: np.abs(x[:, 0]) < 1e-12,
        "arc": lambda x: np.hypot(x[:, 0], x[:, 1]) > 0.5,
    }
    mesh = Mesh.from_arrays(p, cells, parts).with_curve("arc", Circle((0, 0), 1))
    return ContactProblem(
        mesh=mesh,
        material=Material.from_lame(1.0, 1.0),
        conditions={
            "left": Dirichlet((0.0, 0.0)),
            "arc": Neumann((0.0, -0.05)),
            "bottom": Contact(gap=0.02, normal=(0.0, -1.0)),
        },
    )
"""


@pytest.mark.slow
def test_resume_keeps_the_curves_of_the_problem(tmp_path, capsys, monkeypatch):
    """The saved state holds arrays only; a resumed run refines on the problem's curves
    again, so it gives the uninterrupted run's levels (not a run refined on chords)."""
    source = tmp_path / "quarter.py"
    source.write_text(QUARTER_DISC)
    full, part = tmp_path / "full", tmp_path / "part"
    args = ["run", str(source), "--max-ndof", "1500", "--no-figures", "--quiet"]
    assert main([*args, "--out", str(full)]) == 0
    interrupt_after_level(monkeypatch, 2)
    assert main([*args, "--out", str(part)]) == 130
    monkeypatch.undo()
    capsys.readouterr()
    assert main(["run", str(source), "--resume", str(part), "--quiet", "--no-figures"]) == 0
    a = history_without_timings(full / "history.csv")
    b = history_without_timings(part / "history.csv")
    assert len(a) > 4
    assert_same_history(a, b)


@pytest.mark.slow
def test_the_deformed_figure_of_a_frictional_result_marks_stick_and_slip(tmp_path, monkeypatch):
    """The figures of a last level with friction pass the node states, the contact nodes'
    displacement and p_t to the deformed-body figure; without friction none of them."""
    from types import SimpleNamespace

    from plots.figure_checks import synthetic_history, write_csv

    import signorini.cli.figures as cli_figures
    import signorini.plots
    from signorini.fem.material import Material
    from signorini.mesh.builders import rectangle
    from signorini.problem import Contact, ContactProblem, Coulomb, Dirichlet, Neumann
    from signorini.problem.obstacles import Disc

    seen = []
    original = signorini.plots.plot_deformed

    def spy(*args, **kwargs):  # the contact boundary's arrays: a ContactDrawing, 5th argument
        seen.append(args[4] if len(args) > 4 else kwargs["contact"])
        return original(*args, **kwargs)

    # only the deformed body is drawn
    monkeypatch.setattr(signorini.plots, "plot_deformed", spy)
    monkeypatch.setattr(signorini.plots, "make_figures", lambda *args, **kwargs: [])
    monkeypatch.setattr(signorini.plots, "plot_mesh", lambda *args, **kwargs: [])
    write_csv(tmp_path / "history.csv", synthetic_history())
    for friction in (Coulomb(0.3), None):
        problem = ContactProblem(
            rectangle(0.0, 2.0, 0.0, 1.0, nx=8, ny=4),
            Material.from_young(1.0, 0.3),
            {
                "left": Neumann(),
                "right": Neumann(),
                "top": Dirichlet((0.012, -0.02)),
                "bottom": Contact(obstacle=Disc((1.0, -12.5), 12.5), friction=friction),
            },
        )
        res = solve(problem)
        cli_figures.figures(
            "block", tmp_path, SimpleNamespace(result=res, record=SimpleNamespace(level=0))
        )
    with_friction, without = seen
    res_nodes = res.contact.nodes
    assert set(with_friction.state.tolist()) == {"inactive", "stick", "slip"}
    assert with_friction.contact_displacement.shape == (res_nodes.size, 2)
    assert np.abs(with_friction.tangential_pressure).max() > 0
    assert without.state is None and without.contact_displacement is None
    assert without.tangential_pressure is None


@pytest.mark.slow
def test_resume_of_two_touching_bodies_gives_the_uninterrupted_run(tmp_path, capsys, monkeypatch):
    """The two-cylinder run (two bodies whose points coincide where they touch) resumes
    from its state file: the union's bodies are checked one by one, and the history and the
    VTU files (with the body field) equal the uninterrupted run's."""
    full, part = tmp_path / "full", tmp_path / "part"
    args = ["run", "two-cylinders", "--max-ndof", "2000", "--no-figures"]
    assert main([*args, "--out", str(full), "--quiet"]) == 0
    interrupt_after_level(monkeypatch, 4)
    assert main([*args, "--out", str(part)]) == 130
    monkeypatch.undo()
    capsys.readouterr()
    assert main(["run", "two-cylinders", "--resume", str(part), "--quiet", "--no-figures"]) == 0
    a, b = (history_without_timings(f / "history.csv") for f in (full, part))
    assert len(a) > 6
    assert_same_history(a, b)
    last = sorted(p.name for p in full.glob("level_*.vtu"))[-1]
    assert_same_vtu(full / last, part / last)
    import meshio

    assert set(np.unique(meshio.read(part / last).cell_data["body"][0])) == {0, 1}
