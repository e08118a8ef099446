"""The η5 question settled by measurement (docs/method.md, *Estimator*, docs/eta5.md).

Runs both variants of the estimator's normal-stress term η5 (``paper``: the full normal
stress on Γ_C as printed; ``consistent``: balanced by the discrete pressure) on both of the
paper's examples, with adaptive (θ = 0.4) and uniform refinement, and writes the histories,
the figures and a markdown table of fitted slopes and efficiency ranges.

    python examples/eta5_study.py --max-ndof 100000 --out docs/eta5
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from signorini import adaptive, example_6_1, example_6_2, plots
from signorini.output import HistoryWriter, fitted_slope, read_history

EXAMPLES = {"example-6.1": example_6_1, "example-6.2": example_6_2}


def run(name: str, variant: str, uniform: bool, max_ndof: int, out: Path) -> Path:
    """One run; returns the path of its history."""
    mode = "uniform" if uniform else "adaptive"
    path = out / f"{name}_{mode}_{variant}.csv"
    history = HistoryWriter(path)
    for level in adaptive(
        EXAMPLES[name](), max_ndof=max_ndof, uniform=uniform, eta5_variant=variant
    ):
        history.append(level.record.row())
    return path


def summary(path: Path, last: int) -> dict[str, float]:
    """Fitted slopes over the last levels and the efficiency range."""
    h = read_history(path)
    out = {
        "ndof": int(h["ndof"][-1]),
        "eta": float(h["eta"][-1]),
        "slope_eta": fitted_slope(h["ndof"], h["eta"], last=last),
        "slope_eta5": fitted_slope(h["ndof"], h["eta_5"], last=last),
    }
    err = h.get("error_energy")
    if err is not None and np.isfinite(err).any():
        out["slope_error"] = fitted_slope(h["ndof"], err, last=last)
        eff = h["efficiency"]
        out["eff_min"], out["eff_max"] = float(np.nanmin(eff)), float(np.nanmax(eff))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-ndof", type=int, default=100_000)
    parser.add_argument("--out", type=Path, default=Path("docs/eta5"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    for name in EXAMPLES:
        histories = {}
        for variant in ("paper", "consistent"):
            for uniform in (False, True):
                mode = "uniform" if uniform else "adaptive"
                path = run(name, variant, uniform, args.max_ndof, args.out)
                histories[f"{mode}, {variant}"] = path
                s = summary(path, last=3 if uniform else 6)
                rows.append((name, mode, variant, s))
                print(name, mode, variant, {k: round(v, 4) for k, v in s.items()}, flush=True)
        plots.plot_adaptive_vs_uniform(
            histories,
            args.out / f"{name}_eta",
            key="eta",
            title=f"{name}: $\\eta_h$ for both $\\eta_5$ variants",
        )
        if name == "example-6.1":
            plots.plot_adaptive_vs_uniform(
                histories,
                args.out / f"{name}_error",
                key="error_energy",
                title=f"{name}: energy error",
            )
    print()
    print(
        "| example | refinement | η5 | final Ndof | slope η_h | slope η5 | slope error "
        "| efficiency min–max |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for name, mode, variant, s in rows:
        err = f"{s['slope_error']:.2f}" if "slope_error" in s else "—"
        eff = f"{s['eff_min']:.1f}–{s['eff_max']:.1f}" if "eff_min" in s else "—"
        print(
            f"| {name} | {mode} | {variant} | {s['ndof']} | {s['slope_eta']:.2f} "
            f"| {s['slope_eta5']:.2f} | {err} | {eff} |"
        )


if __name__ == "__main__":
    main()
