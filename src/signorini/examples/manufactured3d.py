"""The exact solution of ``example-6.1-3d``: a manufactured frictionless contact problem on
the unit cube whose face z = 0 is in contact with the rigid plane z = 0 on a disc and lifts
off around it (docs/method.md, *Three dimensions: the paper's examples*).

On Γ_C = {z = 0} (outward normal n = −e_z, obstacle ψ = 0, so u·n = −u_z ≤ 0) take a gap
``g ≥ 0`` and a pressure ``p ≥ 0`` with ``g p = 0``, tangential fields ``a = (a_1, a_2)`` and
smooth ``q_1, q_2, c`` of (x, y), and

    u_1 = a_1 − z ∂_x g + z² q_1,   u_2 = a_2 − z ∂_y g + z² q_2,
    u_3 = g − z (p + λ div a) / (λ + 2μ) + z² c.

On z = 0: ψ − u·n = u_3 = g ≥ 0; σ_33 = λ div a + (λ + 2μ) ∂_z u_3 = −p ≤ 0, so
σ_nn = −p and (u·n − ψ) σ_nn = g p = 0; σ_13 = μ (∂_z u_1 + ∂_x u_3) = μ (−∂_x g + ∂_x g) = 0
and σ_23 = 0 likewise: the frictionless Signorini conditions (the paper's (2.3)) hold
pointwise. With ``φ = (x − ½)² + (y − ½)² − R²``,

    g = G (φ⁺)⁴,   p = P (φ⁻)³,

contact on the disc of radius R about the face's centre and a gap outside; g ∈ C³ and p ∈ C²
across the free boundary φ = 0, so that u is C² with piecewise smooth third derivatives
(u ∈ H^{7/2−ε}): the P2 energy error can reach its optimal order h² ~ N^{−2/3}. The body
force is ``f = −div σ(u)``, the side faces carry ``σ(u) n``, the top z = 1 the Dirichlet data
``u``. All terms are closed forms (polynomials and powers of φ), evaluated with their
derivatives to third order by the chain rule.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.polynomial import polynomial as poly

from ..fem.material import Material

__all__ = ["ContactCube", "CONTACT_CUBE"]

#: the derivatives of a function of (x, y) a jet holds: (number of ∂_x, number of ∂_y)
ORDERS = [(i, k - i) for k in range(4) for i in range(k, -1, -1)]


def _poly(coef: list[list[float]]):
    """A polynomial ``Σ c[i][j] xⁱ yʲ`` as coefficients."""
    return np.asarray(coef, dtype=np.float64)


@dataclass(frozen=True)
class ContactCube:
    """The manufactured solution of the module docstring.

    Attributes
    ----------
    material : Material
    radius : float
        R, the contact disc's radius (length units).
    g_scale, p_scale : float
        G and P.
    a1, a2, q1, q2, c : (m, m) float arrays
        The coefficients ``c[i, j]`` of ``xⁱ yʲ`` of the polynomial fields.
    """

    material: Material
    radius: float
    g_scale: float
    p_scale: float
    a1: np.ndarray
    a2: np.ndarray
    q1: np.ndarray
    q2: np.ndarray
    c: np.ndarray

    # -- the fields of (x, y) and their derivatives ------------------------------------------
    def _poly_jet(self, coef: np.ndarray, x: np.ndarray, y: np.ndarray) -> dict:
        """``{(i, j): ∂_xⁱ ∂_yʲ P (n,)}`` to third order."""
        out = {}
        for i, j in ORDERS:  # a loop over the ten derivatives
            d = poly.polyder(poly.polyder(coef, i, axis=0), j, axis=1) if i + j else coef
            out[(i, j)] = poly.polyval2d(x, y, d) if d.size else np.zeros_like(x)
        return out

    def _profile_jet(self, x: np.ndarray, y: np.ndarray, h: tuple) -> dict:
        """``{(i, j): ∂_xⁱ ∂_yʲ h(φ)}`` to third order by the chain rule, ``h = (h, h′, h″,
        h‴)`` at φ; φ is quadratic with ∂_i ∂_j φ = 2 δ_ij."""
        d = (2.0 * (x - 0.5), 2.0 * (y - 0.5))  # ∂_x φ, ∂_y φ
        out = {}
        for i, j in ORDERS:  # a loop over the ten derivatives
            axes = (0,) * i + (1,) * j
            if not axes:
                out[(i, j)] = h[0]
            elif len(axes) == 1:
                out[(i, j)] = h[1] * d[axes[0]]
            elif len(axes) == 2:
                a, b = axes
                out[(i, j)] = h[2] * d[a] * d[b] + h[1] * 2.0 * (a == b)
            else:
                a, b, e = axes
                pairs = 2.0 * ((a == b) * d[e] + (a == e) * d[b] + (b == e) * d[a])
                out[(i, j)] = h[3] * d[a] * d[b] * d[e] + h[2] * pairs
        return out

    def _phi(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        return (x - 0.5) ** 2 + (y - 0.5) ** 2 - self.radius**2

    def gap(self, x: np.ndarray) -> np.ndarray:
        """``g = ψ − u·n`` on Γ_C at points ``(n, 3)`` (read at their x, y): ``(n,)``."""
        return self.g_scale * np.maximum(self._phi(x[:, 0], x[:, 1]), 0.0) ** 4

    def pressure(self, x: np.ndarray) -> np.ndarray:
        """``p = −σ_nn`` on Γ_C at points ``(n, 3)``: ``(n,)``."""
        return self.p_scale * np.maximum(-self._phi(x[:, 0], x[:, 1]), 0.0) ** 3

    def _coefficients(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """``(3, 3, 6, n)``: ``[i, k]`` the jet to second order (the first six of
        :data:`ORDERS`) of the coefficient of ``z^k`` in ``u_i``."""
        plus = np.maximum(self._phi(x, y), 0.0)
        minus = np.maximum(-self._phi(x, y), 0.0)
        G, P = self.g_scale, self.p_scale
        g = self._profile_jet(x, y, (G * plus**4, 4 * G * plus**3, 12 * G * plus**2, 24 * G * plus))
        p = self._profile_jet(x, y, (P * minus**3, -3 * P * minus**2, 6 * P * minus, 0.0 * x))
        a1, a2 = self._poly_jet(self.a1, x, y), self._poly_jet(self.a2, x, y)
        lam, mu = self.material.lam, self.material.mu
        second = ORDERS[:6]

        def shifted(jet, di, dj):  # the jet of a derivative, to second order
            return [jet[(i + di, j + dj)] for i, j in second]

        div_a = np.add(shifted(a1, 1, 0), shifted(a2, 0, 1))
        B3 = -(np.array([p[o] for o in second]) + lam * div_a) / (lam + 2 * mu)
        rows = [
            [[a1[o] for o in second], np.negative(shifted(g, 1, 0)), self._second(self.q1, x, y)],
            [[a2[o] for o in second], np.negative(shifted(g, 0, 1)), self._second(self.q2, x, y)],
            [[g[o] for o in second], B3, self._second(self.c, x, y)],
        ]
        return np.array(rows, dtype=np.float64)

    def _second(self, coef: np.ndarray, x: np.ndarray, y: np.ndarray) -> list:
        jet = self._poly_jet(coef, x, y)
        return [jet[o] for o in ORDERS[:6]]

    # -- the displacement and its derivatives ------------------------------------------------
    def displacement(self, x: np.ndarray) -> np.ndarray:
        """``u (n, 3)`` at points ``(n, 3)``."""
        C = self._coefficients(x[:, 0], x[:, 1])[:, :, 0]  # (3, 3, n)
        z = x[:, 2]
        return (C[:, 0] + z * C[:, 1] + z**2 * C[:, 2]).T

    def _derivatives(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``∇u (n, 3, 3)`` and ``H[n, i, j, k] = ∂_j ∂_k u_i (n, 3, 3, 3)``."""
        C = self._coefficients(x[:, 0], x[:, 1])  # (3, 3 powers, 6 orders, n)
        z = x[:, 2]
        powers = np.stack([np.ones_like(z), z, z**2])  # (3, n)
        dpowers = np.stack([np.zeros_like(z), np.ones_like(z), 2 * z])
        along = np.einsum("ikon,kn->ion", C, powers)  # (3, 6, n): the jets in x, y at z
        dz = np.einsum("ikon,kn->ion", C, dpowers)  # their z-derivatives
        dzz = 2.0 * C[:, 2]  # (3, 6, n)
        n = z.size
        grad = np.empty((n, 3, 3))
        grad[:, :, 0], grad[:, :, 1], grad[:, :, 2] = along[:, 1].T, along[:, 2].T, dz[:, 0].T
        H = np.empty((n, 3, 3, 3))
        H[:, :, 0, 0], H[:, :, 1, 1], H[:, :, 2, 2] = along[:, 3].T, along[:, 5].T, dzz[:, 0].T
        H[:, :, 0, 1] = H[:, :, 1, 0] = along[:, 4].T
        H[:, :, 0, 2] = H[:, :, 2, 0] = dz[:, 1].T
        H[:, :, 1, 2] = H[:, :, 2, 1] = dz[:, 2].T
        return grad, H

    def gradient(self, x: np.ndarray) -> np.ndarray:
        """``∇u (n, 3, 3)``, ``[:, i, j] = ∂u_i/∂x_j``."""
        return self._derivatives(x)[0]

    def stress(self, x: np.ndarray) -> np.ndarray:
        """``σ(u) (n, 3, 3)``."""
        grad = self.gradient(x)
        eps = 0.5 * (grad + np.swapaxes(grad, 1, 2))
        trace = np.einsum("nii->n", eps)
        return 2 * self.material.mu * eps + self.material.lam * trace[:, None, None] * np.eye(3)

    def body_force(self, x: np.ndarray) -> np.ndarray:
        """``f = −div σ(u) = −(μ Δu + (λ + μ) ∇ div u)`` at ``x (n, 3)``."""
        H = self._derivatives(x)[1]
        laplace = np.einsum("nijj->ni", H)
        grad_div = np.einsum("njij->ni", H)
        return -(self.material.mu * laplace + (self.material.lam + self.material.mu) * grad_div)

    def traction(self, x: np.ndarray, normal: np.ndarray) -> np.ndarray:
        """``σ(u) n (n, 3)`` at points ``(n, 3)`` with unit normals ``(n, 3)``."""
        return np.einsum("nij,nj->ni", self.stress(x), normal)


#: the data of example-6.1-3d: λ = μ = 1 (as the paper's Example 6.1), R = 0.35, G = 5,
#: P = 100 (g ≤ 0.10, p ≤ 0.18), cubic tangential fields a, quadratic q and linear c
CONTACT_CUBE = ContactCube(
    material=Material.from_lame(1.0, 1.0),
    radius=0.35,
    g_scale=5.0,
    p_scale=100.0,
    a1=_poly([[0.0, 0.0, 0.0, 0.02], [0.0] * 4, [0.0, 0.02, 0.0, 0.0], [0.0] * 4]),
    a2=_poly([[0.0] * 3, [0.0, 0.0, -0.02], [0.0] * 3, [0.02, 0.0, 0.0]]),
    q1=_poly([[0.0, 0.0], [0.0, 0.03]]),
    q2=_poly([[0.0, 0.0, -0.03], [0.0] * 3, [0.03, 0.0, 0.0]]),
    c=_poly([[0.0, 0.05], [0.05, 0.0]]),
)
