"""The checks of a problem's materials: one :class:`~signorini.fem.material.Material`, or one
per cell region, and what double precision can hold of them together.

With one material per region, the stiffness matrix's condition number is at least the spread
of the elasticity tensors over the body: the largest eigenvalue of any region's tensor over
the smallest of any region's, ``κ_D = max_i (λ*_i + μ_i) / min_j μ_j`` (the 2D tensor's
eigenvalues are ``2 (λ* + μ)`` on volumetric strains and ``2 μ`` twice on deviatoric ones).
It grows with a near-incompressible region (``(λ + μ) / μ = 1 / (1 − 2ν)``) and with the
contrast of stiffness between regions alike, and it multiplies the mesh's own condition
number, so the solution's relative round-off is about ``eps κ_D`` times that
(docs/method.md, *Materials by region*).
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping

import numpy as np

from ..algebra.errors import IllConditionedWarning
from ..algebra.pdas import KKT_WARN
from ..fem.material import Material
from ..mesh.mesh import Mesh
from .fields import ProblemError

__all__ = ["CONTRAST_WARN", "check_materials"]

_EPS = float(np.finfo(np.float64).eps)

#: ``κ_D`` (module docstring) above which the regions' materials are warned about: the
#: solution's round-off is ``eps κ_D`` times the mesh's own condition number, measured at 13
#: to 600 on Example 6.2's meshes (KKT residuals 1.4e-6 and 6.5e-5 at ν = 0.499999999,
#: κ_D = 5e8); beyond ``KKT_WARN / (100 eps)`` (4.5e7) the forces keep fewer than the six
#: digits the solver's own warning asks for (:data:`~signorini.algebra.pdas.KKT_WARN`).
#: Measured on a layered block: contrast 1e8 gives KKT 5e-7, 1e10 gives 5e-5, 1e12 gives
#: 4e-3 (the soft layer held, 1e12 is refused as a singular system)
CONTRAST_WARN = 1e-2 * KKT_WARN / _EPS
#: a region's own ``(λ* + μ) / μ`` (``1 / (1 − 2ν)`` in plane strain) above which a message
#: says it is close to incompressible (ν > 0.4995)
NEARLY_INCOMPRESSIBLE = 1e3
#: ``κ_D`` beyond which the softest region's stiffness is below the round-off of the
#: stiffest's (``eps κ_D > 1``): where they meet, the sum of their entries holds nothing of
#: the soft one, so the matrix cannot represent both
CONTRAST_MAX = 1.0 / _EPS


def check_materials(material: object, mesh: Mesh) -> None:
    """A :class:`Material`, or a mapping giving each cell region of ``mesh`` one, that double
    precision can hold together.

    Raises
    ------
    ProblemError
        Naming the regions without a material, the names that are not regions, a value
        that is not a :class:`Material`, regions in plane strain beside regions in plane
        stress, or the stiffest and softest regions where their
        spread ``κ_D`` exceeds :data:`CONTRAST_MAX`.

    Warns
    -----
    IllConditionedWarning
        Naming the stiffest and softest regions and ``κ_D`` where it exceeds
        :data:`CONTRAST_WARN`.
    """
    kind = "a signorini Material (Material.from_young or Material.from_lame)"
    if isinstance(material, Material):
        return
    if not isinstance(material, Mapping):
        raise ProblemError(
            f"material must be {kind}, or a mapping region name -> Material, got "
            f"{type(material).__name__}"
        )
    given = {str(k): v for k, v in material.items()}
    regions = list(mesh.region_names)
    unknown = sorted(set(given) - set(regions))
    missing = [r for r in regions if r not in given]
    if unknown or missing:
        raise ProblemError(
            "material must give each cell region of the mesh one Material: "
            + (f"region(s) {missing} have none" if missing else "")
            + ("; " if missing and unknown else "")
            + (f"{unknown} are not regions of the mesh" if unknown else "")
            + f"; its regions are {regions}"
        )
    for name, m in given.items():
        if not isinstance(m, Material):
            raise ProblemError(f"the material of region {name!r} must be {kind}, got {m!r}")
    _check_planes(regions, [given[r] for r in regions])
    _check_spread(regions, [given[r] for r in regions])


def _check_planes(names: list[str], materials: list[Material]) -> None:
    """One 2D reduction for the whole body: a plane-strain region (a long body, ε_zz = 0)
    beside a plane-stress one (a thin plate, σ_zz = 0) describes no 3D body."""
    strain = [n for n, m in zip(names, materials, strict=True) if m.plane == "strain"]
    stress = [n for n, m in zip(names, materials, strict=True) if m.plane == "stress"]
    if strain and stress:
        raise ProblemError(
            f"material: region(s) {strain} are in plane strain and region(s) {stress} in plane "
            "stress; one body is either long (plane strain, ε_zz = 0) or a thin plate (plane "
            "stress, σ_zz = 0) throughout: give every region the same plane= (docs/method.md, "
            "*Plane stress*)"
        )


def _describe(name: str, m: Material) -> str:
    return f"region {name!r} (E = {m.young:.6g}, ν = {m.poisson:.12g}, plane {m.plane})"


def _check_spread(names: list[str], materials: list[Material]) -> None:
    """Refuse or warn about the spread ``κ_D`` of the regions' elasticity tensors (module
    docstring); one material on every region is the solver's to judge (its KKT residuals)."""
    if all(m == materials[0] for m in materials):
        return
    top = np.array([m.lam_eff + m.mu for m in materials])
    bottom = np.array([m.mu for m in materials])
    i, j = int(np.argmax(top)), int(np.argmin(bottom))
    spread = float(top[i] / bottom[j])
    if spread <= CONTRAST_WARN:
        return
    if i == j:
        what = (
            f"{_describe(names[i], materials[i])} is close to incompressible beside the other "
            f"regions: its (λ* + μ) / μ = 1 / (1 − 2ν) is {spread:.3g}"
        )
    else:
        what = (
            f"the largest modulus λ* + μ = {top[i]:.6g} of {_describe(names[i], materials[i])} "
            f"is {spread:.3g} times the smallest μ = {bottom[j]:.6g}, of "
            f"{_describe(names[j], materials[j])}"
        )
        own = float(top[i] / bottom[i])
        if own > NEARLY_INCOMPRESSIBLE:
            what += (
                f" (region {names[i]!r} is close to incompressible itself: its (λ* + μ) / μ = "
                f"1 / (1 − 2ν) is {own:.3g})"
            )
    if spread > CONTRAST_MAX:
        raise ProblemError(
            f"material: {what}, beyond 1/eps = {CONTRAST_MAX:.3g}: double precision cannot "
            "hold both in one stiffness matrix (the soft region's entries are below the "
            "round-off of the stiff one's where they meet, as if it were cut off). Bring the "
            "moduli closer (a stiff part many orders stiffer than its neighbour is rigid: "
            "make it an obstacle or hold it with a Dirichlet condition)"
        )
    digits = max(0.0, -np.log10(_EPS * spread))
    warnings.warn(
        f"material: {what} (more than {CONTRAST_WARN:.2g}): the stiffness matrix's condition "
        f"number is at least that times the mesh's own, so the solution keeps fewer than "
        f"{digits:.0f} digits, and a solve may report a singular system although every part "
        "is held (that was checked). Bring the moduli closer if you need more (docs/method.md, "
        "*Materials by region*)",
        IllConditionedWarning,
        stacklevel=4,
    )
