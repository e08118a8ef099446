"""Isotropic linear elastic materials, plane strain (the default) or plane stress, and
Hooke's law (2.1).

.. math::

    \\sigma(v) = \\lambda^*\\,\\mathrm{tr}\\,\\varepsilon(v)\\,I + 2 \\mu\\,\\varepsilon(v),
    \\qquad \\varepsilon(v) = (\\nabla v + \\nabla v^T) / 2,

with ``lam`` the first Lamé parameter (the paper's ``chi`` in (2.1)), ``mu`` the shear
modulus, and ``lam* = lam`` in plane strain, ``lam* = 2 lam mu / (lam + 2 mu)`` in plane
stress (:attr:`Material.lam_eff`; docs/method.md, *Plane stress*). Several materials, one per
cell region, are a :class:`CellMaterials`; the functions here take either. Gradients are stored
last-axis-is-derivative: ``grad_u[..., i, j] = d u_i / d x_j``.

In three dimensions (gradients ``(..., 3, 3)``) the law is the isotropic Hooke's law itself,
``sigma = lam tr(eps) I + 2 mu eps`` with the material's own ``lam`` and ``mu``
(:func:`lame_parameters` with ``dim = 3``): plane strain is the 3D law restricted to
``eps_zz = 0``, so a plane-strain material is the same body in 3D, while plane stress is a
2D reduction only and is refused there.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = [
    "CellMaterials",
    "Material",
    "lame_parameters",
    "on_cells",
    "strain",
    "stress",
    "stress_zz",
    "von_mises",
]

_PLANES = ("strain", "stress")


def _finite_float(value: float, name: str) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number, got {value!r}") from None
    if not math.isfinite(x):
        raise ValueError(f"{name} must be finite, got {x}")
    return x


@dataclass(frozen=True, init=False)
class Material:
    """Isotropic, homogeneous linear elastic material in plane strain or plane stress.

    Built from its Lamé parameters by name, ``Material(lam=..., mu=...)``, or with
    :meth:`from_young` (Young's modulus and Poisson's ratio) or :meth:`from_lame`. Positional
    arguments are refused: ``Material(1000, 0.3)`` could mean either. ``plane="strain"`` (the
    default: a long body, ε_zz = 0) or ``plane="stress"`` (a thin plate, σ_zz = 0); the 2D
    Hooke's law then uses :attr:`lam_eff` in place of ``lam``.

    Units are the user's and must be consistent: if E is in MPa (N/mm²), and so are ``lam``
    and ``mu``, and lengths are in mm, then stresses and tractions are in MPa, body forces in
    N/mm³, and forces along the boundary (per unit thickness, plane strain) in N/mm.

    Parameters
    ----------
    lam : float, keyword-only
        First Lamé parameter (the paper's ``chi`` in (2.1)), in stress units.
    mu : float, keyword-only
        Shear modulus, ``> 0``, in stress units.
    plane : {"strain", "stress"}, keyword-only
        The 2D reduction of the 3D law (docs/method.md, *Plane stress*).

    Raises
    ------
    TypeError
        If a parameter is given by position, or ``lam`` or ``mu`` is missing.
    ValueError
        If a parameter is not finite, ``mu <= 0``, or the plane-strain bulk
        modulus ``lam + mu <= 0`` (the elasticity tensor would not be
        positive definite; in plane stress also ``3 lam + 2 mu <= 0``), or ``plane`` is
        neither ``"strain"`` nor ``"stress"``.
    """

    lam: float
    mu: float
    plane: str

    def __init__(
        self,
        *args: float,
        lam: float | None = None,
        mu: float | None = None,
        plane: str = "strain",
    ) -> None:
        if args:
            given = ", ".join(repr(a) for a in args)
            raise TypeError(
                f"Material takes its parameters by name, got Material({given}): write "
                "Material.from_young(E, nu) for Young's modulus and Poisson's ratio, or "
                "Material(lam=..., mu=...) / Material.from_lame(lam, mu) for the Lamé parameters"
            )
        if lam is None or mu is None:
            missing = " and ".join(n for n, v in (("lam", lam), ("mu", mu)) if v is None)
            raise TypeError(
                f"Material needs {missing}: write Material(lam=..., mu=...), or "
                "Material.from_young(E, nu)"
            )
        lam = _finite_float(lam, "lam")
        mu = _finite_float(mu, "mu")
        if mu <= 0.0:
            raise ValueError(f"shear modulus mu must be positive, got {mu}")
        if lam + mu <= 0.0:
            raise ValueError(
                f"plane-strain bulk modulus lam + mu must be positive, got lam + mu = {lam + mu}"
            )
        if plane not in _PLANES:
            raise ValueError(f'plane must be "strain" or "stress", got {plane!r}')
        if plane == "stress" and 3.0 * lam + 2.0 * mu <= 0.0:
            raise ValueError(
                "bulk modulus 3 lam + 2 mu must be positive in plane stress, got "
                f"{3 * lam + 2 * mu}"
            )
        object.__setattr__(self, "lam", lam)
        object.__setattr__(self, "mu", mu)
        object.__setattr__(self, "plane", plane)

    @classmethod
    def from_lame(cls, lam: float, mu: float, plane: str = "strain") -> Material:
        """Material from the Lamé parameters ``lam``, ``mu`` (stress units) of the 3D law."""
        return cls(lam=lam, mu=mu, plane=plane)

    @classmethod
    def from_young(
        cls,
        E: float,  # noqa: N803 (the usual symbol)
        nu: float,
        plane: str = "strain",
    ) -> Material:
        """Material from Young's modulus and Poisson's ratio, in plane strain (the default) or
        plane stress (``plane="stress"``).

        ``mu = E / (2 (1 + nu))``, ``lam = E nu / ((1 + nu)(1 - 2 nu))``; in plane stress the
        2D law uses ``lam_eff = E nu / (1 - nu²)``.

        Parameters
        ----------
        E : float
            Young's modulus, ``> 0`` (stress units, e.g. MPa with lengths in mm).
        nu : float
            Poisson's ratio, ``-1 < nu < 0.5``.
        plane : {"strain", "stress"}

        Raises
        ------
        ValueError
            If ``E <= 0``, ``nu >= 0.5`` (incompressible limit not supported),
            ``nu <= -1``, or a value is not finite.
        """
        E = _finite_float(E, "Young's modulus E")
        nu = _finite_float(nu, "Poisson's ratio nu")
        if E <= 0.0:
            raise ValueError(f"Young's modulus E must be positive, got {E}")
        if nu >= 0.5:
            raise ValueError(
                f"Poisson's ratio nu must be < 0.5 (incompressible limit not supported), got {nu}"
            )
        if nu <= -1.0:
            raise ValueError(f"Poisson's ratio nu must be > -1, got {nu}")
        mu = E / (2.0 * (1.0 + nu))
        lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
        return cls(lam=lam, mu=mu, plane=plane)

    @property
    def lam_eff(self) -> float:
        """The ``lam`` of the 2D Hooke's law: ``lam`` in plane strain, ``2 lam mu / (lam + 2
        mu)`` in plane stress (σ_zz = 0 eliminates ε_zz)."""
        if self.plane == "strain":
            return self.lam
        return 2.0 * self.lam * self.mu / (self.lam + 2.0 * self.mu)

    @property
    def hooke_norm(self) -> float:
        """``‖C‖``, the largest eigenvalue of the 2D Hooke's law on symmetric strains:
        σ = λ* tr(ε) I + 2 μ ε has ``2 (λ* + μ)`` on ε ∝ I and ``2 μ`` on trace-free ε, so
        ``max(2 (λ* + μ), 2 μ)`` (λ* = :attr:`lam_eff`)."""
        return max(2.0 * (self.lam_eff + self.mu), 2.0 * self.mu)

    @property
    def hooke_norm_3d(self) -> float:
        """``‖C‖`` of the 3D Hooke's law on symmetric 3 × 3 strains: σ = λ tr(ε) I + 2 μ ε
        has ``3 λ + 2 μ`` on ε ∝ I and ``2 μ`` on trace-free ε, so ``max(3 λ + 2 μ, 2 μ)``
        (the material's own λ: plane strain is the 3D law, plane stress is refused in 3D)."""
        return max(3.0 * self.lam + 2.0 * self.mu, 2.0 * self.mu)

    def stress_zz(self, grad_u: np.ndarray) -> np.ndarray:
        """The out-of-plane stress σ_zz of displacement gradients ``grad_u (..., 2, 2)``:
        ``lam (ε_xx + ε_yy)`` in plane strain, zero in plane stress; shape ``(...)``."""
        return stress_zz(self, grad_u)

    @property
    def young(self) -> float:
        """Young's modulus ``E = mu (3 lam + 2 mu) / (lam + mu)``."""
        return self.mu * (3.0 * self.lam + 2.0 * self.mu) / (self.lam + self.mu)

    @property
    def poisson(self) -> float:
        """Poisson's ratio ``nu = lam / (2 (lam + mu))``."""
        return self.lam / (2.0 * (self.lam + self.mu))


class CellMaterials:
    """One :class:`Material` per cell: cell ``c`` has ``materials[index[c]]`` (a mesh's cell
    regions with the material of each, :meth:`~signorini.problem.ContactProblem.material_on`).

    Every function that takes a :class:`Material` takes a :class:`CellMaterials` of the same
    cells in the same order (:func:`on_cells` restricts it to a subset); its :attr:`lam`,
    :attr:`lam_eff` and :attr:`mu` are then ``(n_cells,)`` arrays.

    Parameters
    ----------
    materials : sequence of Material
    index : (n_cells,) int array
        Index into ``materials`` of each cell.
    """

    def __init__(self, materials: Sequence[Material], index: np.ndarray) -> None:
        self.materials = tuple(materials)
        self.index = np.asarray(index, dtype=np.int64)
        table = np.array([[m.lam, m.lam_eff, m.mu] for m in self.materials]).reshape(-1, 3)
        self.lam, self.lam_eff, self.mu = table[self.index].T
        self._zz = np.array([m.lam if m.plane == "strain" else 0.0 for m in self.materials])

    def __len__(self) -> int:
        return self.index.size

    def restrict(self, cells: np.ndarray | slice) -> CellMaterials:
        """The materials of the cells ``cells`` (indices, a mask or a slice), in that order."""
        return CellMaterials(self.materials, self.index[cells])

    def __repr__(self) -> str:
        return f"CellMaterials({list(self.materials)!r}, n_cells={len(self)})"


def on_cells(
    material: Material | CellMaterials, cells: np.ndarray | slice
) -> Material | CellMaterials:
    """``material`` restricted to the cells ``cells``: a :class:`Material` is the same on every
    cell and is returned as it is."""
    return material.restrict(cells) if isinstance(material, CellMaterials) else material


def _per_cell(value: float | np.ndarray, ndim: int) -> float | np.ndarray:
    """A scalar, or an ``(m,)`` array shaped to broadcast against ``(m, ..., 2, 2)``."""
    if np.ndim(value) == 0:
        return value
    return np.reshape(value, (-1,) + (1,) * (ndim - 1))


def strain(grad_u: np.ndarray) -> np.ndarray:
    """Symmetric gradient ``eps = (grad u + grad u^T) / 2``.

    Parameters
    ----------
    grad_u : array_like of float, shape (..., d, d), d = 2 or 3
        ``grad_u[..., i, j] = d u_i / d x_j``.

    Returns
    -------
    ndarray of float64, shape (..., d, d)

    Raises
    ------
    ValueError
        If the last two axes are not ``(2, 2)`` or ``(3, 3)``.
    """
    g = np.asarray(grad_u, dtype=np.float64)
    if g.ndim < 2 or g.shape[-2:] not in ((2, 2), (3, 3)):
        raise ValueError(f"grad_u must have shape (..., 2, 2) or (..., 3, 3), got {g.shape}")
    return 0.5 * (g + np.swapaxes(g, -1, -2))


def stress(material: Material, grad_u: np.ndarray) -> np.ndarray:
    """Cauchy stress of Hooke's law (2.1), ``sigma = lam tr(eps) I + 2 mu eps``.

    Parameters
    ----------
    material : Material or CellMaterials
        With a :class:`CellMaterials` of ``m`` cells, ``grad_u`` has shape ``(m, ..., 2, 2)``.
    grad_u : array_like of float, shape (..., 2, 2)
        Displacement gradients, ``grad_u[..., i, j] = d u_i / d x_j``.

    Returns
    -------
    ndarray of float64, shape (..., 2, 2)
        Symmetric stress tensors (the in-plane ones, with ``lam_eff`` in plane stress);
        ``(..., 3, 3)`` for gradients ``(..., 3, 3)``, the 3D law (:func:`lame_parameters`).
    """
    eps = strain(grad_u)
    if eps.shape[-1] == 3:
        lam, mu = lame_parameters(material, 3)
        sig = 2.0 * _per_cell(mu, eps.ndim) * eps
        tr = _per_cell(lam, eps.ndim - 2) * np.trace(eps, axis1=-2, axis2=-1)
        for i in range(3):
            sig[..., i, i] += tr
        return sig
    sig = 2.0 * _per_cell(material.mu, eps.ndim) * eps
    tr = _per_cell(material.lam_eff, eps.ndim - 2) * (eps[..., 0, 0] + eps[..., 1, 1])
    sig[..., 0, 0] += tr
    sig[..., 1, 1] += tr
    return sig


def stress_zz(material: Material | CellMaterials, grad_u: np.ndarray) -> np.ndarray:
    """Out-of-plane stress σ_zz, shape ``(...)`` of ``grad_u (..., 2, 2)``: ``lam (ε_xx +
    ε_yy)`` in plane strain (ε_zz = 0), zero in plane stress (docs/method.md, *Plane stress*).
    """
    g = np.asarray(grad_u, dtype=np.float64)
    if g.ndim < 2 or g.shape[-2:] != (2, 2):
        raise ValueError(f"grad_u must have shape (..., 2, 2), got {g.shape}")
    if isinstance(material, CellMaterials):
        lam = material._zz[material.index]
    else:
        lam = material.lam if material.plane == "strain" else 0.0
    return _per_cell(lam, g.ndim - 2) * (g[..., 0, 0] + g[..., 1, 1])


def lame_parameters(
    material: Material | CellMaterials, dim: int
) -> tuple[float | np.ndarray, float | np.ndarray]:
    """The ``(lam, mu)`` of Hooke's law in ``dim`` dimensions, the dimension explicit.

    ``dim = 2``: ``(lam_eff, mu)``, plane strain or plane stress (:attr:`Material.lam_eff`).
    ``dim = 3``: ``(lam, mu)``, the isotropic law ``sigma = lam tr(eps) I + 2 mu eps`` of the
    same (E, nu) or (lam, mu); arrays ``(n_cells,)`` for a :class:`CellMaterials`.

    Raises
    ------
    ValueError
        In 3D for a plane-stress material (a thin-plate reduction of the 2D solver, with no
        meaning for a 3D body), naming the remedy; for a ``dim`` other than 2 or 3.
    """
    if dim == 2:
        return material.lam_eff, material.mu
    if dim != 3:
        raise ValueError(f"dim must be 2 or 3, got {dim!r}")
    planes = (
        [m.plane for m in material.materials]
        if isinstance(material, CellMaterials)
        else [material.plane]
    )
    if "stress" in planes:
        raise ValueError(
            'plane="stress" is a 2D reduction (a thin plate, sigma_zz = 0) and has no meaning '
            "for a 3D body: build the material without it, Material.from_young(E, nu) or "
            "Material(lam=..., mu=...), for the full 3D law"
        )
    return material.lam, material.mu


def von_mises(sigma: np.ndarray) -> np.ndarray:
    """The von Mises stress ``sqrt(3/2 s : s)``, ``s = sigma - tr(sigma) I / 3``, of 3D stress
    tensors ``sigma (..., 3, 3)``; shape ``(...)``."""
    sigma = np.asarray(sigma, dtype=np.float64)
    if sigma.shape[-2:] != (3, 3):
        raise ValueError(f"sigma must have shape (..., 3, 3), got {sigma.shape}")
    s = sigma - np.trace(sigma, axis1=-2, axis2=-1)[..., None, None] / 3.0 * np.eye(3)
    return np.sqrt(1.5 * np.einsum("...ij,...ij->...", s, s))
