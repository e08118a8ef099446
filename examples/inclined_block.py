"""A block pressed onto an inclined rigid foundation: a problem of your own, top to bottom.

An elastic block 2 × 0.5 (E = 1000, ν = 0.3) is tilted by 20°. Its top is pushed by a
prescribed displacement 0.03 towards a rigid foundation whose distance from the bottom grows
from 0.005 to 0.035 along it, so only part of the bottom comes into contact; the sides are
traction free. The contact normal is (sin 20°, −cos 20°): not an axis direction, so this
exercises the rotated contact frames.

    python examples/inclined_block.py --max-ndof 50000 --out results/inclined
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from signorini import (
    Contact,
    ContactProblem,
    Dirichlet,
    Material,
    Mesh,
    Neumann,
    adaptive,
    plots,
    rectangle,
    write_vtu,
)

ANGLE = np.deg2rad(20.0)
ROTATION = np.array([[np.cos(ANGLE), -np.sin(ANGLE)], [np.sin(ANGLE), np.cos(ANGLE)]])


def block(nx: int = 8, ny: int = 2) -> Mesh:
    """The tilted block: a structured rectangle, rotated, with its four sides named."""
    flat = rectangle(0.0, 2.0, 0.0, 0.5, nx=nx, ny=ny)
    # the part names travel with the edges: rebuild from the rotated points and flat edges
    parts = {name: flat.boundary[flat.boundary_part == k] for k, name in enumerate(flat.part_names)}
    return Mesh.from_arrays(flat.points @ ROTATION.T, flat.cells, parts)


def problem() -> ContactProblem:
    normal = ROTATION @ np.array([0.0, -1.0])  # outward normal of the bottom
    tangent = ROTATION @ np.array([1.0, 0.0])  # along the bottom, from its left end
    push = 0.03 * normal  # the top moves 0.03 towards the foundation (along +n)
    return ContactProblem(
        mesh=block(),
        material=Material.from_young(1000.0, 0.3),
        conditions={
            "top": Dirichlet(tuple(push)),
            "left": Neumann(),
            "right": Neumann(),
            # the gap ψ grows linearly along the bottom (arclength s ∈ [0, 2])
            "bottom": Contact(gap=lambda x: 0.005 + 0.015 * (x @ tangent)),
        },
        name="inclined block",
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-ndof", type=int, default=50_000)
    parser.add_argument("--out", type=Path, default=Path("results/inclined"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    last = None
    for level in adaptive(problem(), theta=0.4, max_ndof=args.max_ndof):
        r = level.record
        print(
            f"level {r.level:2d}  ndof {r.ndof:7d}  eta {r.eta:.3e}  "
            f"contact force {r.contact_force:9.4f}  active {r.n_active}/{r.n_constrained}"
        )
        last = level

    result = last.result
    write_vtu(args.out / "solution.vtu", result, last.estimate)
    mesh, cs = result.mesh, result.contact
    x = result.space.node_points[cs.nodes]
    plots.plot_mesh(
        mesh.points,
        mesh.cells,
        args.out / "mesh",
        highlight=mesh.edges[cs.facets],
        title="adaptive mesh",
    )
    plots.plot_deformed(
        mesh.points,
        mesh.cells,
        result.u[: mesh.n_points],
        args.out / "deformed",
        plots.ContactDrawing(x, result.pressure),
        scale=5.0,
        title="deformed body and contact pressure",
    )
    # the pressure balances the load: Σ Λ_z equals the normal reaction of the foundation
    print(
        f"resultant normal force {result.total_contact_force:.4f}; "
        f"largest penetration {np.max(cs.normal_displacement(result.u) - cs.gap):.2e}"
    )


if __name__ == "__main__":
    main()
