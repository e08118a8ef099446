"""Measurement: does η6 drift in 2D for P2 against a curved contact geometry?

In three dimensions η6 with the exact obstacle ψ drifts like h^{-1/2} against the error
(docs/method.md, *Three dimensions: the contact condition on P2 faces (measured)*): in full
contact ψ − I_h ψ = O(h³) changes sign inside every face, so Σ s_p d_p ≈ ∫ p (ψ − I_hψ)⁺ =
O(h³). The same count holds in 2D for a curved obstacle. The 2D estimator uses ψ_h, the P2
interpolant of ψ on each contact edge (docs/method.md, *Estimator*), in η6 and η7. This
script measures, under uniform refinement, η6 of the estimator as coded on

* ``block-on-cylinder``: the block [−1, 1] × [0, 1] (E = 1, ν = 0.3, free sides) pushed
  0.01 down onto the rigid cylinder of radius 1 below it (a curved obstacle, ``Disc``; ψ is
  not a polynomial along the straight contact edges), and
* ``hertz``: the half-disc pressed onto a plane (a curved body on a straight obstacle,
  :func:`signorini.examples.hertz`),

with the energy norm of the difference of consecutive levels ``‖u_{ℓ+1} − u_ℓ‖_E`` (u_ℓ
prolongated exactly to the finer mesh; for nested P2 spaces and a linear problem it equals
``(‖u − u_ℓ‖² − ‖u − u_{ℓ+1}‖²)^{1/2}``, an error proxy of the same rate) as the error.

    python benchmarks/eta6_curved.py                # to 70 000 unknowns
    python benchmarks/eta6_curved.py --max-ndof 20000
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from signorini.examples import hertz
from signorini.fem.material import Material
from signorini.fem.stiffness import assemble_stiffness
from signorini.loop import adaptive
from signorini.mesh.builders import rectangle
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann
from signorini.problem.obstacles import Disc


def block_on_cylinder() -> ContactProblem:
    """A block pushed 0.01 down onto the cylinder of radius 1 below it."""
    return ContactProblem(
        rectangle(-1.0, 1.0, 0.0, 1.0, nx=4, ny=2),
        Material.from_young(1.0, 0.3),
        {
            "top": Dirichlet((0.0, -0.01)),
            "left": Neumann(),
            "right": Neumann(),
            "bottom": Contact(obstacle=Disc((0.0, -1.0), 1.0)),
        },
        name="block-on-cylinder",
    )


PROBLEMS = {"block-on-cylinder": block_on_cylinder, "hertz": hertz}


def energy(level, u) -> float:
    """``u K u`` on the level's space (the strain energy's double)."""
    space = level.result.space
    K = assemble_stiffness(
        space.mapping, space.cell_dofs, space.n_dofs, level.result.problem.material
    )
    x = np.asarray(u, dtype=np.float64).ravel()
    return float(x @ (K @ x))


def measure(name: str, max_ndof: int) -> None:
    """Run one problem under uniform refinement and print the table."""
    print(f"\n{name} (uniform refinement, max_ndof = {max_ndof})")
    head = ("level", "ndof", "eta", "eta_6", "eta_7", "diff_E", "eta6/diff", "eta/diff")
    print("  ".join(f"{h:>10}" for h in head))
    levels = list(adaptive(PROBLEMS[name](), uniform=True, max_ndof=max_ndof))
    rows = []
    for level, finer in zip(levels[:-1], levels[1:], strict=True):
        diff = math.sqrt(energy(finer, finer.result.u - level.next_u0))
        rec = level.record
        rows.append((rec.ndof, rec.eta, rec.eta_6, diff))
        values = (rec.eta, rec.eta_6, rec.eta_7, diff, rec.eta_6 / diff, rec.eta / diff)
        print(f"{rec.level:>10}  {rec.ndof:>10}  " + "  ".join(f"{v:10.3e}" for v in values))
    ndof, eta, eta6, diff = (np.array(c, dtype=float) for c in zip(*rows, strict=True))
    with np.errstate(divide="ignore", invalid="ignore"):
        slopes = [np.diff(np.log(y)) / np.diff(np.log(ndof)) for y in (eta, eta6, diff)]
    print(
        f"{name}: slopes in Ndof between levels: eta {np.round(slopes[0], 2)}, "
        f"eta_6 {np.round(slopes[1], 2)}, diff_E {np.round(slopes[2], 2)}"
    )


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-ndof", type=int, default=70_000)
    parser.add_argument("--problem", choices=sorted(PROBLEMS), action="append")
    args = parser.parse_args(argv)
    for name in args.problem or list(PROBLEMS):
        measure(name, args.max_ndof)


if __name__ == "__main__":
    main()
