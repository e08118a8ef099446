"""A pin in a plate's circular hole: two deformable bodies in curved, conforming contact
with Coulomb friction (docs/method.md, *When the iteration cycles*).

The hollow pin (bore radius ``0.4 R``, outer radius ``R − clearance``) sits in the hole of
radius ``R`` of a square plate of half-width ``3 R`` whose outer sides are held. The pin's
bore is moved rigidly: pressed down by ``press``, sideways by ``shift``, and turned by
``rotation`` (radians) about the hole's centre, so that the pin rolls and slides on the
lower part of the hole: a contact arc with stick and slip zones whose ends carry small
forces, where the semismooth Newton method's node states can cycle. The lower arcs are the
contact pair (the pin's, ``y < −0.3 R``, the slave; the hole's, ``y < −0.2 R``, the master);
the rest of both circles is traction free.
"""

from __future__ import annotations

import numpy as np

from ..fem.material import Material
from ..mesh.bodies import union
from ..mesh.curves import Circle
from ..mesh.mesh import Mesh
from ..problem import Contact, ContactProblem, Dirichlet, Neumann
from ..problem.friction_laws import Coulomb

__all__ = ["annulus", "pin_in_hole"]


def annulus(inner: float, outer: float, n_theta: int, n_r: int, square: bool = False) -> Mesh:
    """The ring ``inner ≤ |x| ≤ outer`` (or, with ``square``, between the circle ``inner``
    and the square of half-width ``outer``): ``n_theta`` cells' sides around, ``n_r`` layers,
    two triangles per quadrilateral. Parts ``"inner"`` and ``"outer"``; the inner one
    carries its circle (and the outer one, unless ``square``)."""
    theta = 2 * np.pi * np.arange(n_theta) / n_theta
    c = np.column_stack([np.cos(theta), np.sin(theta)])
    far = outer * c / (np.abs(c).max(axis=1, keepdims=True) if square else 1.0)
    s = np.linspace(0.0, 1.0, n_r + 1)[:, None, None]
    points = ((1 - s) * inner * c + s * far).reshape(-1, 2)
    i, j = (a.ravel() for a in np.meshgrid(np.arange(n_theta), np.arange(n_r)))
    a, b = j * n_theta + i, j * n_theta + (i + 1) % n_theta
    cells = np.concatenate(
        [np.column_stack([a, b, b + n_theta]), np.column_stack([a, b + n_theta, a + n_theta])]
    )
    mid = 0.5 * (inner + outer)  # the square's sides are at least ``outer`` away
    mesh = Mesh.from_arrays(
        points,
        cells,
        {
            "inner": lambda x: np.hypot(x[:, 0], x[:, 1]) < mid,
            "outer": lambda x: np.hypot(x[:, 0], x[:, 1]) >= mid,
        },
    ).with_curve("inner", Circle((0.0, 0.0), inner))
    return mesh if square else mesh.with_curve("outer", Circle((0.0, 0.0), outer))


def _split(mesh: Mesh, name: str, below: float, names: tuple[str, str]) -> Mesh:
    """``mesh`` with its part ``name`` split into ``names[0]`` (edge midpoints with
    ``y < below``) and ``names[1]`` (the rest), both on the part's circle."""
    circle = mesh.curves[mesh.part_index(name)]
    edges = mesh.boundary[mesh.boundary_part == mesh.part_index(name)]
    low = mesh.points[edges, 1].mean(axis=1) < below
    parts = {p: mesh.boundary[mesh.boundary_part == mesh.part_index(p)] for p in mesh.part_names}
    del parts[name]
    parts.update({names[0]: edges[low], names[1]: edges[~low]})
    out = Mesh.from_arrays(mesh.points, mesh.cells, parts)
    for p in mesh.part_names:
        curve = mesh.curves[mesh.part_index(p)]
        if p != name and curve is not None:
            out = out.with_curve(p, curve)
    return out.with_curve(names[0], circle).with_curve(names[1], circle)


def pin_in_hole(
    *,
    radius: float = 1.0,
    clearance: float = 0.01,
    press: float = 0.03,
    shift: float = 0.0,
    rotation: float = 0.01,
    young: tuple[float, float] = (3.0, 1.0),
    poisson: float = 0.3,
    n_theta: int = 48,
    friction: object = None,
) -> ContactProblem:
    """The pin in the hole (module docstring): ``young`` of the pin and the plate,
    ``n_theta`` cells around both circles; ``friction`` the law on the pair (default
    ``Coulomb(0.2)``)."""
    r = float(radius)
    pin = annulus(0.4 * r, r - clearance, n_theta, 4)
    pin = _split(pin, "outer", -0.3 * r, ("contact", "free"))
    plate = annulus(r, 3.0 * r, n_theta, 6, square=True)
    plate = _split(plate, "inner", -0.2 * r, ("hole", "rim"))

    def bore(x: np.ndarray) -> np.ndarray:
        return np.stack([shift - rotation * x[..., 1], -press + rotation * x[..., 0]], axis=-1)

    return ContactProblem(
        mesh=union({"pin": pin, "plate": plate}),
        material={
            "pin": Material.from_young(young[0], poisson),
            "plate": Material.from_young(young[1], poisson),
        },
        conditions={
            "pin.inner": Dirichlet(bore),
            "pin.free": Neumann(),
            "pin.contact": Contact(
                master="plate.hole", friction=Coulomb(0.2) if friction is None else friction
            ),
            "plate.outer": Dirichlet((0.0, 0.0)),
            "plate.rim": Neumann(),
        },
        name="pin-in-hole",
    )
