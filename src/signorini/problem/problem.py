"""The Signorini problem a user states: a mesh, a material, one condition per boundary part,
the body force and (optionally) an exact solution.

The strong form (paper, Section 2; docs/method.md, *The continuous problem*)::

    −div σ(u) = f in Ω,   u = u_D on Γ_D,   σ(u) n = g on Γ_N,
    u·n ≤ ψ,  σ_nn ≤ 0,  (u·n − ψ) σ_nn = 0,  σ_t = 0 on Γ_C.

:class:`ContactProblem` is a public boundary: it checks that every part has exactly one
condition, that every component of the body (cells joined through shared edges) has a
Dirichlet part, that each user function can be called by the convention of docs/method.md,
*User functions*, and that a contact part with a given normal is straight along it. Everything
below it trusts the problem.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from ..fem.material import CellMaterials, Material
from ..fem.space import LagrangeSpace, P2Space, space_of
from ..mesh.bodies import body_of_cells
from ..mesh.curves import Line
from ..mesh.geometry import facet_normals
from ..mesh.mesh import Mesh
from .conditions import Condition, Contact, Dirichlet, ExactSolution, Neumann, Roller
from .corners import check_corner_friction
from .fields import ProblemError, VectorField, check_function
from .materials import check_materials
from .normals import straight_normal
from .pairs import contact_pairs, pair_rigid_motions
from .problem3d import check_dimension, check_problem_3d
from .rigid import free_rigid_motions
from .rollers import check_roller_part, held_nodes, roller_normals

__all__ = ["ContactProblem", "SlenderBodyWarning", "free_ndof"]


def free_ndof(space: P2Space, dirichlet_nodes: np.ndarray) -> int:
    """The paper's Ndof: the free scalar unknowns of ``space``, ``d n_nodes − d n_D``.

    All DOFs of the space (``d = space.n_components`` a node) minus the ``d`` DOFs of each
    of the ``n_D`` nodes ``dirichlet_nodes`` on the closure of Γ_D; constrained contact DOFs
    are counted (docs/method.md, *Data conventions*). The one definition of the count that
    budgets (``max_ndof``) and histories (``ndof``) use.
    """
    return space.n_dofs - space.n_components * len(dirichlet_nodes)


@dataclass(frozen=True)
class ContactProblem:
    """A Signorini problem on an initial mesh.

    Units are the user's, and must be consistent: if E is in MPa (N/mm²) and lengths in mm,
    displacements and gaps are in mm, tractions and stresses in MPa, body forces in N/mm³, and
    forces along the boundary (per unit thickness, plane strain) in N/mm.

    Parameters
    ----------
    mesh : Mesh
        The initial mesh; its boundary parts carry the conditions. Every component of the body
        (cells joined through shared edges) needs a Dirichlet part.
    material : Material or mapping region name -> Material
        One material for the whole body, or one per cell region of the mesh
        (:attr:`~signorini.mesh.Mesh.region_names`, e.g.
        ``{"coating": Material.from_young(...), "base": ...}``); every region needs one.
    conditions : mapping part name -> Dirichlet | Neumann | Contact
        Every boundary part of the mesh must get exactly one condition.
    body_force : callable or None
        ``f(x)`` of the points ``x``, a float array of shape ``(n, 2)``, returning the force
        per unit volume ``(n, 2)`` (or one ``(2,)`` vector); ``None`` for no body force.
        docs/method.md, *User functions*.
    exact : ExactSolution or None
    name : str

    Raises
    ------
    ProblemError
        Before any work, if a part has no condition or a condition names no part, a condition
        or the body force is of the wrong kind, a component of a body with Dirichlet parts has
        none (the message names each such component), a rigid motion is held neither by the
        Dirichlet and Roller parts nor by the contact parts (the message names it), a
        contact part with a given normal is not straight along it, a roller part has a
        corner where its normal is undefined (:func:`~.rollers.check_roller_part`), or a
        node where two
        contact parts meet at an angle lies on a frictional part
        (:func:`~.corners.check_corner_friction`).

    Notes
    -----
    A body whose rigid motions are held only partly by Dirichlet and Roller parts, the rest
    by its contact parts (semi-coercive: a body under force control), is accepted;
    :attr:`rigid_motions` holds those motions, and the solver checks that the load presses
    the body onto its contacts along them (docs/method.md, *Force control*). With contact
    pairs each body's motions are its own, :attr:`rigid_parts` names a boundary part of the
    body of each, and a body may be under force control where the bodies across its pairs
    are held by their own parts (a loaded part on a deformable support).
    """

    mesh: Mesh
    material: Material | Mapping[str, Material]
    conditions: Mapping[str, Condition]
    body_force: VectorField | None = None
    exact: ExactSolution | None = None
    name: str = "problem"
    contact_normals: dict[str, np.ndarray] = field(init=False, repr=False)
    held: dict[str, Dirichlet] = field(init=False, repr=False)
    rollers: dict[str, Roller] = field(init=False, repr=False)
    rigid_motions: np.ndarray = field(init=False, repr=False)
    rigid_parts: tuple[str, ...] = field(init=False, repr=False)
    pairs: dict[str, str] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        mesh = self.mesh
        if not isinstance(mesh, Mesh):
            raise ProblemError(f"mesh must be a signorini Mesh, got {type(mesh).__name__}")
        check_materials(self.material, mesh)
        if not isinstance(self.conditions, Mapping):
            raise ProblemError(
                "conditions must be a mapping part name -> Dirichlet | Neumann | Contact, "
                f"got {type(self.conditions).__name__}"
            )
        unknown = sorted(set(self.conditions) - set(mesh.part_names))
        if unknown:
            raise ProblemError(
                f"conditions name boundary parts the mesh does not have: "
                f"{unknown}; its parts are {list(mesh.part_names)}"
            )
        check_dimension(mesh, self.conditions)
        object.__setattr__(self, "pairs", contact_pairs(mesh, self.conditions))
        masters = set(self.pairs.values())
        missing = [p for p in mesh.part_names if p not in self.conditions and p not in masters]
        if missing:
            raise ProblemError(
                f"boundary part(s) {missing} have no condition; give each part "
                "Dirichlet(...), Neumann(...) or Contact(...)"
            )
        for name, cond in self.conditions.items():
            if not isinstance(cond, Dirichlet | Roller | Neumann | Contact):
                raise ProblemError(
                    f"the condition of part {name!r} must be Dirichlet, Roller, Neumann or "
                    f"Contact, got {type(cond).__name__}"
                )
        if self.body_force is not None:
            check_function(
                self.body_force,
                "ContactProblem(body_force=...)",
                "None or a function f(x) of points x (n, 2)",
            )
        if self.exact is not None and not isinstance(self.exact, ExactSolution):
            raise ProblemError(f"exact must be an ExactSolution, got {type(self.exact).__name__}")
        if not self.dirichlet_parts and not self.contact_parts:
            raise ProblemError(
                "the problem needs a Dirichlet part (meas Γ_D > 0) to rule out rigid body motions"
            )
        held = {name: self._held_condition(name) for name in self.dirichlet_parts}
        object.__setattr__(self, "held", {k: v for k, v in held.items() if v is not None})
        object.__setattr__(
            self, "rollers", {k: self.conditions[k] for k, v in held.items() if v is None}
        )
        if mesh.dim == 3:  # docs/method.md, *Three dimensions: rollers, force control, ...*
            motions = check_problem_3d(
                mesh, self.held, self.rollers, self.contact_parts, self.pairs
            )
            object.__setattr__(self, "rigid_motions", motions)
            object.__setattr__(self, "rigid_parts", ())
            object.__setattr__(self, "contact_normals", {})
            return
        if self.dirichlet_parts:
            _check_components(mesh, self.dirichlet_parts, self.contact_parts)
        if self.pairs:  # each body's own motions (docs/method.md, *Force control*)
            motions, parts = pair_rigid_motions(
                mesh, self.held, self.pairs, self.contact_parts, self._roller_vertices()
            )
        else:
            motions, parts = (
                free_rigid_motions(mesh, self.held, self.contact_parts, self._roller_vertices()),
                (),
            )
        object.__setattr__(self, "rigid_motions", motions)
        object.__setattr__(self, "rigid_parts", parts)
        _warn_if_slender(mesh)
        normals = {name: self._segment_normal(name) for name in self.contact_parts}
        normals = {name: n for name, n in normals.items() if n is not None}
        object.__setattr__(self, "contact_normals", normals)
        check_corner_friction(self)

    @property
    def dirichlet_parts(self) -> list[str]:
        """The parts with a Dirichlet or Roller condition (all or some components held)."""
        return [n for n, c in self.conditions.items() if isinstance(c, Dirichlet | Roller)]

    @property
    def neumann_parts(self) -> list[str]:
        return [n for n, c in self.conditions.items() if isinstance(c, Neumann)]

    @property
    def contact_parts(self) -> list[str]:
        return [n for n, c in self.conditions.items() if isinstance(c, Contact)]

    def material_on(self, mesh: Mesh) -> Material | CellMaterials:
        """The material of each cell of ``mesh`` (the initial mesh or a refinement of it): the
        one :class:`Material` where every region has the same, else a
        :class:`~signorini.fem.material.CellMaterials` from the cells' regions."""
        if isinstance(self.material, Material):
            return self.material
        given = {str(k): v for k, v in self.material.items()}
        materials = [given[name] for name in mesh.region_names]
        if all(m == materials[0] for m in materials):
            return materials[0]
        return CellMaterials(materials, mesh.cell_region)

    def dirichlet_nodes(self, space: P2Space) -> np.ndarray:
        """Sorted P2 nodes of ``space`` whose both DOFs are prescribed: on the closure of a
        part holding both components, or of two parts holding one each (a roller's corner)."""
        return np.flatnonzero(self.held_components(space).all(axis=1))

    def held_components(self, space: P2Space) -> np.ndarray:
        """``(n_nodes, 2)`` bool: which Cartesian components of ``u`` the Dirichlet and
        Roller parts hold at each P2 node of ``space``: both at a node held along two
        independent directions; neither at a node an oblique or curved roller alone holds
        (its normal component: :func:`~.rollers.held_nodes`; docs/method.md, *Rollers and
        components*)."""
        return held_nodes(self, space, values=False).components

    def _held_condition(self, name: str) -> Dirichlet | None:
        """The condition of Dirichlet or Roller part ``name`` as a :class:`Dirichlet`: a
        roller on a straight part along an axis holds the one Cartesian component along its
        normal; ``None`` for a roller on an oblique straight or a curved part (its normal
        component is held in node frames: :mod:`.rollers`)."""
        cond = self.conditions[name]
        if isinstance(cond, Dirichlet):
            return cond
        mean = straight_normal(self.mesh, name)
        if mean is None:
            if self.mesh.dim == 3:
                return None  # held in node frames (problem/rollers3d.py)
            check_roller_part(self.mesh, name)
            return None
        axis = int(np.argmax(np.abs(mean)))
        if np.abs(np.delete(mean, axis)).max() > 1e-12:
            return None
        value = float(np.sign(mean[axis]) * cond.value)
        return Dirichlet(tuple(value if c == axis else None for c in range(mean.size)))

    def _roller_vertices(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """The vertices of each oblique or curved roller part and its normals there."""
        out = {}
        for name in self.rollers:  # a loop over parts
            nodes, normals = roller_normals(self.mesh, name)
            v, first = np.unique(nodes[:, :2].ravel(), return_index=True)
            out[name] = (self.mesh.points[v], normals[:, :2].reshape(-1, self.mesh.dim)[first])
        return out

    def free_ndof(self, mesh: Mesh | LagrangeSpace) -> int:
        """Free scalar unknowns on ``mesh`` (or its space), the paper's Ndof: all DOFs minus
        the held ones (:func:`free_ndof` without rollers; a roller holds one DOF a node)."""
        space = mesh if isinstance(mesh, LagrangeSpace) else space_of(mesh, "P2")
        return space.n_dofs - held_nodes(self, space, values=False).n_held

    def _segment_normal(self, name: str) -> np.ndarray | None:
        """Outward unit normal of a straight contact part with a gap function, checked against
        a given one; ``None`` for a curved or polygonal part or an obstacle given as a shape
        (their directions are per node: docs/method.md, *Contact directions*)."""
        mesh = self.mesh
        given = self.conditions[name].normal
        if self.conditions[name].obstacle is not None or name in self.pairs:
            return None
        ab = mesh.oriented_boundary(mesh.part_facets(name))
        _, n = facet_normals(mesh.points[ab])
        mean = n.mean(axis=0)
        mean /= np.linalg.norm(mean)
        curve = mesh.curves[mesh.part_index(name)]
        straight = np.abs(n - mean).max() <= 1e-8 and (curve is None or isinstance(curve, Line))
        if given is not None and not straight:
            raise ProblemError(
                f"a normal is given for contact part {name!r}, which is not straight (its "
                "edges' outward normals differ); leave normal=None and the direction at each "
                "node is taken from the geometry"
            )
        if not straight:
            return None
        if given is not None:
            g = np.asarray(given, dtype=np.float64).reshape(mesh.dim)  # checked by Contact
            g = g / np.linalg.norm(g)
            if np.abs(g - mean).max() > 1e-6:
                raise ProblemError(
                    f"the normal {tuple(given)} given for contact part {name!r} "
                    f"is not its outward normal {tuple(np.round(mean, 12))}"
                )
        return mean


#: How many floating components an error message describes (the rest are counted).
_NAMED_COMPONENTS = 5
#: slenderness (bounding-box diagonal² / area, about length / thickness for a strip) above
#: which a warning is given. Measured with P2 cantilevers under a tip load against
#: Timoshenko's beam (tests/contact/test_slender.py): tip deflection within 0.05 % up to 500,
#: 0.1 % off at 700, 0.5 % at 1000, 1 to 3 % at 1500; from 2000 the solve is refused as
#: singular, and at 10⁴ the matrix is not positive definite in double precision. The error is
#: the round-off of the assembled matrix, amplified by a condition number growing like
#: slenderness⁴
SLENDER = 500.0


class SlenderBodyWarning(RuntimeWarning):
    """The body is so slender that the linear systems may lose many digits."""


def _warn_if_slender(mesh: Mesh) -> None:
    """Warn when the body's bounding-box diagonal² / area exceeds :data:`SLENDER`."""
    size = np.ptp(mesh.points, axis=0)
    slenderness = float(size @ size) / float(mesh.area.sum())
    if slenderness > SLENDER:
        warnings.warn(
            f"the body is slender: bounding-box diagonal² / area = {slenderness:.3g} (about "
            "length / thickness). Held at one end, its stiffness matrix has a condition number "
            "growing like the fourth power of that ratio, so the results lose digits (measured "
            "on cantilevers against beam theory: 0.1 % off at 700, 0.5 % at 1000, 1 to 3 % at "
            "1500); from about 2000 the solver reports a singular system. A thin body held "
            "along its length is not affected.",
            SlenderBodyWarning,
            stacklevel=4,
        )


def _check_components(mesh: Mesh, dirichlet_parts: list[str], contact_parts: list[str]) -> None:
    """Every component of the body (cells joined through shared edges) must have a Dirichlet
    edge: a component without one can move rigidly (docs/method.md, *The continuous problem*).

    Raises
    ------
    ProblemError
        Naming each component without a Dirichlet edge by its cells, bounding box and
        boundary parts (the first few, and how many more).
    """
    e2c = mesh.facet2cell
    label = body_of_cells(mesh)
    n_comp = int(label.max(initial=0)) + 1
    if n_comp == 1:
        return
    held = np.zeros(n_comp, dtype=bool)
    for name in dirichlet_parts:
        held[label[e2c[mesh.part_facets(name), 0]]] = True
    floating = np.flatnonzero(~held)
    if floating.size == 0:
        return
    # cells, bounding box and boundary parts of each component
    n_cells = np.bincount(label, minlength=n_comp)
    xy = mesh.points[mesh.cells]  # (n_cells, 3, dim)
    lo = np.full((n_comp, mesh.dim), np.inf)
    hi = np.full((n_comp, mesh.dim), -np.inf)
    np.minimum.at(lo, label, xy.min(axis=1))
    np.maximum.at(hi, label, xy.max(axis=1))
    be = np.flatnonzero(mesh.facet_part >= 0)
    pairs = np.unique(np.column_stack([label[e2c[be, 0]], mesh.facet_part[be]]), axis=0)
    lines = []
    for c in floating[:_NAMED_COMPONENTS]:
        parts = [mesh.part_names[p] for p in pairs[pairs[:, 0] == c, 1]]
        on_contact = [p for p in parts if p in contact_parts]
        cells = f"{n_cells[c]} cell{'s' if n_cells[c] > 1 else ''}"
        box = f"[{lo[c, 0]:.6g}, {hi[c, 0]:.6g}] × [{lo[c, 1]:.6g}, {hi[c, 1]:.6g}]"
        line = f"component {c + 1} ({cells} in {box}, boundary parts {parts})"
        if on_contact:
            line += f" is held only by contact parts {on_contact}"
        lines.append(line)
    more = floating.size - len(lines)
    if more:
        lines.append(f"and {more} more")
    raise ProblemError(
        f"the body falls into {n_comp} components (cells joined through shared edges; cells "
        f"that share only a vertex are not joined), and {floating.size} of them ha"
        f"{'ve' if floating.size > 1 else 's'} no Dirichlet part, so nothing rules out "
        f"their rigid body motions: {'; '.join(lines)}. Give each component a Dirichlet part "
        "or join it to the body along an edge; contact alone does not hold a component "
        "(docs/method.md, *The continuous problem*)"
    )
