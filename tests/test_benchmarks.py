"""The benchmark and example scripts run end to end on a small budget."""

from __future__ import annotations

import csv
import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from signorini.algebra import SolverRequest, available_backends, solver_factory
from signorini.algebra.backends.selection import takes_ordering
from signorini.algebra.ranks import solver_ranks

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_adaptive_benchmark_reports_consistent_counts_and_floor(tmp_path):
    """benchmarks/adaptive.py on a 5000-unknown budget: its table agrees with the history it
    writes, each level's ratio is its total over its floor, the summary lines follow from the
    table, and the run ends on the known level of Example 6.2."""
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
    header = lines[0].split()
    end = lines.index("")  # the table ends at the first blank line
    table = [dict(zip(header, line.split(), strict=True)) for line in lines[1:end]]
    with open(tmp_path / "history.csv", newline="") as f:
        history = list(csv.DictReader(f))
    assert [int(row["level"]) for row in table] == list(range(len(history)))
    for row, record in zip(table, history, strict=True):
        assert row["ndof"] == record["ndof"]
        for printed, column in (
            ("solves", "n_solves"),
            ("facts", "n_factorizations"),
            ("updates", "n_updates"),
        ):
            assert row[printed] == record[column], (row["level"], printed)
        assert int(row["solves"]) == int(row["facts"]) + int(row["updates"])
        assert row["reused"] == "yes" and record["n_analyses"] == "1"
        total, floor, ratio = (float(row[k]) for k in ("total", "floor", "ratio"))
        assert floor > 0 and np.isfinite(ratio)
        # the printed values are rounded to 1 ms
        low, high = (total - 5e-4) / (floor + 5e-4), (total + 5e-4) / max(floor - 5e-4, 1e-12)
        assert low <= ratio <= high, (row["level"], total, floor, ratio)
    ndof = [int(row["ndof"]) for row in table]
    assert ndof == sorted(ndof) and ndof[-1] == 4876  # Example 6.2, theta = 0.4
    summary = {line.split(":")[0]: line for line in lines if ":" in line}
    backend = summary["backend"].split()[1].rstrip(";")
    assert {record["backend"] for record in history} == {backend}
    assert f"final level: {ndof[-1]} unknowns" in summary["backend"]
    eta = float(summary["backend"].split("eta = ")[1])
    assert eta == pytest.approx(float(history[-1]["eta"]), rel=1e-4)
    assert eta == pytest.approx(7.2295, rel=1e-4)
    solves = [int(row["solves"]) for row in table if int(row["level"]) >= 5]
    mean = float(summary["PDAS linear solves per level after level 5"].split(": ")[1].split()[0])
    assert mean == pytest.approx(np.mean(solves), abs=5e-3)
    # the phases' shares of ratio_to_ordered_floor sum to it, and PDAS's is its sum over the floors
    assert lines[-2].startswith("ratio_to_ordered_floor=")
    by_phase = lines[-3].split(": ")[-1].split(" + ")
    shares = {word.split()[0]: float(word.split()[1]) for word in by_phase}
    assert list(shares) == ["assemble", "pdas", "estimate", "mark", "refine", "output", "between"]
    assert sum(shares.values()) == pytest.approx(float(lines[-2].split("=")[1]), abs=5e-3)
    ordered = sum(float(row["ordered"]) for row in table)
    pdas = sum(float(row["pdas"]) for row in table)
    slack = 5e-4 * len(table)  # each printed value rounded to 1 ms
    low, high = (pdas - slack) / (ordered + slack), (pdas + slack) / (ordered - slack)
    assert low - 5e-4 <= shares["pdas"] <= high + 5e-4
    # ratio_to_floor: the last line, the ratio of the two sums printed above it
    assert lines[-1].startswith("ratio_to_floor=")
    ratio = float(lines[-1].split("=")[1])
    words = next(line for line in lines if line.startswith("total time ")).split()
    total, floors = float(words[2]), float(words[7])  # "total time T s, sum of floors S s"
    assert np.isfinite(ratio) and ratio > 0
    assert (total - 5e-3) / (floors + 5e-3) <= ratio <= (total + 5e-3) / (floors - 5e-3)


def _factor_line(out: str) -> str:
    return next(line for line in out.splitlines() if line.startswith("peak memory of the loop"))


@pytest.mark.slow
def test_adaptive_benchmark_without_floors_reads_the_loops_factor(tmp_path):
    """``--no-floor`` runs the same levels without the floors; the factor it reports is the
    loop's own (its solver's, read after the level), the one the ordered floor reports."""
    command = [sys.executable, str(ROOT / "benchmarks" / "adaptive.py"), "--max-ndof", "5000"]
    runs = [
        subprocess.run(
            [*command, *extra, "--out", str(tmp_path / name)],
            capture_output=True,
            text=True,
            timeout=300,
            check=True,
        ).stdout
        for name, extra in (("floors", []), ("none", ["--no-floor"]))
    ]
    floors, none = runs
    assert none.strip().splitlines()[-1] == "no floors measured (--no-floor)"
    lines = none.strip().splitlines()
    header = lines[0].split()
    table = [dict(zip(header, line.split(), strict=True)) for line in lines[1 : lines.index("")]]
    assert int(table[-1]["ndof"]) == 4876 and all(row["floor"] == "nan" for row in table)
    nnz = [int(re.search(r"8 bytes x (\d+) non-zeros", _factor_line(out))[1]) for out in runs]
    assert nnz[0] == nnz[1] > 4876
    peak = float(table[-1]["peakMiB"])
    assert float(table[-1]["peak/L"]) == pytest.approx(peak * 2**20 / (8 * nnz[1]), rel=0.01)
    # PARDISO's own memory is the loop's solver's either way, and with the rest it makes the
    # last level's peak
    own = [next(ln for ln in out.splitlines() if "PARDISO's own memory" in ln) for out in runs]
    assert own[0] == own[1] and "its peak" in own[1]
    own_ratio = float(re.search(r"= ([\d.]+) x the factor", own[1])[1])
    rest = next(line for line in none.splitlines() if "beyond PARDISO's own" in line)
    rest_ratio = float(re.search(r"= ([\d.]+) x the factor", rest)[1])
    assert own_ratio + rest_ratio == pytest.approx(float(table[-1]["peak/L"]), abs=0.02)


def test_adaptive_benchmark_factory_keeps_what_the_loop_reads():
    """The factory the benchmark hands the loop keeps the wrapped factory's attributes, so the
    loop computes the ordering and the analysis ahead exactly as with the factory itself, and
    it remembers each solver's factor size and memory as the solver is closed."""
    path = ROOT / "benchmarks" / "adaptive.py"
    spec = importlib.util.spec_from_file_location("bench_adaptive", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    for name in ("pardiso", "scipy", "auto"):
        factory = solver_factory(name)
        made: list = []
        wrapped = bench.remembering_factory(factory, made)
        assert takes_ordering(wrapped) == takes_ordering(factory), name
        assert solver_ranks(wrapped) == solver_ranks(factory), name
    if takes_ordering(solver_factory("pardiso")):
        made = []
        wrapped = bench.remembering_factory(solver_factory("pardiso"), made)
        A = sp.diags([-np.ones(99), 4 * np.ones(100), -np.ones(99)], [-1, 0, 1]).tocsr()
        solver = wrapped(SolverRequest(check_symmetry=False))
        solver.factorize(A)
        memory = solver.memory_kib
        solver.close()
        assert made == [(solver.factor_nnz, memory)] and any(memory.values())


def _tiny_snapshot(folder: Path, cases, eta: float = 0.1, u: float = 0.3) -> None:
    """A hand-made snapshot: per case a two-level history and one level's P2 mesh."""
    import meshio

    points = np.array([[0, 0], [1, 0], [0, 1], [0.5, 0], [0.5, 0.5], [0, 0.5]], float)
    for name in cases:
        out = folder / name
        out.mkdir(parents=True)
        with open(out / "history.csv", "w", newline="") as f:
            writer = csv.writer(f)
            writer.writerow(["level", "ndof", "eta", "backend", "t_solve"])
            for level in range(2):
                writer.writerow([level, 12 * (level + 1), repr(eta / (level + 1)), "scipy", 0.1])
        field = np.linspace(0.0, u, 12).reshape(6, 2)
        mesh = meshio.Mesh(points, [("triangle6", np.arange(6)[None])], {"u": field})
        mesh.write(out / "level_000.vtu")


def test_regression_compare_exact_asks_for_every_bit(tmp_path, capsys):
    """benchmarks/regression.py compare --exact: two hand-made snapshots are the same when
    equal but for timings, and DIFFERENT, naming the first case and entry, at one bit of a
    nodal field or of a history value, where the tolerant compare still says same."""
    path = ROOT / "benchmarks" / "regression.py"
    spec = importlib.util.spec_from_file_location("bench_regression", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    cases = list(bench.CASES)
    last = cases[-1]

    def run(*args: str) -> tuple[int, str]:
        status = bench.main(["compare", *map(str, args)])
        return status, capsys.readouterr().out.strip().splitlines()[-1]

    _tiny_snapshot(tmp_path / "old", cases)
    _tiny_snapshot(tmp_path / "new", cases)
    with open(tmp_path / "new" / cases[0] / "history.csv") as f:
        text = f.read()
    assert text.count(",0.1\n") == 2  # the timings
    (tmp_path / "new" / cases[0] / "history.csv").write_text(text.replace(",0.1\n", ",0.2\n"))
    assert run(tmp_path / "old", tmp_path / "new", "--exact") == (0, "regression: same")

    _tiny_snapshot(tmp_path / "field", cases[:-1])
    _tiny_snapshot(tmp_path / "field", [last], u=np.nextafter(0.3, 1.0))
    status, line = run(tmp_path / "old", tmp_path / "field", "--exact")
    assert status == 1 and line == f"regression: DIFFERENT ({last}: level_000.vtu: field u differs)"
    assert run(tmp_path / "old", tmp_path / "field") == (0, "regression: same")

    _tiny_snapshot(tmp_path / "eta", cases[:1], eta=np.nextafter(0.1, 1.0))
    _tiny_snapshot(tmp_path / "eta", cases[1:-1])
    _tiny_snapshot(tmp_path / "eta", [last], u=np.nextafter(0.3, 1.0))
    status, line = run(tmp_path / "old", tmp_path / "eta", "--exact")
    assert status == 1 and line.startswith(f"regression: DIFFERENT ({cases[0]}: eta at level 0")
    skipped = run(tmp_path / "old", tmp_path / "eta", "--skip", "eta", "--exact")
    assert skipped == (1, f"regression: DIFFERENT ({last}: level_000.vtu: field u differs)")


@pytest.mark.slow
def test_inclined_block_example_runs(tmp_path):
    """The literate example with a non-axis contact normal runs and touches the foundation
    without penetrating it."""
    out = subprocess.run(
        [
            sys.executable,
            str(ROOT / "examples" / "inclined_block.py"),
            "--max-ndof",
            "1500",
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


def test_throughput_benchmark_prints_a_table_of_positive_rates():
    """benchmarks/throughput.py on two small levels: one Markdown row per requested size, at
    the first level of Example 6.2 with at least that many unknowns, every rate positive, the
    share of the dense peak the factorization's rate over the printed peak."""
    out = subprocess.run(
        [
            sys.executable,
            str(ROOT / "benchmarks" / "throughput.py"),
            "--sizes",
            "2000",
            "5000",
            "--blas-n",
            "200",
            "--repeat",
            "2",
        ],
        capture_output=True,
        text=True,
        timeout=300,
        check=True,
    ).stdout
    print(out)
    lines = out.strip().splitlines()
    assert lines[0].startswith("| unknowns |") and set(lines[1]) <= set("|-: ")
    rows = [[cell.strip() for cell in line.strip("|").split("|")] for line in lines[2:4]]
    assert lines[4] == ""
    ndof = [int(row[0].replace(" ", "")) for row in rows]
    assert ndof == [2368, 6144]  # Example 6.2, theta = 0.4: first levels >= 2000 and >= 5000
    for row in rows:
        values = [float(cell.rstrip(" %")) for cell in row[1:]]
        assert all(v > 0 for v in values[:-1]), row
        gflops, share = values[-2], values[-1]
        peak = float(lines[5].split("dense peak: ")[1].split()[0])
        assert share == pytest.approx(100 * gflops / peak, rel=0.05, abs=0.01), (share, peak)


@pytest.mark.slow
@pytest.mark.skipif(
    "pardiso" not in available_backends(), reason="compares orderings for MKL PARDISO"
)
def test_ordering_benchmark_compares_both_orderings_on_both_meshes():
    """benchmarks/ordering.py on a small budget: two meshes, both orderings and the block
    form timed, factor sizes and agreement printed, the last lines the ratios of the adaptive
    mesh's solves."""
    out = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "ordering.py"), "--max-ndof", "8000"],
        capture_output=True,
        text=True,
        timeout=300,
        check=True,
    ).stdout
    print(out)
    lines = out.strip().splitlines()
    assert lines[0].startswith("uniform mesh") and "Example 6.2, adaptive mesh" in out
    totals = [float(x) for x in re.findall(r"complete (\d+\.\d+) s;", out)]
    assert len(totals) == 6 and all(t > 0 for t in totals)
    ratios = [float(x) for x in re.findall(r"complete solve (\d+\.\d+),", out)]
    assert len(ratios) == 4
    # per mesh: vertex graph / own, then in blocks / vertex graph
    pairs = [(0, 1), (1, 2), (3, 4), (4, 5)]
    for ratio, (i, j) in zip(ratios, pairs, strict=True):
        own, ours = totals[i], totals[j]
        # the seconds are printed rounded to 1 ms, the ratio to 0.001
        assert (ours - 5e-4) / (own + 5e-4) - 5e-4 <= ratio <= (ours + 5e-4) / (own - 5e-4) + 5e-4
    agreements = [float(x) for x in re.findall(r"solutions agree to (\d\.\de[-+]\d+)", out)]
    assert len(agreements) == 4 and max(agreements) < 1e-10
    memory = [float(x) for x in re.findall(r"PARDISO's memory (\d+) MiB", out)]
    assert len(memory) == 6 and all(m > 0 for m in memory)
    assert re.fullmatch(r"blocks_ratio=\d+\.\d{3}", lines[-2])
    assert float(lines[-2].split("=")[1]) == ratios[3]
    assert re.fullmatch(r"ordering_ratio=\d+\.\d{3}", lines[-1])
    assert float(lines[-1].split("=")[1]) == ratios[2]


@pytest.mark.slow
def test_adaptive_benchmark_3d_floor_shares_sum_to_the_ratio():
    """benchmarks/adaptive.py --problem example-6.2-3d on a small budget: each level's ratio
    is its total over its floor, the floor's CG converged in a positive number of
    iterations, the phase shares sum to ratio_to_floor (the sum of totals over the sum of
    floors), and largest_ndof is the table's largest level."""
    command = [sys.executable, str(ROOT / "benchmarks" / "adaptive.py")]
    command += ["--problem", "example-6.2-3d", "--max-ndof", "3000"]
    out = subprocess.run(command, capture_output=True, text=True, timeout=300, check=True).stdout
    lines = out.strip().splitlines()
    header = lines[0].split()
    end = lines.index("")
    table = [dict(zip(header, line.split(), strict=True)) for line in lines[1:end]]
    assert len(table) >= 2
    for row in table:
        total, floor, ratio = (float(row[k]) for k in ("total", "floor", "ratio"))
        assert floor > 0 and int(row["fl_its"]) > 0
        # the printed values are rounded to 3 decimals: the ratio lies in the interval
        low, high = (total - 5e-4) / (floor + 5e-4), (total + 5e-4) / (floor - 5e-4)
        assert low - 5e-4 <= ratio <= high + 5e-4
    totals = sum(float(row["total"]) for row in table)
    floors = sum(float(row["floor"]) for row in table)
    ratio = float(re.search(r"^ratio_to_floor=([0-9.]+)$", out, re.M).group(1))
    assert abs(ratio - totals / floors) <= 0.01 * ratio
    shares = re.search(r"^ratio_to_floor by phase .*: (.*)$", out, re.M).group(1)
    assert abs(sum(float(s.split()[1]) for s in shares.split(" + ")) - ratio) <= 0.01
    largest = int(re.search(r"^largest_ndof=(\d+)$", out, re.M).group(1))
    assert largest == max(int(row["ndof"]) for row in table)
