"""A pin in a plate's circular hole with Coulomb friction 0.2: two deformable bodies in
curved contact, the pin pressed down and turned so that it rolls and slides on the hole.

The hollow pin (E = 3, ν = 0.3; bore radius 0.4, outer radius 0.99) sits in the hole of
radius 1 of a square plate (E = 1, half-width 3) held on its outer sides. The bore moves
by (0, −0.03) and turns by 0.01 rad about the hole's centre
(:func:`signorini.examples.pin.pin_in_hole`). Level 2 of the adaptive run is where the
semismooth Newton method's node states cycle (docs/method.md, *When the iteration cycles*).

    signorini run examples/pin_in_hole.py --max-ndof 100000 --out results/pin
"""

from __future__ import annotations

from signorini.examples.pin import pin_in_hole
from signorini.problem import ContactProblem


def problem() -> ContactProblem:
    return pin_in_hole(press=0.03, rotation=0.01)
