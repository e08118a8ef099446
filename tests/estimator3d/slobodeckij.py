"""A brute-force reference for the H^{1/2} seminorm of ``q⁺`` on the unit square, ``q`` a
quadratic polynomial: ``∫∫ (q⁺(x) − q⁺(y))² |x − y|⁻³ dx dy`` in polar coordinates about x,
``y = x + r ω``, where the integrand ``(q⁺(x + r ω) − q⁺(x))² / r²`` is bounded; ω in panels
between the directions of the square's corners, r cut at the roots of ``q(x + r ω)`` (closed
form), Gauss–Legendre in each, and x by composite Gauss on a grid."""

from __future__ import annotations

import numpy as np


def _gauss(n):
    t, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (t + 1), 0.5 * w


def _q(c, x, y):
    return c[0] + c[1] * x + c[2] * y + c[3] * x * x + c[4] * x * y + c[5] * y * y


def seminorm2(c, panels=16, n_x=4, n_w=12, n_r=8):
    """``|q⁺|²_{H^{1/2}}`` on [0, 1]² for monomial coefficients ``c (6,)``."""
    t, wt = _gauss(n_x)
    edges = np.linspace(0.0, 1.0, panels + 1)
    g = (edges[:-1, None] + np.diff(edges)[:, None] * t).ravel()
    wg = (np.diff(edges)[:, None] * wt).ravel()
    X, Y = np.meshgrid(g, g, indexing="ij")
    X, Y, W = X.ravel(), Y.ravel(), np.outer(wg, wg).ravel()
    corners = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    ang = np.sort(np.arctan2(corners[:, 1] - Y[:, None], corners[:, 0] - X[:, None]), axis=1)
    ang = np.concatenate([ang, ang[:, :1] + 2 * np.pi], axis=1)  # 4 panels of the circle
    u, wu = _gauss(n_w)
    theta = (ang[:, :-1, None] + np.diff(ang, axis=1)[..., None] * u).reshape(len(X), -1)
    wth = (np.diff(ang, axis=1)[..., None] * wu).reshape(len(X), -1)
    ox, oy = np.cos(theta), np.sin(theta)
    with np.errstate(divide="ignore"):
        rx = np.where(ox > 0, (1 - X[:, None]) / ox, np.where(ox < 0, -X[:, None] / ox, np.inf))
        ry = np.where(oy > 0, (1 - Y[:, None]) / oy, np.where(oy < 0, -Y[:, None] / oy, np.inf))
    R = np.minimum(rx, ry)
    x0, y0 = X[:, None], Y[:, None]
    # q(x + r ω) = a + b r + e r²
    a = _q(c, x0, y0) + 0 * ox
    b = (c[1] + 2 * c[3] * x0 + c[4] * y0) * ox + (c[2] + c[4] * x0 + 2 * c[5] * y0) * oy
    e = c[3] * ox * ox + c[4] * ox * oy + c[5] * oy * oy
    disc = b * b - 4 * a * e
    sq = np.sqrt(np.maximum(disc, 0))
    with np.errstate(divide="ignore", invalid="ignore"):
        r1 = np.where(e != 0, (-b - sq) / (2 * e), -a / b)
        r2 = np.where(e != 0, (-b + sq) / (2 * e), np.nan)
    roots = np.stack([r1, r2], axis=-1)
    roots = np.where(
        (disc >= 0)[..., None] & (roots > 0) & (roots < R[..., None]), roots, R[..., None]
    )
    cuts = np.sort(np.concatenate([np.zeros_like(R)[..., None], roots, R[..., None]], -1), -1)
    s, ws = _gauss(n_r)
    qx = np.maximum(a, 0.0)
    total = 0.0
    for j in range(3):
        lo, hi = cuts[..., j : j + 1], cuts[..., j + 1 : j + 2]
        r = lo + (hi - lo) * s
        qy = np.maximum(a[..., None] + r * (b[..., None] + r * e[..., None]), 0.0)
        f = (qy - qx[..., None]) ** 2 / (r * r)
        total += np.einsum("pwr,r,pw,pw,p->", f, ws, (hi - lo)[..., 0], wth, W)
    return float(total)


def l2_norm2(c, panels=16, n_x=6):
    """``‖q⁺‖²`` on the unit square by composite Gauss (a check of the face norms)."""
    t, wt = _gauss(n_x)
    edges = np.linspace(0.0, 1.0, panels + 1)
    g = (edges[:-1, None] + np.diff(edges)[:, None] * t).ravel()
    wg = (np.diff(edges)[:, None] * wt).ravel()
    X, Y = np.meshgrid(g, g, indexing="ij")
    return float((np.outer(wg, wg) * np.maximum(_q(c, X, Y), 0.0) ** 2).sum())
