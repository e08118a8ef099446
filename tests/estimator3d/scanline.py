"""An independent reference for integrals over ``{v > 0}`` on the reference triangle: scan
lines ``s₂ = y``, on each the quadratic in ``s₁`` cut at its roots in closed form, and in ``y``
panels between every ``y`` where the cut changes its kind (a root meeting a side, a hat's kink
line or a tangency), each panel smoothed at both ends (``y = y₀ + (y₁ − y₀)(3u² − 2u³)``,
which makes the square-root ends of tangencies analytic) and integrated by Gauss–Legendre.
Shares nothing with :mod:`signorini.estimator.surface` but the monomial form of ``v``."""

from __future__ import annotations

import numpy as np


def _real_roots(a, b, c):
    """Roots of ``a + b y + c y²`` (rows), NaN where none (``(k, 2)``)."""
    a, b, c = np.broadcast_arrays(*(np.asarray(z, dtype=np.float64) for z in (a, b, c)))
    disc = b * b - 4 * a * c
    sq = np.sqrt(np.maximum(disc, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        quad = np.stack([(-b - sq) / (2 * c), (-b + sq) / (2 * c)], axis=1)
        lin = np.where(b != 0, -a / b, np.nan)
    out = np.where((c != 0)[:, None], quad, np.stack([lin, np.full_like(lin, np.nan)], axis=1))
    out[(disc < 0) & (c != 0)] = np.nan
    return out


def _breaks(c):
    """``(k, n)`` the y where the cut of each face changes kind, with 0, 1/2 and 1."""
    c0, c1, c2, c3, c4, c5 = c.T
    k = len(c)
    # v(x, y) = A(y) + B(y) x + c3 x², A = c0 + c2 y + c5 y², B = c1 + c4 y
    rows = [
        _real_roots(c0, c2, c5),  # root at x = 0
        # x = 1 − y: v = c0 + c1 + c3 + y (c2 − c1 + c4 − 2 c3) + y² (c3 − c4 + c5)
        _real_roots(c0 + c1 + c3, c2 - c1 + c4 - 2 * c3, c3 - c4 + c5),
        # x = 1/2
        _real_roots(c0 + c1 / 2 + c3 / 4, c2 + c4 / 2, c5),
        # x = 1/2 − y
        _real_roots(c0 + c1 / 2 + c3 / 4, c2 - c1 + c4 / 2 - c3, c3 - c4 + c5),
        # tangency: B² − 4 c3 A = 0
        _real_roots(c1**2 - 4 * c3 * c0, 2 * c1 * c4 - 4 * c3 * c2, c4**2 - 4 * c3 * c5),
    ]
    y = np.concatenate(rows + [np.tile([0.0, 0.5, 1.0], (k, 1))], axis=1)
    y = np.where((y >= 0) & (y <= 1), y, 1.0)
    return np.sort(y, axis=1)


def piece_of(s):
    """The triangle of the once-refined face that each point lies in."""
    x, y = s[..., 0], s[..., 1]
    return np.where(x + y < 0.5, 0, np.where(x > 0.5, 1, np.where(y > 0.5, 2, 3)))


def integrate(c, f, n_outer=48, n_inner=8):
    """``∫_{T̂ ∩ {v > 0}} f`` for each face with monomial coefficients ``c (k, 6)``;
    ``f(face, s (k, m, 2)) -> (k, m)`` or ``(k, m, p)`` (then the result is ``(k, p)``)."""
    k = len(c)
    yb = _breaks(c)
    u, wu = np.polynomial.legendre.leggauss(n_outer)
    u, wu = 0.5 * (u + 1), 0.5 * wu
    smooth, dsmooth = 3 * u**2 - 2 * u**3, 6 * u * (1 - u)
    y0, y1 = yb[:, :-1, None], yb[:, 1:, None]
    y = (y0 + (y1 - y0) * smooth).reshape(k, -1)  # (k, ny)
    wy = ((y1 - y0) * wu * dsmooth).reshape(k, -1)
    c0, c1, c2, c3, c4, c5 = (z[:, None] for z in c.T)
    A, B = c0 + c2 * y + c5 * y * y, c1 + c4 * y
    length = 1 - y
    roots = _real_roots(A.ravel(), B.ravel(), np.repeat(c3[:, 0], y.shape[1])).reshape(k, -1, 2)
    kinks = np.stack([0.5 - y, np.full_like(y, 0.5)], axis=-1)
    xb = np.concatenate([np.zeros_like(y)[..., None], roots, kinks, length[..., None]], axis=-1)
    xb = np.where(np.isnan(xb), 0.0, np.clip(xb, 0.0, length[..., None]))
    xb = np.sort(xb, axis=-1)
    t, wt = np.polynomial.legendre.leggauss(n_inner)
    t, wt = 0.5 * (t + 1), 0.5 * wt
    total = 0.0
    for j in range(xb.shape[-1] - 1):
        x0, x1 = xb[..., j : j + 1], xb[..., j + 1 : j + 2]
        x = x0 + (x1 - x0) * t  # (k, ny, nt)
        yy = np.broadcast_to(y[..., None], x.shape)
        s = np.stack([x, yy], axis=-1).reshape(k, -1, 2)
        v = (A[..., None] + B[..., None] * x + c3[..., None] * x * x).reshape(k, -1)
        mid = 0.5 * (x0 + x1)
        vm = A[..., None] + B[..., None] * mid + c3[..., None] * mid * mid
        val = f(np.arange(k), s)
        val = val.reshape(x.shape + val.shape[2:])
        sign = ((v.reshape(x.shape) > 0) & (vm > 0)).reshape(x.shape + (1,) * (val.ndim - 3))
        weight = wt * ((x1 - x0) * wy[..., None])  # (k, ny, nt)
        total = total + np.einsum("knt...,knt->k...", val * sign, weight)
    return total
