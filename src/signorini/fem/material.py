"""Plane-strain isotropic material and Hooke's law (2.1).

.. math::

    \\sigma(v) = \\lambda\\,\\mathrm{tr}\\,\\varepsilon(v)\\,I + 2 \\mu\\,\\varepsilon(v),
    \\qquad \\varepsilon(v) = (\\nabla v + \\nabla v^T) / 2,

with ``lam`` the first Lamé parameter (the paper's ``chi`` in (2.1)) and ``mu`` the shear
modulus. Gradients are stored last-axis-is-derivative: ``grad_u[..., i, j] = d u_i / d x_j``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Material", "strain", "stress"]


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
    """Isotropic, homogeneous linear elastic material in plane strain.

    Built from its Lamé parameters by name, ``Material(lam=..., mu=...)``, or with
    :meth:`from_young` (Young's modulus and Poisson's ratio) or :meth:`from_lame`. Positional
    arguments are refused: ``Material(1000, 0.3)`` could mean either.

    Units are the user's and must be consistent: if E is in MPa (N/mm²), and so are ``lam``
    and ``mu``, and lengths are in mm, then stresses and tractions are in MPa, body forces in
    N/mm³, and forces along the boundary (per unit thickness, plane strain) in N/mm.

    Parameters
    ----------
    lam : float, keyword-only
        First Lamé parameter (the paper's ``chi`` in (2.1)), in stress units.
    mu : float, keyword-only
        Shear modulus, ``> 0``, in stress units.

    Raises
    ------
    TypeError
        If a parameter is given by position, or ``lam`` or ``mu`` is missing.
    ValueError
        If a parameter is not finite, ``mu <= 0``, or the plane-strain bulk
        modulus ``lam + mu <= 0`` (the elasticity tensor would not be
        positive definite).
    """

    lam: float
    mu: float

    def __init__(self, *args: float, lam: float | None = None, mu: float | None = None) -> None:
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
        object.__setattr__(self, "lam", lam)
        object.__setattr__(self, "mu", mu)

    @classmethod
    def from_lame(cls, lam: float, mu: float) -> Material:
        """Material from the Lamé parameters ``lam``, ``mu`` (stress units)."""
        return cls(lam=lam, mu=mu)

    @classmethod
    def from_young(cls, E: float, nu: float) -> Material:  # noqa: N803 (the usual symbol)
        """Material from Young's modulus and Poisson's ratio (plane strain).

        ``mu = E / (2 (1 + nu))``, ``lam = E nu / ((1 + nu)(1 - 2 nu))``.

        Parameters
        ----------
        E : float
            Young's modulus, ``> 0`` (stress units, e.g. MPa with lengths in mm).
        nu : float
            Poisson's ratio, ``-1 < nu < 0.5``.

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
        return cls(lam=lam, mu=mu)

    @property
    def young(self) -> float:
        """Young's modulus ``E = mu (3 lam + 2 mu) / (lam + mu)``."""
        return self.mu * (3.0 * self.lam + 2.0 * self.mu) / (self.lam + self.mu)

    @property
    def poisson(self) -> float:
        """Poisson's ratio ``nu = lam / (2 (lam + mu))``."""
        return self.lam / (2.0 * (self.lam + self.mu))


def strain(grad_u: np.ndarray) -> np.ndarray:
    """Symmetric gradient ``eps = (grad u + grad u^T) / 2``.

    Parameters
    ----------
    grad_u : array_like of float, shape (..., 2, 2)
        ``grad_u[..., i, j] = d u_i / d x_j``.

    Returns
    -------
    ndarray of float64, shape (..., 2, 2)

    Raises
    ------
    ValueError
        If the last two axes are not ``(2, 2)``.
    """
    g = np.asarray(grad_u, dtype=np.float64)
    if g.ndim < 2 or g.shape[-2:] != (2, 2):
        raise ValueError(f"grad_u must have shape (..., 2, 2), got {g.shape}")
    return 0.5 * (g + np.swapaxes(g, -1, -2))


def stress(material: Material, grad_u: np.ndarray) -> np.ndarray:
    """Cauchy stress of Hooke's law (2.1), ``sigma = lam tr(eps) I + 2 mu eps``.

    Parameters
    ----------
    material : Material
    grad_u : array_like of float, shape (..., 2, 2)
        Displacement gradients, ``grad_u[..., i, j] = d u_i / d x_j``.

    Returns
    -------
    ndarray of float64, shape (..., 2, 2)
        Symmetric stress tensors.
    """
    eps = strain(grad_u)
    sig = 2.0 * material.mu * eps
    tr = material.lam * (eps[..., 0, 0] + eps[..., 1, 1])
    sig[..., 0, 0] += tr
    sig[..., 1, 1] += tr
    return sig
