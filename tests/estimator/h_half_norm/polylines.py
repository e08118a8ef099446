"""Edge data for the H^{1/2} tests: polylines carrying a quadratic per edge.

``w`` always holds the values at ``[start, end, midpoint]`` (the package's P2 edge-node
order). The monomial form is written out here, independently of the package.

Closed forms used by the tests (t = arc length, ``|·|^2_{1/2}`` the double integral):

* ``v = t`` on [0, 1]: ``1``;  ``v = t^2``: ``∫∫ (t + s)^2 = 7/6``;
  ``v = (t - 1/2)^2``: ``∫∫ (t + s - 1)^2 = 1/6``.
* ``v = (t - a)^+`` on [0, 1]: ``(1 - a)^2 + 2 ∫_0^{1-a} τ^2 (1/τ - 1/(τ + a)) dτ
  = 1 - a^2 + 2 a^2 ln a``.
* hat ``(1 - |t|)^+`` on [-L, L]: ``8 - 8 ln 2 + 4 K(L)`` with
  ``K = 2L - 2 + 4 ln 2 - (L-1)^2 ln(L/(L-1)) - (L+1)^2 ln((L+1)/L)``
  (the first part from ``∫_0^1∫_0^1 (x-s)^2/(x+s)^2 = 3 - 4 ln 2``, ``K`` from
  ``∫_0^1 (1-x)^2 [1/(1-x) - 1/(L-x) + 1/(1+x) - 1/(L+x)] dx``).
* L-shape (unit arms along e1 and e2 from the corner): ``v = x`` on the
  horizontal arm, 0 on the vertical one: ``1 + 2 ∫_0^1 x arctan(1/x) dx = 2``;
  ``v = x`` and ``v = y``: ``2 + 2 ∫∫ (x-y)^2/(x^2+y^2) = 4 - 2 ln 2``.
* two unit segments, v = 1 on one and 0 on the other: at distance 1 on the
  same line ``2 ln(4/3)``; parallel at distance 1 ``π - 2 ln 2``.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import quad

LN2 = np.log(2.0)
L_SHAPE = [[0.0, 1.0], [0.0, 0.0], [1.0, 0.0]]


def monomials(w):
    """``a, b, c`` with ``w(s) = a + b s + c s²`` from values at [start, end, midpoint]."""
    w0, w1, wm = w[:, 0], w[:, 1], w[:, 2]
    return w0, -3 * w0 - w1 + 4 * wm, 2 * w0 + 2 * w1 - 4 * wm


def polyline(vertices, f, breaks=None):
    """Edges of the polyline through ``vertices``; each segment cut at ``breaks``.

    ``f(points (n, 2)) -> (n,)`` gives w, sampled at start, end and midpoint
    (so w is exactly f wherever f is a quadratic along each edge).
    ``breaks`` lists, per segment, interior cut parameters in (0, 1).
    """
    vertices = np.asarray(vertices, dtype=float)
    x0, x1 = [], []
    for i, (p, q) in enumerate(zip(vertices[:-1], vertices[1:], strict=True)):
        cuts = [] if breaks is None else list(breaks[i])
        t = np.array([0.0, *sorted(cuts), 1.0])
        x0.append(p + t[:-1, None] * (q - p))
        x1.append(p + t[1:, None] * (q - p))
    x0, x1 = np.concatenate(x0), np.concatenate(x1)
    w = np.column_stack([f(x0), f(x1), f(0.5 * (x0 + x1))])
    return x0, x1, w


def on_line(t, f):
    """Edges [t_i, t_{i+1}] x {0} of the x-axis with w = f(x)."""
    t = np.asarray(t, dtype=float)
    x0 = np.column_stack([t[:-1], np.zeros(t.size - 1)])
    x1 = np.column_stack([t[1:], np.zeros(t.size - 1)])
    w = np.column_stack([f(t[:-1]), f(t[1:]), f(0.5 * (t[:-1] + t[1:]))])
    return x0, x1, w


def refine_edges(x0, x1, w, n):
    """Split every edge into ``n`` equal edges carrying the same quadratic."""
    a, b, c = monomials(w)

    def q(s):
        return a[:, None] + s * (b[:, None] + s * c[:, None])

    s0 = np.arange(n) / n
    s1 = (np.arange(n) + 1) / n
    nx0 = x0[:, None, :] + s0[None, :, None] * (x1 - x0)[:, None, :]
    nx1 = x0[:, None, :] + s1[None, :, None] * (x1 - x0)[:, None, :]
    nw = np.stack([q(s0), q(s1), q(0.5 * (s0 + s1))], axis=-1)
    return nx0.reshape(-1, 2), nx1.reshape(-1, 2), nw.reshape(-1, 3)


def rigid(points, angle, shift):
    c, s = np.cos(angle), np.sin(angle)
    return points @ np.array([[c, s], [-s, c]]) + np.asarray(shift)


def monotone_polyline(seed, n_seg=5, n_cut=2):
    """A random x-monotone (hence non-self-intersecting) polyline with a random w."""
    rng = np.random.default_rng(seed)
    xs = np.cumsum(rng.uniform(0.3, 1.0, n_seg + 1))
    ys = rng.uniform(-0.8, 0.8, n_seg + 1)
    vertices = np.column_stack([xs, ys])
    breaks = [rng.uniform(0.05, 0.95, n_cut) for _ in range(n_seg)]
    x0, x1, _ = polyline(vertices, lambda p: p[:, 0], breaks)
    k = x0.shape[0]
    nodal = rng.normal(0.2, 1.0, k + 1)
    mid = rng.normal(0.2, 1.0, k)
    return x0, x1, np.column_stack([nodal[:-1], nodal[1:], mid])


def quadratic_max(w):
    """Exact maximum over [0, 1] of the quadratic through [start, end, midpoint] values."""
    a, b, c = monomials(w)
    out = np.maximum(w[:, 0], w[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(c < 0, -b / (2 * c), -1.0)
    inner = (s > 0) & (s < 1)
    return np.where(inner, np.maximum(out, a + s * (b + s * c)), out)


def hat_closed_form(L):
    """Seminorm of the hat ``(1 - |t|)^+`` on [-L, L] (module notes)."""
    if L == 1.0:
        k = 0.0
    else:
        k = (
            2 * L
            - 2
            + 4 * LN2
            - (L - 1) ** 2 * np.log(L / (L - 1))
            - (L + 1) ** 2 * np.log((L + 1) / L)
        )
    return 8 - 8 * LN2 + 4 * k


def brute_force_seminorm(x0, x1, w):
    """Nested adaptive quad of (v(x)-v(y))^2/|x-y|^2, v = max(w, 0) evaluated pointwise.

    Every pair of edges is integrated separately, with the kinks of v (roots found
    by ``np.roots``) and the diagonal passed to QUADPACK as break points.
    """
    a, b, c = monomials(w)
    length = np.hypot(*(x1 - x0).T)
    kinks = []
    for i in range(len(x0)):
        r = np.roots([c[i], b[i], a[i]]) if c[i] != 0 else np.roots([b[i], a[i]])
        kinks.append(sorted(float(z.real) for z in r if abs(z.imag) < 1e-14 and 0 < z.real < 1))

    def v(i, t):
        return max(a[i] + t * (b[i] + t * c[i]), 0.0)

    total = 0.0
    for i in range(len(x0)):
        for j in range(len(x0)):

            def inner(t, i=i, j=j):
                x = x0[i] + t * (x1[i] - x0[i])
                vx = v(i, t)

                def f(s):
                    d = x - x0[j] - s * (x1[j] - x0[j])
                    d2 = d @ d
                    return 0.0 if d2 == 0.0 else (vx - v(j, s)) ** 2 / d2

                brk = kinks[j] + ([t] if i == j else [])
                val = quad(f, 0, 1, points=brk or None, epsabs=1e-15, epsrel=1e-12, limit=200)
                return val[0] * length[j]

            val = quad(inner, 0, 1, points=kinks[i] or None, epsabs=1e-15, epsrel=1e-12, limit=200)
            total += val[0] * length[i]
    return total
