"""Benchmark: the localised bound of η7 calibrated against the exact η7 (2D).

η7 = ‖(u_h·n − ψ)⁺‖_{H^{1/2}(Γ_C)} is computed exactly on curves
(:mod:`signorini.estimator.h_half_norm`); on surfaces it is to be replaced by the localised
bound ``B² = ‖v‖² + Σ_F (h_F⁻¹‖v‖²_F + h_F‖∇_Γ v‖²_F)``
(:mod:`signorini.estimator.h_half_norm.localised`, docs/method.md, *η7 on surfaces: a
localised bound*). This script runs Examples 6.1, 6.2 and the Hertz problem adaptively
(θ = 0.4, the loop's defaults) to a modest budget and prints, per level, the unknowns, the
exact η7 (the loop's own, recomputed here as a check), the bound ``B``, the guaranteed bound
``G`` of the curve weights (``G ≥ η7``; on the Hertz arc with the chord-arc constant measured
on the contact vertices), the ratios ``B/η7`` and ``G/η7``, and ``η7/η`` and ``B/η`` against
the estimator η_h (the energy-error proxy). The last line per example sums up the ratio
``B/η7`` over the levels where η7 > 0.

    python benchmarks/eta7_bound.py                  # to 40 000 unknowns per example
    python benchmarks/eta7_bound.py --max-ndof 40000
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from signorini.estimator.h_half_norm import (
    curve_weights,
    facet_norms2_positive_part,
    hhalf_norm2_positive_part,
    localised_bound2,
)
from signorini.examples import example_6_1, example_6_2, hertz
from signorini.loop import adaptive

PROBLEMS = {"example-6.1": example_6_1, "example-6.2": example_6_2, "hertz": hertz}


def contact_trace(result):
    """The edges of Γ_C and ``u_h·n − ψ_h`` on them, as the estimator's η7 reads them."""
    mesh, cs = result.mesh, result.contact
    gap = result.space.element.facet.facet_values(cs.facet_normal_gap(result.u))
    x0, x1 = mesh.points[cs.facet_nodes[:, 0]], mesh.points[cs.facet_nodes[:, 1]]
    origin = x0.min(axis=0)
    return x0 - origin, x1 - origin, gap, float(np.abs(result.u).max(initial=0.0))


def chord_arc_on_vertices(x0, x1):
    """``max ℓ(p, q) / |p − q|`` over the chain's vertices (ℓ the length along the chain),
    over pairs of vertices at least two edges apart: the far pairs' chord-arc constant, as
    measured on the vertices (1 on a straight Γ_C)."""
    points = np.unique(np.concatenate([x0, x1]), axis=0)
    # order the vertices along the chain by their angle seen from a point far above the
    # chain's middle (the Hertz arc is convex and seen from there in one sweep)
    centre = points.mean(axis=0) + np.array([0.0, 10.0 * np.ptp(points[:, 0])])
    angle = np.arctan2(points[:, 1] - centre[1], points[:, 0] - centre[0])
    order = np.argsort(angle)
    p = points[order]
    arc = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(p, axis=0).T))])
    i, j = np.triu_indices(p.shape[0], k=2)
    chord = np.hypot(*(p[i] - p[j]).T)
    return float(max(1.0, (np.abs(arc[i] - arc[j]) / chord).max(initial=1.0)))


def straight(x0, x1) -> bool:
    """Whether every edge lies on the line of the first one (to round-off)."""
    d = x1[0] - x0[0]
    cross = lambda p: d[0] * (p[:, 1] - x0[0, 1]) - d[1] * (p[:, 0] - x0[0, 0])  # noqa: E731
    size = np.hypot(*d) * np.ptp(np.concatenate([x0, x1]), axis=0).max()
    return bool(np.abs(np.concatenate([cross(x0), cross(x1)])).max() <= 1e-12 * size)


def calibrate(name: str, max_ndof: int) -> list[float]:
    """Run one example and print its table; return the ratios B/η7 where η7 > 0."""
    print(f"\n{name} (θ = 0.4, max_ndof = {max_ndof})")
    head = ("level", "ndof", "eta7", "B", "G", "B/eta7", "G/eta7", "eta7/eta", "B/eta")
    print("  ".join(f"{h:>9}" for h in head))
    ratios, kappas = [], [1.0]
    start = time.perf_counter()
    for level in adaptive(PROBLEMS[name](), max_ndof=max_ndof):
        rec = level.record
        x0, x1, gap, scale = contact_trace(level.result)
        eta7_2, _ = hhalf_norm2_positive_part(x0, x1, gap, validate=False, scale=scale)
        if not math.isclose(math.sqrt(eta7_2), rec.eta_7, rel_tol=1e-9, abs_tol=1e-300):
            raise AssertionError(f"η7 recomputed {math.sqrt(eta7_2)} != loop's {rec.eta_7}")
        norms = facet_norms2_positive_part(x0, x1, gap, validate=False, scale=scale)
        bound = math.sqrt(localised_bound2(norms)[0])
        kappa = 1.0 if straight(x0, x1) else chord_arc_on_vertices(x0, x1)
        kappas.append(kappa)
        near, far = curve_weights(x0, x1, chord_arc=kappa)
        guaranteed = math.sqrt(localised_bound2(norms, near, far)[0])
        eta7 = rec.eta_7
        r = bound / eta7 if eta7 > 0 else math.nan
        g = guaranteed / eta7 if eta7 > 0 else math.nan
        if eta7 > 0:
            ratios.append(r)
        row = (rec.level, rec.ndof)
        values = (eta7, bound, guaranteed, r, g, eta7 / rec.eta, bound / rec.eta)
        print(f"{row[0]:>9}  {row[1]:>9}  " + "  ".join(f"{v:9.3e}" for v in values))
    seconds = time.perf_counter() - start
    if ratios:
        print(
            f"{name}: B/eta7 over {len(ratios)} levels: min {min(ratios):.3f}, "
            f"max {max(ratios):.3f}, last {ratios[-1]:.3f}; chord-arc κ ≤ {max(kappas):.3f} "
            f"({seconds:.1f} s)"
        )
    else:
        print(f"{name}: eta7 = 0 on every level ({seconds:.1f} s)")
    return ratios


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-ndof", type=int, default=40_000)
    parser.add_argument("--problem", choices=sorted(PROBLEMS), action="append")
    args = parser.parse_args(argv)
    for name in args.problem or list(PROBLEMS):
        calibrate(name, args.max_ndof)


if __name__ == "__main__":
    main()
