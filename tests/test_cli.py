"""End-to-end tests of the ``signorini`` command line (:mod:`signorini.cli`)."""

from __future__ import annotations

import csv
import math
import os
import re
import subprocess
import sys
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
    assert all(float(r["t_output"]) < 0.01 for r in rows)  # --no-vtu: nothing to write
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
    assert os.listdir(out) == ["history.csv"]
    _, rows = read_history(out / "history.csv")
    assert len(rows) == 2
    paper = estimate(solve(example_6_1()), eta5="paper").eta_terms[4]
    assert float(rows[0]["eta_5"]) == paper
    assert not math.isclose(paper, estimate(solve(example_6_1())).eta_terms[4], rel_tol=0.5)


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
        ("example-9.9", r"unknown problem 'example-9.9': give one of \['example-6.1', "),
        ("missing.py", "no problem file at missing.py"),
    ],
)
def test_unknown_problem_exits_2(tmp_path, capsys, name, message):
    code = main(["run", name, "--out", str(tmp_path / "x"), "--no-figures"])
    err = capsys.readouterr().err
    assert code == 2 and re.search(message, err) and "Traceback" not in err


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
